"""``load``: a tyre's friction changing with the vertical load beyond the radius law, in the
wheel's equation (issue 14).

μ = μ_B(λ) (1 − κ (F_z − F_ref)): called for by the relation "friction the same at every
load", which only stops at two static loads can check (``campaign --light-runs``).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from landing_gear_sim.diagnosis.catalogue import BRAKE_RUNS, FRICTION, WHEEL, Candidate
from landing_gear_sim.diagnosis.equations.wheel import LOAD_UNIT_N
from landing_gear_sim.diagnosis.families.base import (
    Evidence,
    Family,
    Hidden,
    Proposal,
    term_candidate,
)
from landing_gear_sim.diagnosis.relations import Relation
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import reference_load_n
from msg_tools.units import display, signed

KEY = K.FRICTION_LOAD_SENSITIVITY_PER_N


class Load(Family):
    name = "load"
    reports = "load"
    words: ClassVar[dict[str, str]] = {
        "load": "the tyre's friction changes with its load"}
    equation = "wheel"
    keys = (KEY,)
    relations = (Relation.FRICTION_IN_LOAD,)
    rank = 7
    hidden = (Hidden("load", "load", lambda rng, datasheet: {
        KEY: rng.choice([-1, 1]) * rng.uniform(0.06, 0.15) / 1e4},  # 6-15 % per 10 kN
        KEY, "load_sensitivity_per_n", 0.2, light=True),)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        """Started at the relation's −c / 10 kN, fitted with the friction curve (which the
        calibration bent to it) on the braking runs."""
        broken = evidence.violated(Relation.FRICTION_IN_LOAD)
        if not broken:
            return []
        bound = 0.5 / evidence.model.number(K.LOADING_STATIC_LOAD_N)  # μ halved at most
        start = float(np.clip(-broken[0].deviation / LOAD_UNIT_N, -0.9 * bound, 0.9 * bound))
        return [Proposal(term_candidate(self, self.keys, (start,), ((-bound, bound),),
                                        FRICTION, BRAKE_RUNS, WHEEL))]

    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        kappa = params.number(KEY)
        return (f"μ = μ_B(λ)·(1 {signed(-kappa, '1/N', '.3f')}·"
                f"(F_z − {display(reference_load_n(params), 'N', '.1f')}))")


FAMILY = Load()
