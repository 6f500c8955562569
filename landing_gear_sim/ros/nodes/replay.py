"""``replay`` node: a recorded run (CSV or bag) back on the contract topics.

``topics:=all`` (default): every contract topic and ``/clock``, stamped with the
run's own time, paced at ``speed`` × real time; nothing else is needed.
``topics:=current``: only the run's current command, answering each plant sample
as the profile node does, so the simulated graph re-runs the rig test and its
bag can be compared with the measurement (``landing-gear-sim rig --replay RUN``).
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

from rosgraph_msgs.msg import Clock
from std_msgs.msg import UInt64

from landing_gear_sim.errors import GraphError
from landing_gear_sim.model.runspec import build_scenario
from landing_gear_sim.ros.graph import TOPIC_CLOCK, TOPIC_RUN_END
from landing_gear_sim.ros.nodes.graph_node import GraphNode, main_for
from landing_gear_sim.ros.nodes.handshake import Handshake
from landing_gear_sim.ros.nodes.parameters import declare, lockstep, rig_parameters, run_spec
from landing_gear_sim.ros.nodes.profile import CurrentFeed
from landing_gear_sim.ros.nodes.stamps import to_stamp
from landing_gear_sim.ros.nodes.topics import CONTRACT_KINDS, DATA_QOS, LATCHED_QOS
from msg_tools.bag_io import TYPESTORE, contract_messages
from msg_tools.contract import TOPIC_CURRENT, TOPIC_TYPES
from msg_tools.csv_io import read_mapping
from msg_tools.io import read_run

MODES = ("all", "current")
BATCH = 200  # most samples published per timer tick when catching up


class ReplayNode(GraphNode):
    def __init__(self) -> None:
        super().__init__("replay")
        ahead = lockstep(self)
        mode = str(declare(self, "topics", "all", "all | current"))
        path = str(declare(self, "file", "", "run to replay (CSV or bag)"))
        mapping = str(declare(self, "mapping", "", "column-mapping file for a CSV"))
        self._speed = float(declare(self, "speed", 1.0, "topics=all: playback speed (x real time)",
                                    0.0))
        readers = int(declare(self, "wait_for_subscribers", 0,
                              "topics=all: start once every topic has this many readers"))
        if mode not in MODES:
            raise GraphError(f"topics must be one of {', '.join(MODES)}, got {mode!r}")
        if not path:
            raise GraphError("replay needs the parameter file:=RUN (CSV or bag)")
        if not self._speed > 0:
            raise GraphError(f"speed must be > 0, got {self._speed}")
        self._run = read_run(Path(path), read_mapping(Path(mapping)) if mapping else None)
        if mode == "current":
            params = rig_parameters(self)
            spec = replace(run_spec(self), profile="file", file=path)
            scenario = build_scenario(spec, params, self._run)
            self._feed = CurrentFeed(self, scenario.current_a, scenario.step_s, ahead)
            return
        self._out = {topic: self.publisher(kind, topic, DATA_QOS)
                     for topic, kind in CONTRACT_KINDS.items()}
        self._clock_out = self.publisher(Clock, TOPIC_CLOCK, DATA_QOS)
        self._end = self.publisher(UInt64, TOPIC_RUN_END, LATCHED_QOS)
        self.every_reader = True  # any recorder of the replay, not only the rig's (below)
        self._next = 0
        self._wall_start = 0.0
        self.get_logger().info(f"replaying {path}: {len(self._run)} samples, "
                               f"{self._run.time_s[-1] - self._run.time_s[0]:.2f} s")
        # the readers hear the run's end too: it is latched only while this node lives (so it
        # stays until they have it), and a recorder that matched it after the replay had left
        # waited forever (under load)
        ends = {TOPIC_RUN_END: readers + 1} if readers else {}  # + 1: its own subscription
        Handshake(self, {**self._out, TOPIC_RUN_END: self._end}, [], self._start,
                  dict.fromkeys(self._out, readers) | ends)

    def _start(self) -> None:
        self._wall_start = time.monotonic()
        self.create_timer(1e-3, self._tick)

    def _tick(self) -> None:
        run = self._run
        elapsed = (time.monotonic() - self._wall_start) * self._speed
        due = run.time_s[0] + elapsed
        for _ in range(BATCH):
            if self._next >= len(run) or run.time_s[self._next] > due:
                break
            self._publish(self._next)
            self._next += 1
        if self._next >= len(run) and self.run_samples is None:
            self._end.publish(UInt64(data=len(run)))

    def _publish(self, k: int) -> None:
        self._clock_out.publish(Clock(clock=to_stamp(float(self._run.time_s[k]))))
        messages = contract_messages(self._run, k)
        # at t_k a controller sends the command for (t_k, t_k+1], stamped t_k+1 as logged
        if k + 1 < len(self._run):
            messages[TOPIC_CURRENT] = contract_messages(self._run, k + 1)[TOPIC_CURRENT]
        else:
            del messages[TOPIC_CURRENT]
        for topic, message in messages.items():
            # serialised by rosbags: published as is, no conversion to rclpy classes
            self._out[topic].publish(bytes(TYPESTORE.serialize_cdr(message, TOPIC_TYPES[topic])))


main = main_for(ReplayNode)

if __name__ == "__main__":
    main()
