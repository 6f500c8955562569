"""Detection-rate benchmark of ``diagnose``: a randomized sweep of hidden effects and sizes,
and the campaigns of an independent simulator.

Run: ``python bench/detection.py [--per-cause N] [--nulls N] [--causes a,b] [--seed S]
[--logger-realities] [--independent DIR] [--campaigns CAUSE:SEED,...] [--keep DIR]
[--scheduler tcp://HOST:8786] [--workers N]`` (not
part of ``make bench``: ~20-40 s per campaign here, so the default sweep of 3 campaigns per
cause and family, 5 null campaigns and the ten independent ones takes about 20 minutes on 2
cores). The campaigns run on Dask, like ``history``: a local cluster
by default, a real one with ``--scheduler``; every result goes to a journal
(``out/detection/seed-S.jsonl``) as it comes, so a stopped sweep started again runs only
the rest. Each row also holds every candidate the diagnosis scored (``candidates``: round,
ΔBIC, held-out change, verdict and reason, the largest loss and gain of its held-out fits),
so a sweep tells how near its rules each verdict came.

Each campaign is made by the project's own rig generator: the ordinary datasheet
deviations and sensor noise, plus one effect drawn at random over a realistic range
(or none). A case is correct when the verdict names the hidden cause and its key
parameter is within the issue's tolerance; a null campaign is a false alarm unless the
verdict is ``none``. Target: >= 95 % correct per cause, 0 false alarms. The families
outside the catalogue (``FAMILIES``: the generator's own laws, which the catalogue lacks)
are correct when the verdict is ``discovered`` with that family, a held-out gain and the
key parameter in tolerance (issue 14: right family with held-out gain >= 80 %). With
``--logger-realities`` each campaign is logged as a real logger might (drawn per campaign:
another rate, a counting encoder, a noisy quantised current, a dropout; see
``landing_gear_sim.calibration.logger``).

Effects no family or slot term is (``OUTSIDE``, issue 41): laws outside every equation's
library — two kinds per equation with a generic slot (the valve's static map and A(s), the
wheel's, the tyre's, the flywheel's, the loading device's, the F_x and pressure channels'),
drawn here through the plant's generic slots; right when discovered in the equation with a
held-out gain (no value: no term of the library is the law). ``--causes`` names them like
the others. ``--campaigns`` runs given (cause, seed) pairs alone: a seed draws the rig, the
effect and (with ``--logger-realities``) the logger, so a failure seen in a sweep, or the
seeds whose logger is 200 Hz, can be run again by themselves; ``--keep DIR`` keeps each of
them in DIR/CAUSE-SEED with its ``generating-parameters.yaml``, to diagnose by hand.

Data the project did not make: the campaigns under ``../shared/data/independent/`` (or
``--independent DIR``; skipped when absent), judged against their ``truth.json``
(``bench/independent.py``). Both parts end with a confusion matrix (truth × verdict) and
the key-parameter errors.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

import independent
import numpy as np

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.calibration.logger import Logger
from landing_gear_sim.campaigns.engine import Task, client, run_tasks
from landing_gear_sim.diagnosis.catalogue import gear_walk_key_parameters
from landing_gear_sim.diagnosis.diagnose import Diagnosis, diagnose
from landing_gear_sim.diagnosis.families import HIDDEN, REGISTRY, Hidden
from landing_gear_sim.diagnosis.families.equation_terms import EquationTerms
from landing_gear_sim.diagnosis.scoring import HELD_OUT_THRESHOLD, fit_changes
from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters, load_parameters
from msg_tools.io import read_campaign, read_runs

Draw = Callable[[np.random.Generator, RigParameters], dict]
Truth = Callable[[RigParameters], float]


@dataclass(frozen=True)
class Case:
    """One cause: how to hide it, what to start without, its key parameter and tolerance."""

    draw: Draw
    key: str | Callable[[RigParameters], str]  # a contract parameter (of the hidden rig)
    truth: Truth
    tolerance: float  # absolute if ``absolute`` else relative
    absolute: bool = False
    without: tuple[str, ...] = ()
    light: bool = False  # the campaign needs the light stops (runs at another static load)
    family: str = ""  # out of the catalogue: the family to answer (default: the case's name)


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


def _hidden_case(hidden: Hidden) -> Case:
    return Case(hidden.draw, hidden.key_of, lambda rig: rig.number(hidden.slot_of(rig)),
                hidden.tolerance, hidden.absolute, light=hidden.light, family=hidden.family)


# effects outside the catalogue: every family's hidden effects, from the registry (the
# generator's own laws, which the catalogue lacks); the diagnosis must answer 'discovered'
# with that family, a held-out gain and the parameter
FAMILIES: dict[str, Case] = {name: _hidden_case(hidden) for name, (_, hidden) in HIDDEN.items()}


def _slot(keys: tuple[tuple[str, str], ...], code: int, span: tuple[float, float]) -> Draw:
    """A draw of one term of a generic slot: basis function ``code``, coefficient in
    ``span``."""
    return lambda rng, datasheet: {keys[0][0]: float(code), keys[0][1]: rng.uniform(*span)}


def _product(first: tuple[int, int], second: tuple[int, int]) -> int:
    return basis.product_code(basis.factor_code(*first), basis.factor_code(*second))


# effects no family or slot term is (issue 41): laws outside every library's exact terms,
# drawn here, through the plant's generic slots (the code under test never imports this);
# right when the term is discovered in the equation, with a held-out gain
OUTSIDE: dict[str, tuple[str, Draw]] = {
    # pads that drag once applied, more at speed: [braked before] + ω·[braked before]
    "wheel_drag_rising": ("wheel", lambda rng, d: {
        K.WHEEL_TERMS[0][0]: float(basis.factor_code(basis.BRAKE_ENERGY, basis.STEP)),
        K.WHEEL_TERMS[0][1]: rng.uniform(80.0, 160.0),
        K.WHEEL_TERMS[1][0]: float(_product((basis.OMEGA, basis.IDENTITY),
                                            (basis.BRAKE_ENERGY, basis.STEP))),
        K.WHEEL_TERMS[1][1]: rng.uniform(0.1, 0.4)}),
    # a seal that rubs while the brake is pressed: ω·[P > 0.5 bar]
    "wheel_seal_pressed": ("wheel", _slot(K.WHEEL_TERMS, _product(
        (basis.OMEGA, basis.IDENTITY), (basis.PRESSURE, basis.STEP)), (0.6, 1.2))),
    # a cylinder that leaks faster at speed: √v·t_c
    "load_leak_speed": ("loading device", _slot(K.LOADING_TERMS, _product(
        (basis.SPEED, basis.SIGNED_ROOT), (basis.CONTACT_TIME, basis.IDENTITY)), (10.0, 25.0))),
    # a cylinder whose leak grows with the square root of the time since contact: √t_c·v
    "load_leak_root": ("loading device", _slot(K.LOADING_TERMS, _product(
        (basis.SPEED, basis.IDENTITY), (basis.CONTACT_TIME, basis.SIGNED_ROOT)), (2.0, 5.0))),
    # a friction falling with the square of the speed: μ_B·v²
    "tyre_speed_squared": ("tyre", _slot(K.TYRE_TERMS, _product(
        (basis.CURVE, basis.IDENTITY), (basis.SPEED, basis.SQUARE)), (-6e-5, -3e-5))),
    # a peak that sharpens at speed: μ_B²·v
    "tyre_peak_speed": ("tyre", _slot(K.TYRE_TERMS, _product(
        (basis.CURVE, basis.SQUARE), (basis.SPEED, basis.IDENTITY)), (-0.012, -0.006))),
    # a flywheel bearing whose friction grows with the root of the load the tyre presses
    # on it: sgn v·√F_z (210-390 N at 32 kN)
    "flywheel_bearing_root_load": ("flywheel", _slot(K.FLYWHEEL_TERMS, _product(
        (basis.SPEED, basis.SIGN), (basis.LOAD, basis.SIGNED_ROOT)), (1.2, 2.2))),
    # eddy currents that grow with the root of the rim's speed: √v (160-460 N at 30-60 m/s)
    "flywheel_eddy_root": ("flywheel", _slot(K.FLYWHEEL_TERMS, basis.factor_code(
        basis.SPEED, basis.SIGNED_ROOT), (30.0, 60.0))),
    # a map that bends progressively, as the fourth and the fifth power of the current
    # beyond the dead-band: e⁴, e⁵ (1.3-3.5 bar at 0.9 A)
    "map_fourth_power": ("valve", _slot(K.MAP_TERMS, _product(
        (basis.VALVE_CURRENT, basis.SQUARE), (basis.VALVE_CURRENT, basis.SQUARE)),
        (-4e6, -2e6))),
    "map_fifth_power": ("valve", _slot(K.MAP_TERMS, _product(
        (basis.VALVE_CURRENT, basis.SQUARE), (basis.VALVE_CURRENT, basis.CUBE)),
        (-6e6, -3e6))),
    # a valve that opens faster than it closes: [Ṗ > 1 bar/s]·ΔP in A(s)
    "valve_rising_stiffer": ("valve", _slot(K.VALVE_TERMS, _product(
        (basis.PRESSURE_RATE, basis.STEP), (basis.VALVE_ERROR, basis.IDENTITY)), (0.4, 0.8))),
    # a second stage that opens beyond half a bar of error: ΔP through a dead zone in A(s)
    "valve_second_stage": ("valve", _slot(K.VALVE_TERMS, basis.factor_code(
        basis.VALVE_ERROR, basis.DEAD_ZONE), (0.3, 0.6))),
    # a pressure transducer whose zero drifts faster as it warms: t·√t (0.6-1.8 bar at 20 s)
    "pressure_drift_rising": ("pressure channel", _slot(K.PRESSURE_TERMS, _product(
        (basis.RUN_TIME, basis.IDENTITY), (basis.RUN_TIME, basis.SIGNED_ROOT)),
        (700.0, 2000.0))),
    # a transducer whose gain drifts as the root of the time: P·√t (2-4 % at 20 s)
    "pressure_gain_root": ("pressure channel", _slot(K.PRESSURE_TERMS, _product(
        (basis.PRESSURE, basis.IDENTITY), (basis.RUN_TIME, basis.SIGNED_ROOT)),
        (0.0045, 0.009))),
    # a load cell's zero that drifts in proportion to the load it carries: √t·F_z
    "fx_drift_load": ("F_x channel", _slot(K.FX_TERMS, _product(
        (basis.RUN_TIME, basis.SIGNED_ROOT), (basis.LOAD, basis.IDENTITY)), (1e-3, 3e-3))),
    # a load cell that bends with the load more the longer it runs: F_z²·t
    "fx_bend_time": ("F_x channel", _slot(K.FX_TERMS, _product(
        (basis.LOAD, basis.SIGNED_SQUARE), (basis.RUN_TIME, basis.IDENTITY)), (4e-8, 1e-7))),
}


def random_logger(rng: np.random.Generator) -> Logger:
    """A logger with realities drawn at random (each with probability REALITY)."""
    on = rng.random(4) < REALITY
    noise = rng.uniform(0.002, 0.01) if on[2] else 0.0
    return Logger(rate_hz=float(rng.choice([200.0, 2000.0])) if on[0] else None,
                  encoder_counts=int(rng.choice([64, 256])) if on[1] else 0,
                  current_noise_a=noise, current_adc_bits=12 if on[2] else 0,
                  dropout_s=0.05 if on[3] else 0.0)


REALITY = 0.3


def run_case(cause: str | None, seed: int, datasheet: RigParameters, light: bool = False,
             realities: bool = False, keep: str | None = None
             ) -> tuple[bool, str, float, Diagnosis]:
    """Diagnose one generated campaign (with the light stops when ``light`` or when the
    cause needs them; with ``realities`` as a random logger writes it; kept under ``keep``
    with the parameters that made it, else thrown away); (correct, verdict, key-parameter
    error, the diagnosis)."""
    rng = np.random.default_rng(seed)
    rig = rig_like(datasheet, rng)
    if cause in OUTSIDE:
        return _outside(cause, rig, rng, seed, datasheet, realities, keep)
    case = (CASES | FAMILIES).get(cause) if cause else None
    if case is not None:
        rig = rig.replace(case.draw(rng, datasheet), "hidden effect")
    logger = random_logger(np.random.default_rng([seed, 2])) if realities else None
    with _campaign_folder(keep, cause, seed) as folder:
        generate_campaign(folder, rig, seed, light=light or (case is not None and case.light),
                          logger=logger)
        runs = read_campaign(folder).runs
    result = diagnose(runs, datasheet, without=list(case.without) if case else [])
    return (*_judged(cause, case, rig, result), result)


def _judged(cause: str | None, case: Case | None, rig: RigParameters, result: Diagnosis
            ) -> tuple[bool, str, float]:
    """(correct, verdict, key-parameter error) of a diagnosis of ``case`` hidden in ``rig``."""
    if case is None:  # no cause hidden (a null), or one the sweep does not know
        return result.verdict == "none", result.verdict, math.nan
    if cause in FAMILIES:
        family = FAMILIES[cause].family or cause
        found = [f for f in result.findings if f.cause == "discovered" and f.family == family
                 and f.held_out is not None and f.held_out < HELD_OUT_THRESHOLD]
        verdict = _verdict(result)
        if result.verdict != "discovered" or not found:
            return False, verdict, math.nan
        return _within(case, found[0].parameters.get(_key(case, rig), math.nan), rig, verdict)
    return _catalogue_judged(cause, rig, result.verdict,
                             [(f.cause, f.parameters) for f in result.findings])


def scored(result: Diagnosis) -> list[dict[str, object]]:
    """Every candidate the diagnosis scored, for the journal: its round, ΔBIC, held-out
    change, verdict and reason, and the largest loss and gain of its held-out fits [fit-%
    points] — how near a rule each came (a sweep's margins had been read through a probe)."""
    rows: list[dict[str, object]] = []
    for f in result.candidates:
        changes = [*fit_changes(f.fit_before, f.fit_after).values()]
        rows.append({"cause": f.cause, "family": f.family, "round": f.round,
                     "delta_bic": f.delta_bic, "held_out": f.held_out,
                     "accepted": f.accepted, "reason": f.reason,
                     "loss": round(-min(changes), 2) + 0.0 if changes else None,
                     "gain": round(max(changes), 2) if changes else None})
    return rows


@contextlib.contextmanager
def _campaign_folder(keep: str | None, cause: str | None, seed: int) -> Iterator[Path]:
    """Where a generated campaign is written: ``keep``/CAUSE-SEED, kept (a sweep's miss
    diagnosed again by hand, its truth in generating-parameters.yaml), or a temporary
    folder."""
    if keep is not None:
        folder = Path(keep) / f"{cause or 'none'}-{seed}"
        folder.mkdir(parents=True, exist_ok=True)
        yield folder
        return
    with tempfile.TemporaryDirectory() as temporary:
        yield Path(temporary)


def _outside(cause: str, rig: RigParameters, rng: np.random.Generator, seed: int,
             datasheet: RigParameters, realities: bool, keep: str | None = None
             ) -> tuple[bool, str, float, Diagnosis]:
    """A campaign of an OUTSIDE effect: right when discovered in its equation with a
    held-out gain (no value: the law is none of the library's terms)."""
    equation, draw = OUTSIDE[cause]
    rig = rig.replace(draw(rng, datasheet), "hidden effect")
    logger = random_logger(np.random.default_rng([seed, 2])) if realities else None
    with _campaign_folder(keep, cause, seed) as folder:
        generate_campaign(folder, rig, seed, logger=logger)
        runs = read_campaign(folder).runs
    result = diagnose(runs, datasheet)
    return outside_right(result.to_json(), equation), _verdict(result), math.nan, result


def outside_right(result: dict, equation: str) -> bool:
    """Whether a diagnosis (its JSON, or the verdict guard's answer) of an OUTSIDE effect
    is right: discovered in ``equation``, with a held-out gain."""
    findings = result["findings"]
    first = findings[0] if findings else {}
    held_out = first.get("held_out_delta")
    return (result["verdict"] == "discovered" and first.get("family") == equation
            and held_out is not None and held_out < HELD_OUT_THRESHOLD)


def _verdict(result: Diagnosis) -> str:
    """The verdict with what names it: a discovered term's family, the equation an
    unexplained finding places it in."""
    best = result.findings[0] if result.findings else None
    if best is not None and result.verdict == "discovered":
        return f"discovered {best.family}"
    if best is not None and result.verdict == "unexplained" and best.equation:
        return f"unexplained ({best.equation})"
    return result.verdict


def _key(case: Case, rig: RigParameters) -> str:
    return case.key if isinstance(case.key, str) else case.key(rig)


def _within(case: Case, value: float, rig: RigParameters, verdict: str
            ) -> tuple[bool, str, float]:
    """(key parameter within the case's tolerance, verdict, its error)."""
    truth = case.truth(rig)
    error = abs(value - truth) if case.absolute else abs(value / truth - 1.0)
    return error <= case.tolerance, verdict, error


def catalogue_right(answer: dict, cause: str | None, rig: RigParameters) -> bool:
    """Whether an answer (the verdict guard's, or a diagnosis's JSON) of a campaign that
    hides catalogued ``cause`` (None: nothing) in ``rig`` is right, as the sweep judges its
    own diagnoses (:func:`_catalogue_judged`)."""
    return _catalogue_judged(cause, rig, answer["verdict"],
                             [(f["cause"], f["parameters"]) for f in answer["findings"]])[0]


def _catalogue_judged(cause: str | None, rig: RigParameters, verdict: str,
                      findings: list[tuple[str, Mapping[str, float]]]
                      ) -> tuple[bool, str, float]:
    """(correct, verdict, key-parameter error) of an answer, its ``verdict`` and its
    ``findings`` (cause, key parameters), of a campaign hiding catalogued ``cause`` (None:
    nothing) in ``rig``: that cause named, its key parameter within the case's tolerance."""
    if cause is None:
        return verdict == "none", verdict, math.nan
    case = CASES[cause]
    found = [parameters for name, parameters in findings if name == cause]
    if verdict != cause or not found:
        return False, verdict, math.nan
    return _within(case, found[0].get(_key(case, rig), math.nan), rig, verdict)


def case_task(cause: str | None, seed: int, light: bool = False, realities: bool = False,
              keep: str | None = None) -> dict:
    """One campaign of the sweep, as a journal row."""
    started = time.perf_counter()
    ok, verdict, error, result = run_case(cause, seed, load_parameters(), light, realities,
                                          keep)
    truth = cause or "none"
    if truth in OUTSIDE:
        truth = f"discovered {OUTSIDE[truth][0]} ({truth})"
    elif truth in FAMILIES:
        family = FAMILIES[truth].family
        truth = f"discovered {family}" + (f" ({truth})" if family != truth else "")
    return {"cause": truth, "seed": str(seed),
            "ok": ok, "verdict": verdict, "error": None if math.isnan(error) else error,
            "logger": ", ".join(random_logger(np.random.default_rng([seed, 2])).realities)
            if realities else "", "candidates": scored(result),
            "seconds": round(time.perf_counter() - started, 1)}


def independent_task(folder: str) -> dict:
    """One campaign of the independent simulator, judged against its truth."""
    started = time.perf_counter()
    want = independent.expected(Path(folder))
    campaign = read_runs([Path(folder)])
    result = diagnose(campaign.runs, load_parameters(), without=list(want.without))
    judged = independent.judge(result.to_json(), want)
    errors = [e for e in judged.errors.values() if not math.isnan(e)]
    return {"cause": want.label, "seed": Path(folder).name, "ok": judged.ok,
            "verdict": judged.label, "error": max(errors) if errors else None,
            "errors": judged.errors, "candidates": scored(result),
            "seconds": round(time.perf_counter() - started, 1)}


def unseen_task(folder: str, equation: str) -> dict:
    """One campaign of an effect whose law no family or slot has (issue 41): right when it
    is discovered in its equation; how it ended otherwise."""
    started = time.perf_counter()
    result = diagnose(read_runs([Path(folder)]).runs, load_parameters())
    ok, outcome = independent.judge_unseen(result.to_json(), equation)
    return {"cause": f"{equation} ({Path(folder).name})", "seed": Path(folder).name,
            "ok": ok, "verdict": outcome[:30], "outcome": outcome, "error": None,
            "candidates": scored(result), "seconds": round(time.perf_counter() - started, 1)}


def datasheet_task(folder: str) -> dict:
    """One campaign of another rig handed over with its datasheet (issue 43): right when
    the diagnosis answers its truth (a null: none; a slow valve: its delay, ω_n and ζ)."""
    started = time.perf_counter()
    sheet = independent.datasheet_of(Path(folder))
    result = diagnose(read_runs([Path(folder)]).runs,
                      load_parameters([sheet] if sheet else None, over_reference=True))
    ok, outcome = independent.judge_datasheet(
        result.to_json(), result.extended.number(K.ACTUATOR_NATURAL_FREQUENCY_HZ),
        result.extended.number(K.ACTUATOR_DAMPING_RATIO), Path(folder))
    return {"cause": f"datasheet ({Path(folder).name})", "seed": Path(folder).name,
            "ok": ok, "verdict": outcome[:30], "outcome": outcome, "error": None,
            "candidates": scored(result), "seconds": round(time.perf_counter() - started, 1)}


def _line(row: dict) -> str:
    error = math.nan if row["error"] is None else row["error"]
    return (f"{row['cause']:40s} {row['seed']:>24s} {row['verdict']:30s} {error:10.3g} "
            f"{'yes' if row['ok'] else 'NO':>4s} {row['seconds']:6.1f}"
            + (f"  [{row['logger']}]" if row.get("logger") else ""))


def confusion(rows: list[dict]) -> str:
    """Truth × verdict counts, as text: one column per verdict, numbered (its legend
    below), so the table stays as narrow as the counts."""
    truths = sorted({r["cause"] for r in rows})
    verdicts = sorted({r["verdict"] for r in rows})
    width = max(3, *(len(str(r["cause"])) for r in rows)) + 1
    lines = [" " * width + "".join(f"{f'v{i}':>5s}" for i, _ in enumerate(verdicts, 1))]
    for truth in truths:
        counts = [sum(r["cause"] == truth and r["verdict"] == v for r in rows)
                  for v in verdicts]
        lines.append(f"{truth:{width}s}" + "".join(f"{c or '.':>5}" for c in counts))
    lines.extend(f"  v{i}: {verdict}" for i, verdict in enumerate(verdicts, 1))
    return "\n".join(lines)


def report(title: str, rows: list[dict]) -> None:
    print(f"\n== {title}")
    header = f"{'truth':40s} {'campaign':>24s} {'verdict':30s} {'key error':>10s} {'ok':>4s}"
    print(f"{header} {'s':>6s}")
    outcomes: dict[str, list[bool]] = {}
    for row in rows:
        print(_line(row))
        outcomes.setdefault(row["cause"], []).append(row["ok"])
    print("\nright per truth (target >= 95 %; none: 0 false alarms)")
    for name, results_ in outcomes.items():
        rate = sum(results_) / len(results_)
        print(f"  {name:40s} {100 * rate:5.1f} %  ({sum(results_)}/{len(results_)})")
    total = sum(r["ok"] for r in rows)
    print(f"  {'all':40s} {100 * total / max(len(rows), 1):5.1f} %  ({total}/{len(rows)})")
    print("\nconfusion (rows: truth, columns: verdict)")
    print(confusion(rows))
    unnamed = equation_outcomes(rows)
    if unnamed:
        print("\neffects no named family holds (issue 29: >= 80 % discovered in the right "
              "equation, the rest unexplained naming it; never none, never a catalogue name)")
        for outcome, count in unnamed.items():
            print(f"  {outcome:55s} {count}")


EQUATION_CASES: dict[str, str] = {
    f"discovered {h.family} ({h.name})": h.family
    for f in REGISTRY if isinstance(f, EquationTerms) and f.generic for h in f.hidden} | {
    f"discovered {equation} ({name})": equation for name, (equation, _) in OUTSIDE.items()}
"""Journal truths of the equations' hidden effects -> the equation to name."""


def equation_outcomes(rows: list[dict]) -> dict[str, int]:
    """How the campaigns of the equations' hidden effects ended, counted (empty: none)."""
    counts: dict[str, int] = {}
    for row in rows:
        equation = EQUATION_CASES.get(row["cause"])
        if equation is None:
            continue
        verdict = row["verdict"]
        outcome = ("discovered in its equation, value in tolerance" if row["ok"] else
                   "discovered in its equation, value out of tolerance"
                   if verdict == f"discovered {equation}" else
                   "unexplained, naming its equation" if verdict == f"unexplained ({equation})"
                   else "none" if verdict == "none" else
                   "a catalogue name" if verdict in CASES else f"other: {verdict}")
        counts[outcome] = counts.get(outcome, 0) + 1
    return counts


def _pairs(text: str) -> list[tuple[str | None, int]]:
    """``--campaigns``' CAUSE:SEED pairs (none: a null)."""
    known = {*CASES, *FAMILIES, *OUTSIDE, "none"}
    pairs = []
    for item in text.split(","):
        cause, _, seed = item.partition(":")
        if cause not in known or not seed.isdigit():
            raise argparse.ArgumentTypeError(
                f"{item!r}: not CAUSE:SEED with a cause of --causes or none")
        pairs.append((None if cause == "none" else cause, int(seed)))
    return pairs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-cause", type=int, default=3)
    parser.add_argument("--nulls", type=int, default=5)
    parser.add_argument("--causes", default=",".join([*CASES, *FAMILIES, *OUTSIDE]),
                        help="catalogue causes, out-of-catalogue families and effects outside "
                             "every library (OUTSIDE) (default: all)")
    parser.add_argument("--seed", type=int, default=1000)
    parser.add_argument("--scheduler", help="a running Dask scheduler (default: local)")
    parser.add_argument("--workers", type=int, help="local cluster: worker processes")
    parser.add_argument("--journal", type=Path, help="default out/detection/seed-S.jsonl")
    parser.add_argument("--light-runs", action="store_true",
                        help="every campaign with the light stops (the load family always)")
    parser.add_argument("--logger-realities", action="store_true",
                        help="log each campaign as a random real logger might")
    parser.add_argument("--independent", type=Path, default=independent.FOLDER,
                        help="campaigns with a truth.json (default: ../shared/data/"
                             "independent; skipped when absent)")
    parser.add_argument("--unseen", type=Path, default=independent.UNSEEN,
                        help="campaigns of effects no family or slot has (default: ../shared/"
                             "data/unseen; skipped when absent)")
    parser.add_argument("--only-independent", action="store_true",
                        help="only the campaigns the project did not make")
    parser.add_argument("--campaigns", type=_pairs, default=None, metavar="CAUSE:SEED,...",
                        help="only these campaigns of the own generator (none:SEED a null; "
                             "e.g. seeds whose random logger is 200 Hz), nothing else")
    parser.add_argument("--keep", type=Path, default=None, metavar="DIR",
                        help="write each own campaign to DIR/CAUSE-SEED with the parameters "
                             "that made it (generating-parameters.yaml), to diagnose again")
    args = parser.parse_args()
    plan = [(c, args.seed + 17 * i + j) for i, c in enumerate(args.causes.split(","))
            for j in range(args.per_cause)]
    plan += [(None, args.seed + 900 + j) for j in range(args.nulls)]
    if args.only_independent:
        plan = []
    if args.campaigns is not None:
        plan = args.campaigns
    suffix = ("-light" if args.light_runs else "") + ("-logger" if args.logger_realities else "")
    keep = str(args.keep.resolve()) if args.keep else None  # a worker's cwd may differ
    own = [Task(f"{cause or 'none'}-{seed}{suffix}", case_task,
                (cause, seed, args.light_runs, args.logger_realities, keep))
           for cause, seed in plan]
    theirs = [Task(f"independent-{folder.name}", independent_task, (str(folder),))
              for folder in independent.campaigns(args.independent)]
    unseen = [Task(f"unseen-{folder.name}", unseen_task, (str(folder), equation))
              for folder in independent.campaigns(args.unseen)
              if (equation := independent.unseen_equation(folder)) is not None]
    unseen += [Task(f"datasheet-{folder.name}", datasheet_task, (str(folder),))
               for folder in independent.campaigns(args.unseen)
               if independent.datasheet_of(folder) is not None]
    if args.campaigns is not None:
        theirs, unseen = [], []
    elif not theirs:
        print(f"{args.independent}: no independent campaigns, skipped", file=sys.stderr)
    journal = args.journal or Path("out/detection") / f"seed-{args.seed}{suffix}.jsonl"
    with client(args.scheduler, args.workers) as engine:
        results = run_tasks([*unseen, *theirs, *own], journal, engine,
                            lambda m: print(m, file=sys.stderr, flush=True))
    for row in (results[t.key] for t in unseen if t.key in results):
        print(f"unseen {row['cause']:40s} {'yes' if row['ok'] else 'NO':>4s}  "
              f"{row['outcome']}  ({row['seconds']:.0f} s)")
    for title, tasks in (("own generator", own), ("independent simulator", theirs),
                         ("unseen effects (issue 41: discovered in the right equation; "
                          "issue 43: another rig with its datasheet)", unseen)):
        rows = [results[t.key] for t in tasks if t.key in results]
        if rows:
            report(title, rows)
        if len(rows) < len(tasks):
            print(f"{len(tasks) - len(rows)} campaigns failed to run: start the sweep again")


if __name__ == "__main__":
    main()
