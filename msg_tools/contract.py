"""The data contract of a measured rig run (docs/data-contract.md).

CSV columns carry the units users read (bar); everything inside is SI (Pa).
"""

from __future__ import annotations

from .units import PA_PER_BAR

ATMOSPHERE_PA = 101325.0  # FluidPressure is absolute: gauge + 1 atm

CSV_COLUMNS: tuple[str, ...] = (
    "time_s", "current_ref_A", "brake_pressure_bar", "wheel_speed_rad_s",
    "flywheel_speed_rad_s", "vertical_load_N", "longitudinal_force_N",
)
"""Contract CSV header names, in the order we write them (readers accept any order).

The current of a row is the command in force over the sample interval that ends at that
row's time (the row's pressure already reflects it); the same holds for a bag's
current_ref at its log time."""

RIG_COLUMNS: tuple[str, ...] = CSV_COLUMNS[3:]
"""The columns an actuator-only logger may leave out as a group (wheel off the flywheel:
they read 0); time, current and pressure every run has."""

CSV_SCALE_TO_SI: dict[str, float] = {
    "time_s": 1.0, "current_ref_A": 1.0, "brake_pressure_bar": PA_PER_BAR,
    "wheel_speed_rad_s": 1.0, "flywheel_speed_rad_s": 1.0, "vertical_load_N": 1.0,
    "longitudinal_force_N": 1.0,
}

CSV_TO_FIELD: dict[str, str] = {
    "time_s": "time_s", "current_ref_A": "current_a", "brake_pressure_bar": "pressure_pa",
    "wheel_speed_rad_s": "wheel_speed_rad_s", "flywheel_speed_rad_s": "flywheel_speed_rad_s",
    "vertical_load_N": "vertical_load_n", "longitudinal_force_N": "longitudinal_force_n",
}
"""CSV column → :class:`msg_tools.run.Run` field."""

TOPIC_CURRENT = "/rig/brake/current_ref"
"""The brake command: a ``sensor_msgs/JointState`` whose joint :data:`VALVE_JOINT` carries
the valve current [A] in ``effort``; its stamp is the *end* of the interval the current
holds for (from the previous command's stamp, or the run's start). A CSV row at t holds
the same command. 0.1 bags carry it as ``std_msgs/Float64`` at its log time."""
VALVE_JOINT = "brake_valve"
LEGACY_CURRENT_TYPE = "std_msgs/msg/Float64"
TOPIC_PRESSURE = "/rig/brake/pressure"
# the speeds were on .../joint_state in 0.1; readers still take bags with those names
TOPIC_WHEEL = "/rig/wheel/joint_states"
TOPIC_FLYWHEEL = "/rig/flywheel/joint_states"
TOPIC_WRENCH = "/rig/load_cell/wrench"

NAMESPACE = "rig"
"""Namespace of the graph's nodes by default; every topic above is relative to it (a rig
started in another namespace, ``/rig2``, publishes ``/rig2/brake/pressure``)."""

TOPIC_TYPES: dict[str, str] = {
    TOPIC_CURRENT: "sensor_msgs/msg/JointState",
    TOPIC_PRESSURE: "sensor_msgs/msg/FluidPressure",
    TOPIC_WHEEL: "sensor_msgs/msg/JointState",
    TOPIC_FLYWHEEL: "sensor_msgs/msg/JointState",
    TOPIC_WRENCH: "geometry_msgs/msg/WrenchStamped",
}

FRAMES: dict[str, str] = {
    TOPIC_CURRENT: VALVE_JOINT, TOPIC_PRESSURE: "brake", TOPIC_WHEEL: "wheel",
    TOPIC_FLYWHEEL: "flywheel", TOPIC_WRENCH: "load_cell",
}
"""Each topic's header frame as a run written offline carries it (a JointState's joint is
named as its frame); a bag's reader takes these messages by their fixed layout."""

MAY_LACK = ("flywheel_speed_rad_s", "vertical_load_N", "longitudinal_force_N")
"""The columns a braking log may lack (a logger without load cells or a flywheel encoder)."""
