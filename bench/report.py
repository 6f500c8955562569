"""Report benchmark: the time to write a diagnosis page, its figures drawn side by side on
forked processes against the same page drawn one figure after another (the reference,
measured in the same run, on the same diagnosis).

A campaign is diagnosed once (campaign_v1 of the example data when ``../shared/data`` is
present, else an 8-run campaign of the project's own generator); its page is then written
``--repeat`` times each way, alternating, and the medians compared. The two pages must be
the same files, byte for byte. Issue 61 ("an answer in seconds"): the page had taken as long
as the diagnosis before it.

Run: ``python bench/report.py [--repeat N]`` (part of ``make bench``).
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.diagnosis.diagnose import Diagnosis, diagnose
from landing_gear_sim.model.parameters import load_parameters
from landing_gear_sim.report.diagnosis import write_diagnosis_report
from msg_tools.io import read_campaign

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data" / "campaign_v1"


def _diagnosed(folder: Path) -> tuple[str, Diagnosis]:
    base = load_parameters()
    if SHARED.is_dir():
        return "campaign_v1 (example data)", diagnose(read_campaign(SHARED).runs, base)
    generate_campaign(folder, rig_like(base, np.random.default_rng(500)), 500)
    return "own generator, seed 500", diagnose(read_campaign(folder).runs, base)


def _written(result: Diagnosis, folder: Path, cores: int) -> tuple[float, dict[str, bytes]]:
    """Seconds to write the page with ``cores`` (1: one figure after another), and its
    files."""
    real = os.cpu_count
    os.cpu_count = lambda: cores  # the page's drawing reads it: 1 keeps it in this process
    try:
        started = time.perf_counter()
        write_diagnosis_report(result, folder)
        elapsed = time.perf_counter() - started
    finally:
        os.cpu_count = real
    return elapsed, {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=3, help="pages each way (median)")
    args = parser.parse_args()
    cores = os.cpu_count() or 1
    with tempfile.TemporaryDirectory() as scratch:
        name, result = _diagnosed(Path(scratch) / "campaign")
        print(f"diagnosis page of {name}: {len(result.evidence)} runs; "
              f"{cores} cores; {args.repeat} pages each way, alternating")
        _written(result, Path(scratch) / "warm", 1)  # fonts and caches, not timed
        times: dict[int, list[float]] = {1: [], cores: []}
        files: dict[int, dict[str, bytes]] = {}
        for i in range(args.repeat):
            for n in times:
                elapsed, files[n] = _written(result, Path(scratch) / f"{n}_{i}", n)
                times[n].append(elapsed)
    one, side = statistics.median(times[1]), statistics.median(times[cores])
    same = files[1] == files[cores]
    print(f"one figure after another (reference): {one:.2f} s  "
          f"({', '.join(f'{t:.2f}' for t in times[1])})")
    print(f"side by side on {cores} processes:   {side:.2f} s  "
          f"({', '.join(f'{t:.2f}' for t in times[cores])})")
    print(f"faster: {one / side:.2f}x; the same {len(files[1])} files byte for byte: "
          f"{'yes' if same else 'NO'}")
    if not same:
        raise SystemExit(1)


if __name__ == "__main__":
    main()
