"""Contract CSV read and write (docs/design.md, section 4).

Values are written with the shortest text that reads back to the same float, so
a run written and read again is bit-identical.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from .contract import CSV_COLUMNS, CSV_SCALE_TO_SI, CSV_TO_FIELD
from .errors import RunFormatError
from .run import Run


def read_csv(path: Path, name: str | None = None) -> Run:
    """Read a contract CSV (any column order; extra columns ignored) into a :class:`Run`.

    Raises:
        RunFormatError: missing file, missing contract column, non-numeric or NaN
            values, or time that is not strictly increasing; the message names the file.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise RunFormatError(f"{path}: cannot read ({exc.strerror})") from None
    header, _, body = text.partition("\n")
    columns = [c.strip() for c in header.split(",")]
    missing = [c for c in CSV_COLUMNS if c not in columns]
    if missing:
        raise RunFormatError(f"{path}: missing contract column(s) {', '.join(missing)} "
                             f"(found {', '.join(columns)})")
    try:
        table = np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2)
    except ValueError as exc:
        raise RunFormatError(f"{path}: unreadable values ({exc})") from None
    if table.shape[0] < 2 or table.shape[1] != len(columns):
        raise RunFormatError(f"{path}: expected >= 2 rows of {len(columns)} values")
    fields: dict[str, np.ndarray] = {}
    for column in CSV_COLUMNS:
        values = table[:, columns.index(column)] * CSV_SCALE_TO_SI[column]
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise RunFormatError(f"{path}: column {column} has NaN/inf at row {bad[0] + 2}")
        fields[CSV_TO_FIELD[column]] = values
    steps = np.diff(fields["time_s"])
    if np.any(steps <= 0):
        row = int(np.flatnonzero(steps <= 0)[0]) + 3
        raise RunFormatError(f"{path}: time_s is not strictly increasing at row {row}")
    return Run(name=name or path.stem, source=str(path), **fields)


def write_csv(run: Run, path: Path) -> None:
    """Write ``run`` as a contract CSV (atomically: a failed write leaves no partial file)."""
    path = Path(path)
    table = np.column_stack(
        [getattr(run, CSV_TO_FIELD[c]) / CSV_SCALE_TO_SI[c] for c in CSV_COLUMNS]
    )
    lines = [",".join(CSV_COLUMNS)]
    lines.extend(",".join(map(repr, row)) for row in table.tolist())
    tmp = path.with_name(path.name + ".part")
    tmp.write_text("\n".join(lines) + "\n")
    tmp.replace(path)
