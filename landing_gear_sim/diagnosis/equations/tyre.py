"""The tyre: its force law F_x = F_z·(μ_B(λ)·g(F_z) + Σ c_k φ_k(λ, v, F_z)) (the plant's
:func:`~landing_gear_sim.model.elements.tyre_friction`).

Everything the diagnosis knows about the tyre: its relations — the tyre follows its friction
curve over the braking samples the calibration fits it on; a locked wheel slides at the
curve's μ(λ = 1) at every speed — and its library of terms, read on the curve's samples and,
where the wheel is locked, at slip 1 exactly.

While the wheel is locked its slip is 1 exactly, whatever the wheel channel's resolution or
noise, and μ = F_x/F_z is read from the load cell alone. The tyre's law gives the same
μ(λ = 1, v, F_z) the plant computes, at every speed: a friction that changes with speed
shows as a trend over the speeds the locked wheel slid at. The samples the friction curve
is fitted on cannot show it through a coarse encoder or a 200 Hz log (their slip's noise
sets the tyre's floor): a friction peak sharpening with speed, seen through a 64-count
encoder, read no differently there from a null logged alike, yet its locks slid with 15 %
less grip at 57 m/s than at 27 m/s (the plan's campaign 1561); six nulls of the project's
generator that lock, logged as six loggers, read under 0.06 %.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy.ndimage import maximum_filter1d

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration import friction
from landing_gear_sim.calibration.friction import tyre_carries
from landing_gear_sim.calibration.noise import channel_noise
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.slots import Slot, seen
from landing_gear_sim.calibration.statistics import linear_std
from landing_gear_sim.diagnosis.equations.equation import Declared, Equation
from landing_gear_sim.diagnosis.library import (
    BrakingLibrary,
    about_run_mean,
)
from landing_gear_sim.diagnosis.relations import Check, Checking, Reads, Relation
from landing_gear_sim.diagnosis.selection import (
    Rows,
    Term,
    basis_terms,
    ordinary_fit,
    term_columns,
)
from landing_gear_sim.diagnosis.terms import Shaped
from landing_gear_sim.model import basis
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import (
    curve_at,
    friction_coefficients,
    load_factor_at,
    tyre_friction_at,
)

LAW = "μ = μ_B(λ)·g(F_z)"
"""The tyre's law, as its words and its written terms read it."""

LOCKED_RAD_S = 0.5  # the wheel is locked below this (filtered, and raw all around)
AROUND_S = 0.1  # ... the raw channel reads no more than that within this window
NOISE_Z = 6.0  # ... or than this many times its own noise at the lock (an analogue channel)
SETTLED_S = 0.3  # after a lock begins, the gear's walk and the load's transfer settle
RATE_HZ = 100.0  # samples kept (the signals are low-passed at 20 Hz)
MIN_LOCKED_S = 0.5  # locked time over the campaign a trend is read from
MIN_SPAN_M_S = 5.0  # speeds the locked wheel slid at, at least
SLIDING_FLOOR = 0.02  # a sliding grip changing by less over those speeds does not matter
MIN_MU = 0.05  # the model's μ(λ = 1) a ratio is taken over


def locked_sliding(runs: Sequence[br.Braking], params: RigParameters) -> Check | None:
    """The locked wheel's μ over the model's μ(λ = 1), its relative change over the speeds
    it slid at (a trend within each run, beside a level of each run's own); None where the
    wheel never locks long enough, over too few speeds."""
    ratios, speeds, runs_of = [], [], []
    for i, b in enumerate(runs):
        m = locked_samples(b, params)
        model = tyre_friction_at(params, np.ones(m.size), b.speed_m_s[m], b.load[m])
        m, model = m[model > MIN_MU], model[model > MIN_MU]  # a curve that hardly grips there
        ratios.append(b.force[m] / (b.load[m] * model) - 1.0)
        speeds.append(b.speed_m_s[m])
        runs_of.append(np.full(m.size, i))
    ratio, speed, run = (np.concatenate(x) for x in (ratios, speeds, runs_of))
    span = float(np.ptp(speed)) if speed.size else 0.0
    if speed.size < MIN_LOCKED_S * RATE_HZ or span < MIN_SPAN_M_S:
        return None
    present = np.unique(run)
    levels = (run[:, None] == present[None, :]).astype(float)
    design = np.column_stack([levels, (speed - speed.mean()) / span])
    coef, *_ = np.linalg.lstsq(design, ratio, rcond=None)
    std = linear_std(design, ratio - design @ coef, design.shape[1])
    return Check(Relation.LOCKED_SLIDING, "campaign",
                 f"locked wheel, {speed.min():.3g}–{speed.max():.3g} m/s", float(coef[-1]),
                 float(std[-1]), SLIDING_FLOOR, "of μ")


def locked_samples(b: br.Braking, params: RigParameters) -> np.ndarray:
    """Indices of ``b`` where the wheel has been locked SETTLED_S, loaded, braked, above the
    stop speed; at RATE_HZ."""
    raw = np.abs(b.run.wheel_speed_rad_s)
    candidate = np.abs(b.wheel) < LOCKED_RAD_S
    noise = 1.4826 * float(np.median(raw[candidate])) if candidate.any() else 0.0
    around = maximum_filter1d(raw, size=max(3, int(AROUND_S * b.run.rate_hz)))
    locked = candidate & (around < max(LOCKED_RAD_S, NOISE_Z * noise)) & tyre_carries(b, params)
    index = np.flatnonzero(locked)
    if index.size == 0:
        return index
    began = np.maximum.accumulate(np.where(np.r_[True, np.diff(index) > 1],
                                           b.time_s[index], -np.inf))
    settled = index[b.time_s[index] > began + SETTLED_S]
    return settled[::max(1, round(b.run.rate_hz / RATE_HZ))]


TYRE_TERMS = (Shaped((basis.CURVE,), (basis.SQUARE, basis.CUBE))
              + Shaped((basis.CURVE,), (basis.IDENTITY,))
              * Shaped((basis.SPEED, basis.SLIP), (basis.IDENTITY, basis.SIGNED_ROOT)))
"""The tyre's library: the calibrated curve μ_B in the powers another curve's shape takes
(a magic formula's peak), and scaled by the speed (a friction that falls with the sliding
speed) or the slip (beyond the peak): every term bounded over the slips, 0 where the curve
is (at zero slip a rolling tyre pushes nothing: λ² once gave a locked wheel 0.8 more μ), and
of a finite slope there (the plant's step is sized by the curve's steepest slope). μ_B alone
and its ϑ are the calibration's own, the load the ``load`` family's (within a stop the load
follows the speed: terms in both read alike, and a clean campaign's slip noise filled
them)."""


class TyreLibrary(BrakingLibrary):
    """The tyre's force law F_x = F_z (μ_B(λ) g(F_z) + Σ c_k φ_k(λ, v, F_z)): a friction
    curve of another shape, a friction that changes with speed within a stop. Its error is
    μ = F_x / F_z less the model's over the braking samples the calibration fits its curve
    on; the curve's ϑ are owned (their derivatives: the curve may bend)."""

    equation = Equation.TYRE
    relation = Relation.TYRE_LAW
    unit = "-"
    slot = Slot.TYRE
    sign = 1.0
    terms = basis_terms(TYRE_TERMS, "-")

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        index = friction.friction_indices(b, params)
        if index.size < 20:
            return None
        slip, curve_mu = friction.samples_at(b, params, index)
        factor = load_factor_at(params, b.load[index])
        t1, t2, t3 = friction_coefficients(params)
        model = el.burckhardt_mu(t1, t2, t3, slip)
        measured = seen(Slot.TYRE, friction.tyre_signals(b, params, index))
        slope = t1 * t2 * np.exp(-t2 * slip) - t3
        return Rows((curve_mu - model) * factor,
                    term_columns(terms or self.terms, b, params, index, measured),
                    _curve_derivatives(params, slip, factor),
                    float(np.mean(np.abs(model * factor))),
                    float(np.sqrt(np.mean((slope * factor * _slip_noise(b, index)) ** 2))))

    def law(self, written: str, params: RigParameters) -> str:
        return f"{LAW} {written}"


class LockedTyreLibrary(TyreLibrary):
    """The tyre's law where the wheel is locked (:func:`locked_samples`): the slip is 1
    exactly there whatever the wheel channel reads, so a term in speed shows free of the
    slip's noise that floors the curve's samples (the plan's 1561 and 1544, unexplained in
    the tyre). Its rows are about each run's mean (its relation reads a trend within the
    runs, beside each run's level). Not a check of its own: its relation is the locked
    wheel's; it says which terms a violation of it needs."""

    relation = Relation.LOCKED_SLIDING
    phase = "locked wheel"

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        index = locked_samples(b, params)
        if index.size < 20:
            return None
        _, curve_mu = friction.samples_at(b, params, index)
        factor = load_factor_at(params, b.load[index])
        slip = np.ones(index.size)
        model = curve_at(params, slip, b.speed_m_s[index])
        signals = friction.tyre_signals(b, params, index)
        signals[:, basis.SLIP], signals[:, basis.CURVE] = slip, model
        return about_run_mean((curve_mu - model) * factor,
                              term_columns(terms or self.terms, b, params, index,
                                           seen(Slot.TYRE, signals)),
                              _curve_derivatives(params, slip, factor),
                              float(np.mean(np.abs(model * factor))))


def _curve_derivatives(params: RigParameters, slip: np.ndarray, factor: np.ndarray
                       ) -> np.ndarray:
    """The curve μ_B's derivatives in ϑ1, ϑ2, ϑ3 at ``slip``, times the load ``factor``: the
    terms the calibration owns in the tyre's law (it may bend the curve)."""
    t1, t2, _ = friction_coefficients(params)
    decay = np.exp(-t2 * slip)
    return np.column_stack([1.0 - decay, t1 * slip * decay, -slip]) * factor[:, None]


def _slip_noise(b: br.Braking, index: np.ndarray) -> np.ndarray:
    """The 1-σ of the slip at the samples ``index`` that the wheel channel's noise leaves
    through the calibration's low-pass: the channel's noise (:func:`channel_noise`) over the
    share of its band the filter passes, over the speed."""
    raw = channel_noise(b.run.wheel_speed_rad_s)
    filtered = raw * np.sqrt(min(1.0, 2.0 * br.FILTER_HZ / (b.run.rate_hz / 2.0)))
    return filtered / np.maximum(b.wheel[index], 1.0)


TYRE = TyreLibrary()


LOCKED_TYRE = LockedTyreLibrary()  # the tyre's slot read where the wheel locks; not a check


def _lag(b: br.Braking, params: RigParameters) -> np.ndarray:
    """−Ḟ_x / (v_h F_z): a relaxing tyre's force lags its steady one by σ/v_h
    (σ/v_h·Ḟ_x = F_z·μ − F_x), so the tyre's error, read with no relaxation, is σ times it."""
    hub = np.maximum(br.hub_speed(b, params), el.MIN_HUB_SPEED_M_S)
    return -np.gradient(b.force, b.time_s) / hub / np.maximum(b.load, 1.0)


RELAXATION = Term(K.TYRE_RELAXATION_LENGTH_M, "·lag", "m", math.inf, values=_lag)
"""The relaxation length σ as a term of the tyre's error (its variable −Ḟ_x / (v_h F_z))."""


def relaxation_read(runs: Sequence[ClassifiedRun], params: RigParameters
                    ) -> tuple[float, float] | None:
    """The relaxation length [m] the tyre's error over the curve's samples reads under
    ``params`` (a model whose tyre does not relax), and its t: that error regressed on the
    lag alone, beside the curve's derivatives (the calibration may bend it); None: no
    samples. An ordinary fit: one term needs no sparse solver (whose library, loaded here,
    the fits' processes forked after it had each carried: 50 MB more at their peak). The
    project's generator's 3, 8 and 20 cm read 2.8-3.0, 7.7-7.9 and 19.6-19.7 cm, at t
    2.4-21."""
    rows = [r for run in runs if run.braking
            and (r := TYRE.rows(br.prepare(run, params), params, [RELAXATION])) is not None]
    if not rows:
        return None
    coef, t = ordinary_fit(np.hstack([np.vstack([r.terms for r in rows]),
                                      np.vstack([r.owned for r in rows])]),
                           np.concatenate([r.error for r in rows]))
    return float(coef[0]), float(t[0])


DECLARED = Declared(f"{LAW} (tyre force)", "wheel_speed_rad_s", (
    Checking((Relation.TYRE_LAW,), Reads.CAMPAIGN, TYRE.check),
    Checking((Relation.LOCKED_SLIDING,), Reads.BRAKING_RUNS, locked_sliding)))
