"""``wheel``, ``flywheel`` and ``loading device``: terms no named family holds, in the rig's
own equations (issue 29).

Each family is one equation's generic slot (:mod:`~..equation_library`): called for by the
equation's relation (its error needs a term of its library), it proposes the terms the
error's sparse regression keeps, started at their fit, fitted with the parameters the
calibration owns in the equation, and scored like any candidate. The finding is
``discovered`` with the equation as its family and the extended law written out, e.g.
``J_w·ω̇ = r·F_x − T_b − 62 N m``. They come after every named family (:data:`RANK`): what
is left when none of those is called for or accepted.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from landing_gear_sim.calibration.runs import RunKind, Selector
from landing_gear_sim.diagnosis import equation_library as eq
from landing_gear_sim.diagnosis.catalogue import (
    BRAKE_RUNS,
    FRICTION,
    PRESSURE,
    STATIC_MAP,
    WHEEL,
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
from msg_tools.units import signed

RANK = 8  # after every named family
TOLERANCE = 0.3  # relative, of a hidden effect's value


class EquationTerms(Family):
    """The generic slot of one equation's ``library``; ``free``: the parameters the
    calibration owns in it, fitted again with a term; ``channels``: those compared."""

    library: ClassVar[eq.Library[Any]]
    free: ClassVar[tuple[str, ...]]
    channels: ClassVar[tuple[str, ...]]
    runs: ClassVar[tuple[Selector, ...]] = BRAKE_RUNS
    held_out: ClassVar[tuple[Selector, ...]] = ()
    also_breaks: ClassVar[tuple[Relation, ...]] = ()  # other relations its terms violate
    rank = RANK

    def __init_subclass__(cls) -> None:
        cls.reports = cls.equation = str(cls.library.equation)
        cls.keys = tuple(t.key for t in cls.library.terms)
        cls.relations = (cls.library.relation, *cls.also_breaks)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        """The kept terms, started at their fit, fitted with the parameters the calibration
        owns in the equation on the family's runs."""
        if not evidence.violated(self.library.relation):
            return []
        chosen = self.library.select(evidence.campaign, evidence.model)
        if not chosen:
            return []
        return [Proposal(term_candidate(
            self, [s.term.key for s in chosen],
            [float(np.clip(s.value, -0.9 * s.term.bound, 0.9 * s.term.bound)) for s in chosen],
            [(-s.term.bound, s.term.bound) for s in chosen], self.free, self.runs,
            self.channels, held_out=self.held_out))]

    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        sign = self.library.sign
        written = " ".join(f"{signed(sign * params.number(t.key), t.unit)}{t.symbol}"
                           for t in self.library.terms if t.key in candidate.keys)
        return self.library.law(written, params)


def _hidden(name: str, library: eq.Library[Any], key: str, span: tuple[float, float]) -> Hidden:
    """An effect in ``library``'s slot ``key``, drawn in ``span`` (its SI unit), found within
    TOLERANCE."""
    return Hidden(name, str(library.equation), lambda rng, datasheet: {key: rng.uniform(*span)},
                  key, key.split(".")[1], TOLERANCE)


class WheelTerms(EquationTerms):
    name = "wheel_equation"
    library = eq.WHEEL
    # the tyre pushes a bearing's torque in free rolling; left violated by a brake gain law
    # fitted in its place (rank 6), it has this family tried (discovered.discover)
    also_breaks = (Relation.FREE_ROLLING,)
    free = (K.BRAKE_GAIN_N_M_PER_PA, *FRICTION)
    channels = WHEEL
    hidden = (_hidden("wheel_bearing", eq.WHEEL, K.WHEEL_EXTRA_TORQUE_N_M, (40.0, 120.0)),
              _hidden("wheel_seal", eq.WHEEL, K.WHEEL_EXTRA_TORQUE_N_M_S_PER_RAD, (0.3, 0.8)))


class FlywheelTerms(EquationTerms):
    name = "flywheel_equation"
    library = eq.FLYWHEEL
    free = (K.FLYWHEEL_INERTIA_KG_M2, K.DRAG_COEFF_N_S2_PER_M2)
    channels = ("flywheel_speed_rad_s", "wheel_speed_rad_s")
    hidden = (_hidden("flywheel_bearing", eq.FLYWHEEL, K.FLYWHEEL_EXTRA_FORCE_N,
                      (150.0, 400.0)),)


class LoadingTerms(EquationTerms):
    name = "loading_equation"
    library = eq.LOADING
    free = (K.LOADING_LIFT_COEFF_N_S2_PER_M2,)
    channels = ("vertical_load_n",)
    hidden = (_hidden("load_sag", eq.LOADING, K.LOADING_EXTRA_LOAD_N_S_PER_M, (20.0, 60.0)),)


class ValveTerms(EquationTerms):
    name = "valve_equation"
    library = eq.VALVE
    free = STATIC_MAP
    channels = PRESSURE
    runs = (RunKind.ACTUATOR_RAMP,)  # where the map lives: A(s) pulled k3 31 % off once
    held_out = BRAKE_RUNS
    hidden = (_hidden("valve_map_bend", eq.VALVE, K.ACTUATOR_EXTRA_MAP_PA_PER_A3,
                      (-4e6, -1.5e6)),)


VALVE_FAMILY = ValveTerms()
WHEEL_FAMILY = WheelTerms()
FLYWHEEL_FAMILY = FlywheelTerms()
LOADING_FAMILY = LoadingTerms()
