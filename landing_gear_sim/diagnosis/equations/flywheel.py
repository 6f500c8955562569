"""The flywheel: its momentum balance m_f·v̇ = −F_x − α_d·v² − F₀·sgn v − F₁·v − Σ c_k φ_k(v,
F_z) (the plant's resistance :func:`~landing_gear_sim.model.elements.flywheel_resistance`; read
from measured signals by :mod:`~landing_gear_sim.calibration.flywheel`).

Everything the diagnosis knows about the flywheel: its relation (slowed by F_x and the drag
alone), its library of terms (its bearings' friction, eddy currents), and whether the
flywheel's balance reads a channel's term (:func:`flywheel_reads`).

Whether the flywheel feels what the F_x channel reads: a channel's error shows wherever
the channel is read, the flywheel's balance included; a torque on the wheel does not reach
it (the tyre pushes it, the flywheel feels the true F_x). The F_x channel's families ask it
before they name the channel.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration import flywheel as fly
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.slots import Slot, seen
from landing_gear_sim.diagnosis.equations.equation import Declared, Equation
from landing_gear_sim.diagnosis.library import (
    BrakingLibrary,
    about_run_mean,
    thinned,
)
from landing_gear_sim.diagnosis.relations import Checking, Reads, Relation
from landing_gear_sim.diagnosis.selection import Rows, Term, basis_terms, ordinary_fit, term_columns
from landing_gear_sim.diagnosis.terms import Shaped
from landing_gear_sim.model import basis
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.run import Run

LAW = "m_f·v̇ = −F_x − α_d·v²"
"""The flywheel's law, as its words and its written terms read it."""

FLYWHEEL_TERMS = (Shaped((basis.SPEED,), (basis.SIGN, basis.IDENTITY, basis.CUBE))
                  + Shaped((basis.SPEED,), (basis.SIGN, basis.IDENTITY))
                  * Shaped((basis.LOAD,), (basis.IDENTITY,)))
"""The flywheel's library: its speed in the powers a bearing's friction, eddy currents or a
windage take, and the load the tyre presses on its bearings; α_d v² is the calibration's
own."""


class FlywheelLibrary(BrakingLibrary):
    """The flywheel's momentum balance m_f v̇ = −F_x − α_d v² − Σ c_k φ_k(v, F_z): its
    bearings' friction, eddy currents. Its error is measured integrated over the run,
    m_f v + ∫(F_x + α_d v²) dt about each run's mean, as the calibration measures the
    balance (the differentiated one carries m_f times the speed's noise: 2.7 kN rms)."""

    equation = Equation.FLYWHEEL
    relation = Relation.FLYWHEEL_BALANCE
    unit = "N"
    error_unit = "N s"
    slot = Slot.FLYWHEEL
    terms = basis_terms(FLYWHEEL_TERMS, "N")

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        index = thinned(b.speed_m_s > 1.0 + params.number(K.RIG_TEST_STOP_SPEED_M_S),
                         b.run.rate_hz)
        if index.size < 20:
            return None
        dt = np.diff(b.time_s, prepend=b.time_s[0])
        speed = b.speed_m_s
        balance = fly.momentum_balance(b, params)
        impulse = balance - el.translational_mass(params.vector()) * speed
        measured = seen(Slot.FLYWHEEL, br.measured_signals(b, params, np.zeros(speed.size)))
        everywhere = np.arange(speed.size)
        # a term opposes the motion: the balance's error is minus its impulse
        columns = -np.cumsum(term_columns(terms or self.terms, b, params, everywhere, measured)
                             * dt[:, None], axis=0)
        owned = [speed, np.cumsum(speed * speed * dt)]
        return about_run_mean(balance[index], columns[index],
                               np.column_stack(owned)[index], float(np.std(impulse[index])))

    def law(self, written: str, params: RigParameters) -> str:
        return f"{LAW} {written}"


FLYWHEEL = FlywheelLibrary()


def flywheel_carries(braking: Sequence[br.Braking], params: RigParameters,
                     values: Callable[[br.Braking], np.ndarray]) -> tuple[float, float]:
    """How much of ``values`` (a signal of a braking run) the measured F_x carries that the
    flywheel does not feel: its coefficient in the flywheel's balance error, and its t
    (0, 0: no run to tell). A channel's error shows wherever the channel is read; a torque
    on the wheel (a bearing's) does not reach the flywheel's balance."""
    # the reading's excess adds to the balance as a force that pushes the flywheel: the
    # library's terms oppose its motion
    carried = (Term[br.Braking]("", "", "", 0.0, lambda b, _: -values(b)),)
    rows = [r for b in braking if (r := FLYWHEEL.rows(b, params, carried)) is not None]
    if not rows:
        return 0.0, 0.0
    coef, t = ordinary_fit(np.vstack([np.hstack([r.terms, r.owned]) for r in rows]),
                           np.concatenate([r.error for r in rows]))
    return float(coef[0]), float(t[0])


def flywheel_reads(braking: Sequence[br.Braking], params: RigParameters,
                   values: Callable[[br.Braking], np.ndarray], coefficient: float) -> bool:
    """Whether the flywheel's balance carries ``coefficient`` of ``values`` as the F_x
    channel does (at least half of it, the same way): a channel's error, not a torque on the
    wheel."""
    carried, _ = flywheel_carries(braking, params, values)
    return carried * coefficient > 0 and abs(carried) >= abs(coefficient) / 2


def error(run: ClassifiedRun, b: br.Braking, params: RigParameters, simulated: Run
          ) -> np.ndarray:
    """The flywheel's error: its balance's m_f v̇ + F_x + F_r [N]."""
    return fly.balance_error(b, params)


DECLARED = Declared(f"{LAW} (flywheel)", "flywheel_speed_rad_s", (
    Checking((Relation.FLYWHEEL_BALANCE,), Reads.CAMPAIGN, FLYWHEEL.check),))
