"""Contract rosbag2 writing with ``rosbags`` (mcap or sqlite3), no ROS install needed."""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any, Literal

import numpy as np
from rosbags.rosbag2 import Writer
from rosbags.rosbag2.enums import StoragePlugin
from rosbags.typesys import Stores, get_typestore

from .contract import (
    ATMOSPHERE_PA,
    FRAMES,
    TOPIC_CURRENT,
    TOPIC_FLYWHEEL,
    TOPIC_PRESSURE,
    TOPIC_TYPES,
    TOPIC_WHEEL,
    TOPIC_WRENCH,
)
from .contract_cdr import contract_rows
from .errors import RunFormatError
from .run import Run
from .stamps import ns_of_time, stamp_fields

TYPESTORE = get_typestore(Stores.ROS2_KILTED)
BAG_VERSION: Literal[9] = 9
STORAGE = {"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3}


def _stamp(time_s: float) -> Any:
    return TYPESTORE.types["builtin_interfaces/msg/Time"](**stamp_fields(ns_of_time(time_s)))


def _header(stamp: Any, frame: str) -> Any:
    return TYPESTORE.types["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)


def contract_messages(run: Run, k: int) -> dict[str, Any]:
    """The contract messages of sample ``k`` of ``run``, by topic."""
    stamp = _stamp(float(run.time_s[k]))  # one a sample: its five messages share it
    types = TYPESTORE.types
    empty = np.empty(0)

    def joint(name: str, speed: float) -> Any:
        return types["sensor_msgs/msg/JointState"](
            header=_header(stamp, name), name=[name], position=empty,
            velocity=np.array([speed]), effort=empty)

    vector = types["geometry_msgs/msg/Vector3"]
    wrench = types["geometry_msgs/msg/Wrench"](
        force=vector(x=float(run.longitudinal_force_n[k]), y=0.0, z=float(run.vertical_load_n[k])),
        torque=vector(x=0.0, y=0.0, z=0.0))
    return {
        TOPIC_CURRENT: types["sensor_msgs/msg/JointState"](
            header=_header(stamp, FRAMES[TOPIC_CURRENT]), name=[FRAMES[TOPIC_CURRENT]],
            position=empty, velocity=empty,
            effort=np.array([float(run.current_a[k])])),
        TOPIC_PRESSURE: types["sensor_msgs/msg/FluidPressure"](
            header=_header(stamp, FRAMES[TOPIC_PRESSURE]),
            fluid_pressure=float(run.pressure_pa[k]) + ATMOSPHERE_PA, variance=0.0),
        TOPIC_WHEEL: joint(FRAMES[TOPIC_WHEEL], float(run.wheel_speed_rad_s[k])),
        TOPIC_FLYWHEEL: joint(FRAMES[TOPIC_FLYWHEEL], float(run.flywheel_speed_rad_s[k])),
        TOPIC_WRENCH: types["geometry_msgs/msg/WrenchStamped"](
            header=_header(stamp, FRAMES[TOPIC_WRENCH]), wrench=wrench),
    }


def write_bag(run: Run, path: Path, storage: str = "mcap") -> None:
    """Write ``run`` as a rosbag2 with the contract topics (log time = sample time).

    Written inside a hidden ``.name.part`` folder and moved out when complete: an
    interrupted write leaves no bag (and that folder, which the next write replaces).
    """
    path = Path(path)
    if storage not in STORAGE:
        raise RunFormatError(f"unknown bag storage {storage!r}; use mcap or sqlite3")
    if path.exists():
        raise RunFormatError(f"{path}: exists already, not overwriting")
    if run.absent:  # NaN messages would read back as a signal
        raise RunFormatError(f"{run.source or run.name}: {', '.join(run.absent)} not logged: "
                             "a bag carries every contract topic; write it as CSV")
    stage = path.with_name(f".{path.name}.part")
    shutil.rmtree(stage, ignore_errors=True)
    # the storage file is named after its folder, and mcap embeds that name: write it in a
    # folder of the final name, inside the hidden stage
    with Writer(stage / path.name, version=BAG_VERSION,
                storage_plugin=STORAGE[storage]) as writer:
        connections = [writer.add_connection(topic, msgtype, typestore=TYPESTORE)
                       for topic, msgtype in TOPIC_TYPES.items()]
        log_ns, rows = contract_rows(run)
        topics = [(connection, rows[topic].tobytes(), rows[topic].itemsize)
                  for connection, topic in zip(connections, TOPIC_TYPES, strict=True)]
        for k, log_time in enumerate(log_ns.tolist()):
            for connection, data, size in topics:
                writer.write(connection, log_time, data[k * size:(k + 1) * size])
    os.replace(stage / path.name, path)
    stage.rmdir()
