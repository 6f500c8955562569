"""The flywheel's momentum balance m_f·v̇ = −F_x − F_r read from a braking run's measured
signals: what resists the flywheel (its drag and slots, the plant's own law), the balance
integrated from the run's start, and the fit of its inertia and drag (paper Section IV-D).
The calibration, the diagnosis's flywheel error, its library and the F_x channel's windows
read the balance here."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import scipy.linalg

from landing_gear_sim.calibration.braking import Braking
from landing_gear_sim.calibration.statistics import Estimate, linear_std, sample_weights
from landing_gear_sim.errors import IdentificationError
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import flywheel_resistance_at


def resistance(b: Braking, params: RigParameters, with_drag: bool = True) -> np.ndarray:
    """What resists the flywheel beside F_x at each sample of ``b`` [N]: its drag (unless
    ``with_drag`` is False) and its slots, at the measured speed and load."""
    return flywheel_resistance_at(params, b.speed_m_s, b.load, with_drag)


def momentum_balance(b: Braking, params: RigParameters) -> np.ndarray:
    """The balance from the run's start, m_f v + ∫(F_x + F_r) dt, (n,) [N s]: constant where
    the model holds, whatever it misses integrated."""
    dt = np.diff(b.time_s, prepend=b.time_s[0])
    pushed = b.force + resistance(b, params)
    return el.translational_mass(params.vector()) * b.speed_m_s + np.cumsum(pushed * dt)


def balance_error(b: Braking, params: RigParameters) -> np.ndarray:
    """The balance's error m_f v̇ + F_x + F_r at each sample [N]: the integrated balance's
    rate (it carries m_f times the speed's derivative noise, 2.7 kN rms: a library reads the
    integrated one)."""
    return np.gradient(momentum_balance(b, params), b.time_s)


def fit_flywheel(runs: Sequence[Braking], p: RigParameters) -> list[Estimate]:
    """J_f and α_d from the integrated balance M Δv = −∫(F_x + F_slots) − α ∫v² (robust to
    noise).

    Each run gets its own intercept: anchoring a run to one noisy speed sample
    would shift all its rows and bias the drag.
    """
    blocks, targets = [], []
    for b in runs:
        idx = np.flatnonzero((b.time_s > 0.6) & (b.speed_m_s > 5.0))[::10]
        if idx.size < 20:
            continue
        dt = np.diff(b.time_s, prepend=b.time_s[0])
        # the flywheel's slots are known, like F_x (0 unless a diagnosis found a term)
        force = b.force + resistance(b, p, with_drag=False)
        blocks.append(np.column_stack([-np.cumsum(force * dt)[idx],
                                       -np.cumsum(b.speed_m_s ** 2 * dt)[idx]]))
        targets.append(b.speed_m_s[idx])
    if not blocks:
        raise IdentificationError("no braking run long enough for the flywheel balance")
    offsets = scipy.linalg.block_diag(*[np.ones((len(y), 1)) for y in targets])
    weight = sample_weights(targets)
    x = np.hstack([np.vstack(blocks), offsets]) * weight[:, None]
    y = np.concatenate(targets) * weight
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)
    std_inv, std_ratio = linear_std(x, y - x @ coef, x.shape[1])[:2]
    inv_mass, alpha_over_mass = coef[:2]
    mass = 1.0 / inv_mass
    radius = p.number(K.FLYWHEEL_RADIUS_M)
    names = tuple(b.run.name for b in runs)
    alpha = alpha_over_mass * mass
    std_alpha = abs(alpha) * math.hypot(std_ratio / alpha_over_mass, std_inv * mass)
    return [
        Estimate(K.FLYWHEEL_INERTIA_KG_M2, mass * radius ** 2,
                 mass ** 2 * std_inv * radius ** 2, names, "integrated momentum balance"),
        Estimate(K.DRAG_COEFF_N_S2_PER_M2, float(alpha), float(std_alpha), names,
                 "integrated momentum balance"),
    ]
