"""Contract rosbag2 read and write with ``rosbags`` (mcap or sqlite3), no ROS install needed."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import numpy as np
from rosbags.rosbag2 import Reader, Writer
from rosbags.rosbag2.enums import StoragePlugin
from rosbags.typesys import Stores, get_typestore

from .checks import check_plausible
from .contract import (
    ATMOSPHERE_PA,
    TOPIC_CURRENT,
    TOPIC_FLYWHEEL,
    TOPIC_PRESSURE,
    TOPIC_TYPES,
    TOPIC_WHEEL,
    TOPIC_WRENCH,
)
from .errors import RunFormatError
from .run import Run

TYPESTORE = get_typestore(Stores.ROS2_KILTED)
BAG_VERSION: Literal[9] = 9
STORAGE = {"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3}


def _stamp(time_s: float) -> Any:
    nanoseconds = round(time_s * 1e9)
    time_type = TYPESTORE.types["builtin_interfaces/msg/Time"]
    return time_type(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


def _header(time_s: float, frame: str) -> Any:
    return TYPESTORE.types["std_msgs/msg/Header"](stamp=_stamp(time_s), frame_id=frame)


def contract_messages(run: Run, k: int) -> dict[str, Any]:
    """The contract messages of sample ``k`` of ``run``, by topic."""
    t = float(run.time_s[k])
    types = TYPESTORE.types
    empty = np.empty(0)

    def joint(name: str, speed: float) -> Any:
        return types["sensor_msgs/msg/JointState"](
            header=_header(t, name), name=[name], position=empty,
            velocity=np.array([speed]), effort=empty)

    vector = types["geometry_msgs/msg/Vector3"]
    wrench = types["geometry_msgs/msg/Wrench"](
        force=vector(x=float(run.longitudinal_force_n[k]), y=0.0, z=float(run.vertical_load_n[k])),
        torque=vector(x=0.0, y=0.0, z=0.0))
    return {
        TOPIC_CURRENT: types["std_msgs/msg/Float64"](data=float(run.current_a[k])),
        TOPIC_PRESSURE: types["sensor_msgs/msg/FluidPressure"](
            header=_header(t, "brake"), fluid_pressure=float(run.pressure_pa[k]) + ATMOSPHERE_PA,
            variance=0.0),
        TOPIC_WHEEL: joint("wheel", float(run.wheel_speed_rad_s[k])),
        TOPIC_FLYWHEEL: joint("flywheel", float(run.flywheel_speed_rad_s[k])),
        TOPIC_WRENCH: types["geometry_msgs/msg/WrenchStamped"](
            header=_header(t, "load_cell"), wrench=wrench),
    }


def write_bag(run: Run, path: Path, storage: str = "mcap") -> None:
    """Write ``run`` as a rosbag2 with the contract topics (log time = sample time)."""
    path = Path(path)
    if storage not in STORAGE:
        raise RunFormatError(f"unknown bag storage {storage!r}; use mcap or sqlite3")
    if path.exists():
        raise RunFormatError(f"{path}: exists already, not overwriting")
    with Writer(path, version=BAG_VERSION, storage_plugin=STORAGE[storage]) as writer:
        connections = {topic: writer.add_connection(topic, msgtype, typestore=TYPESTORE)
                       for topic, msgtype in TOPIC_TYPES.items()}
        for k in range(len(run)):
            log_time = round(float(run.time_s[k]) * 1e9)
            for topic, message in contract_messages(run, k).items():
                data = TYPESTORE.serialize_cdr(message, TOPIC_TYPES[topic])
                writer.write(connections[topic], log_time, data)


def read_bag(path: Path, name: str | None = None) -> Run:
    """Read the contract topics of a rosbag2 into a :class:`Run` on the wheel encoder's time base.

    Stamped topics are matched by header stamp (linear interpolation), the
    current command by bag log time (held, as the valve sees it).
    """
    path = Path(path)
    series: dict[str, tuple[list[float], list[Any]]] = {t: ([], []) for t in TOPIC_TYPES}
    try:
        with Reader(path) as reader:
            wanted = [c for c in reader.connections if c.topic in series]
            for connection, log_time, raw in reader.messages(connections=wanted):
                message = TYPESTORE.deserialize_cdr(raw, connection.msgtype)
                stamp = getattr(message, "header", None)
                t = (stamp.stamp.sec + stamp.stamp.nanosec * 1e-9) if stamp else log_time * 1e-9
                series[connection.topic][0].append(t)
                series[connection.topic][1].append(message)
    except Exception as exc:  # rosbags raises several types for damaged bags
        raise RunFormatError(f"{path}: cannot read bag ({exc})") from None
    missing = [topic for topic, (times, _) in series.items() if not times]
    if missing:
        raise RunFormatError(f"{path}: bag has no messages on {', '.join(missing)}")
    base = np.asarray(series[TOPIC_WHEEL][0])

    def on_base(topic: str, value: Any) -> np.ndarray:
        times, messages = series[topic]
        return np.interp(base, times, [value(m) for m in messages])

    current_times, current_msgs = series[TOPIC_CURRENT]
    held = np.searchsorted(current_times, base + 1e-9, side="right") - 1
    fields = {
        "time_s": base,
        "current_a": np.array([m.data for m in current_msgs])[np.clip(held, 0, None)],
        "pressure_pa": on_base(TOPIC_PRESSURE, lambda m: m.fluid_pressure - ATMOSPHERE_PA),
        "wheel_speed_rad_s": on_base(TOPIC_WHEEL, lambda m: m.velocity[0]),
        "flywheel_speed_rad_s": on_base(TOPIC_FLYWHEEL, lambda m: m.velocity[0]),
        "vertical_load_n": on_base(TOPIC_WRENCH, lambda m: m.wrench.force.z),
        "longitudinal_force_n": on_base(TOPIC_WRENCH, lambda m: m.wrench.force.x),
    }
    check_plausible(fields, str(path))
    return Run(name=name or path.name, source=str(path), **fields)
