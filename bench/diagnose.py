"""Diagnosis benchmark: wall time and peak memory of ``diagnose`` on full campaigns.

Run: ``make bench`` (or ``python bench/diagnose.py``). Full 8-run campaigns (~150 s of
1 kHz data) made by the project's own rig generator: one without an extra effect, one
with an actuator delay and one without the load-dependent radius in the starting model.
Targets (issue): <= 60 s and <= 1 GB peak per campaign on this 2-core machine. The
reference measured in the same run is one simulation pass over the campaign (every run
re-simulated with its measured input): the diagnosis costs that many passes.
If ``../shared/data`` is present its example campaigns are timed too.
"""

from __future__ import annotations

import resource
import tempfile
import time
from pathlib import Path

import numpy as np

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.calibration.measured import simulate_all
from landing_gear_sim.diagnosis.diagnose import diagnose
from landing_gear_sim.model.parameters import RigParameters, load_parameters
from msg_tools.io import read_campaign
from msg_tools.run import Run

TARGET_S = 60.0
TARGET_MEMORY_MB = 1024.0
SHARED = Path(__file__).resolve().parents[1].parent / "shared" / "data"
CASES: dict[str, tuple[dict, tuple[str, ...]]] = {
    "no extra effect": ({}, ()),
    "actuator delay 6 ms": ({"elements.actuator_delay": True, "actuator.delay_s": 0.006}, ()),
    "without load-dependent radius": ({}, ("load_dependent_radius",)),
}


def _peak_mb() -> float:
    """Peak resident memory of this process plus that of its largest worker, times the
    workers that run at once (2): an upper bound of the diagnosis' peak."""
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    worker = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    return own + 2 * worker


def _pass_s(runs: list[Run], params: RigParameters) -> float:
    simulate_all(runs, params)  # compiled already; this one warms the caches
    start = time.perf_counter()
    simulate_all(runs, params)
    return time.perf_counter() - start


def _row(name: str, runs: list[Run], base: RigParameters, without: tuple[str, ...]) -> None:
    one_pass = _pass_s(runs, base)
    start = time.perf_counter()
    result = diagnose(runs, base, without=without)
    elapsed = time.perf_counter() - start
    found = ", ".join(f"{k} = {v:.4g}" for f in result.findings[:1]
                      for k, v in f.parameters.items())
    print(f"{name:32s} {result.verdict:22s} {elapsed:6.1f} s  {TARGET_S / elapsed:5.2f}x  "
          f"{elapsed / one_pass:6.0f} passes  {_peak_mb():6.0f} MB  "
          f"{TARGET_MEMORY_MB / _peak_mb():5.2f}x  {found}", flush=True)


def main() -> None:
    print("diagnose on full campaigns (ratios > 1 beat the targets: 60 s, 1 GB)")
    print(f"{'campaign':32s} {'verdict':22s} {'time':>8s} {'ratio':>6s} {'simulation':>13s} "
          f"{'peak':>9s} {'ratio':>6s}  key parameters")
    base = load_parameters()
    for i, (name, (effect, without)) in enumerate(CASES.items()):
        rig = rig_like(base, np.random.default_rng(500 + i)).replace(effect, "hidden effect")
        with tempfile.TemporaryDirectory() as folder:
            generate_campaign(Path(folder), rig, 500 + i)
            runs = read_campaign(Path(folder)).runs
        _row(name, runs, base, without)
    for name in ("campaign_v1", "campaign_v2"):
        if (SHARED / name).is_dir():
            _row(f"{name} (example data)", read_campaign(SHARED / name).runs, base, ())


if __name__ == "__main__":
    main()
