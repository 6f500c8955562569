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
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.statistics import (
    inverse_variance_weights,
    linear_std,
    weighted_least_squares,
)
from landing_gear_sim.calibration.wheel_angle import ORDERS, angle_ripple
from landing_gear_sim.diagnosis.findings import Finding
from landing_gear_sim.diagnosis.scoring import effective_count
from landing_gear_sim.model.actuator import actuator_pressure
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import rolling_radius_at
from landing_gear_sim.model.scenario import logged_to_held
from landing_gear_sim.model.sensors import SensorModel
from msg_tools.units import PA_PER_BAR

Z_VIOLATED = 6.0  # σ: with a dozen checks per campaign, no false alarm from noise
FORCE_FLOOR_N = 150.0  # a load-cell offset or crosstalk smaller than this does not matter
PRESSURE_FLOOR_PA = 0.2 * PA_PER_BAR
TREND_FLOOR = 0.05  # a brake gain changing by less than 5 % over the range does not matter
SETTLED_S = 0.3  # after a current change the valve has settled
MIN_SAMPLES = 200
MIN_RUNS_FOR_DRIFT = 3
FREE_ROLLING = "free rolling ⇒ F_x = J_w ω̇ / r"
GAIN_IN_SPEED = "brake gain constant in speed"
GAIN_IN_PRESSURE = "brake gain linear in pressure"
RUN_DRIFT = "brake gain constant from run to run"
VALVE_DIRECTION = "valve the same with the current rising and falling"
WHEEL_ANGLE = "wheel channel smooth in the wheel's angle"
RUNOUT_FLOOR = 1e-3  # a ripple below 0.1 % of the wheel speed is within the encoder's noise
SLOW_A_S = 0.5  # slower current changes: A(s) errors leave no direction-locked residual


@dataclass(frozen=True)
class Check:
    """One relation on one run (or the campaign) and phase: the deviation found, its 1-σ
    and the floor below which it does not matter, in ``unit``."""

    relation: str
    run: str
    phase: str
    deviation: float
    std: float
    floor: float
    unit: str

    @property
    def z(self) -> float:
        return abs(self.deviation) / self.std if self.std > 0 else math.inf

    @property
    def violated(self) -> bool:
        return self.z > Z_VIOLATED and abs(self.deviation) > self.floor

    def describe(self) -> str:
        return (f"{self.relation} ({self.run}, {self.phase}): {self.deviation:+.4g} {self.unit} "
                f"± {self.std:.2g} ({self.z:.0f}σ)" + ("  VIOLATED" if self.violated else ""))

    def to_json(self) -> dict[str, object]:
        return {"relation": self.relation, "run": self.run, "phase": self.phase,
                "deviation": self.deviation, "std": self.std, "floor": self.floor,
                "unit": self.unit, "violated": self.violated}


def check_campaign(runs: Sequence[ClassifiedRun], params: RigParameters) -> list[Check]:
    """Every check the runs allow, under ``params`` (radius law, wheel inertia, sensor
    offset of the calibrated model)."""
    prepared = [br.prepare(r, params) if r.braking else None for r in runs]
    checks = [c for run, b in zip(runs, prepared, strict=True)
              for c in _run_checks(run, b, params)]
    braking = [b for b in prepared if b is not None]
    if braking:
        checks.extend(_gain_trends(braking, params))
    return checks


def violations(checks: Sequence[Check]) -> list[Check]:
    """The violated checks, strongest first."""
    return sorted((c for c in checks if c.violated), key=lambda c: -c.z)


def inconsistent(broken: Sequence[Check]) -> Finding:
    """Violated relations as an ``unexplained`` finding (nothing in the model explains
    them): the strongest one's deviation, every one in the evidence."""
    best = broken[0]
    return Finding("unexplained", {"deviation": best.deviation}, {"deviation": best.std},
                   "measured relations the model cannot break are violated: "
                   + "; ".join(c.describe() for c in broken[:4])
                   + (f"; and {len(broken) - 4} more" if len(broken) > 4 else ""),
                   {}, {}, None, None, False, tuple(sorted({c.run for c in broken})), ())


def _run_checks(run: ClassifiedRun, prepared: br.Braking | None, params: RigParameters
                ) -> list[Check]:
    """The checks of one run (``prepared``: its filtered signals, for a braking run)."""
    checks = [_zero_current(run, params)]
    if prepared is not None:
        checks.extend([_free_rolling(prepared, params), _wheel_angle(run, params)])
    else:
        checks.extend(_mean_check("no contact ⇒ no load", run.name, "whole run",
                                  getattr(run, name), FORCE_FLOOR_N, "N", label)
                      for name, label in (("vertical_load_n", "F_z"),
                                          ("longitudinal_force_n", "F_x")))
        checks.append(_valve_direction(run, params))
    return [c for c in checks if c is not None]


def _valve_direction(run: ClassifiedRun, params: RigParameters) -> Check | None:
    """Measured minus model pressure where the current fell last, against where it rose
    last (only where it has changed slowly for SETTLED_S and the valve is between its
    dead-band and saturation): a static map cannot tell the two apart, a valve with play
    can. Positive: more pressure on the way down."""
    model = actuator_pressure(params, logged_to_held(run.current_a), run.rate_hz)
    residual = SensorModel.of(params).true_pressure(run.pressure_pa) - model
    change = np.diff(run.current_a, prepend=run.current_a[0])
    last = np.maximum.accumulate(np.where(change != 0.0, np.arange(change.size), 0))
    direction = np.sign(change[last])
    window = max(1, round(SETTLED_S * run.rate_hz))
    fast = np.abs(change) * run.rate_hz > SLOW_A_S
    slow = np.convolve(fast, np.ones(window), mode="full")[:fast.size] == 0
    band = (model > 2 * PRESSURE_FLOOR_PA) & (model < 0.9 * params.number(
        "actuator.max_pressure_pa"))
    falling, rising = (residual[slow & band & (direction == s)] for s in (-1.0, 1.0))
    if min(falling.size, rising.size) < MIN_SAMPLES:
        return None
    std = math.sqrt(sum(float(np.var(r)) / effective_count(r - r.mean())
                        for r in (falling, rising)))
    return Check(VALVE_DIRECTION, run.name, "slow current changes",
                 float(falling.mean() - rising.mean()), std, PRESSURE_FLOOR_PA, "Pa")


def _wheel_angle(run: ClassifiedRun, params: RigParameters) -> Check | None:
    """The wheel channel's strongest ripple with the wheel's angle in free rolling, beyond
    the model's own run-out of that order [relative to ω]."""
    ripple = angle_ripple(run)
    if ripple is None:
        return None
    runout = SensorModel.of(params).runout
    checks = [Check(WHEEL_ANGLE, run.name, f"before braking, {m}× per revolution",
                    ripple.amplitude[i] - runout[2 * i], ripple.std[i], RUNOUT_FLOOR, "of ω")
              for i, m in enumerate(ORDERS)]
    return max(checks, key=lambda c: c.z)


def _mean_check(relation: str, run: str, phase: str, values: np.ndarray, floor: float,
                unit: str, label: str = "") -> Check | None:
    if values.size < MIN_SAMPLES:
        return None
    mean = float(np.mean(values))
    std = float(np.std(values)) / math.sqrt(effective_count(values - mean))
    return Check(relation + (f": {label}" if label else ""), run, phase, mean, std, floor, unit)


def _zero_current(run: ClassifiedRun, params: RigParameters) -> Check | None:
    """Pressure where the current has been zero for SETTLED_S (before braking, between
    pulses): a valve that is shut holds no pressure (the model's sensor offset aside)."""
    off = run.current_a <= 0.0
    samples = max(1, round(SETTLED_S * run.rate_hz))
    settled = np.convolve(off, np.ones(samples), mode="full")[:off.size] >= samples
    pressure = SensorModel.of(params).true_pressure(run.pressure_pa[settled])
    return _mean_check("zero current ⇒ zero pressure", run.name, "current off", pressure,
                       PRESSURE_FLOOR_PA, "Pa")


def free_rolling_excess(b: br.Braking, params: RigParameters) -> tuple[np.ndarray, np.ndarray]:
    """The samples before the brake acts (mask), and the F_x there (the model's crosstalk
    taken off the reading) less the wheel's inertia force J_w ω̇ / r [N]: what the load cell
    reads beyond the physics."""
    m = br.free_rolling(b)
    radius = rolling_radius_at(params, b.load[m])
    inertia = params.number("wheel.inertia_kg_m2") * b.wheel_rate[m] / radius
    force = SensorModel.of(params).true_longitudinal(b.run.longitudinal_force_n[m],
                                                     b.run.vertical_load_n[m])
    return m, force - inertia


def _free_rolling(b: br.Braking, params: RigParameters) -> Check | None:
    _, excess = free_rolling_excess(b, params)
    return _mean_check(FREE_ROLLING, b.run.name, "before braking", excess, FORCE_FLOOR_N, "N")


def _gain_trends(runs: Sequence[br.Braking], params: RigParameters) -> list[Check]:
    """k_b of the torque balance with a linear trend in speed, and in pressure, over the
    braking runs: the relative change over the range seen [1]."""
    torque, pressure, speed = [], [], []
    drift = params.number("brake.gain_drift_per_run")
    for b in runs:
        whole, _ = br.torque_balance(b, params)
        m = br.steady_braking_samples(b)
        # relative to the model's own law: a gain slope or drift it has is no violation
        whole = whole / (1.0 + params.number("brake.gain_slope_wheel_speed_s_per_rad") * b.wheel
                         + params.number("brake.gain_slope_pressure_per_pa") * b.pressure)
        whole = whole / (1.0 + drift * b.run.campaign_order)
        torque.append(whole[m][::10])
        pressure.append(b.pressure[m][::10])
        speed.append(b.speed_m_s[m][::10])
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


def _trend(relation: str, torque: np.ndarray, pressure: np.ndarray, variable: np.ndarray,
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
