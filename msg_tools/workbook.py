"""Excel workbooks (``.xlsx``) as test-bench tools export them, read through openpyxl.

Each sheet is read as the delimited text a logger would have written (numbers as Python
writes them, date-times and clock times as ISO 8601 text, empty cells empty), so a sheet
gets everything :mod:`msg_tools.text_table` recognises: a title or preamble above the
header, units in the header cells or in a row below, a footer. The run is the first
sheet whose table holds the wanted columns.
"""

from __future__ import annotations

import csv
import datetime
import io
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from .binary_tables import library
from .errors import RunFormatError
from .text_table import Table, read_table

SUFFIXES = (".xlsx", ".xlsm")


def read_workbook(path: Path, wanted: Sequence[str], text_columns: Sequence[str] = (),
                  optional: Sequence[str] = ()) -> Table:
    """The ``wanted`` columns of the first sheet of ``path`` that holds them all; when none
    does, an error naming each sheet with what it holds."""
    openpyxl = library("openpyxl", path)
    try:
        book = openpyxl.load_workbook(path, read_only=True, data_only=True)
    except Exception as exc:  # openpyxl raises many types for damaged files
        raise RunFormatError(f"{path}: cannot read the workbook ({exc or type(exc).__name__})"
                             ) from None
    errors = []
    try:
        for sheet in book.worksheets:
            text = _as_text(sheet.iter_rows(values_only=True))
            try:
                return read_table(text, wanted, f"{path} sheet {sheet.title}", text_columns,
                                  optional)
            except RunFormatError as exc:
                errors.append(str(exc).removeprefix(f"{path} "))
    finally:
        book.close()
    raise RunFormatError(f"{path}: no sheet holds the run's columns ({'; '.join(errors)})")


def _as_text(rows: Iterable[tuple[Any, ...]]) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    for row in rows:
        writer.writerow([_cell(value) for value in row])
    return out.getvalue()


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(int(value))
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, datetime.datetime | datetime.date | datetime.time):
        return value.isoformat()
    return str(value)
