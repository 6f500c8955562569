"""Benchmark of the closed-loop Monte Carlo: stops per second per core, the Dask scheduler's
overhead, and the same result on one worker or two.

Run: ``python bench/montecarlo.py`` (part of ``make bench``). The reference is the
block-by-block loop the graph steps (:func:`antiskid.closed_loop.closed_loop`), measured in
the same run. Targets (issue 15: ≥ 20 stops/s/core for a 60 m/s stop, overhead ≤ 5 %) are
reported, never asserted.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"  # nothing here talks DDS; keep it so
os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 100))

from antiskid.closed_loop import closed_loop, make_controller
from antiskid.compiled import compiled_closed_loop
from landing_gear_sim.campaigns.engine import Task, client, run_tasks
from landing_gear_sim.campaigns.montecarlo import (
    Plan,
    case_row,
    chunk_task,
    chunks,
)
from landing_gear_sim.model.parameters import load_parameters

TARGET_STOPS_S = 20.0
TARGET_OVERHEAD = 0.05
REPEATS = 20
CASES = 400


def _rate(function, repeats: int) -> float:
    function()  # compile / warm up
    started = time.perf_counter()
    for _ in range(repeats):
        function()
    return repeats / (time.perf_counter() - started)


def stops_per_second() -> None:
    rig = load_parameters()  # the reference rig: 60 m/s, dry
    print("one core, 60 m/s dry stop (stops/s; target >= 20 for a whole case)")
    for kind in ("threshold", "slip"):
        blocks = _rate(lambda k=kind: closed_loop(rig, make_controller(k, rig, 1e-3)), 3)
        compiled = _rate(lambda k=kind: compiled_closed_loop(rig, k), REPEATS)
        plan = Plan(kind, seed=1, cases=REPEATS, surfaces=("dry",), entry_speed_m_s=(60, 60),
                    load_factor=(1, 1))
        whole = _rate(lambda p=plan: case_row(rig, p, 0), REPEATS)
        print(f"  {kind:9s} block loop {blocks:6.1f}   compiled loop {compiled:6.1f} "
              f"({compiled / blocks:4.0f}x)   whole case (loop + metrics) {whole:6.1f} "
              f"= {whole / TARGET_STOPS_S:4.1f}x target")


def on_dask() -> None:
    rig = load_parameters()
    plan = Plan("threshold", seed=7, cases=CASES)
    tasks = [Task(f"bench-{i[0]}", chunk_task, (rig, plan, i)) for i in chunks(plan)]
    print(f"\n{CASES} dispersed stops (all surfaces) on a LocalCluster, {len(tasks)} tasks")
    results = {}
    for workers in (1, 2):
        with client(None, workers) as engine, tempfile.TemporaryDirectory() as tmp:
            engine.run(lambda: compiled_closed_loop(rig, "threshold"))  # compile on workers
            started = time.perf_counter()
            done = run_tasks(tasks, Path(tmp) / "journal.jsonl", engine, lambda _: None)
            wall = time.perf_counter() - started
        busy = sum(r["seconds"] for r in done.values())
        rows = [row for t in tasks for row in done[t.key]["cases"]]
        results[workers] = (wall, rows)
        print(f"  {workers} worker(s): {wall:6.1f} s wall, {CASES / wall:5.1f} stops/s, "
              f"{CASES / busy:5.1f} stops/s per busy core; scheduler overhead "
              f"{100 * (wall * workers / busy - 1):5.1f} % of task time "
              f"(target <= {100 * TARGET_OVERHEAD:.0f} %)")
    (one, rows1), (two, rows2) = results[1], results[2]
    print(f"  2 workers / 1 worker: {one / two:.2f}x faster (2 cores); results identical: "
          f"{rows1 == rows2}")


if __name__ == "__main__":
    stops_per_second()
    on_dask()
