"""``actuator`` node: valve static map + A(s); brake current command → brake pressure.

The actuator steps by time, not by message: a command (``sensor_msgs/JointState``, the
valve current in ``effort``) holds from the previous command's stamp up to its own, so
a command stamped t moves the valve through every plant step that ends by t, and the
pressure after each step is published stamped with the step's end. A controller may
answer every plant sample (stamp t_k + h) or every tenth (t_k + 10·h): the valve sees the
same time either way.

The pressures of a command's interval are published as soon as it arrives, each with
its step's stamp: in lockstep the plant waits for them, in real time it takes each at its
step (a 100 Hz controller's ten pressures at once, used one per plant step). A node of
its own that followed the plant's samples instead cost the real-time graph half a
millisecond of p99 jitter at a subscriber (0.78 -> 1.34 ms).
"""

from __future__ import annotations

from sensor_msgs.msg import FluidPressure, JointState

from landing_gear_sim.model.blocks import ActuatorBlock
from landing_gear_sim.ros.graph import TOPIC_HYDRAULIC
from landing_gear_sim.ros.nodes.graph_node import GraphNode, main_for
from landing_gear_sim.ros.nodes.handshake import Handshake, announce_ready
from landing_gear_sim.ros.nodes.parameters import rig_and_run
from landing_gear_sim.ros.nodes.stamps import RunClock, ns_of
from landing_gear_sim.ros.nodes.topics import command_current
from msg_tools.contract import ATMOSPHERE_PA, TOPIC_CURRENT, VALVE_JOINT


class ActuatorNode(GraphNode):
    def __init__(self) -> None:
        super().__init__("actuator")
        params, scenario, self._lockstep = rig_and_run(self)
        # real time: the first command's stamp is step 0 (its interval began before the
        # actuator could know the run's start: the valve is at rest then anyway)
        self._run_clock = RunClock(scenario.step_s, 0 if self._lockstep else None)
        ActuatorBlock(params, scenario.step_s).step(0.0)  # JIT now: see PlantNode
        self._block = ActuatorBlock(params, scenario.step_s)
        self._done = 0 if self._lockstep else -1  # pressures are published up to this step
        self._steps = int(scenario.current_a.size)  # the run's longest length
        self._current_a = 0.0  # the latest command
        self._refused = 0
        self._message = FluidPressure()
        self._message.header.frame_id = "brake"
        self._out = self.publisher(FluidPressure, TOPIC_HYDRAULIC)
        command = self.subscription(JointState, TOPIC_CURRENT, self._on_command)
        Handshake(self, {TOPIC_HYDRAULIC: self._out}, [command], announce_ready(self))

    def _on_command(self, message: JointState) -> None:
        current_a = command_current(message)
        if current_a is None:
            self._refuse(f"a command without an effort for joint '{VALVE_JOINT}' ignored")
            return
        self._run_clock.observe(message.header.stamp)
        end = self._run_clock.step_of(message.header.stamp)
        if self._lockstep and end > 2 * self._steps:
            # another run's command (stamped in wall time: ~1.7e12 steps to go) once kept the
            # valve stepping towards it until a stop killed it mid-publish; a controller's
            # last command may end past the run (its period's end), not far past
            end_s = self._steps * self._run_clock.step_s
            self._refuse(f"a command stamped {ns_of(message.header.stamp) * 1e-9:.6f} s "
                         f"ignored: far past the run's end ({end_s:g} s); a node of another "
                         "run on this namespace?")
            return
        if end <= self._done and self._lockstep:
            self._refuse(f"a command stamped {ns_of(message.header.stamp) * 1e-9:.6f} s ignored: "
                         f"it ends an interval the valve has passed (at "
                         f"{self._done * self._run_clock.step_s:.6f} s); a command holds from "
                         "the previous one's stamp up to its own")
            return
        self._current_a = current_a  # real time: one that came late holds from now on
        self._advance(end)

    def _advance(self, target: int) -> None:
        while self._done < target:
            pressure = self._block.step(self._current_a)
            self._done += 1
            self._message.header.stamp = self._run_clock.stamp(self._done)
            self._message.fluid_pressure = pressure + ATMOSPHERE_PA
            self._out.publish(self._message)

    def _refuse(self, reason: str) -> None:
        self._refused += 1
        if self._refused in (1, 10, 100, 1000):
            self.get_logger().warning(f"{reason} ({self._refused} so far)")


main = main_for(ActuatorNode)

if __name__ == "__main__":
    main()
