"""``actuator`` node: valve static map + A(s); brake current reference → brake pressure.

The j-th current of the run is the command held over step j (the controller or
profile sends exactly one per plant sample), so its pressure is stamped (j+1)·h.
"""

from __future__ import annotations

from sensor_msgs.msg import FluidPressure
from std_msgs.msg import Float64

from landing_gear_sim.model.blocks import ActuatorBlock, step_time
from landing_gear_sim.ros.graph import TOPIC_HYDRAULIC
from landing_gear_sim.ros.nodes.common import (
    GraphNode,
    Handshake,
    announce_ready,
    main_for,
    to_stamp,
)
from landing_gear_sim.ros.nodes.parameters import rig_and_run
from msg_tools.contract import ATMOSPHERE_PA, TOPIC_CURRENT


class ActuatorNode(GraphNode):
    def __init__(self) -> None:
        super().__init__("actuator")
        params, scenario, _ = rig_and_run(self)  # the actuator reacts alike in both clocks
        self._step_s = scenario.step_s
        self._block = ActuatorBlock(params, self._step_s)
        self._count = 0
        self._message = FluidPressure()
        self._message.header.frame_id = "brake"
        self._out = self.publisher(FluidPressure, TOPIC_HYDRAULIC)
        current = self.subscription(Float64, TOPIC_CURRENT, self._on_current)
        Handshake(self, {TOPIC_HYDRAULIC: self._out}, [current], announce_ready(self))

    def _on_current(self, message: Float64) -> None:
        pressure = self._block.step(message.data)
        self._count += 1
        self._message.header.stamp = to_stamp(step_time(self._count, self._step_s))
        self._message.fluid_pressure = pressure + ATMOSPHERE_PA
        self._out.publish(self._message)


main = main_for(ActuatorNode)

if __name__ == "__main__":
    main()
