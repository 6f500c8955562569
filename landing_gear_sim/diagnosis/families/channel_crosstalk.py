"""``channel_crosstalk``: the load cell's F_x channel carrying another channel, in its
measurement equation (issue 14).

Called for by the relation "free rolling ⇒ F_x = J_w ω̇ / r": what the F_x channel reads
where the true F_x is known — before braking (the wheel's inertia force) and off the ground
(0) — is regressed on the channel library by a sparse solver (BIC). A channel kept must
show in the flywheel's momentum balance too, the F_x channel's rule for every term of it
(:func:`~..equations.fx_channel.flywheel_reads_term`): a bearing's torque on the wheel
breaks the free-rolling relation alike, and was once named a crosstalk.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.catalogue import BRAKE_RUNS, FRICTION, WHEEL, Candidate
from landing_gear_sim.diagnosis.equations.fx_channel import flywheel_reads_term
from landing_gear_sim.diagnosis.equations.load_cell import FORCE_FLOOR_N
from landing_gear_sim.diagnosis.families.base import (
    DECIMATE,
    Evidence,
    Family,
    Hidden,
    Proposal,
    term_candidate,
)
from landing_gear_sim.diagnosis.relations import Relation
from landing_gear_sim.diagnosis.selection import Term, variable
from landing_gear_sim.diagnosis.sparse import sparse_coefficients
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.units import signed

FRACTION_BOUND = 0.1  # of the other channel at most


LIBRARY: tuple[Term[ClassifiedRun], ...] = (
    Term(K.SENSORS_CROSSTALK_FX_PER_FZ, "F_z", "-", FRACTION_BOUND,
         lambda run, params: run.vertical_load_n),)
"""The other channels the F_x channel may carry, each as a fraction of it."""


class ChannelCrosstalk(Family):
    name = "channel_crosstalk"
    reports = "channel_crosstalk"
    words: ClassVar[dict[str, str]] = {
        "channel_crosstalk": "a load cell reads part of another force"}
    equation = "F_x channel"
    keys = tuple(t.key for t in LIBRARY)
    relations = (Relation.FREE_ROLLING,)
    rank = 5
    hidden = (Hidden("channel_crosstalk", "channel_crosstalk", lambda rng, datasheet: {
        K.SENSORS_CROSSTALK_FX_PER_FZ: rng.choice([-1, 1]) * rng.uniform(0.008, 0.03)},
        K.SENSORS_CROSSTALK_FX_PER_FZ, "crosstalk_fx_per_fz", 0.1),)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        """The kept channels, fitted with what a crosstalk distorts in the calibration (the
        brake gain of the torque balance, the friction curve of μ = F_x/F_z, the flywheel
        inertia and drag of its momentum balance: without the drag the fraction came out 9 %
        high)."""
        if not evidence.violated(Relation.FREE_ROLLING):
            return []
        terms = {term: fraction for term, fraction in select_terms(
            evidence.runs, evidence.braking, evidence.model).items()
            if flywheel_reads_term(evidence.braking, evidence.model, term, fraction)}
        if not terms:
            return []
        free = (K.BRAKE_GAIN_N_M_PER_PA, K.FLYWHEEL_INERTIA_KG_M2, K.DRAG_COEFF_N_S2_PER_M2,
                *FRICTION)
        return [Proposal(term_candidate(
            self, [t.key for t in terms], list(terms.values()),
            [(-FRACTION_BOUND, FRACTION_BOUND)] * len(terms), free, BRAKE_RUNS,
            (*WHEEL, "flywheel_speed_rad_s")))]

    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        kept = [t for t in LIBRARY if t.key in candidate.keys]
        return "F_x,read = F_x " + " ".join(
            f"{signed(v, spec='.4g')}·{t.symbol}"
            for t, v in ((t, params.number(t.key)) for t in kept))


def select_terms(runs: Sequence[ClassifiedRun], braking: Sequence[br.Braking],
                 params: RigParameters) -> dict[Term[ClassifiedRun], float]:
    """The channels the F_x channel carries, with their fractions, where the true F_x is
    known: before braking (``braking``: the braking runs prepared) and off the ground (the
    other ``runs``); sparse regression, BIC; kept when they move F_x by more than the
    consistency floor."""
    excess, columns = [], []
    for b in braking:
        mask, y = br.free_rolling_excess(b, params)
        excess.append(y[::DECIMATE])
        columns.append(_channels(b.run, mask, params))
    for run in runs:
        if not run.braking:
            excess.append(run.longitudinal_force_n[::DECIMATE])
            columns.append(_channels(run, np.ones(len(run), dtype=bool), params))
    y, x = np.concatenate(excess), np.vstack(columns)
    if y.size < 4 * len(LIBRARY):
        return {}
    fractions = sparse_coefficients(x, y)
    return {term: float(c) for term, c, top in zip(LIBRARY, fractions,
                                                   np.max(np.abs(x), axis=0), strict=True)
            if abs(c) * top > FORCE_FLOOR_N}


def _channels(run: ClassifiedRun, mask: np.ndarray, params: RigParameters) -> np.ndarray:
    """The library's channels of ``run`` at ``mask``, decimated, shape (m, k)."""
    return np.column_stack([variable(t, run, params)[mask] for t in LIBRARY])[::DECIMATE]


FAMILY = ChannelCrosstalk()
