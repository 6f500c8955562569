"""A run's contract messages serialised all at once, as rows of fixed CDR layouts.

Every message of a contract topic has one layout: its frame id and joint name are the
same in every sample, so only its stamp and its numbers change, at fixed offsets. A run's
messages of one topic are then the rows of one numpy structured array, filled column by
column, and a bag's messages that hold a layout's constants are read back the same way.
rosbags builds and serialises them one message object at a time, ~10 µs each: ~1 s for
the ~100,000 messages of a 20 s run, most of a ``convert`` to a bag (issue 61's target is
1 s for the whole command), and ~0.8 s to read them. The bytes are rosbags' own, to the
bit (the layouts are checked against its ``serialize_cdr``: ``test_msg_tools``); a
message of another layout (another frame or joint, a position for a velocity) is read
through rosbags (:mod:`msg_tools.bag_read`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .contract import (
    ATMOSPHERE_PA,
    FRAMES,
    TOPIC_CURRENT,
    TOPIC_FLYWHEEL,
    TOPIC_PRESSURE,
    TOPIC_WHEEL,
    TOPIC_WRENCH,
)
from .run import Run
from .stamps import NS_PER_S, ns_of_times

HEADER = b"\x00\x01\x00\x00"
"""CDR's encapsulation header: plain CDR, little-endian (as rosbags and rclpy write)."""

Item = tuple[str, str, object]
"""A layout's item: (name, numpy format, constant value or None for a column)."""


def _string(name: str, text: str) -> list[Item]:
    data = text.encode() + b"\x00"
    return [(f"{name}.length", "<u4", len(data)), (name, f"S{len(data)}", data)]


def _doubles(name: str, count: int) -> list[Item]:
    """A sequence of ``count`` float64 (its count, then its elements as columns)."""
    return [(f"{name}.count", "<u4", count),
            *[(f"{name}[{i}]", "<f8", None) for i in range(count)]]


def _header(frame: str) -> list[Item]:
    return [("sec", "<i4", None), ("nanosec", "<u4", None), *_string("frame_id", frame)]


def _joint(name: str, velocity: int, effort: int) -> list[Item]:
    return [*_header(name), ("name.count", "<u4", 1), *_string("name[0]", name),
            *_doubles("position", 0), *_doubles("velocity", velocity),
            *_doubles("effort", effort)]


@dataclass(frozen=True)
class Layout:
    """One message type's fixed CDR layout: a structured dtype whose fields sit where CDR
    aligns them (each primitive on a multiple of its size, counted from the end of the
    encapsulation header), and the fields every message holds the same value in."""

    dtype: np.dtype
    constants: dict[str, object]
    template: np.ndarray
    """A message's bytes (uint8) with its constants and zero elsewhere."""
    fixed: np.ndarray
    """Which of its bytes hold a constant (bool)."""

    @classmethod
    def of(cls, items: Sequence[Item]) -> Layout:
        names, formats, offsets = ["header"], ["S4"], [0]
        constants: dict[str, object] = {"header": HEADER}
        end = len(HEADER)
        for name, fmt, value in items:
            size = np.dtype(fmt).itemsize
            align = 1 if fmt.startswith("S") else size
            end = len(HEADER) + -(-(end - len(HEADER)) // align) * align
            names.append(name)
            formats.append(fmt)
            offsets.append(end)
            if value is not None:
                constants[name] = value
            end += size
        dtype = np.dtype({"names": names, "formats": formats, "offsets": offsets,
                          "itemsize": end})
        template = np.zeros(1, dtype)
        fixed = np.zeros(end, bool)
        for name, value in constants.items():
            template[name] = value
            offset = offsets[names.index(name)]
            fixed[offset:offset + dtype[name].itemsize] = True
        return cls(dtype, constants, template.view(np.uint8), fixed)

    def rows(self, columns: dict[str, np.ndarray]) -> np.ndarray:
        """The messages whose varying fields are ``columns`` (each of the run's length);
        padding bytes are zero, as rosbags writes them."""
        n = len(next(iter(columns.values())))
        out = np.zeros(n, self.dtype)
        for name, value in (self.constants | columns).items():
            out[name] = value
        return out

    def read(self, messages: bytes) -> np.ndarray | None:
        """The rows of ``messages`` (serialised messages of this layout, end to end), or
        None unless every one holds the layout's constants (another frame or joint, a
        longer name: they need rosbags)."""
        rows = np.frombuffer(messages, self.dtype)
        raw = np.frombuffer(messages, np.uint8).reshape(len(rows), self.dtype.itemsize)
        if not np.array_equal(raw[:, self.fixed], np.broadcast_to(
                self.template[self.fixed], (len(rows), int(self.fixed.sum())))):
            return None
        return rows


LAYOUTS: dict[str, Layout] = {
    TOPIC_CURRENT: Layout.of(_joint(FRAMES[TOPIC_CURRENT], velocity=0, effort=1)),
    TOPIC_PRESSURE: Layout.of([*_header(FRAMES[TOPIC_PRESSURE]), ("fluid_pressure", "<f8", None),
                               ("variance", "<f8", 0.0)]),
    TOPIC_WHEEL: Layout.of(_joint(FRAMES[TOPIC_WHEEL], velocity=1, effort=0)),
    TOPIC_FLYWHEEL: Layout.of(_joint(FRAMES[TOPIC_FLYWHEEL], velocity=1, effort=0)),
    TOPIC_WRENCH: Layout.of([*_header(FRAMES[TOPIC_WRENCH]), *[
        (f"{part}.{axis}", "<f8", None if (part, axis) in (("force", "x"), ("force", "z"))
         else 0.0) for part in ("force", "torque") for axis in "xyz"]]),
}
"""The contract topics' layouts, as :func:`msg_tools.bag_io.contract_messages` builds them."""


COLUMNS: dict[str, str] = {
    "current_ref_A": "effort[0]", "brake_pressure_bar": "fluid_pressure",
    "wheel_speed_rad_s": "velocity[0]", "flywheel_speed_rad_s": "velocity[0]",
    "vertical_load_N": "force.z", "longitudinal_force_N": "force.x",
}
"""Contract column → the column of its topic's layout that holds the field a bag's reader
reads there by default (:data:`msg_tools.bag_fields.CONTRACT_SOURCES`)."""


def contract_rows(run: Run) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """``run``'s log times [ns] and each contract topic's serialised messages, a row a
    sample (``rows[topic][k].tobytes()`` is sample k's message)."""
    log_ns = ns_of_times(run.time_s)
    sec, nanosec = np.divmod(log_ns, NS_PER_S)
    stamp = {"sec": sec, "nanosec": nanosec}
    values = {
        TOPIC_CURRENT: {"effort[0]": run.current_a},
        TOPIC_PRESSURE: {"fluid_pressure": run.pressure_pa + ATMOSPHERE_PA},
        TOPIC_WHEEL: {"velocity[0]": run.wheel_speed_rad_s},
        TOPIC_FLYWHEEL: {"velocity[0]": run.flywheel_speed_rad_s},
        TOPIC_WRENCH: {"force.x": run.longitudinal_force_n, "force.z": run.vertical_load_n},
    }
    return log_ns, {topic: LAYOUTS[topic].rows(stamp | columns)
                    for topic, columns in values.items()}
