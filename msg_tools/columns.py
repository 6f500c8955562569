"""From a table's named columns to a :class:`~msg_tools.run.Run`: mapping, units, time, checks."""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import replace

import numpy as np

from .checks import check_plausible
from .contract import CSV_COLUMNS, CSV_TO_FIELD, MAY_LACK, RIG_COLUMNS
from .errors import RunFormatError
from .mapping import DATETIME, DEFAULT_MAPPING, Channel, Mapping
from .run import Run
from .text_table import MASTER_TIME, Table
from .units import QUANTITY, UNITS, parse_unit


def wanted_columns(mapping: Mapping) -> list[str]:
    return [mapping[c].column for c in CSV_COLUMNS]


def rig_columns(mapping: Mapping) -> list[str]:
    """The columns an actuator-only log may lack as a group (:data:`RIG_COLUMNS`)."""
    return [mapping[c].column for c in RIG_COLUMNS]


def text_columns(mapping: Mapping) -> list[str]:
    """Columns read as text: time, which may be numbers or calendar date-times."""
    return [mapping["time_s"].column]


def run_from_table(table: Table, where: str, name: str, mapping: Mapping | None = None
                   ) -> Run:
    """The run in ``table`` (SI, checked); the message of any error names ``where``."""
    mapping = mapping or DEFAULT_MAPPING
    fields: dict[str, np.ndarray] = {}
    notes = table.notes
    channels = _channels(table, where, mapping)
    shape = np.shape(table.columns[channels["time_s"].column])
    absent = tuple(CSV_TO_FIELD[c] for c in RIG_COLUMNS if c not in channels)
    if not set(RIG_COLUMNS) & set(channels):  # an actuator-only log: the wheel off
        fields.update({CSV_TO_FIELD[c]: np.zeros(shape) for c in RIG_COLUMNS})
        notes += (f"{where}: no wheel, flywheel or load channels: an actuator-only log, "
                  "read with the wheel off the flywheel (they are 0)",)
        absent = ()
    elif absent:  # a braking log without load cells or a flywheel encoder
        fields.update({field: np.full(shape, np.nan) for field in absent})
        notes += (f"{where}: {', '.join(absent)} not logged: what needs "
                  f"{'them' if len(absent) > 1 else 'it'} skips this run and says so",)
    notes += tuple(_unit_against_name(channels, table, where))
    uses = Counter(channel.column for channel in channels.values())
    for contract, channel in channels.items():
        raw = table.columns[channel.column]
        clock = _clock_seconds(raw) if contract == "time_s" else None
        if clock is not None:
            notes += (f"{where}: time column {channel.column} read as a clock time of day "
                      f"(HH:MM:SS), from {raw[0]}",)
        fields[CSV_TO_FIELD[contract]] = clock if clock is not None else \
            _to_si(channel, raw, where, table.owned and uses[channel.column] == 1)
    check_plausible(fields, where)
    return Run(name=name, source=where, notes=notes, absent=absent, **fields)


def _unit_against_name(channels: dict[str, Channel], table: Table, where: str
                       ) -> list[str]:
    """A note for each contract-named column whose stated unit is not the one its name
    says (psi in the units row under brake_pressure_bar): the file's statement is read,
    and which of the two is wrong only its writer knows."""
    return [f"{where}: column {contract} says {table.units.get(contract)!r} in its units row "
            f"while its name says {DEFAULT_MAPPING[contract].unit}: read as "
            f"{table.units.get(contract)!r}; if the numbers are "
            f"{DEFAULT_MAPPING[contract].unit}, correct the units row"
            for contract, channel in channels.items()
            if channel.column == contract and contract in table.units
            and channel.unit != DEFAULT_MAPPING[contract].unit]


def _channels(table: Table, where: str, mapping: Mapping) -> dict[str, Channel]:
    """Each contract column's channel in ``table``, in the unit the file states."""
    channels, missing = {}, []
    for contract in CSV_COLUMNS:
        channel = _with_written_unit(_master_time(mapping[contract], contract, table),
                                     contract, table, where)
        if channel.column in table.columns:
            channels[contract] = channel
        else:
            missing.append((contract, channel.column))
    lacking = [c for c, _ in missing]
    for contract, column in missing:
        if column in table.other_lengths:
            length = len(next(iter(table.columns.values())))
            raise RunFormatError(
                f"{where}: {column} ({contract}) has {table.other_lengths[column]} samples, "
                f"the file's other vectors {length}: the vectors of one run must be of one "
                "length (cut or padded when the file was written?)")
    if missing and lacking != list(RIG_COLUMNS) and not set(lacking) <= set(MAY_LACK):
        found = ", ".join(table.columns) or "none"
        named = ", ".join(f"{column} for {contract}" for contract, column in missing)
        raise RunFormatError(f"{where}: missing column(s) {named} (found {found}); name "
                             "them in a column-mapping file (--mapping FILE; "
                             "docs/data-contract.md says how; an actuator-only log may leave "
                             "out all four wheel, flywheel and load channels; a braking log "
                             "its load cells or its flywheel encoder, not its time, current, "
                             "pressure or wheel speed)")
    return channels


def _master_time(channel: Channel, contract: str, table: Table) -> Channel:
    if contract == "time_s" and channel.column not in table.columns and \
            MASTER_TIME in table.columns:
        return replace(channel, column=MASTER_TIME)
    return channel


def _with_written_unit(channel: Channel, contract: str, table: Table, where: str) -> Channel:
    """``channel`` in the unit the file itself states (units row, header cell, MDF/TDMS
    metadata), unless the mapping file declared another one: then that is an error."""
    written = table.units.get(channel.column)
    if written is None or channel.unit == DATETIME:
        return channel
    quantity = QUANTITY[CSV_TO_FIELD[contract]]
    unit = parse_unit(written, quantity)
    if unit is None:
        raise RunFormatError(f"{where}: column {channel.column} has the unit {written!r}, "
                             f"not one of {', '.join(UNITS[quantity])} for {contract}")
    if unit == channel.unit:
        return channel
    if channel.unit_declared:
        raise RunFormatError(f"{where}: column {channel.column} says its unit is {written!r} "
                             f"but the column mapping declares {channel.unit!r}")
    return channel.with_unit(unit, UNITS[quantity][unit])


def _to_si(channel: Channel, raw: np.ndarray, where: str, in_place: bool = False
           ) -> np.ndarray:
    """``raw`` in SI (``in_place``: into ``raw`` itself when it is a float array, which no
    one else then reads)."""
    if raw.dtype.kind in "USO":
        raw = np.char.replace(np.char.strip(raw.astype(str), '"'), ",", ".")
        try:
            raw = raw.astype(float)
        except ValueError:
            return _calendar_seconds(channel, raw, where)
    if raw.dtype.kind == "M":
        return _calendar_seconds(channel, raw, where)
    values = channel.to_si(raw, out=raw if in_place and raw.dtype == np.float64 else None)
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise RunFormatError(f"{where}: column {channel.column} has NaN/inf at data row "
                             f"{bad[0] + 1}")
    return values


_CLOCK = re.compile(r"(\d{1,2}):(\d{2}):(\d{2}(?:[.,]\d*)?)")
DAY_S = 86400.0


def _clock_seconds(raw: np.ndarray) -> np.ndarray | None:
    """Seconds of a time-of-day column (``HH:MM:SS.ffffff``, as loggers without a date
    stamp), counting on past midnight; None when the column is not one."""
    if raw.dtype.kind not in "USO" or raw.size == 0 or not _CLOCK.fullmatch(
            str(raw[0]).strip().strip('"')):
        return None
    parts = [_CLOCK.fullmatch(str(value).strip().strip('"')) for value in raw]
    if not all(parts):
        return None
    seconds = np.array([int(h) * 3600 + int(m) * 60 + float(s.replace(",", "."))
                        for h, m, s in (p.groups() for p in parts if p)])
    days = np.concatenate([[0], np.cumsum(np.diff(seconds) < -DAY_S / 2)])
    return seconds + DAY_S * days


def _calendar_seconds(channel: Channel, raw: np.ndarray, where: str) -> np.ndarray:
    """Seconds since the epoch of a datetime column (µs resolution)."""
    try:
        stamps = raw.astype("datetime64[us]")
    except ValueError:
        raise RunFormatError(f"{where}: column {channel.column} holds neither numbers, "
                             f"clock times (HH:MM:SS) nor ISO 8601 date-times (first value "
                             f"{str(raw[0])!r})") from None
    return stamps.astype(np.int64) * 1e-6
