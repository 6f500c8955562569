"""A locked wheel's sliding friction (issue 41): a relation the tyre's law declares.

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

from collections.abc import Sequence

import numpy as np
from scipy.ndimage import maximum_filter1d

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.friction import tyre_carries
from landing_gear_sim.calibration.statistics import linear_std
from landing_gear_sim.diagnosis.relations import Check, Relation
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import tyre_friction_at

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
