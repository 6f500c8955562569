"""``run_drift``: the brake gain moving from one braking run to the next in the campaign's
run order (wear, a brake that beds in), in the wheel's equation (issue 14).

k_b,i = k_b (1 + d (i − ī)), i the braking run's place in file-name order: called for by
the relation "brake gain constant from run to run".
"""

from __future__ import annotations

from typing import ClassVar

from landing_gear_sim.diagnosis.catalogue import BRAKE_RUNS, FRICTION, WHEEL, Candidate
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
from msg_tools.units import display, signed

KEY = K.BRAKE_GAIN_DRIFT_PER_RUN
BOUNDS = (-0.2, 0.2)  # per run: a fifth of k_b from one run to the next at most


class RunDrift(Family):
    name = "run_drift"
    reports = "run_drift"
    words: ClassVar[dict[str, str]] = {
        "run_drift": "the brake changes from run to run (wear)"}
    equation = "wheel"
    keys = (KEY,)
    relations = (Relation.RUN_DRIFT,)
    rank = 6  # beside the gain's law: runs in rising pressure order make one read as the other
    hidden = (Hidden("run_drift", "run_drift", lambda rng, datasheet: {
        KEY: rng.choice([-1, 1]) * rng.uniform(0.015, 0.04)}, KEY, "gain_drift_per_run", 0.2),)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        """Started at the relation's first-to-last change spread over the braking runs,
        fitted with k_b and the friction curve; checked on half the braking runs."""
        broken = evidence.violated(Relation.RUN_DRIFT)
        if not broken:
            return []
        runs = sum(r.braking for r in evidence.runs)
        start = broken[0].deviation / max(runs - 1, 1)
        return [Proposal(term_candidate(self, self.keys, (start,), (BOUNDS,),
                                        (K.BRAKE_GAIN_N_M_PER_PA, *FRICTION), BRAKE_RUNS,
                                        WHEEL))]

    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        gain = display(params.number(K.BRAKE_GAIN_N_M_PER_PA), "N m/Pa")
        return (f"k_b,i = {gain}·(1 {signed(params.number(KEY), '1', '.2f')}·(i − ī)), "
                "i: braking run in run order")


FAMILY = RunDrift()
