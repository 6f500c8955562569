"""A sample's time as a ROS stamp: whole seconds and nanoseconds, to the nanosecond.

The one rule every writer of the contract stamps by (a bag written offline, a node of the
graph) and every reader reads back; the message types (rosbags' or rclpy's) stay theirs.
"""

from __future__ import annotations

import numpy as np

NS_PER_S = 1_000_000_000


def ns_of_time(time_s: float) -> int:
    """A time [s] to the nearest nanosecond."""
    return round(time_s * 1e9)


def ns_of_times(time_s: np.ndarray) -> np.ndarray:
    """:func:`ns_of_time` of each time, as int64 (the same rounding: half to even)."""
    return np.rint(np.asarray(time_s, dtype=float) * 1e9).astype(np.int64)


def stamp_fields(nanoseconds: int) -> dict[str, int]:
    """A ROS time's fields (``sec``, ``nanosec``) for ``nanoseconds``."""
    sec, nanosec = divmod(nanoseconds, NS_PER_S)
    return {"sec": sec, "nanosec": nanosec}


def ns_of_fields(sec: int, nanosec: int) -> int:
    """The nanoseconds of a ROS time's fields."""
    return sec * NS_PER_S + nanosec


def seconds_of_fields(sec: int, nanosec: int) -> float:
    """A ROS time's fields as seconds."""
    return sec + nanosec * 1e-9
