"""Stamps of a run's samples: seconds and nanoseconds as ROS times, and the run's clock."""

from __future__ import annotations

from builtin_interfaces.msg import Time

from landing_gear_sim.model.scenario import step_time
from msg_tools.stamps import ns_of_fields, ns_of_time, stamp_fields


def to_stamp(time_s: float) -> Time:
    return stamp_of_ns(ns_of_time(time_s))


def stamp_of_ns(nanoseconds: int) -> Time:
    return Time(**stamp_fields(nanoseconds))


def ns_of(stamp: Time) -> int:
    return ns_of_fields(stamp.sec, stamp.nanosec)


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
        return stamp_of_ns((self.origin_ns or 0) + ns_of_time(step_time(step, self.step_s)))

