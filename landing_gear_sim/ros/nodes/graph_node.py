"""A node of the rig graph: its base class, its lean spin loop, and its process's main().

The nodes are thin: they declare parameters, create publishers and subscriptions,
and call the blocks of :mod:`landing_gear_sim.model.blocks` once per message.
"""

from __future__ import annotations

import logging
import os
import signal
import sys
import time
from collections.abc import Callable
from typing import Any

import rclpy
from rclpy.duration import Duration
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.executors import ExternalShutdownException
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import QoSProfile
from rclpy.signals import SignalHandlerGuardCondition
from rclpy.subscription import Subscription
from std_msgs.msg import UInt64

from landing_gear_sim.errors import LandingGearSimError
from landing_gear_sim.ros.graph import FOR_THE_BAG, RECORDER, TOPIC_RUN_END
from landing_gear_sim.ros.nodes import stop_requested
from landing_gear_sim.ros.nodes.parameters import check_overrides, declare, refuse_changes
from landing_gear_sim.ros.nodes.topics import DATA_QOS, LATCHED_QOS, relative
from msg_tools.contract import NAMESPACE

RCLError = _rclpy.RCLError  # what rcl raises once its context is shut down

END_ACK_S = 8.0
"""The longest a node stays on after the run's end for the recorder to acknowledge what it
published for the bag; under the launcher's grace of 10 s."""

_NO_PUB_EVENTS = PublisherEventCallbacks(use_default_callbacks=False)
_NO_SUB_EVENTS = SubscriptionEventCallbacks(use_default_callbacks=False)


def say(node: Node, message: str, error: bool = False) -> None:
    """Log ``message`` (an ``error``, or information) through ROS, or plainly once a signal
    has shut ROS down (rcl can no longer publish to /rosout then, and says so on stderr)."""
    if node.context.ok() and error:  # rclpy: one severity per call site, or ValueError
        node.get_logger().error(message)
    elif node.context.ok():
        node.get_logger().info(message)
    else:
        print(f"[{node.get_name()}] {'error: ' * error}{message}", file=sys.stderr, flush=True)


class RunFinishedError(Exception):
    """Raised inside the executor to leave spin() once a node's work is done."""


class GraphNode(Node):
    """A node of the rig graph: it leaves once the plant announces the run's end.

    Subclasses override :meth:`pending` (work still due after the end, e.g. the
    recorder's last messages; by default, what it published for the bag that the recorder
    has yet to acknowledge) and :meth:`close` (release files, always called).
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
        self._for_the_bag: list[Publisher] = []
        self.every_reader = False  # True: waits for every reader, not only the recorder
        self._ended_at: float | None = None
        self.exit_code = 0  # what the process exits with once the run is over
        self.subscription(UInt64, TOPIC_RUN_END, self._on_run_end, LATCHED_QOS)

    def publisher(self, kind: Any, topic: str, qos: QoSProfile = DATA_QOS) -> Publisher:
        """A publisher without rclpy's default QoS-event handlers (each one is polled every
        executor wait; measured: they cost the graph a tenth of its step rate)."""
        publisher = self.create_publisher(kind, relative(topic), qos,
                                          event_callbacks=_NO_PUB_EVENTS)
        if topic in FOR_THE_BAG:
            self._for_the_bag.append(publisher)
        return publisher

    def subscription(self, kind: Any, topic: str, callback: Callable[[Any], None],
                     qos: QoSProfile = DATA_QOS, raw: bool = False) -> Subscription:
        """A subscription without the default QoS-event handlers (see :meth:`publisher`)."""
        return self.create_subscription(kind, relative(topic), callback, qos, raw=raw,
                                        event_callbacks=_NO_SUB_EVENTS)

    def pending(self) -> bool:
        """Whether the recorder has yet to acknowledge what this node published for the bag
        (for at most END_ACK_S after the run's end). DDS keeps a message only in its writer
        until every reader has it: a profile node that left at the end took with it the
        commands a starved recorder had not received, and the bag lacked them (853, once,
        in CI). Only while the recorder reads them (unless :attr:`every_reader`): a lost
        reader (a stopped actuator) never acknowledges, and the recorder leaves once its bag
        is whole."""
        if self._ended_at is None:
            self._ended_at = time.monotonic()
        held = [p.topic_name for p in not_acknowledged(self, self._for_the_bag, time.monotonic())
                if self.every_reader or self._recorder_reads(p.topic_name)]
        if held and time.monotonic() - self._ended_at > END_ACK_S:
            self.get_logger().warning(
                f"leaving with {', '.join(held)} not acknowledged within {END_ACK_S:g} s of "
                "the run's end: the bag may lack its last messages")
            return False
        return bool(held)

    def _recorder_reads(self, topic: str) -> bool:
        """Whether this rig's recorder subscribes to ``topic`` (as the graph shows it now)."""
        return any(info.node_name == RECORDER and info.node_namespace == self.get_namespace()
                   for info in self.get_subscriptions_info_by_topic(topic))

    def close(self) -> None:
        """Called once when the node stops, however it stops."""

    def _on_run_end(self, message: UInt64) -> None:
        if self.run_samples is None:
            self.run_samples = int(message.data)
            self.create_timer(0.05, self._leave_when_done)

    def _leave_when_done(self) -> None:
        if not self.pending():
            raise RunFinishedError(self.get_name())


ACK_SLICE_S = 0.1
"""How long one wait for acknowledgements lasts before the node looks for a signal."""


def not_acknowledged(node: Node, publishers: list[Publisher],
                     deadline: float | None) -> list[Publisher]:
    """Those of ``publishers`` whose messages a reader has yet to acknowledge at ``deadline``
    (monotonic; None: no limit), or when a signal shut the node's context down: waited for
    in slices, since rcl's wait does not end on a signal (the plant waiting for a starved
    recorder ignored Ctrl-C, then died of the shut context with a traceback)."""
    waiting = list(publishers)
    while waiting and node.context.ok():
        left = ACK_SLICE_S if deadline is None else deadline - time.monotonic()
        try:
            waiting = [p for p in waiting if not p.wait_for_all_acked(
                Duration(seconds=min(max(left, 0.0), ACK_SLICE_S)))]
        except RCLError:  # the context shut down between the check and the wait
            break
        if deadline is not None and time.monotonic() >= deadline:
            break
    return waiting


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
