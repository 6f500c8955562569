"""``input_history``: a valve with play, in the valve's equation (issue 14).

The valve sees the current only once it has moved the backlash w the other way, so on the
way down it holds more pressure than on the way up, ≈ k1·w: called for by the relation
"valve the same with the current rising and falling" with more pressure on the way down.
"""

from __future__ import annotations

from typing import ClassVar

from landing_gear_sim.diagnosis.catalogue import (
    ACTUATOR_RUNS,
    BRAKE_RUNS,
    PRESSURE,
    STATIC_MAP,
    Candidate,
)
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
from msg_tools.units import display

KEY = K.ACTUATOR_BACKLASH_A
BOUNDS = (0.0, 0.2)  # A: a fifth of the valve's range


class InputHistory(Family):
    name = "input_history"
    reports = "input_history"
    words: ClassVar[dict[str, str]] = {
        "input_history": "the valve's pressure depends on its past (a hysteresis)"}
    equation = "valve"
    keys = (KEY,)
    relations = (Relation.VALVE_DIRECTION,)
    rank = 0  # the valve first: what it misreads reaches every run
    hidden = (Hidden("input_history", "input_history",
                     lambda rng, datasheet: {KEY: rng.uniform(0.004, 0.04)},
                     KEY, "backlash_a", 0.2),)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        """The play started at excess / k1, fitted with the static map (fitted across both
        directions, it averaged the play away) on the actuator runs, checked on the braking
        runs' pressure."""
        excess = [c.deviation for c in evidence.violated(Relation.VALVE_DIRECTION)]
        if not excess or max(excess) <= 0:
            return []
        k1 = evidence.model.number(K.ACTUATOR_MAP_K1_PA_PER_A)
        start = min(max(max(excess) / k1, 1e-3), BOUNDS[1])
        return [Proposal(term_candidate(self, self.keys, (start,), (BOUNDS,), STATIC_MAP,
                                        ACTUATOR_RUNS, PRESSURE, held_out=BRAKE_RUNS))]

    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        half = display(params.number(KEY) / 2, "A", ".1f")
        return f"P_static = map(i_v), i_v = play(i, ±{half})"


FAMILY = InputHistory()
