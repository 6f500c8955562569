"""Benchmark of ``history`` on Dask: 20 campaigns identified on 1 and on 2 workers.

Run: ``python bench/history.py`` (part of ``make bench``). The campaigns are generated
here (own generator, one rig, six runs each: two actuator, three constant-pressure, one
oscillating). Issue 15's target (≥ 1.8× on 2 workers) is for a machine with ≥ 4 cores;
on 2 cores the ratio seen and the per-task overhead are reported, never asserted.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"  # nothing here talks DDS; keep it so
os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 100))

import numpy as np

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.campaigns.engine import Task, client, run_tasks
from landing_gear_sim.campaigns.history import campaign_task
from landing_gear_sim.model.parameters import load_parameters

CAMPAIGNS = 20
RUNS = ("actuator_ramp", "actuator_steps_sweep", "brake_const_20bar", "brake_const_30bar",
        "brake_const_40bar", "brake_osc_low")


def main() -> None:
    base = load_parameters()
    with tempfile.TemporaryDirectory() as tmp:
        rig = rig_like(base, np.random.default_rng(5))
        folders = []
        for day in range(CAMPAIGNS):
            folders.append(Path(tmp) / f"day-{day:02d}")
            generate_campaign(folders[-1], rig, seed=100 + day, names=RUNS)
        tasks = [Task(str(f), campaign_task, (str(f), base, False)) for f in folders]
        print(f"history: {CAMPAIGNS} campaigns of {len(RUNS)} runs, identify only")
        walls = {}
        for workers in (1, 2):
            with client(None, workers) as engine:
                started = time.perf_counter()
                done = run_tasks(tasks, Path(tmp) / f"journal-{workers}.jsonl", engine,
                                 lambda _: None)
                walls[workers] = time.perf_counter() - started
            busy = sum(r["seconds"] for r in done.values())
            print(f"  {workers} worker(s): {walls[workers]:6.1f} s wall, task time "
                  f"{busy:6.1f} s; overhead per task "
                  f"{(walls[workers] * workers - busy) / len(tasks):5.2f} s")
        print(f"  2 workers / 1 worker: {walls[1] / walls[2]:.2f}x faster on "
              f"{os.cpu_count()} cores (target >= 1.8x on >= 4 cores)")


if __name__ == "__main__":
    main()
