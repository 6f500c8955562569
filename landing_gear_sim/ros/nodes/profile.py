"""``profile`` node: the open-loop current reference of a run, one value per plant sample.

Profiles are those of ``landing-gear-sim simulate`` (``run.profile``), including a
run's recorded current (``run.profile:=file``, ``run.file:=RUN.csv|BAG``).
"""

from __future__ import annotations

import numpy as np
from sensor_msgs.msg import JointState

from landing_gear_sim.ros.nodes.graph_node import GraphNode, main_for
from landing_gear_sim.ros.nodes.handshake import Handshake, announce_ready
from landing_gear_sim.ros.nodes.parameters import rig_and_run
from landing_gear_sim.ros.nodes.stamps import RunClock
from landing_gear_sim.ros.nodes.topics import command_message
from msg_tools.contract import TOPIC_CURRENT, TOPIC_WHEEL


class CurrentFeed:
    """Send the held current of each step, paced by the plant's samples, each stamped with
    the end of the step it holds for.

    In lockstep an open-loop current need not wait for the sample it belongs to: on
    sample k the feed sends the current of step k+1 (steps 0 and 1 on sample 0), so the
    actuator's pressure is ready before the plant asks and the profile is off the
    critical path of a step (measured: +12 % steps/s at 500 and 1000 Hz). A closed-loop controller
    cannot do this. In real time the feed answers sample k with step k.
    """

    def __init__(self, node: GraphNode, current_a: np.ndarray, step_s: float,
                 ahead: bool) -> None:
        self._current_a = current_a
        self._clock = RunClock(step_s, 0 if ahead else None)
        self._lead = 1 if ahead else 0
        self._message = command_message()
        self._out = node.publisher(JointState, TOPIC_CURRENT)
        wheel = node.subscription(JointState, TOPIC_WHEEL, self._on_sample)
        Handshake(node, {TOPIC_CURRENT: self._out}, [wheel], announce_ready(node))

    def _on_sample(self, message: JointState) -> None:
        self._clock.observe(message.header.stamp)
        step = self._clock.step_of(message.header.stamp)
        first = 0 if step == 0 else step + self._lead
        for index in range(first, min(step + self._lead + 1, self._current_a.size)):
            # the current of step j holds over [t_j, t_j+1): stamped with its end
            self._message.header.stamp = self._clock.stamp(index + 1)
            self._message.effort[0] = float(self._current_a[index])
            self._out.publish(self._message)


class ProfileNode(GraphNode):
    def __init__(self) -> None:
        super().__init__("profile")
        _, scenario, ahead = rig_and_run(self)
        self._feed = CurrentFeed(self, scenario.current_a, scenario.step_s, ahead)


main = main_for(ProfileNode)

if __name__ == "__main__":
    main()
