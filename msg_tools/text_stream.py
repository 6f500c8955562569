"""A long delimited text file read straight into arrays, without its text in memory.

:func:`~msg_tools.text_table.read_table` takes the whole text and its lines: ~4.6 times the
file's size at the peak (an hour at 1 kHz, 206 MB, took ~1 GB to read and 2.2 GB to
``convert``). A large file whose layout its first and last lines show (the preamble, header
and units rows in the head, data to the end, a decimal point) is read here: the layout from
those lines by the same functions, the numbers by numpy from the open file, a chunk of rows
at a time into one array per column (the run is then made of them in place). Anything else
(a decimal comma, thousands separators, a footer, a last line cut short, clock times, a
compressed file, a value that does not read) goes the whole-text way, which handles it and
words its errors: this is a shortcut with one answer, never a second reader.
"""

from __future__ import annotations

import codecs
import itertools
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .errors import RunFormatError
from .text_table import (
    Dialect,
    Table,
    data_block,
    delimiter,
    is_data,
    read_header,
    read_table,
    read_text,
    sniff,
)

LARGE_BYTES = 8_000_000
"""Files from this size on take the shortcut (below it the text is small anyway)."""
END_BYTES = 65_536  # read from each end of the file to see its layout
CHUNK_ROWS = 5_000  # rows parsed at a time: ~0.5 MB of text


def read_table_file(path: Path, wanted: Sequence[str], where: str,
                    text_columns: Sequence[str] = (), optional: Sequence[str] = ()) -> Table:
    """:func:`~msg_tools.text_table.read_table` of the file at ``path``. A text column
    (time, which may be a clock time) read by the shortcut holds numbers: a column that
    is no numbers goes the whole-text way."""
    path = Path(path)
    if path.suffix.lower() != ".gz":
        try:
            large = path.stat().st_size >= LARGE_BYTES
        except OSError:
            large = False
        table = _streamed(path, wanted, where, optional) if large else None
        if table is not None:
            return table
    return read_table(read_text(path), wanted, where, text_columns, optional)


def _streamed(path: Path, wanted: Sequence[str], where: str, optional: Sequence[str] = ()
              ) -> Table | None:
    """The table read from the open file, or None where the layout needs the whole text."""
    ends = _ends(path)
    if ends is None:
        return None
    head, tail, encoding = ends
    try:
        dialect = sniff(tail, where)
    except RunFormatError:
        return None
    if dialect.decimal != "." or not (tail and is_data(tail[-1], dialect)):
        return None
    first, last = data_block(head, dialect)
    if not 0 < first < last:
        return None
    try:
        header = read_header(head[:first], dialect, wanted, where, optional)
    except RunFormatError:
        return None
    wanted = header.present
    values = _load(path, encoding, dialect, [header.column(w) for w in wanted], first)
    if values is None:
        return None
    return Table(dict(zip(wanted, values, strict=True)), header.units, owned=True)


def _ends(path: Path) -> tuple[list[str], list[str], str] | None:
    """The whole lines of the file's head and tail as numpy counts lines (``\\n``), and its
    encoding; None when the file is UTF-16 or its text is not whole (no final newline:
    maybe cut short)."""
    with path.open("rb") as file:
        head = file.read(END_BYTES)
        file.seek(max(0, path.stat().st_size - END_BYTES))
        tail = file.read()
    if head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)) or not tail.endswith(b"\n"):
        return None
    tail = tail[tail.find(b"\n") + 1:]  # from a line's start: no character cut in two
    encoding = "utf-8-sig" if head.startswith(codecs.BOM_UTF8) else "utf-8"
    try:
        texts = [codecs.getincrementaldecoder(encoding)().decode(head), tail.decode(encoding)]
    except UnicodeDecodeError:
        encoding = "latin-1"
        texts = [head.decode(encoding), tail.decode(encoding)]
    head_lines, tail_lines = ([line.removesuffix("\r") for line in text.split("\n")]
                              for text in texts)
    return head_lines[:-1], tail_lines[:-1], encoding  # the head's last is cut; "" after \n


def _load(path: Path, encoding: str, dialect: Dialect, columns: list[int], first: int
          ) -> list[np.ndarray] | None:
    """The ``columns`` of the data from line ``first`` on, each an array of its own, filled
    CHUNK_ROWS rows at a time: at the peak the columns and one chunk (numpy's loadtxt of the
    whole file grows one array past its end size, and its columns were views of it that
    kept it alive beside the run's SI copies: 1.4 times the file's size to convert)."""
    values = [np.empty(_line_count(path) - first) for _ in columns]
    done = 0
    try:
        with path.open(encoding=encoding, newline="") as file:
            lines = itertools.islice(file, first, None)
            while chunk := list(itertools.islice(lines, CHUNK_ROWS)):
                block = np.loadtxt(chunk, delimiter=delimiter(dialect), quotechar='"',
                                   ndmin=2, usecols=columns)
                for column, read in zip(values, block.T, strict=True):
                    column[done:done + len(block)] = read
                done += len(block)
    except (ValueError, UnicodeDecodeError):
        return None
    return [column[:done] for column in values]


def _line_count(path: Path) -> int:
    """Lines of ``path`` (its ``\n``: the file ends with one), counted in binary blocks."""
    with path.open("rb") as file:
        return sum(block.count(b"\n") for block in iter(lambda: file.read(1 << 20), b""))
