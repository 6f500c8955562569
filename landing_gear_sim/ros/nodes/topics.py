"""The graph's topics as a node sees them: names relative to its namespace, QoS, each contract
topic's message class, the brake command's message, and what the graph shows unlinked."""

from __future__ import annotations

from typing import Any

from geometry_msgs.msg import WrenchStamped
from rclpy.node import Node, NodeNameNonExistentError
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import FluidPressure, JointState

from msg_tools.contract import (
    NAMESPACE,
    TOPIC_CURRENT,
    TOPIC_FLYWHEEL,
    TOPIC_PRESSURE,
    TOPIC_TYPES,
    TOPIC_WHEEL,
    TOPIC_WRENCH,
    VALVE_JOINT,
)

DATA_QOS = QoSProfile(reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST,
                      depth=5000, durability=DurabilityPolicy.VOLATILE)
"""Every data link: reliable, and deep enough that a slow recorder loses nothing for seconds."""
LATCHED_QOS = QoSProfile(reliability=ReliabilityPolicy.RELIABLE,
                         history=HistoryPolicy.KEEP_LAST, depth=50,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
"""Run end and readiness: late joiners still get them."""

CONTRACT_KINDS = {TOPIC_CURRENT: JointState, TOPIC_PRESSURE: FluidPressure, TOPIC_WHEEL: JointState,
                  TOPIC_FLYWHEEL: JointState, TOPIC_WRENCH: WrenchStamped}
"""rclpy message class of each contract topic (msg_tools.contract.TOPIC_TYPES)."""


def relative(topic: str) -> str:
    """A contract topic (``/rig/brake/pressure``) relative to the node's namespace
    (``brake/pressure``), so that the namespace moves it; others (``/clock``) as they are."""
    return topic.removeprefix(f"/{NAMESPACE}/")



def command_message() -> JointState:
    """A brake command to fill: ``effort[0]`` is the valve current [A]; the stamp ends the
    interval it holds for (:data:`msg_tools.contract.TOPIC_CURRENT`)."""
    message = JointState(name=[VALVE_JOINT], effort=[0.0])
    message.header.frame_id = VALVE_JOINT
    return message


def command_current(message: JointState) -> float | None:
    """The valve current [A] a command carries, or None when it names no valve effort."""
    names = list(message.name)
    index = names.index(VALVE_JOINT) if VALVE_JOINT in names else 0 if not names else -1
    return float(message.effort[index]) if 0 <= index < len(message.effort) else None



def outside_gaps(node: Node, publishers: dict[str, Publisher]) -> list[str]:
    """What the graph shows that is not linked yet, in words: readers of ``publishers``
    not matched, no node publishing brake commands, or a command publisher (an outside
    controller the plant was not told about) that does not read the plant's samples yet."""
    gaps = [f"{p.topic_name}: {p.get_subscription_count()} of {shown} readers matched"
            for p in publishers.values()
            if (shown := node.count_subscribers(p.topic_name)) > p.get_subscription_count()]
    commands = command_topic(node)
    samples = node.resolve_topic_name(relative(TOPIC_WHEEL))
    writers = {_full_name(i) for i in node.get_publishers_info_by_topic(commands)}
    readers = {_full_name(i) for i in node.get_subscriptions_info_by_topic(samples)}
    if not writers:
        gaps.append(f"no node publishes brake commands on {commands} (an outside controller "
                    "not started?)")
    gaps += [f"{name} publishes {commands} but does not read {samples} yet"
             for name in sorted(writers - readers)]
    return gaps


def command_topic(node: Node) -> str:
    """The topic the actuator beside ``node`` reads brake commands from, as the graph shows
    it: a user remaps it on the actuator and the command source (``-r
    brake/current_ref:=brake/cmd``), not on the plant. The contract's name, resolved for
    ``node``, while no actuator is seen."""
    default = node.resolve_topic_name(relative(TOPIC_CURRENT))
    try:
        read = node.get_subscriber_names_and_types_by_node("actuator", node.get_namespace())
    except NodeNameNonExistentError:
        return default
    commands = [topic for topic, types in read if TOPIC_TYPES[TOPIC_CURRENT] in types]
    return commands[0] if len(commands) == 1 else default


def _full_name(endpoint: Any) -> str:
    return f"{endpoint.node_namespace.rstrip('/')}/{endpoint.node_name}"

