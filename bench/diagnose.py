"""Diagnosis benchmark: wall time and peak memory of ``diagnose`` on full campaigns.

Run: ``make bench`` (or ``python bench/diagnose.py``). Full 8-run campaigns (~150 s of
1 kHz data) made by the project's own rig generator: one without an extra effect, one
with an actuator delay, starting models without an element, and a partial campaign
(braking runs only). Targets (issue 15): <= 15 s for a full campaign of the generator's
defaults or the example data, <= 45 s for any campaign, <= 1 GB peak, on this 2-core
machine. The reference measured in the same run is one simulation pass over the campaign
(every run re-simulated with its measured input): the diagnosis costs that many passes.
``BEFORE`` has the same cases' times before the speed-up (commit 7d43ac7, this machine).
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

TARGET_DEFAULT_S = 15.0
TARGET_ANY_S = 45.0
TARGET_MEMORY_MB = 1024.0
SHARED = Path(__file__).resolve().parents[1].parent / "shared" / "data"
BRAKING = ("brake_const_10bar", "brake_const_20bar", "brake_const_30bar", "brake_osc_low",
           "brake_osc_high")
# name: (hidden effect, starting model without, runs (None: all), a generator default?)
CASES: dict[str, tuple[dict, tuple[str, ...], tuple[str, ...] | None, bool]] = {
    "no extra effect": ({}, (), None, True),
    "actuator delay 6 ms": ({"elements.actuator_delay": True, "actuator.delay_s": 0.006}, (),
                            None, False),
    "without load-dependent radius": ({}, ("load_dependent_radius",), None, False),
    "without friction curve": ({}, ("friction_curve",), None, False),
    "without drag": ({}, ("drag",), None, False),
    "braking runs only, without gear walk": ({}, ("gear_walk",), BRAKING, False),
}
# seconds before the speed-up (commit 7d43ac7, this machine, same campaigns): the first three
# and the example data from that version's own run of this benchmark, the others measured
# with that version's diagnose on 2026-11-23
BEFORE: dict[str, float] = {
    "no extra effect": 56.0, "actuator delay 6 ms": 32.0, "without load-dependent radius": 66.0,
    "without friction curve": 43.4, "without drag": 66.4,
    "braking runs only, without gear walk": 67.9,
    "campaign_v1 (example data)": 33.0, "campaign_v2 (example data)": 32.0,
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


def _row(name: str, runs: list[Run], base: RigParameters, without: tuple[str, ...],
         target_s: float) -> None:
    one_pass = _pass_s(runs, base)
    start = time.perf_counter()
    result = diagnose(runs, base, without=without)
    elapsed = time.perf_counter() - start
    found = ", ".join(f"{k} = {v:.4g}" for f in result.findings[:1]
                      for k, v in f.parameters.items())
    before = f"{BEFORE[name] / elapsed:5.1f}x" if name in BEFORE else "    -"
    print(f"{name:38s} {result.verdict:22s} {elapsed:6.1f} s  {target_s:4.0f} s "
          f"{target_s / elapsed:5.2f}x  {before}  {elapsed / one_pass:5.0f} passes  "
          f"{_peak_mb():5.0f} MB {TARGET_MEMORY_MB / _peak_mb():5.2f}x  {found}", flush=True)


def main() -> None:
    print("diagnose on full campaigns (ratios > 1 beat the targets; 'faster': against the "
          "time before the speed-up)")
    print(f"{'campaign':38s} {'verdict':22s} {'time':>8s} {'target':>6s} {'ratio':>6s} "
          f"{'faster':>6s} {'simulation':>12s} {'peak':>8s} {'ratio':>5s}  key parameters")
    base = load_parameters()
    for i, (name, (effect, without, names, default)) in enumerate(CASES.items()):
        rig = rig_like(base, np.random.default_rng(500 + i)).replace(effect, "hidden effect")
        with tempfile.TemporaryDirectory() as folder:
            generate_campaign(Path(folder), rig, 500 + i, names)
            runs = read_campaign(Path(folder)).runs
        _row(name, runs, base, without, TARGET_DEFAULT_S if default else TARGET_ANY_S)
    for name in ("campaign_v1", "campaign_v2"):
        if (SHARED / name).is_dir():
            _row(f"{name} (example data)", read_campaign(SHARED / name).runs, base, (),
                 TARGET_DEFAULT_S)


if __name__ == "__main__":
    main()
