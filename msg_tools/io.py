"""Read a run from any supported source, and a campaign (a folder of runs)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .bag_io import read_bag
from .csv_io import Mapping, read_csv
from .errors import RunFormatError
from .run import Run


def is_bag(path: Path) -> bool:
    """A rosbag2 folder (metadata.yaml) or a single .mcap / .db3 file."""
    path = Path(path)
    return (path.is_dir() and (path / "metadata.yaml").exists()) or path.suffix in {".mcap",
                                                                                    ".db3"}


def read_run(path: Path, mapping: Mapping | None = None) -> Run:
    """A run from a CSV file or a rosbag2."""
    path = Path(path)
    if not path.exists():
        raise RunFormatError(f"{path}: no such file or folder")
    if is_bag(path):
        return read_bag(path)
    return read_csv(path, mapping=mapping)


@dataclass(frozen=True)
class Campaign:
    """The readable runs of a campaign folder, and one message per file that was not."""

    folder: Path
    runs: tuple[Run, ...]
    problems: tuple[str, ...]


def campaign_sources(folder: Path) -> list[Path]:
    """Run files of a campaign folder: CSVs and rosbag2 folders, sorted by name."""
    folder = Path(folder)
    if not folder.is_dir():
        raise RunFormatError(f"{folder}: not a folder")
    found = [p for p in folder.iterdir() if p.suffix == ".csv" or is_bag(p)]
    return sorted(found)


def read_campaign(folder: Path, mapping: Mapping | None = None) -> Campaign:
    """Read every run of ``folder``; a bad file is reported and skipped, not fatal."""
    runs, problems = [], []
    for source in campaign_sources(folder):
        try:
            runs.append(read_run(source, mapping))
        except RunFormatError as exc:
            problems.append(str(exc))
    if not runs:
        raise RunFormatError(f"{folder}: no readable run" +
                             (f" ({'; '.join(problems)})" if problems else ""))
    return Campaign(Path(folder), tuple(runs), tuple(problems))


def read_runs(paths: Sequence[Path], mapping: Mapping | None = None) -> Campaign:
    """Runs from files, bags and campaign folders, in the order given.

    A bad file inside a folder is reported and skipped; a bad file named explicitly
    is an error (the user asked for it). Two runs with the same name are an error.
    """
    runs: list[Run] = []
    problems: list[str] = []
    for path in map(Path, paths):
        if path.is_dir() and not is_bag(path):
            campaign = read_campaign(path, mapping)
            runs.extend(campaign.runs)
            problems.extend(campaign.problems)
        else:
            runs.append(read_run(path, mapping))
    names = [r.name for r in runs]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise RunFormatError(f"run name {twice[0]!r} given twice; runs need distinct names")
    return Campaign(Path(paths[0]) if paths else Path("."), tuple(runs), tuple(problems))


def resample(run: Run, rate_hz: float) -> Run:
    """``run`` on a uniform time base from its first sample (linear; current held)."""
    start = float(run.time_s[0])
    n = int(np.floor((run.time_s[-1] - start) * rate_hz + 1e-9)) + 1
    base = start + np.arange(n) / rate_hz
    held = np.clip(np.searchsorted(run.time_s, base + 1e-12, side="right") - 1, 0, None)

    def linear(values: np.ndarray) -> np.ndarray:
        return np.interp(base, run.time_s, values)

    return Run(
        name=run.name, source=run.source, time_s=base, current_a=run.current_a[held],
        pressure_pa=linear(run.pressure_pa), wheel_speed_rad_s=linear(run.wheel_speed_rad_s),
        flywheel_speed_rad_s=linear(run.flywheel_speed_rad_s),
        vertical_load_n=linear(run.vertical_load_n),
        longitudinal_force_n=linear(run.longitudinal_force_n),
    )


def is_uniform(run: Run, tolerance: float = 1e-6) -> bool:
    """Whether the samples are evenly spaced (to ``tolerance`` of a period)."""
    steps = np.diff(run.time_s)
    return bool(np.ptp(steps) <= tolerance * np.median(steps) + 1e-12)
