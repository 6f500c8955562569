"""Unit mix-ups a range check cannot see, found by what the rig's physics makes redundant.

A speed logged in rpm but declared rad/s, or a pressure in psi declared as bar, stays
within any physical range; but before braking the wheel rolls freely on the flywheel (equal
rim speeds), the valve's pressure follows its current through the datasheet map within
tens of percent, and over a stop the flywheel loses the momentum the load cell's force
takes from it. A ratio far from 1 that matches a unit factor names the unit.

What still calibrates but may mislead is a note (:func:`unit_notes`): a pressure that reads
one atmosphere at zero current (logged absolute), a pressure flat at its top while the
valve's current asks for more (a transducer clipping), a wheel speed counted from an
encoder's lines (its resolution named).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np

from landing_gear_sim.calibration.runs import ClassifiedRun, RunKind
from landing_gear_sim.errors import IdentificationError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.actuator import actuator_pressure
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import (
    logged_or_set_load_n,
    rim_speed_m_s,
    rolling_radius_at,
)
from landing_gear_sim.model.scenario import BRAKE_ON_CURRENT_A
from msg_tools.checks import CONTACT_LOAD_N, MIN_BRAKING_SAMPLES, TURNING_RAD_S
from msg_tools.run import Run
from msg_tools.units import PA_PER_BAR, UNITS

PLAUSIBLE_RATIO = (0.5, 2.0)  # measured/expected: other rigs differ, not by a unit factor
MATCH = 0.15  # a ratio within 15 % of a unit factor is taken for that unit
VALVE_PRESSURE_PA = 5 * PA_PER_BAR  # compare where the valve map is clear of its dead-band
ATMOSPHERE_PA = 101325.0
ABSOLUTE_MATCH_PA = 0.05 * PA_PER_BAR  # a pressure at rest this close to one atmosphere
CLIP_SAMPLES = 50  # a flat top held this long ...
CLIP_HEADROOM = 1.1  # ... where the valve map gives this much more is a clipping sensor
LATTICE_SHARE = 0.01  # a counted channel takes no more distinct values than this share ...
LATTICE_LEVELS = 3  # ... and at least this many


def check_units(runs: Sequence[ClassifiedRun], params: RigParameters) -> None:
    """Raise :class:`IdentificationError` naming the column and its likely unit."""
    for run in runs:
        _check_dead_speeds(run)  # first: a dead encoder reads as no stop, or no time
        _check_load(run, params)  # first: a load in kN reads as a wheel never on the flywheel
        _check_speeds(run, params)
        _check_pressure(run, params)
        _check_momentum(run, params)


def unit_notes(runs: Sequence[ClassifiedRun], params: RigParameters) -> list[str]:
    """What the runs still calibrate with but a user should hear of: an absolute pressure,
    a clipping pressure transducer, a counted wheel channel and its resolution (each a
    note; empty: nothing)."""
    return [note for note in (_absolute_pressure(runs), _clipped_pressure(runs, params),
                              _counted_wheel(runs), _other_load(runs, params),
                              _other_valve(runs, params)) if note]


def _absolute_pressure(runs: Sequence[ClassifiedRun]) -> str | None:
    at_rest = np.concatenate([r.pressure_pa[r.current_a < BRAKE_ON_CURRENT_A] for r in runs])
    if at_rest.size < MIN_BRAKING_SAMPLES:
        return None
    level = float(np.median(at_rest))
    if abs(level - ATMOSPHERE_PA) > ABSOLUTE_MATCH_PA:
        return None
    return (f"brake_pressure_bar reads {level / PA_PER_BAR:.2f} bar at zero current: logged "
            "absolute? The model's pressure is gauge (a column mapping with offset: -1.01325 "
            "reads it so); a transducer offset reads the same, and the diagnosis may name it "
            "pressure_sensor_offset")


def _clipped_pressure(runs: Sequence[ClassifiedRun], params: RigParameters) -> str | None:
    clipped: dict[str, tuple[float, int, float]] = {}
    for run in runs:
        top = float(np.max(run.pressure_pa))
        flat = run.pressure_pa >= top - 1e-9 * abs(top)
        if top <= VALVE_PRESSURE_PA or flat.sum() < CLIP_SAMPLES:
            continue
        asked = float(np.max(actuator_pressure(params, run.current_a, run.rate_hz)[flat]))
        if asked > CLIP_HEADROOM * top:
            clipped[run.name] = (top, int(flat.sum()), asked)
    if not clipped:
        return None
    top = min(v[0] for v in clipped.values())
    return (f"brake_pressure_bar stays flat at {top / PA_PER_BAR:.3g} bar in "
            f"{', '.join(clipped)} ({sum(v[1] for v in clipped.values())} samples) where the "
            f"valve map gives up to {max(v[2] for v in clipped.values()) / PA_PER_BAR:.3g} "
            "bar: a transducer clipping there? Its samples read the pressure low")


def counted_wheel_step(runs: Sequence[ClassifiedRun]) -> float | None:
    """The speed per count of a counting encoder's wheel channel (every braking run's speeds
    on a lattice: whole lines per sample), median over the runs; None: an analogue channel
    or no braking run."""
    steps = [lattice_step(r.wheel_speed_rad_s) for r in runs if r.braking]
    if not steps or None in steps:
        return None
    return float(np.median([s for s in steps if s is not None]))


def _counted_wheel(runs: Sequence[ClassifiedRun]) -> str | None:
    """The wheel channel of a counting encoder, with the lines per revolution its lattice
    means."""
    step = counted_wheel_step(runs)
    if step is None:
        return None
    rate = float(np.median([r.rate_hz for r in runs if r.braking]))
    return (f"wheel_speed_rad_s is counted: {2 * math.pi * rate / step:.0f} lines per "
            f"revolution ({step:.3g} rad/s per count at {rate:g} Hz); effects in the wheel "
            "channel (a skew, a ripple with its angle) are judged through that resolution, "
            "and small ones may not show")


def lattice_step(values: np.ndarray) -> float | None:
    """The step of the lattice ``values`` sit on (a counting encoder's speed per count), or
    None when they take many values (an analogue channel)."""
    levels = np.unique(values)
    if levels.size > LATTICE_SHARE * values.size:
        return None
    # a log's last digit splits a level in two (24.5436926 and 24.5436926001)
    levels = levels[np.r_[True, np.diff(levels) > 1e-6 * float(np.max(np.abs(levels)))]]
    if levels.size < LATTICE_LEVELS:
        return None
    step = float(np.min(np.diff(levels)))
    multiples = (levels - levels[0]) / step
    return step if float(np.max(np.abs(multiples - np.round(multiples)))) < 1e-3 else None


def _likely(ratio: float, quantity: str, contract_unit: str) -> str | None:
    """The unit whose factor to ``contract_unit`` explains ``ratio`` (value read / truth)."""
    units = UNITS[quantity]
    for unit, factor in units.items():
        if unit != contract_unit and abs(ratio * factor / units[contract_unit] - 1) < MATCH:
            return unit
    return None


def _refuse(run: ClassifiedRun, column: str, ratio: float, what: str, unit: str | None,
            also: str = "") -> None:
    hint = f"; it looks like {unit}{also}: declare the unit (units row, header '[{unit}]' " \
           "or a column mapping)" if unit else "; check its unit and the rig parameters"
    if ratio < 0 and unit is None:
        # a transducer wired or logged the other way round: the magnitude may be right
        hint = ("; its sign is the contract's opposite: a column mapping with scale: -1 reads "
                "it so" + ("" if PLAUSIBLE_RATIO[0] <= -ratio <= PLAUSIBLE_RATIO[1]
                           else ", then check its unit and the rig parameters"))
    raise IdentificationError(f"{run.source or run.name}: {column} is {ratio:.3g} times "
                              f"{what}{hint}")


CERTAIN_FACTOR = 10.0  # a datasheet value off by this is a unit, not another rig
LOAD_PERCENTILE = 95.0  # a stop's load near its static set point (lift takes from it at speed)


def _load_ratio(run: ClassifiedRun, params: RigParameters) -> float | None:
    """A braking run's load near its set point over the rig's static load (None: not a
    braking run)."""
    if not run.braking or run.lacks("vertical_load_n"):
        return None
    static = params.number(K.LOADING_STATIC_LOAD_N)
    return float(np.percentile(run.vertical_load_n, LOAD_PERCENTILE)) / static


def _check_load(run: ClassifiedRun, params: RigParameters) -> None:
    """A load whose ratio to the datasheet's static load is a unit's factor at least
    CERTAIN_FACTOR from 1 (kN; a load in lbf reads like a rig 4.4 times lighter); any other
    disagreement is the datasheet's to settle (:func:`_other_load`, a note)."""
    ratio = _load_ratio(run, params)
    if ratio is None or 1.0 / CERTAIN_FACTOR <= ratio <= CERTAIN_FACTOR:
        return
    unit = _likely(ratio, "force", "N")
    if unit:
        _refuse(run, "vertical_load_N", ratio,
                f"the rig's static load ({K.LOADING_STATIC_LOAD_N} "
                f"{params.number(K.LOADING_STATIC_LOAD_N) / 1e3:.3g} kN) near its top", unit)


def _other_load(runs: Sequence[ClassifiedRun], params: RigParameters) -> str | None:
    ratios = [r for r in (_load_ratio(run, params) for run in runs) if r is not None]
    if not ratios or PLAUSIBLE_RATIO[0] <= float(np.median(ratios)) <= PLAUSIBLE_RATIO[1]:
        return None
    return (f"vertical_load_N reads {float(np.median(ratios)):.3g} times the rig's static "
            f"load ({K.LOADING_STATIC_LOAD_N} "
            f"{params.number(K.LOADING_STATIC_LOAD_N) / 1e3:.3g} kN) near its top: another "
            "rig? Name its static load in the datasheet (--config) so the model loads the "
            "wheel as the rig did")


def _check_dead_speeds(run: Run) -> None:
    """Raise where one speed channel holds one value throughout while the other turns: the
    wheel is driven by the flywheel, so a dead encoder (unplugged, a channel not wired to
    the logger) and not a stop ('stop 0.0 m', or 'time must be strictly increasing' once
    the dead speed was integrated to a distance)."""
    speeds = {"flywheel_speed_rad_s": run.flywheel_speed_rad_s,
              "wheel_speed_rad_s": run.wheel_speed_rad_s}
    if run.lacks(*speeds):
        return
    # the flywheel turns with the wheel off it (an actuator run): the wheel only on it
    on = run.vertical_load_n > CONTACT_LOAD_N if not run.lacks("vertical_load_n") else False
    for (dead, values), (other, turning) in itertools.permutations(speeds.items()):
        driving = np.abs(turning) > TURNING_RAD_S
        if dead == "wheel_speed_rad_s":
            driving &= on
        if np.ptp(values) == 0.0 and np.count_nonzero(driving) >= MIN_BRAKING_SAMPLES:
            raise IdentificationError(
                f"{run.source or run.name}: {dead} reads {values[0]:g} throughout while "
                f"{other} turns at up to {np.max(np.abs(turning)):.0f} rad/s: a dead "
                "channel (an encoder unplugged, or not wired to the logger); the run cannot "
                "be read without it")


def _check_speeds(run: ClassifiedRun, params: RigParameters) -> None:
    load = logged_or_set_load_n(run, params)  # a log without load cells: rpm named too
    rolling = ((run.time_s < run.brake_start_s) & (load > CONTACT_LOAD_N)
               & (np.abs(run.flywheel_speed_rad_s) > TURNING_RAD_S))
    if not run.braking or rolling.sum() < MIN_BRAKING_SAMPLES:
        return
    radius = float(np.median(rolling_radius_at(params, load[rolling])))
    wheel = run.wheel_speed_rad_s[rolling] * rolling_radius_at(params, load[rolling])
    ratio = float(np.median(wheel) / np.median(rim_speed_m_s(params, run.flywheel_speed_rad_s[
        rolling])))
    if PLAUSIBLE_RATIO[0] <= ratio <= PLAUSIBLE_RATIO[1]:
        return
    _refuse_linear_speeds(run, params, ratio, radius)
    wheel_unit, flywheel_unit = _likely(ratio, "speed", "rad/s"), _likely(1 / ratio, "speed",
                                                                         "rad/s")
    if flywheel_unit and not wheel_unit:
        _refuse(run, "flywheel_speed_rad_s", 1 / ratio,
                "what the wheel's speed gives while rolling freely", flywheel_unit)
    _refuse(run, "wheel_speed_rad_s", ratio,
            "what the flywheel's speed gives while rolling freely", wheel_unit)


LINEAR_SPEEDS = {"km/h": 3.6, "mph": 2.23694, "m/s": 1.0}
"""A rim's speed logged in a linear unit, by its factor from m/s."""


def _refuse_linear_speeds(run: ClassifiedRun, params: RigParameters, ratio: float,
                          radius_m: float) -> None:
    """Raise where the speeds' ``ratio`` (the wheel's rim over the flywheel's) is what a
    rim speed logged in a linear unit makes, naming the channel that is off and the scale
    that reads it: the wheel's (ratio f·r), the flywheel's (1/(f·R)), or both (r/R, where
    the flywheel's momentum against the load cell's impulse, f·R, names the unit); of those
    near, the nearest. Both in km/h had read 'wheel_speed_rad_s is 0.31 times', the wheel's
    radius, and the flywheel alone in km/h had blamed the wheel."""
    rim_m = params.number(K.FLYWHEEL_RADIUS_M)
    momentum = _momentum_ratio(run, params)
    found: list[tuple[float, str, dict[str, float]]] = []
    for unit, factor in LINEAR_SPEEDS.items():
        wheel = {"wheel_speed_rad_s": 1 / (factor * radius_m)}
        flywheel = {"flywheel_speed_rad_s": 1 / (factor * rim_m)}
        found.append((factor * radius_m, unit, wheel))
        if unit != "m/s":  # a rim of 1 m: m/s is rad/s
            found.append((1 / (factor * rim_m), unit, flywheel))
            if momentum is not None and _near(momentum, factor * rim_m):
                found.append((radius_m / rim_m, unit, wheel | flywheel))
    near = [(abs(math.log(ratio / expected)), unit, scales)
            for expected, unit, scales in found if _near(ratio, expected)]
    if not near:
        return
    _, unit, scales = min(near, key=lambda n: n[0])
    said = " and ".join(scales)
    fix = " and ".join(f"{c}: scale {v:.4g}" for c, v in scales.items())
    raise IdentificationError(
        f"{run.source or run.name}: {said} look{'s' * (len(scales) == 1)} like a rim speed "
        f"in {unit} (the wheel's rim over the flywheel's reads {ratio:.3g} of what it "
        f"should): a column mapping reads {'it' if len(scales) == 1 else 'them'} as rad/s "
        f"({fix})")


def _near(value: float, factor: float) -> bool:
    return abs(value / factor - 1) < MATCH


def _pressure_ratio(run: ClassifiedRun, params: RigParameters) -> float | None:
    """The measured pressure over what the datasheet's valve map gives for the run's
    current, where the map is clear of its dead-band (None: too few such samples)."""
    expected = actuator_pressure(params, run.current_a, run.rate_hz)
    clear = expected > VALVE_PRESSURE_PA
    if clear.sum() < MIN_BRAKING_SAMPLES:
        return None
    return float(np.median(run.pressure_pa[clear]) / np.median(expected[clear]))


def _check_pressure(run: ClassifiedRun, params: RigParameters) -> None:
    ratio = _pressure_ratio(run, params)
    if ratio is None or PLAUSIBLE_RATIO[0] <= ratio <= PLAUSIBLE_RATIO[1]:
        return
    unit = _likely(ratio, "pressure", "bar")
    if unit is None and not run.braking and ratio > 0:
        return  # no unit's factor: another valve, whose map its runs give (_other_valve)
    _refuse(run, "brake_pressure_bar", ratio, "what the valve map gives for its current", unit)


def _other_valve(runs: Sequence[ClassifiedRun], params: RigParameters) -> str | None:
    """What says that the actuator runs' valve is not the datasheet's (a pressure no unit's
    factor off its map: a real valve's step log had been refused as 0.154 times the map;
    the calibration takes the map from the runs)."""
    for run in runs:
        ratio = None if run.braking else _pressure_ratio(run, params)
        if ratio is None or PLAUSIBLE_RATIO[0] <= ratio <= PLAUSIBLE_RATIO[1] \
                or _likely(ratio, "pressure", "bar") is not None or ratio <= 0:
            continue
        source = ("the quasi-static ramp" if any(r.kind is RunKind.ACTUATOR_RAMP for r in runs)
                  else "the held levels of the step log")
        return (f"{run.source or run.name}: brake_pressure_bar is {ratio:.3g} times what the "
                "datasheet's valve map gives for its current, no unit's factor: another valve "
                f"than the datasheet's; its map is calibrated from {source} (give its "
                "datasheet with --config to start from it)")
    return None


EDGE_SAMPLES = 20  # a speed at a stop's start or end: the mean of this many samples


def _momentum_ratio(run: ClassifiedRun, params: RigParameters) -> float | None:
    """The flywheel's momentum lost while the wheel is on it over the load cell's impulse
    (None: a run that cannot tell)."""
    on = np.flatnonzero((run.time_s >= run.brake_start_s) & (run.vertical_load_n > CONTACT_LOAD_N)
                        & (np.abs(run.flywheel_speed_rad_s) > TURNING_RAD_S))
    if not run.braking or on.size < MIN_BRAKING_SAMPLES or run.lacks("longitudinal_force_n"):
        return None
    span = slice(on[0], on[-1] + 1)
    omega = run.flywheel_speed_rad_s[span]
    momentum = params.number(K.FLYWHEEL_INERTIA_KG_M2) / params.number(K.FLYWHEEL_RADIUS_M) \
        * (np.mean(omega[:EDGE_SAMPLES]) - np.mean(omega[-EDGE_SAMPLES:]))
    force, time = run.longitudinal_force_n[span], run.time_s[span]
    # the trapezoid (scipy.integrate's import cost each command that reads a log 0.7 s)
    impulse = float(np.sum(np.diff(time) * (force[1:] + force[:-1])) / 2.0)
    return abs(float(momentum) / impulse) if impulse else math.inf


def _check_momentum(run: ClassifiedRun, params: RigParameters) -> None:
    """The flywheel's momentum lost while the wheel is on it, J_f/R_f·Δω_f, against the
    impulse of the load cell's force, ∫F_x dt. Both speeds in rpm pass the free-rolling
    check (they agree); this one names them. The drag (a few percent of the force) is left
    out: it grows with the speed squared, so a speed in the wrong unit would swell it."""
    ratio = _momentum_ratio(run, params)
    if ratio is None or PLAUSIBLE_RATIO[0] <= ratio <= PLAUSIBLE_RATIO[1]:
        return
    speed_unit, force_unit = _likely(ratio, "speed", "rad/s"), _likely(1 / ratio, "force", "N")
    if force_unit and not speed_unit:
        _refuse(run, "longitudinal_force_N", 1 / ratio, "what the flywheel's momentum lost "
                "over the stop gives", force_unit)
    _refuse(run, "flywheel_speed_rad_s", ratio, "what the load cell's force takes from it over "
            "the stop", speed_unit, also=", and wheel_speed_rad_s too (the two agree while "
            "rolling freely)")
