"""The wheel: its torque balance J_w·ω̇ = r·F_x − T_b − T₀·sgn ω − T₁·ω − Σ c_k φ_k, with the
brake's torque T_b = k_b·P·(gain law) (the plant's :func:`~landing_gear_sim.model.plant.
derivatives`; read from measured signals by :func:`~landing_gear_sim.calibration.braking.
torque_balance`).

Everything the diagnosis knows about the wheel: its relations — the brake gain of the
balance constant in speed and linear in pressure (a local k_b with a linear trend), constant
from run to run (k_b of each run, in the campaign's run order: wear, a brake that beds in),
smooth in the wheel's angle (a disc's run-out), the friction the same at every load (where
runs at two static loads share slips: a tyre's load sensitivity beyond the radius law), the
wheel turned by the tyre and the brake alone — and its library of terms (a bearing's
friction, a released brake that drags, a seal, pads that drag once applied).

The relation "friction the same at every load" (issue 14, the ``load`` family): μ = F_x/F_z
compared at the same slip on stops at two static loads.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.interpolate

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.friction import friction_indices, samples_at
from landing_gear_sim.calibration.measured import run_static_load_n
from landing_gear_sim.calibration.runs import ClassifiedRun, RunKind
from landing_gear_sim.calibration.slots import Slot
from landing_gear_sim.calibration.statistics import (
    cluster_std,
    inverse_variance_weights,
    linear_std,
    weighted_least_squares,
)
from landing_gear_sim.calibration.wheel_angle import (
    BRAKE_RUNOUT_KEYS,
    ORDERS,
    brake_ripple,
)
from landing_gear_sim.diagnosis.equations.equation import Declared, Equation
from landing_gear_sim.diagnosis.library import (
    BrakingLibrary,
    thinned,
    torque_rows,
)
from landing_gear_sim.diagnosis.relations import (
    MIN_SAMPLES,
    Check,
    Checking,
    Reads,
    Relation,
)
from landing_gear_sim.diagnosis.selection import Rows, Term, basis_terms
from landing_gear_sim.diagnosis.terms import Shaped
from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.run import Run
from msg_tools.units import PA_PER_BAR

LAW = "J_w·ω̇ = r·F_x − T_b"
"""The wheel's law, as its words and its written terms read it."""

TREND_FLOOR = 0.05  # a brake gain changing by less than 5 % over the range does not matter
MIN_RUNS_FOR_DRIFT = 3
BRAKE_RUNOUT_FLOOR = 0.01  # a disc's ripple below 1 % of the torque does not matter
SLIP_KNOTS = 8  # inner knots of the free friction curve
MIN_SLIP = 0.008  # below, a few hub-speed errors (0.01 m/s at the 3 m/s stop speed: 0.003)
MAX_SLIP = 0.3  # beyond, a skidding wheel is on its way to lock, not on the steady curve
LOAD_SPREAD = 0.05  # static loads closer than 5 % cannot show a law in load
LOAD_UNIT_N = 1e4
LOAD_FLOOR = 0.03  # μ changing by less than 3 % per 10 kN does not matter


def friction_in_load(runs: Sequence[br.Braking], params: RigParameters) -> list[Check]:
    """μ = F_x/F_z (the model's load factor taken off) as a free curve in the measured slip
    (cubic B-spline) times (1 + c (F_z − F̄_z)), over the slips that runs at a light and at
    a heavy static load share: c, the relative change of μ per LOAD_UNIT_N of load.

    Within a stop the load follows the speed (F_z0 − k_L v²), so a law in load and one in
    speed read the same there, and where the light runs hold other slips than the heavy
    ones, the free curve and the law trade: so only shared slips count, and only with ≥ 2
    constant-pressure runs at each of two static loads LOAD_SPREAD apart. The curve is free,
    not the model's (a calibration bends its curve to a law in load); the σ counts each run
    once (cluster sandwich: what differs from run to run without a law in load is not
    load)."""
    per_run = [x for x in (_friction_run(b, params) for b in runs
                           if b.run.kind is RunKind.BRAKE_CONSTANT) if x is not None]
    shared = _shared_slips(per_run)
    if shared is None:
        return []
    statics = np.array([static for *_, static in shared])
    slip, mu, load = (np.concatenate([run[k] for run in shared]) for k in range(3))
    curve = _slip_basis(slip)
    shape, *_ = np.linalg.lstsq(curve, mu, rcond=None)
    design = np.column_stack([curve, (load - load.mean()) / LOAD_UNIT_N * (curve @ shape)])
    coef, *_ = np.linalg.lstsq(design, mu, rcond=None)
    std = cluster_std(design, mu - design @ coef, [run[0].size for run in shared])
    lo, hi = float(slip.min()), float(slip.max())
    return [Check(Relation.FRICTION_IN_LOAD, "campaign",
                  f"{len(shared)} constant-pressure runs at {statics.min() / 1e3:.3g}–"
                  f"{statics.max() / 1e3:.3g} kN static load, slip {lo:.3f}–{hi:.3f}",
                  float(coef[-1]), float(std[-1]), LOAD_FLOOR,
                  f"of μ per {LOAD_UNIT_N / 1e3:g} kN")]


Friction = tuple[np.ndarray, np.ndarray, np.ndarray, float]
"""One run's slip, μ and F_z [N] on the steady friction curve, and its static load [N]."""


def _shared_slips(per_run: Sequence[Friction]) -> list[Friction] | None:
    """The runs cut to the slips (5-95 % of each group) that the light and the heavy runs
    (static load below or above the middle of their range) share; None unless ≥ 2 runs of
    each keep enough samples there."""
    statics = np.array([static for *_, static in per_run])
    if len(per_run) < 4 or np.ptp(statics) < LOAD_SPREAD * statics.mean():
        return None
    light = list(statics < (statics.min() + statics.max()) / 2)
    slips = [np.concatenate([run[0] for run, lit in zip(per_run, light, strict=True)
                             if lit == group]) for group in (True, False)]
    lo = max(float(np.quantile(s, 0.05)) for s in slips)
    hi = min(float(np.quantile(s, 0.95)) for s in slips)
    kept, groups = [], []
    for (slip, mu, load, static), lit in zip(per_run, light, strict=True):
        inside = (slip >= lo) & (slip <= hi)
        if inside.sum() >= MIN_SAMPLES // 4:
            kept.append((slip[inside], mu[inside], load[inside], static))
            groups.append(lit)
    return kept if min(groups.count(True), groups.count(False)) >= 2 else None


def _friction_run(b: br.Braking, params: RigParameters) -> Friction | None:
    """One run's Friction on the steady curve (100 Hz, away from lock transients, where F_x
    is not yet the steady μ(λ) F_z); None when it has too few samples."""
    load = run_static_load_n(b.run, params)
    i = friction_indices(b, params)
    slip, mu = samples_at(b, params, i)
    keep = (np.abs(b.wheel_rate[i]) < br.STEADY_RATE_RAD_S2) & (slip > MIN_SLIP) & (
        slip < MAX_SLIP)
    if load is None or keep.sum() < MIN_SAMPLES // 4:
        return None
    return slip[keep], mu[keep], b.load[i][keep], load


def _slip_basis(slip: np.ndarray) -> np.ndarray:
    """Cubic B-spline columns in the slip, knots at its quantiles, (n, k)."""
    inner = np.quantile(slip, np.linspace(0.0, 1.0, SLIP_KNOTS + 2)[1:-1])
    low, high = float(slip.min()), float(slip.max())
    knots = np.concatenate([[low] * 4, inner, [high] * 4])
    return scipy.interpolate.BSpline.design_matrix(slip, knots, 3).toarray()


def gain_trends(runs: Sequence[br.Braking], params: RigParameters) -> list[Check]:
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
    checks = [_trend(Relation.GAIN_IN_SPEED, t, p, v, "m/s"),
              _trend(Relation.GAIN_IN_PRESSURE, t, p, p / PA_PER_BAR, "bar")]
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
    return Check(Relation.RUN_DRIFT, "campaign", f"{k.size} runs in order",
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


def brake_angle(prepared: br.Braking, params: RigParameters) -> Check | None:
    """The brake torque's strongest ripple with the wheel's angle while it brakes, beyond
    the model's own run-out of that order [relative to T_b]."""
    run = prepared.run
    ripple = brake_ripple(run, params, prepared)
    if ripple is None:
        return None
    model = [params.number(k) for k in BRAKE_RUNOUT_KEYS[::2]]
    checks = [Check(Relation.BRAKE_ANGLE, run.name, f"braking, {m}× per revolution",
                    ripple.amplitude[i] - model[i], ripple.std[i], BRAKE_RUNOUT_FLOOR, "of T_b")
              for i, m in enumerate(ORDERS)]
    return max(checks, key=lambda c: c.z)


WHEEL_TERMS = (
    Shaped((basis.OMEGA,), (basis.SIGN, basis.IDENTITY, basis.SIGNED_SQUARE, basis.SIGNED_ROOT))
    + Shaped((basis.SPEED, basis.LOAD, basis.SLIP),
             (basis.IDENTITY, basis.SIGNED_SQUARE, basis.SIGNED_ROOT))
    + Shaped((basis.PRESSURE,), (basis.STEP, basis.SIGNED_SQUARE, basis.SIGNED_ROOT))
    + Shaped((basis.BRAKE_ENERGY,), (basis.STEP, basis.IDENTITY, basis.SIGNED_ROOT))
    + Shaped((basis.OMEGA,), (basis.SIGN,)) * Shaped((basis.PRESSURE,), (basis.STEP,)))
"""The wheel's library: its speeds, load and slip in the shapes a bearing, a seal, a
windage or a tyre's rolling loss take; whether the brake is applied and has been; the
pressure beyond linear (k_b P is the calibration's own)."""


class WheelLibrary(BrakingLibrary):
    """The wheel's torque balance J_w ω̇ = r F_x − T_b − Σ c_k φ_k: a bearing's friction, a
    released brake that drags, a seal, pads that drag once applied. Its error is measured
    where the brake holds steadily and, with no brake at all, in the free rolling before
    it."""

    equation = Equation.WHEEL
    relation = Relation.WHEEL_BALANCE
    unit = "N m"
    slot = Slot.WHEEL
    terms = basis_terms(WHEEL_TERMS, "N m")

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        index = thinned(br.steady_braking_samples(b) | br.free_rolling(b), b.run.rate_hz)
        if index.size < 20:
            return None
        return torque_rows(b, params, index, Slot.WHEEL, terms or self.terms)

    def law(self, written: str, params: RigParameters) -> str:
        return f"{LAW} {written}"


WHEEL = WheelLibrary()


def error(run: ClassifiedRun, b: br.Braking, params: RigParameters, simulated: Run
          ) -> np.ndarray:
    """The wheel's error: the brake torque its balance measures less the model's [N m]."""
    torque, energy = br.torque_balance(b, params)
    return torque - br.model_torque(b, params, energy, np.arange(b.time_s.size))


DECLARED = Declared(f"{LAW} (wheel rotation)", "longitudinal_force_n", (
    Checking((Relation.GAIN_IN_SPEED, Relation.GAIN_IN_PRESSURE, Relation.RUN_DRIFT),
             Reads.BRAKING_RUNS, gain_trends),
    Checking((Relation.FRICTION_IN_LOAD,), Reads.BRAKING_RUNS, friction_in_load),
    Checking((Relation.BRAKE_ANGLE,), Reads.BRAKING_RUN, brake_angle),
    Checking((Relation.WHEEL_BALANCE,), Reads.CAMPAIGN, WHEEL.check)))
