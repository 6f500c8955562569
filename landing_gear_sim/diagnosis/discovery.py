"""Discovery of terms the catalogue lacks (issue 14, part 3, brake torque first).

When the brake-gain consistency checks are violated, the wheel's torque balance
r F_x − J_w ω̇ = k_b P (1 + Σ c_i x_i) is regressed on a library of physical terms x_i
with a sparse solver (scikit-learn's LARS lasso, its penalty chosen by BIC): the fewest terms
that explain the gain's variation are kept. Each kept term fills the plant's slot for it
(the brake gain's slopes), and the extension is scored exactly like a catalogue candidate:
fitted with k_b and the friction curve it distorted, ΔBIC against the same re-fit without
it, and the gain on held-out runs. A term that passes is reported as ``discovered`` with its
family and its formula, never under a catalogue name.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.diagnosis.catalogue import BRAKE_RUNS, FRICTION, WHEEL, Candidate
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.units import PA_PER_BAR

DISCOVERED = "discovered"
DECIMATE = 100  # samples: the balance's residual is smooth; BIC must not count it 100x
MIN_RELATIVE_EFFECT = 0.02  # a term changing the gain by less over its range is dropped


@dataclass(frozen=True)
class LibraryTerm:
    """A physical term the brake gain may depend on, and the plant slot that holds it."""

    family: str
    key: str
    symbol: str
    bound: float  # |coefficient| admissible [1/unit of x]
    values: Callable[[br.Braking], np.ndarray]


BRAKE_LIBRARY = (
    LibraryTerm("sliding_speed", "brake.gain_slope_wheel_speed_s_per_rad", "ω", 1 / 200.0,
                lambda b: b.wheel),
    LibraryTerm("pressure_level", "brake.gain_slope_pressure_per_pa", "P", 1 / 60e5,
                lambda b: b.pressure),
)


def select_brake_terms(runs: Sequence[br.Braking], params: RigParameters
                       ) -> dict[LibraryTerm, float]:
    """Terms of BRAKE_LIBRARY the torque balance of ``runs`` needs, with their coefficient
    (the sparse fit's, a start for the output-error fit)."""
    ratio, columns = [], []
    for b in runs:
        torque, _ = br.torque_balance(b, params)
        m = np.flatnonzero(br.steady_braking_samples(b))[::DECIMATE]
        ratio.append(torque[m] / (params.number("brake.gain_n_m_per_pa") * b.pressure[m]))
        columns.append(np.column_stack([t.values(b)[m] for t in BRAKE_LIBRARY]))
    y, x = np.concatenate(ratio), np.vstack(columns)
    if y.size < 4 * len(BRAKE_LIBRARY):
        return {}
    spread = x.std(axis=0)
    # imported here: scikit-learn costs ~1 s to import and most diagnoses never get here
    from sklearn.linear_model import LassoLarsIC

    fit = LassoLarsIC(criterion="bic").fit((x - x.mean(axis=0)) / spread, y)
    coefficients = fit.coef_ / spread / np.mean(y)
    return {term: float(c) for term, c, span in zip(BRAKE_LIBRARY, coefficients, np.ptp(x, axis=0),
                                                     strict=True)
            if abs(c) * span > MIN_RELATIVE_EFFECT}


def discovered_candidate(terms: dict[LibraryTerm, float]) -> Candidate:
    """The kept terms as a candidate the scoring treats like a catalogue entry."""
    chosen = list(terms)
    return Candidate(DISCOVERED, None, tuple(t.key for t in chosen),
                     (tuple(terms[t] for t in chosen),),
                     tuple((-t.bound, t.bound) for t in chosen),
                     ("brake.gain_n_m_per_pa", *FRICTION), BRAKE_RUNS, WHEEL, (),
                     tuple((t.key.split(".")[1], t.key) for t in chosen))


def families(candidate: Candidate) -> str:
    return "+".join(t.family for t in BRAKE_LIBRARY if t.key in candidate.keys)


def term_formula(candidate: Candidate, params: RigParameters) -> str:
    """The extended law with its fitted values, e.g. ``T_b = k_b·P·(1 − 6.4e-04·ω)``."""
    parts = []
    for t in BRAKE_LIBRARY:
        if t.key in candidate.keys:
            value = params.number(t.key) * (PA_PER_BAR if t.symbol == "P" else 1.0)
            unit = "·P[bar]" if t.symbol == "P" else "·ω[rad/s]"
            parts.append(f"{'+' if value >= 0 else '−'} {abs(value):.3g}{unit}")
    gain = params.number("brake.gain_n_m_per_pa") * PA_PER_BAR
    return f"T_b = {gain:.4g} N m/bar·P·(1 {' '.join(parts)})"
