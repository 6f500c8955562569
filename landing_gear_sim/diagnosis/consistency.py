"""Consistency of what the rig measures twice (issue 14, part 1).

The rig measures more than the model needs. Relations that hold whatever the model's
parameters are checked on each run and phase, against their noise; a violation is evidence
on its own, even where the calibrated model fits well (a calibration can bend the friction
curve, the brake gain or the drag to swallow an effect the relations still show):

* free rolling (no brake): the load cell's F_x is the wheel's own inertia, J_w ω̇ / r;
* zero current ⇒ zero pressure (once the valve has settled);
* no contact (actuator-only runs) ⇒ zero loads;
* the valve's pressure against the model's, where the current changes slowly, does not
  depend on whether the current last rose or fell (play, hysteresis: ``input_history``);
* in free rolling the wheel channel is smooth in the wheel's angle: no ripple once or twice
  per revolution beyond the model's (run-out, an out-of-round code wheel: ``wheel_angle``);
  and so is the brake torque while it brakes (a disc's run-out: ``wheel_angle`` too);
* at the same slip, μ = F_x/F_z does not depend on the load, where runs at two static
  loads share slips (a tyre's load sensitivity beyond the radius law: ``load``);
* the brake gain of the wheel's torque balance r F_x − J_w ω̇ = k_b P does not depend on
  the speed or on the pressure level (a local k_b, fitted with a linear trend), nor on the
  run (k_b of each run, in the campaign's run order: wear, a brake that beds in).

Each check is a deviation with its 1-σ from the residual's own noise (autocorrelation
counted) and a physical floor below which nothing matters; violated when it exceeds both
Z_VIOLATED σ and the floor. No plotting here (:mod:`landing_gear_sim.report.diagnosis`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.plausibility import counted_wheel_step
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.statistics import (
    effective_count,
    inverse_variance_weights,
    linear_std,
    weighted_least_squares,
)
from landing_gear_sim.calibration.wheel_angle import (
    BRAKE_RUNOUT_KEYS,
    ORDERS,
    brake_ripple,
    checked_ripple,
)
from landing_gear_sim.diagnosis.equation_library import Campaign, equation_checks
from landing_gear_sim.diagnosis.equations import DECLARED, declaring
from landing_gear_sim.diagnosis.findings import Finding
from landing_gear_sim.diagnosis.load_relation import (
    LOAD_SPREAD,
    friction_in_load,
)
from landing_gear_sim.diagnosis.locked_wheel import locked_sliding
from landing_gear_sim.diagnosis.relations import (
    MIN_CHECK_S,
    MIN_SAMPLES,
    Z_VIOLATED,
    Check,
    Relation,
    violations,
)
from landing_gear_sim.diagnosis.settled_valve import (
    PRESSURE_FLOOR_PA,
    SETTLED_S,
    settled_valve,
)
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.scenario import (
    commanded,
)
from landing_gear_sim.model.sensors import SensorModel
from msg_tools.units import PA_PER_BAR

FORCE_FLOOR_N = 150.0  # a load-cell offset or crosstalk smaller than this does not matter
TREND_FLOOR = 0.05  # a brake gain changing by less than 5 % over the range does not matter
MIN_RUNS_FOR_DRIFT = 3
MAX_BRAKING_SLIP = 0.15  # beyond, the torque balance's derivative error dominates
RUNOUT_FLOOR = 1e-3  # a ripple below 0.1 % of the wheel speed is within the encoder's noise
TIMING_FLOOR_S = 1e-3  # a channel out of step by less than a millisecond does not matter
BRAKE_RUNOUT_FLOOR = 0.01  # a disc's ripple below 1 % of the torque does not matter


FREE_ROLLING = Relation.FREE_ROLLING
GAIN_IN_SPEED = Relation.GAIN_IN_SPEED
GAIN_IN_PRESSURE = Relation.GAIN_IN_PRESSURE
RUN_DRIFT = Relation.RUN_DRIFT
VALVE_DIRECTION = Relation.VALVE_DIRECTION
FRICTION_IN_LOAD = Relation.FRICTION_IN_LOAD
WHEEL_ANGLE = Relation.WHEEL_ANGLE
PRESSURE_TIMING = Relation.PRESSURE_TIMING
BRAKE_ANGLE = Relation.BRAKE_ANGLE


def check_campaign(runs: Sequence[ClassifiedRun], params: RigParameters) -> list[Check]:
    """Every check the runs allow, under ``params`` (radius law, wheel inertia, sensor
    offset of the calibrated model)."""
    prepared = [br.prepare(r, params) if r.braking else None for r in runs]
    checks = [c for run, b in zip(runs, prepared, strict=True)
              for c in _run_checks(run, b, params)]
    braking = [b for b in prepared if b is not None]
    if braking:
        checks.extend(_gain_trends(braking, params))
        checks.extend(_pressure_timing(braking, params))
        checks.extend(friction_in_load(braking, params))
        if (sliding := locked_sliding(braking, params)) is not None:
            checks.append(sliding)
    checks.extend(equation_checks(Campaign(runs, braking), params))
    return checks


def unchecked_relations(runs: Sequence[ClassifiedRun], checks: Sequence[Check]) -> list[str]:
    """The relations a campaign with braking runs left unchecked, each with what would
    check it (for ``problems``: a relation not checked is not a relation that holds)."""
    if not any(r.braking for r in runs) or any(c.relation == FRICTION_IN_LOAD for c in checks):
        return []
    return [f"{FRICTION_IN_LOAD}: not checked, no two constant-pressure stops at each of two "
            f"static loads ≥ {LOAD_SPREAD:.0%} apart that share slips; stops at a second static "
            "load (e.g. 70 % at 70 % of the pressures: `campaign --light-runs`) show a tyre's "
            "friction changing with the load"]


def coarse_channels(runs: Sequence[ClassifiedRun], checks: Sequence[Check]) -> list[str]:
    """What a counted wheel channel cannot resolve (for ``problems``: a ``none`` through a
    coarse encoder is no proof of a smooth wheel): the smallest ripple with the wheel's angle
    a run's free-rolling check would call violated, Z_VIOLATED of its σ (median over runs)."""
    if counted_wheel_step(runs) is None:
        return []
    stds = [c.std for c in checks if c.relation == WHEEL_ANGLE]
    if not stds:
        return []
    bound = max(Z_VIOLATED * float(np.median(stds)), RUNOUT_FLOOR)
    return [f"{WHEEL_ANGLE}: through the counted wheel channel a ripple below "
            f"{100 * bound:.1f} % of ω does not show ({Z_VIOLATED:g}σ of the free-rolling "
            f"checks, median over {len(stds)})"]


def under_floor(checks: Sequence[Check]) -> list[str]:
    """The deviations beyond Z_VIOLATED σ that lie under their floor, or within what the
    noise in the model's inputs can make (for ``problems``): the data show them, the
    diagnosis does not report them as structure, and ``none`` does not rule out an effect
    of their size (a tyre's μ_B·v² law logged at 200 Hz read 0.027 at 11σ under the 0.046
    its slip noise then allowed, and was said nowhere)."""
    under = [f"{c.reading()} lies under its floor {c.floor:.4g} {c.unit} (the least that "
             "matters, or what the log's noise makes of it): an effect of this size is not "
             "told from that here"
             for c in sorted(checks, key=lambda c: -c.z)
             if c.z > Z_VIOLATED and not c.violated]
    within = [f"{c.reading()} lies within the {c.input_noise:.4g} {c.unit} the noise in "
              "the model's inputs can make of it (a noisy logged current fed to the valve): "
              "an effect of this size is not told from that here"
              for c in violations(checks) if c.within_input_noise]
    return under + within


def inconsistent(broken: Sequence[Check]) -> Finding:
    """Violated relations as an ``unexplained`` finding (nothing in the model explains
    them): the strongest one's deviation, every one in the evidence, and the equation (or
    the channel's measurement) its relation checks."""
    best = broken[0]
    equation = declaring(best.relation)
    channel = DECLARED[equation].channel
    return Finding(cause="unexplained", parameters={"deviation": best.deviation},
                   std={"deviation": best.std}, units={"deviation": best.unit},
                   evidence=f"measured relations the model cannot break are violated, in the "
                   f"{equation}: " + "; ".join(c.describe() for c in broken[:4])
                   + (f"; and {len(broken) - 4} more" if len(broken) > 4 else ""),
                   fit_before={}, fit_after={}, delta_bic=None, held_out=None, accepted=False,
                   fitted_on=tuple(sorted({c.run for c in broken})), equation=str(equation),
                   channel=channel)


def _run_checks(run: ClassifiedRun, prepared: br.Braking | None, params: RigParameters
                ) -> list[Check]:
    """The checks of one run (``prepared``: its filtered signals, for a braking run)."""
    checks = [_zero_current(run, params)]
    if prepared is not None:
        checks.extend([_free_rolling(prepared, params), _wheel_angle(run, params),
                       _brake_angle(run, prepared, params)])
    else:
        fx = SensorModel.of(params).true_longitudinal(run.longitudinal_force_n,
                                                      run.vertical_load_n, br.run_time_s(run))
        checks.extend(_mean_check(Relation.NO_CONTACT, run.name, f"whole run, {label}",
                                  values, FORCE_FLOOR_N, "N", run.rate_hz)
                      for values, label in ((run.vertical_load_n, "F_z"), (fx, "F_x")))
        checks.append(_valve_direction(run, params))
    return [c for c in checks if c is not None]


def _valve_direction(run: ClassifiedRun, params: RigParameters) -> Check | None:
    """Measured minus model pressure where the current fell last, against where it rose
    last (on the settled samples, :func:`~.settled_valve.settled_valve`): a static map
    cannot tell the two apart, a valve with play can. Positive: more pressure on the way
    down."""
    valve = settled_valve(run, params)
    if valve is None:
        return None
    falling, rising = (valve.residual_pa[valve.settled & (valve.direction == s)]
                       for s in (-1.0, 1.0))
    if min(falling.size, rising.size) < MIN_CHECK_S * run.rate_hz:
        return None
    std = math.sqrt(sum(float(np.var(r)) / effective_count(r - r.mean())
                        for r in (falling, rising)))
    return Check(VALVE_DIRECTION, run.name, "slow current changes",
                 float(falling.mean() - rising.mean()), std, PRESSURE_FLOOR_PA, "Pa")


def _wheel_angle(run: ClassifiedRun, params: RigParameters) -> Check | None:
    """The wheel channel's strongest ripple with the wheel's angle in free rolling, beyond
    the model's own run-out of that order [relative to ω]."""
    ripple = checked_ripple(run)
    if ripple is None:
        return None
    runout = SensorModel.of(params).runout
    checks = [Check(WHEEL_ANGLE, run.name, f"before braking, {m}× per revolution",
                    ripple.amplitude[i] - runout[2 * i], ripple.std[i], RUNOUT_FLOOR, "of ω")
              for i, m in enumerate(ORDERS)]
    return max(checks, key=lambda c: c.z)


def _brake_angle(run: ClassifiedRun, prepared: br.Braking, params: RigParameters
                 ) -> Check | None:
    """The brake torque's strongest ripple with the wheel's angle while it brakes, beyond
    the model's own run-out of that order [relative to T_b]."""
    ripple = brake_ripple(run, params, prepared)
    if ripple is None:
        return None
    model = [params.number(k) for k in BRAKE_RUNOUT_KEYS[::2]]
    checks = [Check(BRAKE_ANGLE, run.name, f"braking, {m}× per revolution",
                    ripple.amplitude[i] - model[i], ripple.std[i], BRAKE_RUNOUT_FLOOR, "of T_b")
              for i, m in enumerate(ORDERS)]
    return max(checks, key=lambda c: c.z)


def _mean_check(relation: Relation, run: str, phase: str, values: np.ndarray, floor: float,
                unit: str, rate_hz: float) -> Check | None:
    if values.size < MIN_CHECK_S * rate_hz:
        return None
    mean = float(np.mean(values))
    std = float(np.std(values)) / math.sqrt(effective_count(values - mean))
    return Check(relation, run, phase, mean, std, floor, unit)


def _zero_current(run: ClassifiedRun, params: RigParameters) -> Check | None:
    """Pressure where the current has commanded nothing for SETTLED_S (before braking,
    between pulses): a valve that is shut holds no pressure (the model's sensor offset
    aside). 'Nothing' as the brake's start reads it: a noisy, quantised log's current is
    never exactly 0."""
    off = ~commanded(run.current_a, run.rate_hz)
    samples = max(1, round(SETTLED_S * run.rate_hz))
    settled = np.convolve(off, np.ones(samples), mode="full")[:off.size] >= samples
    pressure = SensorModel.of(params).true_pressure(run.pressure_pa[settled],
                                                    (run.time_s - run.time_s[0])[settled])
    return _mean_check(Relation.ZERO_CURRENT, run.name, "current off", pressure,
                       PRESSURE_FLOOR_PA, "Pa", run.rate_hz)


def _free_rolling(b: br.Braking, params: RigParameters) -> Check | None:
    _, excess = br.free_rolling_excess(b, params)
    return _mean_check(FREE_ROLLING, b.run.name, "before braking", excess, FORCE_FLOOR_N, "N",
                       b.run.rate_hz)


def _gain_trends(runs: Sequence[br.Braking], params: RigParameters) -> list[Check]:
    """k_b of the torque balance with a linear trend in speed, and in pressure, over the
    braking runs: the relative change over the range seen [1]."""
    torque, pressure, speed = [], [], []
    gain = params.number(K.BRAKE_GAIN_N_M_PER_PA)
    for b in runs:
        whole, energy = br.torque_balance(b, params)
        m = np.flatnonzero(br.steady_braking_samples(b))[::10]
        # relative to the model's whole gain law: a fade, slope or drift it has is no
        # violation (a fade the model had explained read as a gain falling with speed)
        law = br.model_torque(b, params, energy, m) / (gain * b.pressure[m])
        torque.append(whole[m] / law)
        pressure.append(b.pressure[m])
        speed.append(b.speed_m_s[m])
    t, p, v = (np.concatenate(x) for x in (torque, pressure, speed))
    if t.size < MIN_SAMPLES:
        return []
    checks = [_trend(GAIN_IN_SPEED, t, p, v, "m/s"),
              _trend(GAIN_IN_PRESSURE, t, p, p / PA_PER_BAR, "bar")]
    per_run = [(tq, pr) for tq, pr in zip(torque, pressure, strict=True)
               if tq.size >= MIN_SAMPLES // 10]
    if len(per_run) >= MIN_RUNS_FOR_DRIFT:
        checks.append(_run_drift(per_run))
    return checks


def _pressure_timing(runs: Sequence[br.Braking], params: RigParameters) -> list[Check]:
    """How late the pressure channel is against the brake torque it makes [s] (positive:
    the channel is late), beyond the model's own delay of that channel: the torque balance's
    T ≈ a·M + b·Ṁ, M the model's torque of the measured pressure (taken back by the model's
    delay of the channel), so T(t) ≈ a·M(t + d), d = b/a. A valve's transport delay leaves
    the measured pressure in step with the torque; a channel stamped late does not (an
    actuator delay and a wheel channel 'leading' by as much were once reported together).
    Away from lock (slip < MAX_BRAKING_SLIP), where the balance's derivative dominates."""
    rows, columns = [], []
    for b in runs:
        b = br.in_step(b, params)
        torque, energy = br.torque_balance(b, params)
        model = br.model_torque(b, params, energy, np.arange(b.time_s.size))
        slope = np.gradient(model, 1.0 / b.run.rate_hz)
        m = np.flatnonzero(br.braking_samples(b) & (br.slip(b, params) < MAX_BRAKING_SLIP))[::10]
        rows.append(torque[m])
        columns.append(np.column_stack([model[m], slope[m]]))
    t, design = np.concatenate(rows), np.vstack(columns)
    if t.size < MIN_SAMPLES or np.ptp(design[:, 1]) == 0.0:
        return []
    coef, *_ = np.linalg.lstsq(design, t, rcond=None)
    std = linear_std(design, t - design @ coef, 2)
    lag = float(coef[1] / coef[0])
    lag_std = math.hypot(std[1], lag * std[0]) / abs(float(coef[0]))
    return [Check(PRESSURE_TIMING, "campaign", f"{len(runs)} braking runs, slip < "
                  f"{MAX_BRAKING_SLIP:g}", lag, lag_std, TIMING_FLOOR_S, "s")]


def _run_drift(per_run: Sequence[tuple[np.ndarray, np.ndarray]]) -> Check:
    """k_b of each run (T = k_b P, its 1-σ from the run's own residual), then a straight line
    through them in run order: the relative change from the first run to the last [1]. The
    σ are scaled up to the scatter about the line when that is larger (model errors that
    differ from run to run are not wear)."""
    gains, std = [], []
    for torque, pressure in per_run:
        design = pressure[:, None]
        coef, *_ = np.linalg.lstsq(design, torque, rcond=None)
        gains.append(coef[0])
        std.append(linear_std(design, torque - design @ coef, 1)[0])
    k = np.array(gains)
    weights = inverse_variance_weights(k, np.array(std))
    design = np.column_stack([np.ones(k.size), np.arange(k.size)])
    (_, slope), covariance, chi2 = weighted_least_squares(design, k, weights)
    inflation = max(1.0, chi2 / max(k.size - 2, 1))
    mean = float(np.average(k, weights=weights))
    span = k.size - 1
    return Check(RUN_DRIFT, "campaign", f"{k.size} runs in order",
                 float(slope * span / mean),
                 float(np.sqrt(covariance[1, 1] * inflation) * span / abs(mean)), TREND_FLOOR,
                 "of k_b")


def _trend(relation: Relation, torque: np.ndarray, pressure: np.ndarray, variable: np.ndarray,
           unit: str) -> Check:
    """T = k_b P (1 + β (x − x̄)/(x_max − x_min)): β is the relative change of the gain over
    the range of x seen."""
    span = float(np.ptp(variable)) or 1.0
    centred = (variable - variable.mean()) / span
    design = np.column_stack([pressure, pressure * centred])
    coef, *_ = np.linalg.lstsq(design, torque, rcond=None)
    std = linear_std(design, torque - design @ coef, 2)
    gain = coef[0]
    return Check(relation, "campaign", f"{variable.min():.3g}–{variable.max():.3g} {unit}",
                 float(coef[1] / gain), float(std[1] / abs(gain)), TREND_FLOOR, "of k_b")
