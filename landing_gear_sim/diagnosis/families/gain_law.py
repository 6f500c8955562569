"""``sliding_speed`` and ``pressure_level``: the brake gain's law in the wheel's equation,
terms of one library (issue 14).

When the brake-gain relations are violated, the wheel's torque balance
r F_x − J_w ω̇ = k_b P (1 + Σ c_i x_i) is regressed on the library of physical terms x_i
(the wheel speed, the pressure) by a sparse solver (scikit-learn's LARS lasso, its penalty
chosen by BIC): the fewest terms that explain the gain's variation are kept, each a family
of its own (several kept: their names joined by '+').
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.diagnosis.catalogue import BRAKE_RUNS, FRICTION, WHEEL, Candidate
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
from msg_tools.units import PA_PER_BAR, display, signed

MIN_RELATIVE_EFFECT = 0.02  # a term changing the gain by less over its range is dropped


LIBRARY: tuple[Term[br.Braking], ...] = (
    Term(K.BRAKE_GAIN_SLOPE_WHEEL_SPEED_S_PER_RAD, "ω", "s/rad", 1 / 200.0,
         lambda b, params: b.wheel),
    Term(K.BRAKE_GAIN_SLOPE_PRESSURE_PER_PA, "P", "1/Pa", 1 / 60e5,
         lambda b, params: b.pressure),
)
"""The brake gain's terms: k_b P (1 + Σ c_i x_i), each coefficient's SI unit and admissible
magnitude."""
NAMES = {LIBRARY[0].key: "sliding_speed", LIBRARY[1].key: "pressure_level"}
"""The family each term names."""
SHOWN = {LIBRARY[0].key: ("rad/s", 1.0), LIBRARY[1].key: ("bar", PA_PER_BAR)}
"""Each term's variable as the law shows it: its unit, and SI to that unit."""


class GainLaw(Family):
    name = "gain_law"
    reports = "sliding_speed"  # or pressure_level, or both: the kept terms name it
    words: ClassVar[dict[str, str]] = {
        "sliding_speed": "the tyre's friction changes with its sliding speed"}
    equation = "wheel"
    keys = tuple(t.key for t in LIBRARY)
    relations = (Relation.GAIN_IN_SPEED, Relation.GAIN_IN_PRESSURE)
    rank = 6
    hidden = (
        Hidden("sliding_speed", "sliding_speed", lambda rng, datasheet: {
            LIBRARY[0].key: rng.choice([-1, 1]) * rng.uniform(0.08, 0.25) / 190.0},
            LIBRARY[0].key, "gain_slope_wheel_speed_s_per_rad", 0.2),
        Hidden("pressure_level", "pressure_level", lambda rng, datasheet: {
            LIBRARY[1].key: rng.choice([-1, 1]) * rng.uniform(0.08, 0.25) / 50e5},
            LIBRARY[1].key, "gain_slope_pressure_per_pa", 0.2),
    )

    def propose(self, evidence: Evidence) -> list[Proposal]:
        """The kept terms, started at their sparse fit, fitted with k_b and the friction
        curve on the braking runs."""
        if not any(evidence.violated(r) for r in self.relations):
            return []
        terms = select_terms(evidence.braking, evidence.model)
        if not terms:
            return []
        return [Proposal(term_candidate(
            self, [t.key for t in terms], list(terms.values()),
            [(-t.bound, t.bound) for t in terms], (K.BRAKE_GAIN_N_M_PER_PA, *FRICTION),
            BRAKE_RUNS, WHEEL, reports="+".join(NAMES[t.key] for t in terms)))]

    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        parts = []
        for t in LIBRARY:
            if t.key in candidate.keys:
                unit, per_si = SHOWN[t.key]
                value = params.number(t.key) * per_si
                parts.append(f"{signed(value)}·{t.symbol}[{unit}]")
        gain = display(params.number(K.BRAKE_GAIN_N_M_PER_PA), "N m/Pa")
        return f"T_b = {gain}·P·(1 {' '.join(parts)})"


def select_terms(runs: Sequence[br.Braking], params: RigParameters
                 ) -> dict[Term[br.Braking], float]:
    """Terms of LIBRARY the torque balance of ``runs`` needs, with their coefficient (the
    sparse fit's, a start for the output-error fit)."""
    ratio, columns = [], []
    for b in runs:
        torque, _ = br.torque_balance(b, params)
        m = np.flatnonzero(br.steady_braking_samples(b))[::DECIMATE]
        ratio.append(torque[m] / (params.number(K.BRAKE_GAIN_N_M_PER_PA) * b.pressure[m]))
        columns.append(np.column_stack([variable(t, b, params)[m] for t in LIBRARY]))
    y, x = np.concatenate(ratio), np.vstack(columns)
    if y.size < 4 * len(LIBRARY):
        return {}
    coefficients = sparse_coefficients(x, y) / np.mean(y)
    return {term: float(c) for term, c, span in zip(LIBRARY, coefficients, np.ptp(x, axis=0),
                                                     strict=True)
            if abs(c) * span > MIN_RELATIVE_EFFECT}


FAMILY = GainLaw()
