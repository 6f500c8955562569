"""Where each contract quantity is in a file, and how to turn it into SI.

A column-mapping file (YAML) names, for any contract column it changes, the file's column
(tables: CSV, MATLAB, HDF5, Parquet, MDF4, TDMS) or topic and field (bags), the unit, and an
optional ``scale`` and ``offset`` applied to the raw number before its unit::

    time_s: {column: t, unit: ms}               # or unit: datetime (ISO 8601 text)
    current_ref_A: {column: I_valve, unit: mA}
    brake_pressure_bar: {column: p_brake, unit: psi, offset: -14.696}
    longitudinal_force_N: {column: Fx, unit: kN, scale: -1}
    wheel_speed_rad_s: {topic: /wheel/joint_states, field: "position[0]", unit: rad}

so that ``SI value = (raw * scale + offset) * unit factor``. Columns the file does not
mention keep the contract's name and unit. A ``field`` ending in ``position[i]`` (or a
JointState without velocities) is differentiated (:mod:`msg_tools.derivative`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import yaml

from .contract import CSV_COLUMNS, CSV_SCALE_TO_SI, CSV_TO_FIELD
from .errors import RunFormatError
from .units import ANGLE_UNITS, QUANTITY, UNITS, unit_names

DATETIME = "datetime"
"""The unit of a time column holding calendar text (``2024-05-02T10:00:00.125``)."""


@dataclass(frozen=True)
class Channel:
    """Where one contract quantity comes from and its conversion to SI.

    Attributes:
        column: the table column (CSV header name, MATLAB variable, …).
        unit: the unit of the raw numbers (a key of ``UNITS[quantity]``, or ``datetime``).
        factor: SI per unit.
        scale, offset: applied to the raw number before the unit (sign flips, zero offsets).
        topic, field: in a bag, the topic and the message field (``""``: the contract's).
        unit_declared: the mapping file gave the unit (a units row may not contradict it;
            without it a bag's values are taken as SI).
    """

    column: str
    unit: str
    factor: float
    scale: float = 1.0
    offset: float = 0.0
    topic: str = ""
    field: str = ""
    unit_declared: bool = False

    def to_si(self, raw: np.ndarray, factor: float | None = None,
              out: np.ndarray | None = None) -> np.ndarray:
        """SI values of ``raw`` (``factor`` instead of the unit's, e.g. 1 for SI bags;
        ``out``: a float array to write them into, ``raw`` itself included), the same
        operations in the same order either way (the same bits)."""
        factor = self.factor if factor is None else factor
        if out is None:
            return (np.asarray(raw, dtype=float) * self.scale + self.offset) * factor
        np.multiply(raw, self.scale, out=out)
        np.add(out, self.offset, out=out)
        return np.multiply(out, factor, out=out)

    def with_unit(self, unit: str, factor: float) -> Channel:
        return replace(self, unit=unit, factor=factor)


Mapping = dict[str, Channel]
"""Contract column (``time_s``, ``current_ref_A``, …) → :class:`Channel`."""

CONTRACT_UNITS: dict[str, str] = {
    "time_s": "s", "current_ref_A": "A", "brake_pressure_bar": "bar",
    "wheel_speed_rad_s": "rad/s", "flywheel_speed_rad_s": "rad/s", "vertical_load_N": "N",
    "longitudinal_force_N": "N",
}

DEFAULT_MAPPING: Mapping = {
    c: Channel(c, CONTRACT_UNITS[c], CSV_SCALE_TO_SI[c]) for c in CSV_COLUMNS}


def read_mapping(path: Path) -> Mapping:
    """Read a column-mapping file (see the module doc); unknown keys and units are refused."""
    try:
        document = yaml.safe_load(Path(path).read_text())
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        # brackets open a YAML list inside {…}: the commonest slip in a bag's field
        hint = ("; quote a field with brackets: field: \"velocity[0]\""
                if isinstance(exc, yaml.YAMLError) and "[" in Path(path).read_text() else "")
        raise RunFormatError(f"{path}: cannot read column mapping ({exc}){hint}") from None
    if not isinstance(document, dict):
        raise RunFormatError(f"{path}: a column mapping is 'contract_column: {{column, unit}}'")
    unknown = sorted(set(document) - set(CSV_COLUMNS))
    if unknown:
        raise RunFormatError(f"{path}: {unknown[0]!r} is not a contract column "
                             f"({', '.join(CSV_COLUMNS)})")
    mapping = dict(DEFAULT_MAPPING)
    for contract, entry in document.items():
        mapping[contract] = _channel(contract, entry, str(path))
    return mapping


KEYS = {"column", "unit", "scale", "offset", "topic", "field"}


def _channel(contract: str, entry: object, where: str) -> Channel:
    if not isinstance(entry, dict) or not entry:
        raise RunFormatError(f"{where}: {contract} needs a mapping such as "
                             "{column: NAME, unit: UNIT}")
    extra = sorted(set(entry) - KEYS)
    if extra:
        raise RunFormatError(f"{where}: {contract}: unknown key {extra[0]!r} "
                             f"(use {', '.join(sorted(KEYS))})")
    unit = str(entry.get("unit", CONTRACT_UNITS[contract]))
    factor = unit_factor(contract, unit, str(entry.get("field", "")), where)
    try:
        scale, offset = float(entry.get("scale", 1.0)), float(entry.get("offset", 0.0))
    except (TypeError, ValueError):
        raise RunFormatError(f"{where}: {contract}: scale and offset must be numbers") from None
    if scale == 0.0 or not np.isfinite(scale) or not np.isfinite(offset):
        raise RunFormatError(f"{where}: {contract}: scale must be finite and non-zero")
    return Channel(column=str(entry.get("column", contract)), unit=unit, factor=factor,
                   scale=scale, offset=offset, topic=str(entry.get("topic", "")),
                   field=str(entry.get("field", "")), unit_declared="unit" in entry)


def unit_factor(contract: str, unit: str, field: str = "", where: str = "") -> float:
    """SI per ``unit`` for ``contract`` (an angle unit for a differentiated position)."""
    if contract == "time_s" and unit == DATETIME:
        return 1.0
    units = UNITS[QUANTITY[CSV_TO_FIELD[contract]]]
    if "position" in field:
        units = ANGLE_UNITS
    if unit not in units:
        raise RunFormatError(f"{where}: unit {unit!r} of {contract} is not one of "
                             f"{unit_names(units)}")
    return units[unit]
