"""Identification benchmark: time for a full campaign (target <= 60 s), accuracy and honesty
of the stated uncertainty over hidden rigs made by the project's own generator.

Run: ``make bench`` (or ``python bench/identify.py [N_RIGS]``). If the example campaigns of
``../shared/data`` are present they are identified too and compared with their generating
parameters (the product itself never reads those).

``python bench/identify.py --against DIR`` (the code before, a ``git worktree``): each
campaign of ``../shared/data`` (v1, v2 and the independent ones) identified by the code now
and before, each in a fresh interpreter of its checkout (compiled code loaded before the
clock starts), one after the other: the time before over the time now, and whether every
estimate and its σ are the same to the bit.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
from checkouts import is_checkout, measured_in

from landing_gear_sim.calibration.campaign import DEVIATING, generate_campaign, rig_like
from landing_gear_sim.calibration.identify import identify
from landing_gear_sim.calibration.validate import validate
from landing_gear_sim.model.parameters import load_parameters
from msg_tools.io import read_campaign

TARGET_S = 60.0
TARGET_REL = 0.05
HERE = Path(__file__).resolve().parents[1]
SHARED = HERE.parent / "shared" / "data"
SHARED_KEYS = {  # generating-parameters.json name -> our key (and unit factor)
    "flywheel_inertia": ("flywheel.inertia_kg_m2", 1.0), "drag_coeff": ("drag.coeff_n_s2_per_m2",
                                                                        1.0),
    "brake_gain": ("brake.gain_n_m_per_pa", 1.0), "map_k1": ("actuator.map_k1_pa_per_a", 1.0),
    "act_wn": ("actuator.natural_frequency_hz", 1 / (2 * np.pi)),
    "act_zeta": ("actuator.damping_ratio", 1.0),
}


def _oscillating_fits(runs, params) -> str:
    fits = [(c.scores["wheel_speed_rad_s"].fit_percent, c.scores["pressure_pa"].fit_percent)
            for c in validate(runs, params) if c.kind == "brake_oscillating"]
    return ", ".join(f"wheel {w:.2f} % / pressure {p:.2f} %" for w, p in fits)


def hidden_rigs(n: int) -> None:
    base = load_parameters()
    errors: dict[str, list[float]] = {k: [] for k in DEVIATING}
    z: dict[str, list[float]] = {k: [] for k in DEVIATING}
    times = []
    for seed in range(100, 100 + n):
        rig = rig_like(base, np.random.default_rng(seed), deviation=0.03)
        with tempfile.TemporaryDirectory() as folder:
            generate_campaign(Path(folder), rig, seed)
            runs = read_campaign(Path(folder)).runs
            start = time.perf_counter()
            result = identify(runs, base)
            times.append(time.perf_counter() - start)
        for e in result.estimates:
            if e.key in errors:
                truth = rig.number(e.key)
                errors[e.key].append(abs(e.value - truth) / truth)
                z[e.key].append(abs(e.value - truth) / e.std)
    print(f"-- {n} hidden rigs (datasheet ±3 %), own generator")
    print(f"identify time: median {np.median(times):.1f} s, max {max(times):.1f} s "
          f"(target <= {TARGET_S:.0f} s, ratio {TARGET_S / max(times):.1f}x)")
    print(f"{'parameter':32s} {'max |error|':>12s} {'ratio to 5 %':>13s} {'max |err|/σ':>12s}")
    for key in DEVIATING:
        worst = max(errors[key])
        print(f"{key:32s} {100 * worst:11.3f}% {TARGET_REL / worst:12.1f}x {max(z[key]):12.1f}")


def shared_campaigns() -> None:
    for name in ("campaign_v2", "campaign_v1"):
        folder = SHARED / name
        if not folder.is_dir():
            print(f"-- {folder} not present; skipped")
            continue
        truth = json.loads((folder / "generating-parameters.json").read_text())
        campaign = read_campaign(folder)
        start = time.perf_counter()
        result = identify(campaign.runs, load_parameters())
        elapsed = time.perf_counter() - start
        found = {e.key: e.value for e in result.estimates}
        print(f"-- {name} (effect: {truth['effect']['cause']}): identify {elapsed:.1f} s")
        si = truth["parameters_SI"]
        pairs = [(SHARED_KEYS[k][0], si[k] * SHARED_KEYS[k][1]) for k in SHARED_KEYS]
        pairs += [(f"friction.theta{i + 1}", v) for i, v in enumerate(si["burckhardt"])]
        for key, value in pairs:
            print(f"   {key:32s} {found[key]:12.6g}  truth {value:12.6g}  "
                  f"error {100 * (found[key] - value) / value:+6.2f} %")
        print(f"   oscillating runs: {_oscillating_fits(campaign.runs, result.params)}")


# what a fresh interpreter of a checkout measures (the API it uses is the same before)
MEASURE = """
import hashlib, json, sys, time
from pathlib import Path
from landing_gear_sim.calibration.identify import identify
from landing_gear_sim.calibration.measured import simulate_all
from landing_gear_sim.model.parameters import load_parameters
from msg_tools.io import read_campaign
runs, base = read_campaign(Path(sys.argv[1])).runs, load_parameters()
simulate_all(runs, base)  # the compiled code loaded from its cache
start = time.perf_counter()
result = identify(runs, base)
elapsed = time.perf_counter() - start
estimates = repr([(e.key, e.value, e.std) for e in result.estimates]).encode()
print(json.dumps({"checkout": str(Path(identify.__code__.co_filename).resolve().parents[2]),
                  "seconds": elapsed, "estimates": hashlib.blake2b(estimates).hexdigest()}))
"""


def _measure(checkout: Path, folder: Path) -> dict:
    """One identification of ``folder`` by ``checkout``'s code in a fresh interpreter."""
    return measured_in(checkout, MEASURE, str(folder), bench="bench/identify.py")


def against(before: Path) -> None:
    folders = [SHARED / "campaign_v1", SHARED / "campaign_v2",
               *sorted(p for p in (SHARED / "independent").glob("I*") if p.is_dir())]
    print("identify now and before (fresh interpreters): seconds, before over now, estimates")
    ratios = []
    for folder in (f for f in folders if f.is_dir()):
        now, then = _measure(HERE, folder), _measure(before, folder)
        ratios.append(then["seconds"] / now["seconds"])
        same = "same" if now["estimates"] == then["estimates"] else "DIFFER"
        print(f"{folder.name:22s} now {now['seconds']:5.1f} s  before {then['seconds']:5.1f} s"
              f"  {ratios[-1]:4.2f}x faster  estimates {same}", flush=True)
    if ratios:
        print(f"median {np.median(ratios):.2f}x faster over {len(ratios)} campaigns")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("rigs", type=int, nargs="?", default=8, help="hidden rigs (default 8)")
    parser.add_argument("--against", type=Path, help="the code before (a checkout)")
    args = parser.parse_args()
    if args.against:
        if not is_checkout(args.against):
            parser.error(f"--against: {args.against} is not a checkout of the package")
        against(args.against)
        return
    hidden_rigs(args.rigs)
    shared_campaigns()


if __name__ == "__main__":
    main()
