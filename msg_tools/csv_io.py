"""CSV read and write: the contract layout, or any layout a logger writes.

Reading goes through :mod:`msg_tools.text_table` (separator, decimal comma, encoding,
preamble, units row, text columns recognised) and a column mapping
(:mod:`msg_tools.mapping`). Values are written with 12 significant digits (far below any
sensor's resolution), time with 1 µs resolution whatever its origin: a recording stamped
with epoch time (~1.7e9 s) keeps its microseconds, which 12 significant digits would round
to 10 ms. CSV -> bag -> CSV gives back the same text.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np

from .columns import rig_columns, run_from_table, text_columns, wanted_columns
from .contract import CSV_COLUMNS, CSV_SCALE_TO_SI, CSV_TO_FIELD
from .mapping import DEFAULT_MAPPING, Mapping
from .mapping import read_mapping as read_mapping
from .run import Run
from .text_stream import read_table_file
from .text_table import Table

TIME_FORMAT = ".6f"  # 1 µs, absolute epoch times included (float64 resolves 0.24 µs there)
VALUE_FORMAT = ".12g"
CHUNK_ROWS = 5_000  # rows formatted at a time: ~3 MB of Python numbers and text


def read_csv(path: Path, name: str | None = None, mapping: Mapping | None = None) -> Run:
    """Read a delimited text run (``.csv``, ``.txt``, ``.tsv``, ``.gz`` of those) into a
    :class:`Run` (SI); extra columns of any type are ignored.

    Raises:
        RunFormatError: missing file or column, non-numeric, NaN or implausible
            values, time not strictly increasing; the message names the file.
    """
    path = Path(path)
    return read_named(path, lambda wanted, text, optional: read_table_file(
        path, wanted, str(path), text, optional), name, mapping)


def read_named(path: Path, table_of: Callable[[list[str], list[str], list[str]], Table],
               name: str | None = None, mapping: Mapping | None = None) -> Run:
    """The run of ``path`` whose table ``table_of`` reads, given the columns it must find,
    those read as text and those an actuator-only log may lack (a delimited text file, a
    workbook's sheet)."""
    mapping = mapping or DEFAULT_MAPPING
    table = table_of(wanted_columns(mapping), text_columns(mapping), rig_columns(mapping))
    return run_from_table(table, str(path), name or run_name(path), mapping)


def run_name(path: Path) -> str:
    """A run's name: its file name without its suffix (both of ``.csv.gz``)."""
    stem = Path(path.stem) if path.suffix.lower() == ".gz" else path
    return stem.stem


def format_csv(run: Run) -> str:
    """The contract CSV text of ``run``."""
    return "".join(csv_chunks(run))


def csv_chunks(run: Run, rows: int = CHUNK_ROWS, delimiter: str = ",") -> Iterator[str]:
    """The contract CSV text of ``run`` in pieces of ``rows`` rows, header first: a long run
    is written without its whole text in memory (an hour at 1 kHz, 206 MB of text, had
    taken ~1.6 GB as one list of Python numbers and lines); ``delimiter``: a tab for TSV."""
    columns = [c for c in CSV_COLUMNS if CSV_TO_FIELD[c] not in run.absent]  # as logged
    yield delimiter.join(columns) + "\n"
    formats = [TIME_FORMAT if c == "time_s" else VALUE_FORMAT for c in columns]
    for start in range(0, len(run), rows):
        block = np.column_stack([getattr(run, CSV_TO_FIELD[c])[start:start + rows]
                                 / CSV_SCALE_TO_SI[c] for c in columns]).tolist()
        yield "".join(delimiter.join(format(value, f)
                                     for value, f in zip(row, formats, strict=True))
                      + "\n" for row in block)


def write_csv(run: Run, path: Path, delimiter: str = ",") -> None:
    """Write ``run`` as a contract CSV (atomically: a failed write leaves no partial file;
    ``delimiter``: a tab for TSV)."""
    path = Path(path)
    tmp = path.with_name(path.name + ".part")
    try:
        with tmp.open("w", encoding="utf-8", newline="") as out:
            out.writelines(csv_chunks(run, delimiter=delimiter))
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    tmp.replace(path)
