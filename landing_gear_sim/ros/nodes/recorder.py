"""``recorder`` node: the contract topics into a rosbag2 (mcap by default, or sqlite3).

Messages are recorded as the raw bytes received (no re-serialisation), sample by
sample in a fixed topic order, each with the sample's stamp as log time; the j-th
current command is logged at the stamp of sample j+1, as the data contract reads it
(the command in force over the interval that ends there). So the same run gives the
same bag files, whatever the machine load.

The bag is written in segments (see :mod:`msg_tools.bag_segments`) of at least
``segment_s`` of sim time and ``segment_samples`` samples — a rule on the data, so the
files are the same on every run — and joined into one file when it closes
(``join_segments``; on a stop by a signal only a bag of up to JOIN_ON_STOP_MESSAGES
messages, a longer one keeps its segments). SIGINT/SIGTERM close the bag complete; after
SIGKILL it still opens and lacks only the open segment: about half a second of wall time
at the graph's real-time factors (closing a segment costs ~30 ms, so at a high real-time
factor the sample floor keeps the recorder from spending its time closing segments).
"""

from __future__ import annotations

import bisect
import math
import struct
import time
from collections import deque
from pathlib import Path

from landing_gear_sim.errors import GraphError
from landing_gear_sim.ros.graph import INCOMPLETE_BAG_EXIT, RECORDER, SENSOR_TOPICS
from landing_gear_sim.ros.nodes import stop_requested
from landing_gear_sim.ros.nodes.graph_node import GraphNode, main_for, say
from landing_gear_sim.ros.nodes.handshake import Handshake, announce_ready
from landing_gear_sim.ros.nodes.parameters import check_overrides, declare, lockstep
from landing_gear_sim.ros.nodes.topics import CONTRACT_KINDS, DATA_QOS, relative
from msg_tools.bag_segments import SegmentedBagWriter
from msg_tools.contract import TOPIC_CURRENT, TOPIC_TYPES, TOPIC_WHEEL

LAG_SAMPLES = 2000  # a sample still missing a message this far behind is written without it
END_GRACE_S = 5.0  # after the run's end, wait while messages came this recently
JOIN_ON_STOP_MESSAGES = 100_000  # ~1-2 s of joining; launch sends SIGTERM 5 s after SIGINT


def stamp_ns(raw: bytes) -> int:
    """Header stamp [ns] of a serialized stamped message (CDR, header first)."""
    order = "<" if raw[1] == 1 else ">"
    sec, nanosec = struct.unpack_from(order + "iI", raw, 4)
    return sec * 1_000_000_000 + nanosec


class RecorderNode(GraphNode):
    def __init__(self) -> None:
        super().__init__(RECORDER)
        lockstep(self)
        path = str(declare(self, "bag", "", "rosbag2 folder to create"))
        storage = str(declare(self, "storage", "mcap", "mcap | sqlite3"))
        self._segment_ns = round(float(declare(self, "segment_s", 0.5, "sim time per closed "
                                               "segment [s]: the most a crash loses", 0.0))
                                 * 1e9)
        self._segment_samples = int(declare(self, "segment_samples", 500,
                                            "fewest samples per closed segment", 1))
        join = bool(declare(self, "join_segments", True, "join the segments into one file "
                            "when the bag closes (false: keep them)"))
        self._in_segment = 0
        if not path:
            raise GraphError("recorder needs the parameter bag:=FOLDER")
        check_overrides(self)  # a typo must not leave an empty bag behind
        # the bag holds the names the rig published under (``/rig2/...`` for a second rig)
        self._names = {topic: self.resolve_topic_name(relative(topic)) for topic in TOPIC_TYPES}
        self._writer = SegmentedBagWriter(
            Path(path), {self._names[topic]: kind for topic, kind in TOPIC_TYPES.items()},
            storage, join)
        self._samples: dict[int, dict[str, bytes]] = {}
        self._order: list[int] = []  # sample stamps in order (the wheel topic's arrival order)
        self._currents: deque[tuple[int, bytes]] = deque()  # commands not written yet
        self._latest_command_ns = -1
        self._written = 0
        self._counts = dict.fromkeys(SENSOR_TOPICS, 0)  # sensor messages written, by topic
        self._segment_start: int | None = None
        self._end_seen_at: float | None = None
        self._heard_at = -math.inf  # when a message last came in (monotonic)
        subscriptions = [self.subscription(kind, topic, self._callback(topic), DATA_QOS,
                                           raw=True)
                         for topic, kind in CONTRACT_KINDS.items()]
        Handshake(self, {}, subscriptions, announce_ready(self))
        self.get_logger().info(f"recording into {path} ({storage})")

    def _callback(self, topic: str):
        if topic == TOPIC_CURRENT:
            return self._on_current

        def on_sample(raw: bytes) -> None:
            self._heard_at = time.monotonic()
            stamp = stamp_ns(raw)
            if topic == TOPIC_WHEEL:
                self._order.append(stamp)
            self._samples.setdefault(stamp, {})[topic] = raw
            self._flush()

        return on_sample

    def _on_current(self, raw: bytes) -> None:
        self._heard_at = time.monotonic()
        stamp = stamp_ns(raw)
        self._currents.append((stamp, raw))
        self._latest_command_ns = max(self._latest_command_ns, stamp)
        self._flush()

    def _complete(self, index: int) -> bool:
        """A sample's sensors are in, and the command that holds up to it (none for the first)."""
        stamp = self._order[index]
        return len(self._samples.get(stamp, {})) == len(SENSOR_TOPICS) and (
            index == 0 or self._latest_command_ns >= stamp)

    def _flush(self, force: bool = False) -> None:
        """Write every sample that is complete (or, forced or lagging, whatever it has)."""
        while self._written < len(self._order):
            index = self._written
            lagging = len(self._order) - index > LAG_SAMPLES
            if not (force or lagging or self._complete(index)):
                return
            self._write_sample(index)

    def _write_sample(self, index: int) -> None:
        stamp = self._order[index]
        if self._segment_start is None:
            self._segment_start = stamp
        elif (stamp - self._segment_start >= self._segment_ns
              and self._in_segment >= self._segment_samples):
            self._writer.roll()
            self._segment_start, self._in_segment = stamp, 0
        self._in_segment += 1
        while self._currents and self._currents[0][0] <= stamp:
            command_ns, raw = self._currents.popleft()
            self._writer.write(self._names[TOPIC_CURRENT], command_ns, raw)
        messages = self._samples.pop(stamp, {})
        for topic in SENSOR_TOPICS:
            if topic in messages:
                self._writer.write(self._names[topic], stamp, messages[topic])
                self._counts[topic] += 1
        self._written += 1

    def pending(self) -> bool:
        now = time.monotonic()
        if self._end_seen_at is None:
            self._end_seen_at = now
        missing = sum(self._lacking().values())
        return keeps_waiting(missing, now - max(self._end_seen_at, self._heard_at))

    def _lacking(self) -> dict[str, int]:
        """What the bag lacks of the run so far (see :func:`lacks`)."""
        covered = bisect.bisect_right(self._order, self._latest_command_ns, 0, self._written)
        return lacks(self.run_samples, self._counts, self._written - max(covered, 1))

    def close(self) -> None:
        self._flush(force=True)
        lacking = self._lacking()
        if lacking:  # a bag short of its run is no success: the launcher and the rig say so
            what = "; ".join(f"{missing} of its {self.run_samples} samples lack "
                             f"{self._names[topic]}" for topic, missing in lacking.items())
            why = ("stopped by a signal" if stop_requested()
                   else f"nothing more came in {END_GRACE_S:g} s")
            say(self, f"the bag lacks part of the run: {what} ({why})", error=True)
            self.exit_code = INCOMPLETE_BAG_EXIT
        join = joins_on_close(stop_requested(), self._writer.message_count)
        self._writer.close(join=join)
        kept = "" if join or not self._writer.joins else (
            f"; stopped by a signal: its {self._writer.segment_count} segments kept, not "
            "joined (joining that many messages takes longer than a stop may; "
            f"`landing-gear-sim join {self._writer.path}` joins them)")
        say(self, f"bag closed: {self._writer.path} ({self._written} samples, "
                  f"{self._writer.message_count} messages{kept})")


def keeps_waiting(missing: int, quiet_s: float) -> bool:
    """Whether a recorder whose run has ended waits on: ``missing`` messages of the run are
    not in its bag yet and a message came within END_GRACE_S (``quiet_s`` ago). It had
    given up 5 s after the end, however busy the machine: 831 of 1500 samples, while the
    rest were still arriving."""
    return missing > 0 and quiet_s <= END_GRACE_S


def lacks(samples: int | None, counts: dict[str, int], uncovered: int) -> dict[str, int]:
    """How many of a run's ``samples`` lack each topic's message (None: the run's end never
    heard, as on a stop by a signal): a sensor topic has one message a sample (``counts``
    written); the current's commands need only cover every sample after the first (a
    controller slower than the plant sends fewer, each held until the next), so a sample
    lacks one when no command at or after its stamp came (``uncovered``). A command that
    came after its sample had been written (the recorder lagging behind) covers it all the
    same."""
    if samples is None:
        return {}
    missing = {topic: samples - count for topic, count in counts.items() if count < samples}
    if uncovered > 0:
        missing[TOPIC_CURRENT] = uncovered
    return missing


def joins_on_close(stopped: bool, messages: int) -> bool:
    """Whether the segments are joined when the bag closes: at a run's own end always; on a
    stop by a signal only while that is quick (JOIN_ON_STOP_MESSAGES). A 300 s run's join,
    1.5 M messages at 10-20 µs each, outlasted launch's SIGKILL at 15 s on a busy machine:
    launch called the run failed (the segmented bag was complete all the same)."""
    return not stopped or messages <= JOIN_ON_STOP_MESSAGES


main = main_for(RecorderNode)

if __name__ == "__main__":
    main()
