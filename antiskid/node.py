"""``antiskid_controller`` node: a controller of :mod:`antiskid` in the rig graph.

``ros2 run landing_gear_sim antiskid_controller --ros-args -p type:=slip``. It answers
each plant sample (wheel and flywheel speeds with the same stamp) with the current for
that step on ``/rig/brake/current_ref``, stamped with the next sample's time (the end
of the interval it holds for); the step function is the one the offline closed
loop calls (:func:`antiskid.closed_loop.make_controller`). Settings: ``threshold.*`` and
``slip.*`` parameters (see :class:`ThresholdParams`, :class:`SlipParams`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import fields

from sensor_msgs.msg import JointState

from landing_gear_sim.model.scenario import step_time
from landing_gear_sim.ros.nodes.graph_node import GraphNode, main_for
from landing_gear_sim.ros.nodes.handshake import Handshake, announce_ready
from landing_gear_sim.ros.nodes.parameters import declare, rig_and_run
from landing_gear_sim.ros.nodes.stamps import RunClock
from landing_gear_sim.ros.nodes.topics import command_message
from msg_tools.contract import TOPIC_CURRENT, TOPIC_FLYWHEEL, TOPIC_WHEEL

from .closed_loop import CONTROLLERS, make_controller, settings_type
from .errors import ControllerError


class AntiskidControllerNode(GraphNode):
    def __init__(self) -> None:
        super().__init__("antiskid_controller")
        rig, scenario, lockstep = rig_and_run(self)
        kind = str(declare(self, "type", "threshold", "threshold | slip"))
        if kind not in CONTROLLERS:
            raise ControllerError(f"type must be one of {', '.join(CONTROLLERS)}, got {kind!r}")
        settings = {f.name: declare(self, f"{kind}.{f.name}", f.default, f"{kind} setting")
                    for f in fields(settings_type(kind))}
        self._step = make_controller(kind, rig, scenario.step_s, settings)
        self._run_clock = RunClock(scenario.step_s, 0 if lockstep else None)
        self._speeds: dict[int, dict[str, float]] = {}
        self._message = command_message()
        self._out = self.publisher(JointState, TOPIC_CURRENT)
        inputs = [self.subscription(JointState, topic, self._on_speed(topic))
                  for topic in (TOPIC_WHEEL, TOPIC_FLYWHEEL)]
        Handshake(self, {TOPIC_CURRENT: self._out}, inputs, announce_ready(self))
        self.get_logger().info(f"{kind} controller: {settings}")

    def _on_speed(self, topic: str) -> Callable[[JointState], None]:
        def take(message: JointState) -> None:
            self._run_clock.observe(message.header.stamp)
            step = self._run_clock.step_of(message.header.stamp)
            speeds = self._speeds.setdefault(step, {})
            speeds[topic] = message.velocity[0]
            if len(speeds) == 2:
                del self._speeds[step]
                self._answer(step, speeds[TOPIC_WHEEL], speeds[TOPIC_FLYWHEEL])

        return take

    def _answer(self, step: int, wheel_rad_s: float, flywheel_rad_s: float) -> None:
        time_s = step_time(step, self._run_clock.step_s)
        self._message.effort[0] = self._step(time_s, wheel_rad_s, flywheel_rad_s)
        self._message.header.stamp = self._run_clock.stamp(step + 1)  # held until the next sample
        self._out.publish(self._message)


main = main_for(AntiskidControllerNode)

if __name__ == "__main__":
    main()
