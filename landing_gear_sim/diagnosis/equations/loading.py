"""The loading device: its set point F_z0 − k_L·v² − c·v − Σ c_k φ_k(v, t_c), t_c the time
since touch-down, followed through a first-order servo (the plant's :func:`~landing_gear_sim.
model.plant.loading_step`; what the set point loses: :func:`~landing_gear_sim.model.elements.
load_taken`).

Everything the diagnosis knows about the loading device: its relation (the vertical load
follows its law once settled) and its library of terms (a load that sags with speed beside
the lift law, a cylinder that leaks).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.slots import Slot, seen
from landing_gear_sim.diagnosis.equations.equation import Declared, Equation
from landing_gear_sim.diagnosis.library import (
    BrakingLibrary,
    about_run_mean,
    thinned,
)
from landing_gear_sim.diagnosis.relations import Checking, Reads, Relation
from landing_gear_sim.diagnosis.selection import Rows, Term, basis_terms, term_columns
from landing_gear_sim.diagnosis.terms import Shaped, Without
from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import (
    load_taken_at,
)
from msg_tools.run import Run
from msg_tools.units import display

SETTLE_S = 0.5  # after the touch-down ramp, before the loading device's load is its law
LOADING_TERMS = Without(
    Shaped((basis.SPEED, basis.CONTACT_TIME),
           (basis.IDENTITY, basis.SIGNED_SQUARE, basis.CUBE, basis.SIGNED_ROOT))
    + Shaped((basis.SPEED,), (basis.IDENTITY,)) * Shaped((basis.CONTACT_TIME,),
                                                          (basis.IDENTITY,)),
    frozenset({basis.factor_code(basis.SPEED, basis.SIGNED_SQUARE)}))
"""The loading device's library: the speed and the time since contact in powers (a
cylinder that leaks, a servo that sags, a lift law of another form); k_L v² is the
calibration's own."""


LAW = "F_z = F_z0 − {k_L}·v²"
"""The loading device's set point, the one text its declaration and its library write
(``k_L``: the symbol, or the value)."""


class LoadingLibrary(BrakingLibrary):
    """The loading device's set point F_z0 − k_L v² − Σ c_k φ_k(v, t_c): a load that sags
    with speed beside the lift law, a cylinder that leaks. Its error is measured once the
    load has settled, about each run's own static load."""

    equation = Equation.LOADING
    relation = Relation.LOADING_LAW
    unit = "N"
    slot = Slot.LOADING
    # a quarter per cent of the static load (80 N of 32 kN): a leak of 0.4 % at 54σ was
    # under the half per cent and came out `none`; the nulls' loading checks sit below 2σ,
    # a few newtons (a load cell's 100 N noise averages out over a stop)
    min_effect = 0.0025
    terms = basis_terms(LOADING_TERMS, "N")

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        loaded = b.load > br.LOADED_N
        if not loaded.any():
            return None
        touchdown = b.time_s[np.argmax(loaded)]
        settled = b.time_s > touchdown + params.number(K.LOADING_TOUCHDOWN_RAMP_S) + SETTLE_S
        index = thinned(settled & loaded, b.run.rate_hz)
        if index.size < 20:
            return None
        speed = b.speed_m_s[index]
        measured = seen(Slot.LOADING, br.measured_signals(b, params, np.zeros(b.time_s.size))
                        [index])
        taken = load_taken_at(params, b.time_s[index], speed)
        # the set point the servo was following: the load led by its lag (a set point that
        # falls with v² is followed τ late, 120 N at 60 m/s braking at 8 m/s²)
        tau = params.number(K.LOADING_SERVO_TIME_CONSTANT_S)
        setpoint = b.load + tau * np.gradient(b.load, b.time_s)
        return about_run_mean(setpoint[index] + taken,
                               -term_columns(terms or self.terms, b, params, index, measured),
                               (speed * speed)[:, None], float(np.mean(b.load[index])))

    def law(self, written: str, params: RigParameters) -> str:
        lift = display(params.number(K.LOADING_LIFT_COEFF_N_S2_PER_M2), "N s^2/m^2", ".3g")
        return f"{LAW.format(k_L=lift)} {written}"


LOADING = LoadingLibrary()


def error(run: ClassifiedRun, b: br.Braking, params: RigParameters, simulated: Run
          ) -> np.ndarray:
    """The loading device's output error: the measured vertical load less the model's [N]."""
    return run.vertical_load_n - simulated.vertical_load_n


DECLARED = Declared(f"{LAW.format(k_L='k_L')} (loading device)", "vertical_load_n", (
    Checking((Relation.LOADING_LAW,), Reads.CAMPAIGN, LOADING.check),))
