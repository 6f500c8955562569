"""``wheel_angle`` in the wheel's equation: a brake torque that ripples once or twice per
wheel revolution (a disc's run-out or thickness variation; issue 28).

T_b = k_b P (1 + e₁ cos(θ + φ₁) + e₂ cos(2θ + φ₂)), θ the wheel's angle: called for by the
relation "brake torque smooth in the wheel's angle" while the free rolling holds (an
encoder's ripple makes ω̇ ripple too: :mod:`.encoder_ripple` ranks first). An independent
rig's 5 % run-out once gave 'unexplained', a 7.8 Hz line.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

import numpy as np

from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.wheel_angle import BRAKE_RUNOUT_KEYS, brake_ripple
from landing_gear_sim.diagnosis.catalogue import BRAKE_RUNS, WHEEL, Candidate
from landing_gear_sim.diagnosis.equations.wheel import BRAKE_RUNOUT_FLOOR
from landing_gear_sim.diagnosis.families.base import (
    Evidence,
    Family,
    Hidden,
    Proposal,
    term_candidate,
)
from landing_gear_sim.diagnosis.families.encoder_ripple import waves
from landing_gear_sim.diagnosis.relations import Relation
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.units import display

BOUNDS = (0.0, 0.3)  # relative: a third of the torque at most


class DiscRunout(Family):
    name = "disc_runout"
    reports = "wheel_angle"
    words: ClassVar[dict[str, str]] = {
        "wheel_angle": "something turns with the wheel, once per revolution"}
    equation = "wheel"
    keys = BRAKE_RUNOUT_KEYS[::2]
    relations = (Relation.BRAKE_ANGLE,)
    rank = 3
    hidden = (Hidden("disc_runout", "wheel_angle", lambda rng, datasheet: {
        K.BRAKE_RUNOUT_1: rng.uniform(0.02, 0.08),
        K.BRAKE_RUNOUT_1_PHASE_RAD: rng.uniform(-np.pi, np.pi)},
        K.BRAKE_RUNOUT_1, "brake_runout_1", 0.1),)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        """The kept orders, each run at its own phase, fitted alone on the braking runs'
        wheel channels."""
        if not evidence.violated(Relation.BRAKE_ANGLE):
            return []
        orders = select_orders(evidence.runs, evidence.model)
        if not orders:
            return []
        return [Proposal(term_candidate(
            self, tuple(orders), tuple(orders.values()), [BOUNDS] * len(orders), (),
            BRAKE_RUNS, WHEEL, names=[f"brake_{k.split('.')[1]}" for k in orders]))]

    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        gain = display(params.number(K.BRAKE_GAIN_N_M_PER_PA), "N m/Pa")
        return (f"T_b = {gain}·P·(1 + {waves(candidate, params, BRAKE_RUNOUT_KEYS)}), "
                "θ: wheel angle, φ: each run's own")


def select_orders(runs: Sequence[ClassifiedRun], params: RigParameters) -> dict[str, float]:
    """The orders of the brake torque's ripple with the wheel's angle that the braking runs
    need, with the median amplitude over the runs (``brake.runout_m`` -> relative
    amplitude), kept above the consistency floor."""
    ripples = [r for r in (brake_ripple(run, params) for run in runs if run.braking)
               if r is not None]
    if not ripples:
        return {}
    amplitude = np.median([r.amplitude for r in ripples], axis=0)
    return {BRAKE_RUNOUT_KEYS[2 * i]: float(a) for i, a in enumerate(amplitude)
            if a > BRAKE_RUNOUT_FLOOR}


FAMILY = DiscRunout()
