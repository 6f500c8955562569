"""``valve`` dynamics: a term in A(s)'s generic slot (issue 41) — a valve stiffer at
pressure, a spool's friction, a release unlike the apply.

Called for by "valve follows A(s) between its levels" (:mod:`~..equations.valve`), fitted
with ω_n, ζ and the static map on the actuator runs, held out on the braking runs'
pressure: a law of the valve must predict the pressure the brake was given.
"""

from __future__ import annotations

from landing_gear_sim.diagnosis.catalogue import (
    ACTUATOR,
    ACTUATOR_RUNS,
    BRAKE_RUNS,
    PRESSURE,
    STATIC_MAP,
)
from landing_gear_sim.diagnosis.equations.valve import VALVE_DYNAMICS
from landing_gear_sim.diagnosis.families.base import Hidden
from landing_gear_sim.diagnosis.families.equation_terms import TOLERANCE, EquationTerms
from landing_gear_sim.diagnosis.relations import Relation
from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K

STIFFENING = basis.product_code(basis.factor_code(basis.PRESSURE, basis.IDENTITY),
                                basis.factor_code(basis.VALVE_ERROR, basis.IDENTITY))


class ValveDynamicsTerms(EquationTerms):
    name = "valve_dynamics_equation"
    library = VALVE_DYNAMICS
    free = (*ACTUATOR, *STATIC_MAP[:3])
    channels = PRESSURE
    runs = ACTUATOR_RUNS
    held_out = BRAKE_RUNS
    # a spool that sticks settles short of the map from either side, as a play would
    also_breaks = (Relation.VALVE_DIRECTION,)
    # a valve whose stiffness rises with the pressure, ω_n² (1 + c P): 1.4-1.8 times as
    # stiff at 20 bar, 1.8-2.6 times at 40 (seen where A(s) is: the steps and the sweep)
    hidden = (Hidden("valve_stiffens", "valve", lambda rng, datasheet: {
        K.VALVE_TERMS[0][0]: float(STIFFENING),
        K.VALVE_TERMS[0][1]: rng.uniform(2e-7, 4e-7)}, K.VALVE_TERMS[0][1], "P·ΔP",
        TOLERANCE),)


FAMILY = ValveDynamicsTerms()
