"""``loading_device`` node: lift map + servo; flywheel speed at t_k → vertical force at t_{k+1}."""

from __future__ import annotations

from geometry_msgs.msg import Vector3Stamped
from sensor_msgs.msg import JointState

from landing_gear_sim.model.blocks import LoadingBlock
from landing_gear_sim.ros.graph import TOPIC_LOAD
from landing_gear_sim.ros.nodes.graph_node import GraphNode, main_for
from landing_gear_sim.ros.nodes.handshake import Handshake, announce_ready
from landing_gear_sim.ros.nodes.parameters import rig_and_run
from landing_gear_sim.ros.nodes.stamps import RunClock
from msg_tools.contract import TOPIC_FLYWHEEL


class LoadingDeviceNode(GraphNode):
    def __init__(self) -> None:
        super().__init__("loading_device")
        params, scenario, lockstep = rig_and_run(self)
        self._run_clock = RunClock(scenario.step_s, 0 if lockstep else None)
        LoadingBlock(params, scenario.step_s, True).step(0, 0.0)  # JIT now: see PlantNode
        self._block = LoadingBlock(params, scenario.step_s, scenario.contact)
        self._message = Vector3Stamped()
        self._message.header.frame_id = "gear"
        self._out = self.publisher(Vector3Stamped, TOPIC_LOAD)
        speed = self.subscription(JointState, TOPIC_FLYWHEEL, self._on_speed)
        Handshake(self, {TOPIC_LOAD: self._out}, [speed], announce_ready(self))

    def _on_speed(self, message: JointState) -> None:
        self._run_clock.observe(message.header.stamp)
        step = self._run_clock.step_of(message.header.stamp)
        self._message.vector.z = self._block.step(step, message.velocity[0])
        self._message.header.stamp = self._run_clock.stamp(step + 1)
        self._out.publish(self._message)


main = main_for(LoadingDeviceNode)

if __name__ == "__main__":
    main()
