"""The start handshake: a node starts once every link it has is matched, and says so."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

from rclpy.node import Node
from std_msgs.msg import String

from landing_gear_sim.errors import GraphError
from landing_gear_sim.ros.graph import TOPIC_READY
from landing_gear_sim.ros.nodes.parameters import declare
from landing_gear_sim.ros.nodes.topics import LATCHED_QOS

if TYPE_CHECKING:
    from landing_gear_sim.ros.nodes.graph_node import GraphNode

HANDSHAKE_PERIOD_S = 0.02


class Handshake:
    """Start only when every link is matched.

    A node is *linked* when each of its publishers has the number of matched
    subscribers the graph description expects (``expected_subscribers``:
    ``topic=count``) and each of its subscriptions has a publisher. Peers announce
    it on :data:`TOPIC_READY`; the plant waits for them (``peers``).
    """

    def __init__(self, node: Node, publishers: dict[str, Any], subscriptions: Iterable[Any],
                 on_linked: Callable[[], None], expected: dict[str, int] | None = None) -> None:
        self._node = node
        if expected is None:
            expected = _parse_counts(declare(node, "expected_subscribers", [""],
                                             "topic=count: matched readers to wait for"))
        self._expected = expected
        self._publishers = publishers
        self._subscriptions = list(subscriptions)
        self._on_linked = on_linked
        self._started = time.monotonic()
        self._timer = node.create_timer(HANDSHAKE_PERIOD_S, self._check)

    def missing(self) -> list[str]:
        """Links not matched yet, in words."""
        gaps = [f"{topic} has {self._publishers[topic].get_subscription_count()}/{count} readers"
                for topic, count in self._expected.items()
                if self._publishers[topic].get_subscription_count() < count]
        gaps += [f"no publisher on {s.topic_name}" for s in self._subscriptions
                 if s.get_publisher_count() < 1]
        return gaps

    def _check(self) -> None:
        if self.missing():
            return
        self._timer.cancel()
        self._node.destroy_timer(self._timer)
        self._on_linked()


def _parse_counts(items: Iterable[str]) -> dict[str, int]:
    counts = {}
    for item in items:
        if not item:
            continue
        topic, _, count = str(item).partition("=")
        if not count.isdigit():
            raise GraphError(f"expected_subscribers: {item!r} is not topic=count")
        counts[topic] = int(count)
    return counts


def ready_message(name: str, run_id: str) -> str:
    """What a node says on TOPIC_READY: its name and its session (see :func:`read_ready`)."""
    return f"{name} {run_id}".rstrip()


def read_ready(text: str) -> tuple[str, str]:
    """(node name, session) of a TOPIC_READY message (a node name holds no space)."""
    name, _, run_id = text.partition(" ")
    return name, run_id


def announce_ready(node: GraphNode) -> Callable[[], None]:
    """A callback that tells the plant this node is linked (latched, once)."""
    publisher = node.publisher(String, TOPIC_READY, LATCHED_QOS)

    def ready() -> None:
        publisher.publish(String(data=ready_message(node.get_name(), node.run_id)))
        node.get_logger().info("linked; waiting for the plant")

    return ready

