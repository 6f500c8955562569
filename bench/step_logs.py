"""A valve's step log, as a user with only that log, its datasheet and a mapping file has
it (issue 43): one run of time, current and pressure, diagnosed in one call.

Run: ``python bench/step_logs.py [--count N] [--seed S] [--cycles C]`` (~5-20 s a log).

Each log is made by the project's generator, from a datasheet of a valve 4x slower than the
reference (3 Hz, ζ 0.9, its own map), the rig ±3 % off it, with a transport delay of
50-150 ms and a release unlike the apply (a stiffness that holds only while the pressure
rises, ``[Ṗ > 1 bar/s]·ΔP``, 0.4-0.8 of the map's: outside the valve library's exact terms,
whose ``sgn Ṗ·ΔP`` is two-sided), all drawn here. ``--cycles`` applies and releases (held
3 s, 3 s apart). Right when the verdict is the delay within 10 % and the release/apply
difference is discovered in the valve's equation (its library's terms or the valve_direction
family) with a held-out gain; with one cycle the
release cannot check what the apply fitted, and the right answer is ``inconclusive`` saying
what one more step would settle.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from landing_gear_sim.calibration.campaign import NOISE, rig_like
from landing_gear_sim.diagnosis.diagnose import INCONCLUSIVE, diagnose
from landing_gear_sim.diagnosis.families import REGISTRY
from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.parameters import RigParameters, load_parameters
from msg_tools.csv_io import read_csv, write_csv

DATASHEET = """/**:
  ros__parameters:
    actuator:
      natural_frequency_hz: 3.0
      damping_ratio: 0.9
      map_k1_pa_per_a: 1.5e6
      map_k2_pa_per_a2: 3.0e5
      max_pressure_pa: 1.2e6
"""
RISING_STIFFER = basis.product_code(basis.factor_code(basis.PRESSURE_RATE, basis.STEP),
                                    basis.factor_code(basis.VALVE_ERROR, basis.IDENTITY))
LEVELS = (0.6, 0.35, 0.8)  # of the valve's largest current, in turn
VALVE_FAMILIES = {family.reports: family.equation for family in REGISTRY}
"""A discovered finding's family -> its equation: the release/apply difference is named
in the valve's, by its library's terms or by the valve_direction family (the bench had
counted the valve library's alone, and read a right valve_direction as no valve term)."""


def hidden_valve(datasheet: RigParameters, rng: np.random.Generator
                 ) -> tuple[RigParameters, float]:
    rig = rig_like(datasheet, rng).replace({**NOISE, "elements.actuator_delay": True}, "noise")
    delay = float(rng.uniform(0.05, 0.15))
    return rig.replace({K.ACTUATOR_DELAY_S: delay, K.VALVE_TERMS[0][0]: float(RISING_STIFFER),
                        K.VALVE_TERMS[0][1]: rng.uniform(0.4, 0.8)}, "hidden effect"), delay


def step_log(rig: RigParameters, cycles: int, seed: int, folder: Path) -> Path:
    """The three-column log of ``cycles`` applies and releases."""
    top = rig.number(K.ACTUATOR_MAX_CURRENT_A)
    profile = sc.applies_and_releases(tuple(LEVELS[k % 3] * top for k in range(cycles)))
    duration = 15.0 if cycles == 1 else 2.0 + 6.0 * cycles
    result = simulate(rig, sc.actuator_test(rig, profile, duration, "valve_step"))
    full = folder / "full.csv"
    write_csv(result.to_run(noise=seed), full)
    lines = full.read_text().splitlines()
    full.unlink()
    path = folder / "valve_step.csv"
    path.write_text("\n".join(",".join(line.split(",")[:3]) for line in lines) + "\n")
    return path


def one_log(seed: int, cycles: int, datasheet: RigParameters) -> tuple[bool, str]:
    rig, delay = hidden_valve(datasheet, np.random.default_rng(seed))
    with tempfile.TemporaryDirectory() as folder:
        result = diagnose([read_csv(step_log(rig, cycles, seed, Path(folder)))], datasheet)
    found = {f.cause: f for f in result.findings}
    if cycles == 1:
        said = any("one more step" in p for p in result.problems)
        return (result.verdict == INCONCLUSIVE and said,
                f"{result.verdict} (truth {delay * 1e3:.1f} ms)")
    fitted = found["actuator_delay"].parameters["delay_s"] if "actuator_delay" in found \
        else float("nan")
    valve = found.get("discovered")
    in_valve = valve is not None and VALVE_FAMILIES.get(valve.family) == "valve"
    law = f"{valve.family}: {valve.term}" if valve is not None and in_valve else "no valve term"
    gain = valve is not None and valve.held_out is not None and valve.held_out < 0
    ok = (result.verdict == "actuator_delay" and abs(fitted / delay - 1.0) <= 0.1
          and in_valve and gain)
    return ok, (f"delay {fitted * 1e3:.1f} ms (truth {delay * 1e3:.1f}, "
                f"{100 * (fitted / delay - 1):+.1f} %); {law}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=5)
    parser.add_argument("--seed", type=int, default=4300)
    parser.add_argument("--cycles", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        sheet = Path(folder) / "datasheet.yaml"
        sheet.write_text(DATASHEET)
        datasheet = load_parameters([sheet], over_reference=True)
    right = 0
    for seed in range(args.seed, args.seed + args.count):
        started = time.perf_counter()
        ok, outcome = one_log(seed, args.cycles, datasheet)
        right += ok
        print(f"{seed}  {'yes' if ok else 'NO ':3s}  {outcome}  "
              f"({time.perf_counter() - started:.1f} s)", flush=True)
    print(f"{right}/{args.count} right ({args.cycles} cycles a log)")
    sys.exit(0 if right == args.count else 1)


if __name__ == "__main__":
    main()
