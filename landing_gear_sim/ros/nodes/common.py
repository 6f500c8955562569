"""What every node of the graph shares: parameters, QoS, stamps, the start handshake, main().

The nodes are thin: they declare parameters, create publishers and subscriptions,
and call the blocks of :mod:`landing_gear_sim.model.blocks` once per message.
"""

from __future__ import annotations

import logging
import os
import signal
import sys
import time
from collections.abc import Callable, Iterable
from typing import Any

import rclpy
from builtin_interfaces.msg import Time
from geometry_msgs.msg import WrenchStamped
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.executors import ExternalShutdownException
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node, NodeNameNonExistentError
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerGuardCondition
from rclpy.subscription import Subscription
from sensor_msgs.msg import FluidPressure, JointState
from std_msgs.msg import String, UInt64

from landing_gear_sim.errors import GraphError, LandingGearSimError
from landing_gear_sim.model.blocks import step_time
from landing_gear_sim.ros.graph import TOPIC_READY, TOPIC_RUN_END
from landing_gear_sim.ros.nodes import stop_requested
from landing_gear_sim.ros.nodes.parameters import check_overrides, declare, refuse_changes
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

RCLError = _rclpy.RCLError  # what rcl raises once its context is shut down

DATA_QOS = QoSProfile(reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST,
                      depth=5000, durability=DurabilityPolicy.VOLATILE)
"""Every data link: reliable, and deep enough that a slow recorder loses nothing for seconds."""
LATCHED_QOS = QoSProfile(reliability=ReliabilityPolicy.RELIABLE,
                         history=HistoryPolicy.KEEP_LAST, depth=50,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
"""Run end and readiness: late joiners still get them."""

HANDSHAKE_PERIOD_S = 0.02

CONTRACT_KINDS = {TOPIC_CURRENT: JointState, TOPIC_PRESSURE: FluidPressure, TOPIC_WHEEL: JointState,
                  TOPIC_FLYWHEEL: JointState, TOPIC_WRENCH: WrenchStamped}
"""rclpy message class of each contract topic (msg_tools.contract.TOPIC_TYPES)."""


def to_stamp(time_s: float) -> Time:
    return stamp_of_ns(round(time_s * 1e9))


def stamp_of_ns(nanoseconds: int) -> Time:
    return Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


def ns_of(stamp: Time) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


class RunClock:
    """Sample k of a run ↔ its stamp: origin + k·h, to the nanosecond.

    Lockstep runs on sim time from 0 (``origin_ns=0``). In real time the plant stamps
    sample 0 with the ROS clock when the run starts, and every other node takes that stamp
    as the origin from the first sample it receives (:meth:`observe`), so stamps are ROS
    time (``ros2 topic delay`` works) and indices stay exact.
    """

    def __init__(self, step_s: float, origin_ns: int | None = 0) -> None:
        self.step_s = step_s
        self.origin_ns = origin_ns

    def observe(self, stamp: Time) -> None:
        """Take ``stamp`` as the origin if none is known yet (the run's first sample)."""
        if self.origin_ns is None:
            self.origin_ns = ns_of(stamp)

    def step_of(self, stamp: Time) -> int:
        """The step a stamp belongs to (stamps are origin + k·h rounded to 1 ns)."""
        return round((ns_of(stamp) - (self.origin_ns or 0)) * 1e-9 / self.step_s)

    def stamp(self, step: int) -> Time:
        return stamp_of_ns((self.origin_ns or 0) + round(step_time(step, self.step_s) * 1e9))


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


_NO_PUB_EVENTS = PublisherEventCallbacks(use_default_callbacks=False)
_NO_SUB_EVENTS = SubscriptionEventCallbacks(use_default_callbacks=False)


def say(node: Node, message: str) -> None:
    """Log ``message`` through ROS, or plainly once a signal has shut ROS down (rcl can no
    longer publish to /rosout then, and says so on stderr)."""
    if node.context.ok():
        node.get_logger().info(message)
    else:
        print(f"[{node.get_name()}] {message}", file=sys.stderr, flush=True)


def relative(topic: str) -> str:
    """A contract topic (``/rig/brake/pressure``) relative to the node's namespace
    (``brake/pressure``), so that the namespace moves it; others (``/clock``) as they are."""
    return topic.removeprefix(f"/{NAMESPACE}/")


class RunFinishedError(Exception):
    """Raised inside the executor to leave spin() once a node's work is done."""


class GraphNode(Node):
    """A node of the rig graph: it leaves once the plant announces the run's end.

    Subclasses override :meth:`pending` (work still due after the end, e.g. the
    recorder's last messages) and :meth:`close` (release files, always called).
    Parameter services are served by :func:`spin` unless ``parameter_services`` is false.
    """

    def __init__(self, name: str) -> None:
        # ``-r __ns:=/rig2`` (or launch's namespace) moves the node and all its topics
        super().__init__(name, namespace=NAMESPACE)
        self.serves_parameters = bool(declare(
            self, "parameter_services", True, "serve ros2 param (false: the last bit of "
            "lockstep speed, no services)"))
        self.run_id = str(declare(self, "run_id", "", "identity of the session this node "
                                  "takes part in (the plant starts only with its own)"))
        self.run_samples: int | None = None
        self.exit_code = 0  # what the process exits with once the run is over
        self.subscription(UInt64, TOPIC_RUN_END, self._on_run_end, LATCHED_QOS)

    def publisher(self, kind: Any, topic: str, qos: QoSProfile = DATA_QOS) -> Publisher:
        """A publisher without rclpy's default QoS-event handlers (each one is polled every
        executor wait; measured: they cost the graph a tenth of its step rate)."""
        return self.create_publisher(kind, relative(topic), qos, event_callbacks=_NO_PUB_EVENTS)

    def subscription(self, kind: Any, topic: str, callback: Callable[[Any], None],
                     qos: QoSProfile = DATA_QOS, raw: bool = False) -> Subscription:
        """A subscription without the default QoS-event handlers (see :meth:`publisher`)."""
        return self.create_subscription(kind, relative(topic), callback, qos, raw=raw,
                                        event_callbacks=_NO_SUB_EVENTS)

    def pending(self) -> bool:
        return False

    def close(self) -> None:
        """Called once when the node stops, however it stops."""

    def _on_run_end(self, message: UInt64) -> None:
        if self.run_samples is None:
            self.run_samples = int(message.data)
            self.create_timer(0.05, self._leave_when_done)

    def _leave_when_done(self) -> None:
        if not self.pending():
            raise RunFinishedError(self.get_name())


SERVICE_POLL_S = 0.05
"""How often :func:`spin` answers waiting service requests (``ros2 param``)."""


def spin(node: Node) -> None:
    """Run the node's subscriptions and timers until shutdown (SIGINT/SIGTERM) or an error.

    A lean stand-in for rclpy's SingleThreadedExecutor: one wait set over the node's
    subscriptions and timers, and every message waiting on a ready subscription taken in
    the same wake-up. rclpy's executor builds tasks and a wait set per callback; measured
    here, a two-process ping-pong ran 2900 round trips/s with it and 5400 with this loop.
    Services (``ros2 param``, type descriptions) are answered from a second wait set polled
    every :data:`SERVICE_POLL_S`, so the lockstep exchange does not pay for them per step.
    """
    context = node.context
    handle = context.handle
    if handle is None or not context.ok():  # a signal came while the node was being built
        return
    shutdown = SignalHandlerGuardCondition(context)
    serve = not isinstance(node, GraphNode) or node.serves_parameters
    wait_ns = round(SERVICE_POLL_S * 1e9) if serve else -1
    polled = time.monotonic()
    node.get_logger().info("running (SIGINT or SIGTERM stops it)")
    try:
        while context.ok():
            subscriptions = list(node.subscriptions)
            timers = [t for t in node.timers if not t.is_canceled()]
            wait_set = _rclpy.WaitSet(len(subscriptions), 1, len(timers), 0, 0, 0, handle)
            for subscription in subscriptions:
                wait_set.add_subscription(subscription.handle)
            for timer in timers:
                wait_set.add_timer(timer.handle)
            wait_set.add_guard_condition(shutdown.handle)
            wait_set.wait(wait_ns)
            if not context.ok():
                raise ExternalShutdownException()
            _run_timers(timers, wait_set.get_ready_entities("timer"))
            _take_all(subscriptions, wait_set.get_ready_entities("subscription"))
            if serve and time.monotonic() - polled >= SERVICE_POLL_S:
                _answer(list(node.services), handle)
                polled = time.monotonic()
    finally:
        shutdown.destroy()


def _answer(services: list[Any], handle: Any) -> None:
    """Answer every request waiting on ``services`` now (a wait set that does not block)."""
    wait_set = _rclpy.WaitSet(0, 0, 0, 0, len(services), 0, handle)
    for service in services:
        wait_set.add_service(service.handle)
    wait_set.wait(0)
    ready = wait_set.get_ready_entities("service")
    for service in services:
        if service.handle.pointer not in ready:
            continue
        with service.handle:
            request, header = service.handle.service_take_request(service.srv_type.Request)
        if header is not None:
            service.send_response(service.callback(request, service.srv_type.Response()),
                                  header)


def _run_timers(timers: list[Any], ready: list[int]) -> None:
    for timer in timers:
        if timer.handle.pointer in ready and not timer.is_canceled():
            with timer.handle:
                timer.handle.call_timer_with_info()
            timer.callback()


def _take_all(subscriptions: list[Subscription], ready: list[int]) -> None:
    for subscription in subscriptions:
        if subscription.handle.pointer not in ready:
            continue
        while True:
            with subscription.handle:
                taken = subscription.handle.take_message(subscription.msg_type,
                                                         subscription.raw)
            if taken is None:
                break
            subscription.callback(taken[0])  # type: ignore[call-arg]  # message-only callbacks


def run_node(factory: Callable[[], Node], args: list[str] | None = None) -> int:
    """init, build the node, spin until the run ends or a signal; one error line on failure."""
    node = None
    try:
        rclpy.init(args=args)  # its handlers take SIGINT/SIGTERM from here on
        if stop_requested():  # one came while the node was starting (see nodes/__init__)
            return 0
        node = factory()
        check_overrides(node)
        node.add_on_set_parameters_callback(lambda changes: refuse_changes(node, changes))
        spin(node)
    except (RunFinishedError, KeyboardInterrupt, ExternalShutdownException):
        pass
    except LandingGearSimError as exc:
        print(f"{_program()}: error: {exc}", file=sys.stderr)
        return 2
    except RCLError:
        if rclpy.ok():
            raise
        # a signal shut the context down while the node was being set up: a clean stop
    finally:
        if isinstance(node, GraphNode):
            node.close()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
        # the work is done: a second Ctrl-C (ros2 launch forwards one after the terminal's)
        # must not kill the exit, which Python makes with default handlers (exit -2)
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
    return node.exit_code if isinstance(node, GraphNode) else 0


def _program() -> str:
    name = sys.argv[0].rsplit("/", 1)[-1]
    return name[:-3] if name.endswith(".py") else name


def _leave(code: int) -> None:
    """Exit now that the node is closed (bag, rclpy): without the interpreter's teardown,
    whose garbage collection over numpy, scipy and numba objects took 2.6 s of a 4.4 s stop
    on a loaded machine, past launch's grace (it escalated to SIGTERM and SIGKILL)."""
    logging.shutdown()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


def main_for(factory: Callable[[], Node]) -> Callable[[], None]:
    """A console-script ``main`` for a node class."""

    def main(args: list[str] | None = None) -> None:
        code = run_node(factory, args)
        _leave(code)

    return main
