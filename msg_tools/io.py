"""Read a run from any supported source, and a campaign (a folder of runs, sub-folders too)."""

from __future__ import annotations

import dataclasses
import hashlib
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .bag_files import STORAGE_SUFFIXES, storage_files
from .binary_tables import READERS
from .columns import run_from_table
from .csv_io import read_csv, read_named, run_name
from .errors import RunFormatError
from .mapping import Mapping
from .run import SIGNALS, Run
from .timebase import end_rates, rate_change_note, split_at_gaps, time_base_notes
from .workbook import SUFFIXES as WORKBOOK_SUFFIXES
from .workbook import read_workbook

TEXT_SUFFIXES = (".csv", ".txt", ".tsv", ".dat", ".asc")
NOT_RUNS = (".yaml", ".yml", ".json", ".md", ".rst", ".html", ".png", ".svg", ".pdf", ".log",
            ".py", ".part", ".zip")
"""Files a campaign folder may hold beside its runs (configs, reports, notes): not reported."""
SEPARATOR = "__"  # joins sub-folder and file names into a run name (it names report files)


def is_bag(path: Path) -> bool:
    """A rosbag2 folder (``metadata.yaml``, or storage files only), a single ``.mcap`` /
    ``.db3`` file, or a ROS 1 ``.bag``."""
    path = Path(path)
    if path.is_dir():
        return (path / "metadata.yaml").exists() or _lost_its_metadata(path)
    return path.suffix.lower() in (*STORAGE_SUFFIXES, ".bag")


def _lost_its_metadata(folder: Path) -> bool:
    """A bag folder without ``metadata.yaml``: one storage file, or rosbag2's segment
    names (``<folder>_0.mcap``, ``<folder>_1.mcap``); several other storage files are
    separate runs."""
    files = storage_files(folder)
    return len(files) == 1 or (len(files) > 1 and all(
        p.stem.rsplit("_", 1)[0] == folder.name for p in files))


def _kind(path: Path) -> str:
    """``bag``, ``text``, ``workbook``, ``binary``, ``other`` (not a run) or ``unknown``."""
    suffixes = [s.lower() for s in path.suffixes[-2:]]
    last = suffixes[-1] if suffixes else ""
    if is_bag(path):
        return "bag"
    if last in TEXT_SUFFIXES or (last == ".gz" and suffixes[0] in TEXT_SUFFIXES):
        return "text"
    if last in WORKBOOK_SUFFIXES:
        return "workbook"
    if last in READERS:
        return "binary"
    return "other" if last in NOT_RUNS or path.is_dir() else "unknown"


def read_run(path: Path, mapping: Mapping | None = None, name: str | None = None) -> Run:
    """A run from a bag, a delimited text file or a binary table (see ``README`` formats),
    with what its time base costs in its notes (:func:`~msg_tools.timebase.time_base_notes`:
    judged here, once, for every command)."""
    run = _read_any(Path(path), mapping, name)
    judged = time_base_notes(run)
    return dataclasses.replace(run, notes=(*run.notes, *judged)) if judged else run


def _read_any(path: Path, mapping: Mapping | None, name: str | None) -> Run:
    if not path.exists():
        raise RunFormatError(f"{path}: no such file or folder")
    kind = _kind(path)
    if kind == "bag":
        from .bag_read import read_bag  # rosbags: imported for a bag only

        return read_bag(path, name, mapping)
    if kind == "text":
        return read_csv(path, name, mapping)
    if kind == "workbook":
        return read_named(path, lambda wanted, text, optional: read_workbook(
            path, wanted, text, optional), name, mapping)
    if kind == "binary":
        table = READERS[path.suffix.lower()](path)
        return run_from_table(table, str(path), name or run_name(path), mapping)
    raise RunFormatError(f"{path}: not a run file (reads .csv/.txt/.tsv[.gz], .xlsx, .mat, "
                         ".h5, .parquet, .mf4, .tdms, rosbag2 folders, .mcap, .db3, ROS 1 "
                         ".bag)")


@dataclass(frozen=True)
class Campaign:
    """The readable runs of a campaign folder; ``problems``: one message per file that was
    not read (also in ``skipped``) and what reading the others had to say."""

    folder: Path
    runs: tuple[Run, ...]
    problems: tuple[str, ...]
    skipped: tuple[str, ...] = ()

    def said(self) -> list[str]:
        """Each problem as a user reads it: 'skipped: …' for a file not read, 'note: …' for
        what reading a run said (an actuator-only log had read 'skipped' and was read)."""
        return [f"{'skipped' if p in self.skipped else 'note'}: {p}" for p in self.problems]


def campaign_sources(folder: Path, skipped: list[str] | None = None) -> list[Path]:
    """Run files and bags in ``folder`` and its sub-folders, sorted; hidden entries
    (``.name``, macOS ``._name``) and files such as configs and reports left out. A link
    is followed once: an entry reaching a folder or file already read is left out, and
    said in ``skipped`` (a link to the folder itself once recursed 82 levels deep)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise RunFormatError(f"{folder}: not a folder")
    found: list[Path] = []
    said = skipped if skipped is not None else []
    _sources(folder, {folder.resolve()}, found, said)
    return _without_copies(found, said)


def _without_copies(found: list[Path], skipped: list[str]) -> list[Path]:
    """``found`` without files byte-identical to one before them, each said in ``skipped``
    (a copy under another name had been counted as one more run, and held out)."""
    sizes = [p.stat().st_size if p.is_file() else -1 for p in found]
    shared = Counter(sizes)
    kept: list[Path] = []
    first: dict[tuple[int, str], Path] = {}
    for path, size in zip(found, sizes, strict=True):
        if size < 0 or shared[size] == 1:  # a folder, or no file of its size
            kept.append(path)
            continue
        key = (size, _digest(path))
        if key in first:
            skipped.append(f"{path}: byte-identical to {first[key]}, read once (a copy is "
                           "not another run)")
            continue
        first[key] = path
        kept.append(path)
    return kept


def _sources(folder: Path, seen: set[Path], found: list[Path], skipped: list[str]) -> None:
    for entry in sorted(folder.iterdir()):
        if entry.name.startswith(".") or entry.name == "__MACOSX":
            continue
        kind = _kind(entry)
        if kind == "other" and not entry.is_dir():
            continue
        real = entry.resolve()
        if entry.is_symlink() and (real in seen or (entry.is_dir() and _tangled(real, seen))):
            skipped.append(f"{entry}: a link to {real}, already read (links are followed "
                           "once)")
            continue
        seen.add(real)
        if entry.is_dir() and kind != "bag":
            _sources(entry, seen, found, skipped)
        else:
            found.append(entry)


def _tangled(real: Path, seen: set[Path]) -> bool:
    """Whether a linked folder ``real`` holds a folder already read (a loop) or lies in one
    (read there anyway)."""
    return any(real in p.parents or p in real.parents for p in seen)


def read_campaign(folder: Path, mapping: Mapping | None = None,
                  progress: Callable[[str], None] | None = None) -> Campaign:
    """Read every run of ``folder``; a bad file is reported and skipped, not fatal. A run
    with long gaps becomes its parts (:func:`~msg_tools.timebase.split_at_gaps`)."""
    folder = Path(folder)
    runs: list[Run] = []
    problems: list[str] = []
    sources = campaign_sources(folder, problems)
    skipped = list(problems)
    names = _distinct_names(folder, sources, problems)
    for number, source in enumerate(sources, 1):
        if progress and len(sources) > 1:
            progress(f"reading {number}/{len(sources)}: {source.relative_to(folder)}")
        try:
            parts, notes = _read_parts(source, mapping, names[source])
        except RunFormatError as exc:
            problems.append(str(exc))
            skipped.append(str(exc))
            continue
        runs.extend(parts)
        problems.extend(notes)
    if not runs:
        raise RunFormatError(f"{folder}: no readable run" +
                             (f" ({'; '.join(problems)})" if problems else ""))
    return Campaign(folder, tuple(runs), tuple(problems), tuple(skipped))


def _read_parts(path: Path, mapping: Mapping | None, name: str | None = None
                ) -> tuple[tuple[Run, ...], tuple[str, ...]]:
    """The run of ``path`` as its parts (split at long gaps), and what reading and
    splitting it had to say: its time base judged as :func:`read_run` judges it, the split
    speaking for its gaps (a gap while braking had been told twice, then its part left
    out a third time)."""
    run = _read_any(Path(path), mapping, name)
    split = split_at_gaps(run)
    rate = rate_change_note(run)
    return tuple(split.parts), (*run.notes, *([rate] if rate else []), *split.notes)


def _digest(path: Path) -> str:
    """The SHA-256 of a file's bytes, read in pieces (a long log is not held twice)."""
    digest = hashlib.sha256()
    with path.open("rb") as stream:
        for piece in iter(lambda: stream.read(1 << 20), b""):
            digest.update(piece)
    return digest.hexdigest()


def _distinct_names(folder: Path, sources: list[Path], problems: list[str]
                    ) -> dict[Path, str]:
    """Each source's run name, distinct: a name two files share (one run in two formats,
    other data in each) takes its file's suffix, and ``problems`` says so (two rows of one
    name had been validated, the second plot overwriting the first)."""
    names: dict[Path, str] = {}
    for source in sources:
        name = _campaign_name(folder, source)
        if name in names.values():
            first = next(s for s, n in names.items() if n == name)
            renamed = f"{name}_{source.suffix.lstrip('.').lower() or 'bag'}"
            problems.append(f"{source}: its run name {name!r} is {first.name}'s too: read as "
                            f"{renamed!r}")
            name = renamed
        names[source] = name
    return names


def _campaign_name(folder: Path, source: Path) -> str:
    parts = source.relative_to(folder).parts
    stem = source.name if source.is_dir() else run_name(source)
    return SEPARATOR.join([*parts[:-1], stem])


def read_runs(paths: Sequence[Path], mapping: Mapping | None = None) -> Campaign:
    """Runs from files, bags and campaign folders, in the order given.

    A bad file inside a folder is reported and skipped; a bad file named explicitly
    is an error (the user asked for it). Two runs with the same name are an error. A
    run with long gaps becomes its parts.
    """
    runs: list[Run] = []
    problems: list[str] = []
    skipped: list[str] = []
    for path in map(Path, paths):
        if path.is_dir() and not is_bag(path):
            campaign = read_campaign(path, mapping)
            runs.extend(campaign.runs)
            problems.extend(campaign.problems)
            skipped.extend(campaign.skipped)
        else:
            parts, notes = _read_parts(path, mapping)
            runs.extend(parts)
            problems.extend(notes)
    names = [r.name for r in runs]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise RunFormatError(f"run name {twice[0]!r} given twice; runs need distinct names")
    return Campaign(Path(paths[0]) if paths else Path("."), tuple(runs), tuple(problems),
                    tuple(skipped))


def resample(run: Run, rate_hz: float) -> Run:
    """``run`` on a uniform time base from its first sample (linear; current held)."""
    start = float(run.time_s[0])
    n = int(np.floor((run.time_s[-1] - start) * rate_hz + 1e-9)) + 1
    return at_times(run, start + np.arange(n) / rate_hz)


def at_one_rate(run: Run) -> Run:
    """``run``, or a run whose rate changes resampled at its faster rate, as its note says
    (statistics over the raw samples had counted the slower part at its own weight: a
    log from 1 kHz to 500 Hz read an efficiency of 0.367 for 0.359)."""
    rates = end_rates(run)
    if rates is None:
        return run
    return dataclasses.replace(resample(run, max(rates)), notes=run.notes)


def at_times(run: Run, times_s: np.ndarray) -> Run:
    """``run``'s signals at ``times_s`` (on its own clock, within its span): linear between
    its samples, the current held (a command steps, it does not ramp)."""
    held = np.clip(np.searchsorted(run.time_s, times_s + 1e-12, side="right") - 1, 0, None)
    linear = {name: np.interp(times_s, run.time_s, getattr(run, name))
              for name in SIGNALS if name != "current_a"}
    return Run(name=run.name, source=run.source, time_s=times_s, current_a=run.current_a[held],
               absent=run.absent, **linear)


def is_uniform(run: Run, tolerance: float = 1e-6) -> bool:
    """Whether the samples are evenly spaced (to ``tolerance`` of a period)."""
    steps = np.diff(run.time_s)
    return bool(np.ptp(steps) <= tolerance * np.median(steps) + 1e-12)
