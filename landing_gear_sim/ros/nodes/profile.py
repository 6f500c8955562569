"""``profile`` node: the open-loop current reference of a run, one value per plant sample.

Profiles are those of ``landing-gear-sim simulate`` (``run.profile``), including a
run's recorded current (``run.profile:=file``, ``run.file:=RUN.csv|BAG``).
"""

from __future__ import annotations

import numpy as np
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from landing_gear_sim.ros.nodes.common import (
    GraphNode,
    Handshake,
    announce_ready,
    main_for,
    step_of,
)
from landing_gear_sim.ros.nodes.parameters import rig_and_run
from msg_tools.contract import TOPIC_CURRENT, TOPIC_WHEEL


class CurrentFeed:
    """Send the held current of each step, paced by the plant's samples.

    In lockstep an open-loop current need not wait for the sample it belongs to: on
    sample k the feed sends the current of step k+1 (steps 0 and 1 on sample 0), so the
    actuator's pressure is ready before the plant asks and the profile is off the
    critical path of a step (measured: +12 % steps/s at 500 and 1000 Hz). A closed-loop controller
    cannot do this. In real time the feed answers sample k with step k.
    """

    def __init__(self, node: GraphNode, current_a: np.ndarray, rate_hz: float,
                 ahead: bool) -> None:
        self._current_a = current_a
        self._rate_hz = rate_hz
        self._lead = 1 if ahead else 0
        self._message = Float64()
        self._out = node.publisher(Float64, TOPIC_CURRENT)
        wheel = node.subscription(JointState, TOPIC_WHEEL, self._on_sample)
        Handshake(node, {TOPIC_CURRENT: self._out}, [wheel], announce_ready(node))

    def _on_sample(self, message: JointState) -> None:
        step = step_of(message.header.stamp, self._rate_hz)
        first = 0 if step == 0 else step + self._lead
        for index in range(first, min(step + self._lead + 1, self._current_a.size)):
            self._message.data = float(self._current_a[index])
            self._out.publish(self._message)


class ProfileNode(GraphNode):
    def __init__(self) -> None:
        super().__init__("profile")
        _, scenario, ahead = rig_and_run(self)
        self._feed = CurrentFeed(self, scenario.current_a, scenario.rate_hz, ahead)


main = main_for(ProfileNode)

if __name__ == "__main__":
    main()
