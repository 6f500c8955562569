"""Delimited text as rig loggers write it, read into named columns.

Recognised without configuration: the encoding (UTF-8 with or without BOM, UTF-16 with a
BOM, else Latin-1), the separator (``,`` ``;`` tab ``|`` or blanks), a decimal comma, a
metadata preamble above the header, a units row below it or units in the header cells
(``p_brake [bar]``), quoted cells, thousands separators (``32,412.5``, ``32.412,5``,
``32'412.5``), text columns (read only when asked for) and a footer.
The data block is the longest run of lines that split into the same number of cells,
at least two of them numbers; the header is the last line above it naming the wanted
columns.
"""

from __future__ import annotations

import codecs
import csv
import gzip
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import RunFormatError

SEPARATORS = (",", ";", "\t", "|", " ")
SAMPLE_LINES = 40  # lines of the data block used to decide its separator
_UNIT_IN_HEADER = re.compile(r"^(.*?)\s*[\[(]([^\])]*)[\])]\s*$")
_DECIMAL_COMMA = re.compile(r"^[+-]?\d*,\d+([eE][+-]?\d+)?$")
_BOTH_MARKS = re.compile(r"^[+-]?[\d.,' \u00a0\u202f]*\d$")
THOUSANDS = {".": ",'\u00a0\u202f ", ",": ".'\u00a0\u202f "}
"""The marks that may group thousands, by decimal mark (a space only between quotes or
where blanks do not separate the cells)."""


MASTER_TIME = "<master time>"
"""The column of a format's own time base (MDF master channel, TDMS waveform timing),
used for time when the mapped time column is absent."""


@dataclass(frozen=True)
class Table:
    """Columns of one table by name (raw numbers, or text for text columns) and the units
    its header or units row gave (by column; absent where none was written)."""

    columns: dict[str, np.ndarray]
    units: dict[str, str]
    notes: tuple[str, ...] = ()
    owned: bool = False
    """The columns are this table's alone (float arrays no one else holds): the run is made
    of them in place, not beside them (a long file's peak memory)."""
    other_lengths: dict[str, int] = field(default_factory=dict)
    """Vectors of a file of named vectors (MATLAB, HDF5, ...) left out for a length other
    than the table's, with their lengths: a column missing for that is named as such."""


GZIP_MAGIC = b"\x1f\x8b"


def read_text(path: Path) -> str:
    """The text of ``path`` (gzip-compressed if it ends in ``.gz`` or its bytes say so: a
    logger's archive keeps its ``.csv`` name), encoding detected."""
    try:
        raw = Path(path).read_bytes()
        if path.suffix.lower() == ".gz" or raw.startswith(GZIP_MAGIC):
            raw = gzip.decompress(raw)
    except (OSError, EOFError) as exc:
        raise RunFormatError(f"{path}: cannot read ({getattr(exc, 'strerror', None) or exc})"
                             ) from None
    return decode(raw)


def decode(raw: bytes) -> str:
    """Text of ``raw``: a BOM decides, else UTF-8, else Latin-1 (which never fails)."""
    if raw.startswith(codecs.BOM_UTF8):
        return raw[len(codecs.BOM_UTF8):].decode("utf-8", errors="replace")
    if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return raw.decode("utf-16", errors="replace")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


@dataclass(frozen=True)
class Dialect:
    separator: str
    decimal: str
    cells: int  # per line of the data block


def read_table(text: str, wanted: Sequence[str], where: str,
               text_columns: Sequence[str] = (), optional: Sequence[str] = ()) -> Table:
    """The ``wanted`` columns of ``text`` (numbers; ``text_columns`` as text), those of them
    ``optional`` where the header has them. A wanted name may be the whole header cell,
    unit included (``t [s]``, copied from the file)."""
    lines, notes = _complete_lines(text, where)
    dialect = sniff(lines, where)
    first, last = data_block(lines, dialect)
    header = read_header(lines[:first], dialect, wanted, where, optional)
    wanted = header.present
    body = lines[first:last]
    numeric = [w for w in wanted if w not in text_columns]
    values, grouped = _numbers(body, dialect, header.names,
                               [header.bare[w] for w in numeric], where, first)
    columns = dict(zip(numeric, values, strict=True))
    if grouped:
        notes += (f"{where}: numbers with thousands separators read ({grouped})",)
    for name in wanted:
        if name in text_columns:
            columns[name] = _text(body, dialect, header.column(name))
    return Table(columns, header.units, notes)


@dataclass(frozen=True)
class Header:
    """The header above a data block: its cell ``names``, the ``units`` it gives (by column
    name, and by each wanted name), and each wanted name as a bare cell name (``t [s]`` →
    ``t``)."""

    names: list[str]
    units: dict[str, str]
    bare: dict[str, str]
    present: list[str]  # the wanted names the header has (an optional one may be absent)

    def column(self, wanted: str) -> int:
        return self.names.index(self.bare[wanted])


def read_header(above: list[str], dialect: Dialect, wanted: Sequence[str], where: str,
                optional: Sequence[str] = ()) -> Header:
    """The :class:`Header` of the lines ``above`` the data that names ``wanted`` (those of
    them ``optional`` where it has them).

    Raises:
        RunFormatError: no header row, or a wanted column missing (named).
    """
    bare = {w: _name(w) for w in wanted}
    required = [w for w in wanted if w not in optional]
    try:
        header_at, names = find_header(above, dialect, list(dict.fromkeys(
            bare[w] for w in required)), where)
    except RunFormatError:
        find_header(above, dialect, list(dict.fromkeys(bare.values())), where)  # names all
        raise
    units = _header_units(above[header_at], dialect, names)
    for row in above[header_at + 1:]:  # units rows, down to the data
        cells = split(row, dialect.separator)
        if len(cells) == len(names):
            units.update({n: c.strip() for n, c in zip(names, cells, strict=True) if c.strip()})
    units.update({w: units[b] for w, b in bare.items() if w != b and b in units})
    folded = {n.lower(): n for n in names}
    bare = {w: b if b in names else folded.get(b.lower(), b) for w, b in bare.items()}
    _refuse_twice_named(names, [bare[w] for w in wanted], where)
    return Header(names, units, bare, [w for w in wanted if bare[w] in names])


def _refuse_twice_named(names: list[str], used: Sequence[str], where: str) -> None:
    """Raise where a column the run is read from is named twice: which is the run's cannot
    be told (an extra pressure column of 0.6 P had been read silently as the first)."""
    for name in dict.fromkeys(used):
        positions = [k + 1 for k, n in enumerate(names) if n == name]
        if len(positions) > 1:
            raise RunFormatError(
                f"{where}: column {name!r} appears twice (columns "
                f"{' and '.join(map(str, positions))}): which one is the run's cannot be "
                "told; rename the other in the file's header")


def _complete_lines(text: str, where: str) -> tuple[list[str], tuple[str, ...]]:
    """The text's lines without the NUL bytes a power loss pads a file with (4 kB of a
    block, or a file sparse to its allocated size) and without a last line that a logger
    stopped writing half-way (no final newline, fewer cells than the rows above, numbers up
    to where it stops), with a note of each; a file whose last row is whole but lacks the
    final newline is whole."""
    unpadded = text.rstrip("\0")
    padding = len(text) - len(unpadded)
    notes = (f"{where}: {padding} NUL bytes after its last row (as a power loss leaves a "
             "file), dropped",) if padding else ()
    lines, cut = _without_a_cut_line(unpadded, where)
    return lines, notes + cut


def _without_a_cut_line(text: str, where: str) -> tuple[list[str], tuple[str, ...]]:
    """The text's lines without a last one a logger stopped writing half-way, and a note."""
    lines = text.splitlines()
    if text.endswith(("\n", "\r")) or len(lines) < 3:
        return lines, ()
    try:
        dialect = sniff(lines[:-1], where)
    except RunFormatError:
        return lines, ()
    cells = split(lines[-1], dialect.separator)
    partial = 0 < len(cells) < dialect.cells and all(
        _is_number(c, dialect.decimal) for c in cells[:-1])
    if not partial:
        return lines, ()
    rows = sum(is_data(line, dialect) for line in lines[:-1])
    return lines[:-1], (f"{where}: last line cut short (the logger stopped mid-write?): "
                        f"{rows} complete rows read, the partial one dropped",)


def split(line: str, separator: str) -> list[str]:
    if separator == " ":
        return line.split()
    return next(csv.reader([line], delimiter=separator))


def sniff(lines: list[str], where: str) -> Dialect:
    """Separator and decimal mark from the file's last lines (the data, not the preamble; a
    file short enough that they reach its first line is read without it, its header)."""
    sample = [line for line in lines[-SAMPLE_LINES - 5:] if line.strip()][-SAMPLE_LINES:]
    if not sample:
        raise RunFormatError(f"{where}: the file is empty")
    if len(sample) == 1:
        raise RunFormatError(f"{where}: no data rows (the file has one line: "
                             f"{sample[0][:60]!r})")
    found = _dialect(sample)
    if found is None and len(sample) > 2 and sample[0] == next(x for x in lines if x.strip()):
        found = _dialect(sample[1:])
    if found is None:
        raise RunFormatError(f"{where}: no table of numbers found (separator , ; tab | or "
                             "blanks; is this a text table?)")
    return found


def _dialect(sample: list[str]) -> Dialect | None:
    """The separator and decimal mark that make the most columns of ``sample`` numbers."""
    best: tuple[int, Dialect] | None = None
    for separator in SEPARATORS:
        rows = [split(line, separator) for line in sample]
        counts = {len(r) for r in rows}
        if len(counts) != 1 or counts == {1}:
            continue
        decimal = "," if separator != "," and _uses_decimal_comma(rows) else "."
        numeric = sum(all(_is_number(r[k], decimal) for r in rows) for k in range(len(rows[0])))
        if numeric >= 2 and (best is None or numeric > best[0]):
            best = (numeric, Dialect(separator, decimal, len(rows[0])))
    return None if best is None else best[1]


def _uses_decimal_comma(rows: list[list[str]]) -> bool:
    """A number holding both marks decides (the later one is the decimal mark: 32.412,5);
    else a comma between digits is a decimal comma."""
    cells = [cell.strip() for row in rows for cell in row]
    both = [c for c in cells if "." in c and "," in c and _BOTH_MARKS.match(c)]
    if both:
        return both[0].rfind(",") > both[0].rfind(".")
    return any(_DECIMAL_COMMA.match(cell) for cell in cells)


def _is_number(cell: str, decimal: str) -> bool:
    return _plain(cell, decimal) is not None


def _plain(cell: str, decimal: str) -> str | None:
    """``cell`` as Python writes the number (decimal point, no grouping), or None when it
    is no number."""
    text = cell.strip().strip('"').strip()
    plain = text.replace(decimal, ".") if decimal == "," else text
    if _is_float(plain):
        return plain
    grouped = re.fullmatch(rf"[+-]?\d{{1,3}}([{THOUSANDS[decimal]}])\d{{3}}(\1\d{{3}})*"
                           rf"({re.escape(decimal)}\d*)?([eE][+-]?\d+)?", text)
    if grouped is None:
        return None
    plain = text.replace(grouped.group(1), "").replace(decimal, ".")
    return plain if _is_float(plain) else None


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def is_data(line: str, dialect: Dialect) -> bool:
    cells = split(line, dialect.separator) if line.strip() else []
    return len(cells) == dialect.cells and sum(
        _is_number(c, dialect.decimal) for c in cells) >= 2


def data_block(lines: list[str], dialect: Dialect) -> tuple[int, int]:
    """[first, last) lines of the data: after the header and units rows, before a footer."""
    last = len(lines)
    while last > 0 and not is_data(lines[last - 1], dialect):
        last -= 1
    first = 0
    while first < last and not (is_data(lines[first], dialect)
                                and is_data(lines[min(first + 1, last - 1)], dialect)):
        first += 1
    return first, last


def find_header(above: list[str], dialect: Dialect, wanted: Sequence[str], where: str
                ) -> tuple[int, list[str]]:
    """Index and cell names of the header: the last line above the data naming ``wanted``."""
    candidates = []
    for index in range(len(above) - 1, -1, -1):
        cells = split(above[index], dialect.separator)
        if len(cells) != dialect.cells:
            continue
        names = [_name(cell) for cell in cells]
        candidates.append((index, names))
        if all(w in names for w in wanted):
            return index, names
        folded = [n.lower() for n in names]
        if all(w.lower() in folded for w in wanted):
            return index, [_original(n, wanted) for n in names]
    found = candidates[-1][1] if candidates else []
    missing = [w for w in wanted if w not in found]
    if not candidates:
        raise RunFormatError(f"{where}: no header row above the numbers (expected the "
                             f"columns {', '.join(wanted)})")
    raise RunFormatError(f"{where}: missing column(s) {', '.join(missing)} "
                         f"(found {', '.join(found)}); name them in a column-mapping file "
                         "(--mapping FILE; docs/data-contract.md says how)")


def _name(cell: str) -> str:
    match = _UNIT_IN_HEADER.match(cell.strip())
    return (match.group(1) if match else cell).strip().strip('"')


def _original(name: str, wanted: Sequence[str]) -> str:
    return next((w for w in wanted if w.lower() == name.lower()), name)


def _header_units(line: str, dialect: Dialect, names: list[str]) -> dict[str, str]:
    units = {}
    for name, cell in zip(names, split(line, dialect.separator), strict=True):
        match = _UNIT_IN_HEADER.match(cell.strip())
        if match:
            units[name] = match.group(2).strip()
    return units


def delimiter(dialect: Dialect) -> str | None:
    return None if dialect.separator == " " else dialect.separator


def _numbers(body: list[str], dialect: Dialect, names: list[str], wanted: list[str],
             where: str, offset: int) -> tuple[list[np.ndarray], str]:
    """The ``wanted`` numeric columns, parsed in one pass over the data lines, and the
    columns whose numbers group thousands (comma-separated names; empty: none)."""
    rows = body if dialect.decimal == "." else [line.replace(",", ".") for line in body]
    columns = [names.index(n) for n in wanted]
    try:
        return _loaded(rows, dialect, columns), ""
    except ValueError as exc:
        grouped = _grouped_columns(body, dialect, columns)
        if not grouped:
            raise _unreadable(exc, names, where, offset) from None
    try:
        return _loaded(_ungrouped(body, dialect, columns), dialect, columns), ", ".join(
            names[k] for k in grouped)
    except ValueError as exc:
        raise _unreadable(exc, names, where, offset) from None


def _loaded(rows: list[str], dialect: Dialect, columns: list[int]) -> list[np.ndarray]:
    return list(np.loadtxt(rows, delimiter=delimiter(dialect), quotechar='"', ndmin=2,
                           usecols=columns).T)


def _grouped_columns(body: list[str], dialect: Dialect, columns: list[int]) -> list[int]:
    """The ``columns`` with a cell that groups thousands."""
    found: list[int] = []
    for line in body:
        cells = split(line, dialect.separator)
        found += [k for k in columns if k not in found and len(cells) > k
                  and _plain(cells[k], dialect.decimal) not in
                  (None, cells[k].strip().strip('"').replace(dialect.decimal, "."))]
        if len(found) == len(columns):
            break
    return sorted(found)


def _ungrouped(body: list[str], dialect: Dialect, columns: list[int]) -> list[str]:
    """The data lines with the ``columns`` as Python writes numbers (cells it cannot read
    left as they are, for the error to name)."""
    wanted = set(columns)
    out = []
    for line in body:
        cells = split(line, dialect.separator)
        out.append(dialect.separator.join(
            (_plain(c, dialect.decimal) or c) if k in wanted else "0"
            for k, c in enumerate(cells)))
    return out


def _unreadable(exc: ValueError, names: list[str], where: str, offset: int
                ) -> RunFormatError:
    found = re.search(r"string ['\"](.*)['\"] to float64 at row (\d+), column (\d+)",
                      str(exc))
    if not found:
        return RunFormatError(f"{where}: unreadable values ({exc})")
    line = int(found.group(2)) + offset + 1
    column = names[int(found.group(3)) - 1]
    return RunFormatError(f"{where}: column {column}: unreadable value {found.group(1)!r} "
                          f"at line {line}")


def _text(body: list[str], dialect: Dialect, index: int) -> np.ndarray:
    return np.loadtxt(body, delimiter=delimiter(dialect), usecols=[index], quotechar='"',
                      dtype=str, ndmin=1)
