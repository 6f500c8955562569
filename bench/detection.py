"""Detection-rate benchmark of ``diagnose``: a randomized sweep of hidden effects and sizes.

Run: ``python bench/detection.py [--per-cause N] [--nulls N] [--causes a,b] [--seed S]``
(not part of ``make bench``: ~70 s per campaign on 2 cores, so the default sweep of
3 campaigns per cause and 5 null campaigns takes about 40 minutes).

Each campaign is made by the project's own rig generator: the ordinary datasheet
deviations and sensor noise, plus one effect drawn at random over a realistic range
(or none). A case is correct when the verdict names the hidden cause and its key
parameter is within the issue's tolerance; a null campaign is a false alarm unless the
verdict is ``none``. Target: >= 95 % correct per cause, 0 false alarms.
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.diagnosis.catalogue import gear_walk_key_parameters
from landing_gear_sim.diagnosis.diagnose import diagnose
from landing_gear_sim.model.parameters import RigParameters, load_parameters
from msg_tools.io import read_campaign

Draw = Callable[[np.random.Generator, RigParameters], dict]
Truth = Callable[[RigParameters], float]


@dataclass(frozen=True)
class Case:
    """One cause: how to hide it, what to start without, its key parameter and tolerance."""

    draw: Draw
    key: str
    truth: Truth
    tolerance: float  # absolute if ``absolute`` else relative
    absolute: bool = False
    without: tuple[str, ...] = ()


def _number(key: str) -> Truth:
    return lambda rig: rig.number(key)


CASES: dict[str, Case] = {
    "actuator_delay": Case(
        lambda r, d: {"elements.actuator_delay": True, "actuator.delay_s": r.uniform(0.002, 0.02)},
        "delay_s", _number("actuator.delay_s"), 1e-3, absolute=True),
    "pressure_sensor_offset": Case(
        lambda r, d: {"elements.pressure_sensor_offset": True,
                      "sensors.pressure_offset_pa": r.choice([-1, 1]) * r.uniform(0.3e5, 2e5)},
        "offset_pa", _number("sensors.pressure_offset_pa"), 0.2),
    "tire_relaxation": Case(
        lambda r, d: {"elements.tire_relaxation": True,
                      "tyre.relaxation_length_m": r.uniform(0.2, 0.8)},
        "relaxation_length_m", _number("tyre.relaxation_length_m"), 0.2),
    "brake_fade": Case(
        lambda r, d: {"elements.brake_fade": True, "brake.fade_fraction": r.uniform(0.15, 0.45),
                      "brake.fade_energy_j": r.uniform(0.8e6, 4e6)},
        "fade_fraction", _number("brake.fade_fraction"), 0.2),
    "gear_walk": Case(
        lambda r, d: {"gear_walk.stiffness_n_m_per_rad":
                      d.number("gear_walk.stiffness_n_m_per_rad") * r.uniform(0.6, 1.5)},
        "frequency_hz", lambda rig: gear_walk_key_parameters(rig)["frequency_hz"], 0.05,
        without=("gear_walk",)),
    "drag": Case(
        lambda r, d: {"drag.coeff_n_s2_per_m2": r.uniform(0.15, 0.8)},
        "drag_coeff_n_s2_per_m2", _number("drag.coeff_n_s2_per_m2"), 0.2, without=("drag",)),
    "actuator_dynamics": Case(
        lambda r, d: {"actuator.natural_frequency_hz": r.uniform(6.0, 20.0)},
        "natural_frequency_hz", _number("actuator.natural_frequency_hz"), 0.1,
        without=("actuator_dynamics",)),
    "load_dependent_radius": Case(
        lambda r, d: {"radius.b_m_per_n": d.number("radius.b_m_per_n") * r.uniform(0.7, 1.5)},
        "radius_b_m_per_n", _number("radius.b_m_per_n"), 0.3, without=("load_dependent_radius",)),
    "friction_curve": Case(
        lambda r, d: {"friction.theta1": d.number("friction.theta1") * r.uniform(0.6, 0.85)},
        "theta1", _number("friction.theta1"), 0.1, without=("friction_curve",)),
}


def run_case(cause: str | None, seed: int, datasheet: RigParameters) -> tuple[bool, str, float]:
    """Diagnose one generated campaign; (correct, verdict, key-parameter error)."""
    rng = np.random.default_rng(seed)
    rig = rig_like(datasheet, rng)
    case = CASES.get(cause) if cause else None
    if case is not None:
        rig = rig.replace(case.draw(rng, datasheet), "hidden effect")
    with tempfile.TemporaryDirectory() as folder:
        generate_campaign(Path(folder), rig, seed)
        runs = read_campaign(Path(folder)).runs
    result = diagnose(runs, datasheet, without=list(case.without) if case else [])
    if case is None:
        return result.verdict == "none", result.verdict, math.nan
    found = [f for f in result.findings if f.cause == cause]
    if result.verdict != cause or not found:
        return False, result.verdict, math.nan
    value, truth = found[0].parameters[case.key], case.truth(rig)
    error = abs(value - truth) if case.absolute else abs(value / truth - 1.0)
    return error <= case.tolerance, result.verdict, error


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cause", type=int, default=3)
    parser.add_argument("--nulls", type=int, default=5)
    parser.add_argument("--causes", default=",".join(CASES))
    parser.add_argument("--seed", type=int, default=1000)
    args = parser.parse_args()
    datasheet = load_parameters()
    plan = [(c, args.seed + 17 * i + j) for i, c in enumerate(args.causes.split(","))
            for j in range(args.per_cause)]
    plan += [(None, args.seed + 900 + j) for j in range(args.nulls)]
    outcomes: dict[str, list[bool]] = {}
    print(f"{'hidden':24s} {'seed':>6s} {'verdict':24s} {'key error':>10s} {'ok':>4s} {'s':>6s}",
          flush=True)
    for cause, seed in plan:
        started = time.perf_counter()
        ok, verdict, error = run_case(cause, seed, datasheet)
        name = cause or "none"
        outcomes.setdefault(name, []).append(ok)
        print(f"{name:24s} {seed:6d} {verdict:24s} {error:10.3g} {'yes' if ok else 'NO':>4s} "
              f"{time.perf_counter() - started:6.1f}", flush=True)
    print("\ndetection rate per cause (target >= 95 %; none: 0 false alarms)")
    for name, results in outcomes.items():
        rate = sum(results) / len(results)
        print(f"  {name:24s} {100 * rate:5.1f} %  ({sum(results)}/{len(results)})")


if __name__ == "__main__":
    main()
