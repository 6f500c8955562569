"""Reading benchmark: memory and time to read a long run as a bag and as the same CSV.

A 5-minute 1 kHz run (synthetic signals of the contract's ranges, written by this script) is
written as a contract CSV and as an mcap bag; each is read in a fresh process and the peak
memory allocated while reading (tracemalloc) is reported. Target (issue
13): reading the bag takes <= 1.5x the memory of reading the CSV, and bag -> CSV -> bag keeps
time to 1 µs. Printed too (issue 30): ``convert`` (read, write the CSV) at most 1x the
input's size.

Run: ``python bench/io.py [DURATION_S]`` (part of ``make bench``).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from msg_tools.bag_io import write_bag
from msg_tools.csv_io import write_csv
from msg_tools.io import read_run
from msg_tools.run import Run

TARGET_RATIO = 1.5
EPOCH_S = 1.7e9  # wall-clock stamps, as every real recording has
PROBE = """
import sys, time, tracemalloc
from pathlib import Path
from msg_tools.csv_io import write_csv
from msg_tools.io import read_run
tracemalloc.start()
started = time.perf_counter()
run = read_run(sys.argv[1])
if len(sys.argv) > 2:  # convert: read, then write the CSV
    write_csv(run, Path(sys.argv[2]))
elapsed = time.perf_counter() - started
print(tracemalloc.get_traced_memory()[1], elapsed)
"""
CONVERT_TARGET = 1.0  # issue 30: convert's peak memory at most the input's size


def long_run(duration_s: float, rate_hz: float = 1000.0) -> Run:
    t = np.arange(round(duration_s * rate_hz)) / rate_hz
    slow = 0.5 + 0.3 * np.sin(2 * np.pi * 0.5 * t)
    return Run(name="long", time_s=EPOCH_S + t, current_a=slow, pressure_pa=3e6 * slow,
               wheel_speed_rad_s=200 - 0.5 * t + np.sin(t), flywheel_speed_rad_s=80 - 0.2 * t,
               vertical_load_n=1e5 + 1e3 * np.sin(3 * t), longitudinal_force_n=2e4 * slow)


def probe(path: Path, output: Path | None = None) -> tuple[float, float]:
    """(peak MB allocated while reading, seconds) of one read in a fresh interpreter
    (tracemalloc: Python objects and numpy arrays; the imports are not counted); with
    ``output``, of reading and writing it as CSV (``convert``)."""
    out = subprocess.run([sys.executable, "-c", PROBE, str(path),
                          *([str(output)] if output else [])], check=True,
                         capture_output=True, text=True).stdout.split()
    return float(out[0]) / 1e6, float(out[1])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("duration_s", nargs="?", type=float, default=300.0,
                        help="length of the run at 1 kHz [s] (default 300)")
    duration = parser.parse_args().duration_s
    with tempfile.TemporaryDirectory() as folder:
        run = long_run(duration)
        csv_path, bag_path = Path(folder) / "long.csv", Path(folder) / "long_bag"
        started = time.perf_counter()
        write_csv(run, csv_path)
        write_bag(run, bag_path)
        print(f"{duration:.0f} s at 1 kHz written in {time.perf_counter() - started:.1f} s: "
              f"CSV {csv_path.stat().st_size / 1e6:.0f} MB, bag "
              f"{sum(p.stat().st_size for p in bag_path.iterdir()) / 1e6:.0f} MB")
        csv_mb, csv_s = probe(csv_path)
        bag_mb, bag_s = probe(bag_path)
        print(f"read CSV: peak {csv_mb:6.0f} MB allocated, {csv_s:5.1f} s")
        print(f"read bag: peak {bag_mb:6.0f} MB allocated, {bag_s:5.1f} s")
        ratio = bag_mb / csv_mb
        print(f"bag / CSV memory: {ratio:.2f} (target <= {TARGET_RATIO})")
        sizes = {"CSV": csv_path.stat().st_size / 1e6,
                 "bag": sum(p.stat().st_size for p in bag_path.iterdir()) / 1e6}
        for kind, source in (("CSV", csv_path), ("bag", bag_path)):
            peak_mb, seconds = probe(source, Path(folder) / f"converted_{kind}.csv")
            print(f"convert {kind} -> CSV: peak {peak_mb:6.0f} MB allocated = "
                  f"{peak_mb / sizes[kind]:.1f}x the input's {sizes[kind]:.0f} MB "
                  f"(target <= {CONVERT_TARGET:g}x), {seconds:5.1f} s")
        back = Path(folder) / "back.csv"
        write_csv(read_run(bag_path), back)
        again = Path(folder) / "again_bag"
        write_bag(read_run(back), again)
        drift = float(np.max(np.abs(read_run(again).time_s - run.time_s)))
        print(f"bag -> CSV -> bag: largest time change {drift * 1e6:.3f} µs (target <= 1 µs)")
    return 0 if ratio <= TARGET_RATIO and drift <= 1e-6 else 1


if __name__ == "__main__":
    sys.exit(main())
