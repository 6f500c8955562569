"""Which topic and message field carries each contract quantity in a bag, and reading it.

The contract topics (:mod:`msg_tools.contract`) are used where present. Otherwise a topic
is found by its tail: ``/brake/pressure`` matches ``/rig2/brake/pressure`` or
``/brake/pressure`` (one match only), and ``joint_states`` also matches ``joint_state``
(the graph's name for the speeds in 0.1, and other rigs'). A
column-mapping file may name ``topic`` and ``field`` (``data``, ``fluid_pressure``,
``velocity[0]``, ``velocity[wheel]`` — a JointState entry by joint name —, ``position[0]``,
``wrench.force.x``). A JointState without velocities gives its positions, which the reader
differentiates.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any

from .contract import (
    ATMOSPHERE_PA,
    LEGACY_CURRENT_TYPE,
    MAY_LACK,
    NAMESPACE,
    TOPIC_CURRENT,
    TOPIC_FLYWHEEL,
    TOPIC_PRESSURE,
    TOPIC_WHEEL,
    TOPIC_WRENCH,
    VALVE_JOINT,
)
from .errors import RunFormatError
from .mapping import Channel

CONTRACT_SOURCES: dict[str, tuple[str, str]] = {
    "current_ref_A": (TOPIC_CURRENT, f"effort[{VALVE_JOINT}]"),
    "brake_pressure_bar": (TOPIC_PRESSURE, "fluid_pressure"),
    "wheel_speed_rad_s": (TOPIC_WHEEL, "velocity[wheel]"),
    "flywheel_speed_rad_s": (TOPIC_FLYWHEEL, "velocity[flywheel]"),
    "vertical_load_N": (TOPIC_WRENCH, "wrench.force.z"),
    "longitudinal_force_N": (TOPIC_WRENCH, "wrench.force.x"),
}
"""Contract column → (contract topic, field)."""
LEGACY_FIELDS: dict[tuple[str, str], str] = {("current_ref_A", LEGACY_CURRENT_TYPE): "data"}
"""(contract column, message type) → field, for the types of 0.1 bags."""

_STEP = re.compile(r"(\w+)(?:\[(\w+)\])?")


@dataclass(frozen=True)
class FieldPath:
    """A field such as ``wrench.force.x`` or ``velocity[wheel]`` (index or joint name)."""

    text: str

    @cached_property
    def steps(self) -> list[tuple[str, str]]:
        steps = _STEP.findall(self.text)
        if not steps:
            raise RunFormatError(f"field {self.text!r}: expected e.g. wrench.force.x or "
                                 "velocity[0]")
        return steps

    @cached_property
    def absolute(self) -> bool:
        """Whether it reads a FluidPressure: absolute, where the contract is gauge."""
        return self.steps[-1][0] == "fluid_pressure"

    def read(self, message: Any) -> tuple[float, bool]:
        """(value, whether it is a JointState position standing in for a velocity)."""
        value: Any = message
        position = False
        for name, index in self.steps:
            if name == "velocity" and index and _positions_only(message):
                name, position = "position", True
            value = getattr(value, name)
            if index:
                value = value[_index(message, index)]
        if name == "position":
            position = True
        if self.absolute:
            value = value - ATMOSPHERE_PA
        return float(value), position


def _positions_only(message: Any) -> bool:
    """A JointState that carries positions and no velocities."""
    return hasattr(message, "position") and len(message.velocity) == 0 and len(
        message.position) > 0


def _index(message: Any, index: str) -> int:
    if index.isdigit():
        return int(index)
    names = list(getattr(message, "name", []))
    return names.index(index) if index in names else 0


@dataclass(frozen=True)
class Source:
    """Where one contract column is read from in a bag."""

    contract: str
    topic: str
    field: FieldPath
    channel: Channel


def resolve(mapping: dict[str, Channel], types: Mapping[str, str], where: str) -> list[Source]:
    """The bag source of each contract column except time (the wheel's stamps).

    Args:
        types: message type of each topic in the bag (``{"/rig/brake/pressure":
            "sensor_msgs/msg/FluidPressure"}``).
    """
    topics = sorted(types)
    sources = []
    for contract, (default_topic, default_field) in CONTRACT_SOURCES.items():
        channel = mapping[contract]
        if (not channel.topic and contract in MAY_LACK
                and not _matching(default_topic, types)):
            continue  # a braking log may lack it, as a CSV may lack its column
        topic = channel.topic or _find_topic(default_topic, types, contract, where)
        if topic not in topics:
            raise RunFormatError(f"{where}: bag has no topic {topic} (for {contract}; it has "
                                 f"{_listing(types)})")
        field = channel.field or LEGACY_FIELDS.get((contract, types[topic]), default_field)
        sources.append(Source(contract, topic, FieldPath(field), channel))
    return sources


def _listing(types: Mapping[str, str]) -> str:
    """The bag's topics with their types, for an error a user can act on (issue 30)."""
    return ", ".join(f"{topic} ({kind})" for topic, kind in sorted(types.items())) or "no topic"


def _matching(contract_topic: str, types: Mapping[str, str]) -> list[str]:
    """The bag's topics that may be ``contract_topic``: itself, or one ending as it does
    (another namespace)."""
    if contract_topic in types:
        return [contract_topic]
    tail = contract_topic.removeprefix(f"/{NAMESPACE}")
    tails = {tail, tail.removesuffix("s")} if tail.endswith("joint_states") else {tail}
    return [t for t in sorted(types) if any(t.endswith(x) for x in tails)]


def _find_topic(contract_topic: str, types: Mapping[str, str], contract: str, where: str
                ) -> str:
    found = _matching(contract_topic, types)
    if len(found) == 1:
        return found[0]
    hint = (f"topics {', '.join(found)} all match" if found
            else f"no topic matches; it has {_listing(types)}")
    raise RunFormatError(f"{where}: bag has no messages on {contract_topic} for {contract} "
                         f"({hint}); name the topic in a column-mapping file "
                         f"({contract}: {{topic: /your/topic}})")
