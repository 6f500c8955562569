"""The relation "friction the same at every load" (issue 14, the ``load`` family): μ = F_x/F_z
compared at the same slip on stops at two static loads."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.interpolate

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.friction import friction_indices, samples_at
from landing_gear_sim.calibration.measured import run_static_load_n
from landing_gear_sim.calibration.runs import RunKind
from landing_gear_sim.calibration.statistics import cluster_std
from landing_gear_sim.diagnosis.relations import MIN_SAMPLES, Check, Relation
from landing_gear_sim.model.parameters import RigParameters

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
