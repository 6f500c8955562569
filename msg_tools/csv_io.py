"""CSV read and write: the contract layout, or any layout through a column-mapping file.

A column-mapping file (YAML) names, for each contract column, the file's column and
its unit::

    time_s: {column: t, unit: ms}
    current_ref_A: {column: I_valve, unit: mA}
    brake_pressure_bar: {column: p_brake, unit: psi}
    wheel_speed_rad_s: {column: n_wheel, unit: rpm}
    flywheel_speed_rad_s: {column: n_flywheel, unit: rpm}
    vertical_load_N: {column: Fz, unit: kN}
    longitudinal_force_N: {column: Fx, unit: kN}

Values are written with 12 significant digits (far below any sensor's resolution), time
with 1 µs resolution whatever its origin: a recording stamped with epoch time (~1.7e9 s)
keeps its microseconds, which 12 significant digits would round to 10 ms. CSV -> bag ->
CSV gives back the same text.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import yaml

from .checks import check_plausible
from .contract import CSV_COLUMNS, CSV_SCALE_TO_SI, CSV_TO_FIELD
from .errors import RunFormatError
from .run import Run
from .units import QUANTITY, UNITS

TIME_FORMAT = ".6f"  # 1 µs, absolute epoch times included (float64 resolves 0.24 µs there)
VALUE_FORMAT = ".12g"

Mapping = dict[str, tuple[str, float]]
"""Contract column → (file column, factor to SI)."""

DEFAULT_MAPPING: Mapping = {c: (c, CSV_SCALE_TO_SI[c]) for c in CSV_COLUMNS}


def read_mapping(path: Path) -> Mapping:
    """Read a column-mapping file; every contract column must be mapped with a known unit."""
    try:
        document = yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as exc:
        raise RunFormatError(f"{path}: cannot read column mapping ({exc})") from None
    if not isinstance(document, dict):
        raise RunFormatError(f"{path}: a column mapping is 'contract_column: {{column, unit}}'")
    mapping: Mapping = {}
    for contract in CSV_COLUMNS:
        entry = document.get(contract)
        if not isinstance(entry, dict) or "column" not in entry or "unit" not in entry:
            raise RunFormatError(f"{path}: {contract} needs 'column' and 'unit'")
        units = UNITS[QUANTITY[CSV_TO_FIELD[contract]]]
        if entry["unit"] not in units:
            raise RunFormatError(f"{path}: unit {entry['unit']!r} of {contract} is not one of "
                                 f"{', '.join(units)}")
        mapping[contract] = (str(entry["column"]), units[entry["unit"]])
    return mapping


def read_csv(path: Path, name: str | None = None, mapping: Mapping | None = None) -> Run:
    """Read a run CSV (any column order; extra columns ignored) into a :class:`Run` (SI).

    Raises:
        RunFormatError: missing file or column, non-numeric, NaN or implausible
            values, time not strictly increasing, gaps; the message names the file.
    """
    path = Path(path)
    mapping = mapping or DEFAULT_MAPPING
    try:
        text = path.read_text()
    except OSError as exc:
        raise RunFormatError(f"{path}: cannot read ({exc.strerror})") from None
    if not text.strip():
        raise RunFormatError(f"{path}: the file is empty")
    header, _, body = text.partition("\n")
    columns = [c.strip() for c in header.split(",")]
    missing = [source for source, _ in mapping.values() if source not in columns]
    if missing:
        raise RunFormatError(f"{path}: missing column(s) {', '.join(missing)} "
                             f"(found {', '.join(columns)})")
    if not body.strip():
        raise RunFormatError(f"{path}: expected >= 2 rows of {len(columns)} values, found none")
    try:
        table = np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2)
    except ValueError as exc:
        raise RunFormatError(f"{path}: unreadable values ({exc})") from None
    if table.shape[0] < 2 or table.shape[1] != len(columns):
        raise RunFormatError(f"{path}: expected >= 2 rows of {len(columns)} values")
    fields: dict[str, np.ndarray] = {}
    for contract, (source, factor) in mapping.items():
        values = table[:, columns.index(source)] * factor
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise RunFormatError(f"{path}: column {source} has NaN/inf at row {bad[0] + 2}")
        fields[CSV_TO_FIELD[contract]] = values
    check_plausible(fields, str(path))
    return Run(name=name or path.stem, source=str(path), **fields)


def format_csv(run: Run) -> str:
    """The contract CSV text of ``run``."""
    table = np.column_stack(
        [getattr(run, CSV_TO_FIELD[c]) / CSV_SCALE_TO_SI[c] for c in CSV_COLUMNS]
    )
    formats = [TIME_FORMAT if c == "time_s" else VALUE_FORMAT for c in CSV_COLUMNS]
    lines = [",".join(CSV_COLUMNS)]
    lines.extend(",".join(format(value, f) for value, f in zip(row, formats, strict=True))
                 for row in table.tolist())
    return "\n".join(lines) + "\n"


def write_csv(run: Run, path: Path) -> None:
    """Write ``run`` as a contract CSV (atomically: a failed write leaves no partial file)."""
    path = Path(path)
    tmp = path.with_name(path.name + ".part")
    tmp.write_text(format_csv(run))
    tmp.replace(path)
