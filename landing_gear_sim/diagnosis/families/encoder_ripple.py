"""``wheel_angle`` in the wheel channel's measurement: an encoder that ripples once or twice
per wheel revolution (run-out, an out-of-round or oval code wheel; issue 14).

The encoder reads ω (1 + e₁ cos(θ + φ₁) + e₂ cos(2θ + φ₂)): called for by the relation "wheel
channel smooth in the wheel's angle" (free rolling); the orders are picked by sparse
regression in the angle domain, each run at its own phase.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

import numpy as np
import scipy.linalg

from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.wheel_angle import ORDERS, TREND, ripple_design
from landing_gear_sim.diagnosis.catalogue import BRAKE_RUNS, Candidate
from landing_gear_sim.diagnosis.equations.wheel_channel import RUNOUT_FLOOR
from landing_gear_sim.diagnosis.families.base import (
    Evidence,
    Family,
    Hidden,
    Proposal,
    term_candidate,
)
from landing_gear_sim.diagnosis.relations import Relation
from landing_gear_sim.diagnosis.sparse import sparse_coefficients
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.sensors import RUNOUT_KEYS
from msg_tools.units import display

BOUNDS = (0.0, 0.1)  # relative: a tenth of ω at most
DECIMATE = 3  # samples: keeps a twice-per-revolution ripple at 60 m/s (62 Hz) resolved


def _hide(rng: np.random.Generator, datasheet: RigParameters) -> dict[str, float]:
    """A ripple once or twice per revolution (the generator gives each run a start angle
    of its own)."""
    key = f"sensors.wheel_runout_{rng.choice([1, 2])}"
    return {key: rng.uniform(0.002, 0.02), f"{key}_phase_rad": rng.uniform(-np.pi, np.pi)}


class EncoderRipple(Family):
    name = "encoder_ripple"
    reports = "wheel_angle"
    words: ClassVar[dict[str, str]] = {
        "wheel_angle": "something turns with the wheel, once per revolution"}
    equation = "wheel channel"
    keys = RUNOUT_KEYS[::2]
    relations = (Relation.WHEEL_ANGLE,)
    rank = 2
    hidden = (Hidden("wheel_angle", "wheel_angle", _hide, K.SENSORS_WHEEL_RUNOUT_1,
                     "wheel_runout_1", 0.1),)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        """The kept orders, fitted alone on the braking runs' wheel channel (the ripple
        averages out of everything the calibration fitted)."""
        if not evidence.violated(Relation.WHEEL_ANGLE):
            return []
        orders = select_orders(evidence.runs)
        if not orders:
            return []
        return [Proposal(term_candidate(self, tuple(orders), tuple(orders.values()),
                                        [BOUNDS] * len(orders), (), BRAKE_RUNS,
                                        ("wheel_speed_rad_s",)))]

    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        return f"ω_read = ω·(1 + {waves(candidate, params, RUNOUT_KEYS)}), θ: wheel angle, " \
            "φ: each run's own"


def select_orders(runs: Sequence[ClassifiedRun]) -> dict[str, float]:
    """The orders of the wheel channel's ripple with the wheel's angle that the free rolling
    of ``runs`` needs (sparse regression on cos(mθ), sin(mθ) of each run: a run has a phase
    of its own), with the median amplitude over the runs: ``sensors.wheel_runout_m`` ->
    relative amplitude, kept above the consistency floor."""
    fitted = [f for f in (ripple_design(r) for r in runs if r.braking) if f is not None]
    if not fitted:
        return {}
    detrended, columns = [], []
    for y, design in fitted:
        trend = design[:, :TREND]
        coef, *_ = np.linalg.lstsq(trend, y, rcond=None)
        detrended.append((y - trend @ coef)[::DECIMATE])
        columns.append(design[::DECIMATE, TREND:])
    coef = sparse_coefficients(scipy.linalg.block_diag(*columns), np.concatenate(detrended))
    pairs = coef.reshape(len(fitted), len(ORDERS), 2)
    amplitude = np.median(np.hypot(pairs[..., 0], pairs[..., 1]), axis=0)
    return {RUNOUT_KEYS[2 * i]: float(a) for i, a in enumerate(amplitude) if a > RUNOUT_FLOOR}


def waves(candidate: Candidate, params: RigParameters, keys: Sequence[str]) -> str:
    """The ripple's orders among ``keys`` (amplitude, phase, ...) that ``candidate`` fits."""
    return " + ".join(f"{display(params.number(k), '1', '.2f')}·cos({m}θ + φ{m})" for m, k in
                      zip(ORDERS, keys[::2], strict=True) if k in candidate.keys)


FAMILY = EncoderRipple()
