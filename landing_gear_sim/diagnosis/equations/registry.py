"""The rig's equations, gathered: what each declares (:data:`DECLARED`, from its module: its
law, channel and relations with their checks), its libraries of terms in the order the
diagnosis reads them (:data:`LIBRARIES`), and what follows from them for a campaign or a
model (every relation's checks, the laws a model's slots hold). Adding an equation: its
module, and its line in :data:`MODULES`.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

from landing_gear_sim.calibration.braking import Braking
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.equations import (
    flywheel,
    fx_channel,
    load_cell,
    loading,
    pressure_channel,
    tyre,
    valve,
    wheel,
    wheel_channel,
)
from landing_gear_sim.diagnosis.equations.equation import Declared, Equation, ErrorOf
from landing_gear_sim.diagnosis.equations.flywheel import FLYWHEEL
from landing_gear_sim.diagnosis.equations.fx_channel import FX_CHANNEL
from landing_gear_sim.diagnosis.equations.loading import LOADING
from landing_gear_sim.diagnosis.equations.pressure_channel import PRESSURE_CHANNEL
from landing_gear_sim.diagnosis.equations.tyre import LOCKED_TYRE, TYRE
from landing_gear_sim.diagnosis.equations.valve import VALVE, VALVE_DYNAMICS
from landing_gear_sim.diagnosis.equations.wheel import WHEEL
from landing_gear_sim.diagnosis.library import Campaign, Library
from landing_gear_sim.diagnosis.relations import Check, Checking, Relation
from landing_gear_sim.model.parameters import RigParameters

MODULES: dict[Equation, ModuleType] = {
    Equation.VALVE: valve, Equation.WHEEL: wheel, Equation.TYRE: tyre,
    Equation.FLYWHEEL: flywheel, Equation.LOADING: loading, Equation.FX_CHANNEL: fx_channel,
    Equation.PRESSURE_CHANNEL: pressure_channel, Equation.WHEEL_CHANNEL: wheel_channel,
    Equation.LOAD_CELL: load_cell,
}
"""Each equation's module: the one line to add with an equation's module."""

DECLARED: dict[Equation, Declared] = {e: m.DECLARED for e, m in MODULES.items()}
"""Each equation's law, channel and relations, as its module declares them (a relation
checks the one equation that declares it)."""

ERRORS: dict[Equation, ErrorOf] = {e: m.error for e, m in MODULES.items()
                                   if hasattr(m, "error")}
"""The equations whose error a braking run's measured signals give at every sample (each its
module's ``error``), in the order :mod:`.placing` reads them."""


def declaring(relation: Relation) -> Equation:
    """The equation that declares ``relation`` (a violation of it lives there)."""
    return next(e for e, declared in DECLARED.items() if relation in declared.relations)


LIBRARIES: tuple[Library[Any], ...] = (VALVE, VALVE_DYNAMICS, WHEEL, TYRE, FLYWHEEL, LOADING,
                                       FX_CHANNEL, PRESSURE_CHANNEL)
"""Every equation's library that checks its relation, in the order they are read (the
tyre's locked library is not a check: its relation is the locked wheel's)."""

__all__ = [
    "DECLARED",
    "FLYWHEEL",
    "FX_CHANNEL",
    "LIBRARIES",
    "LOADING",
    "LOCKED_TYRE",
    "PRESSURE_CHANNEL",
    "TYRE",
    "VALVE",
    "VALVE_DYNAMICS",
    "WHEEL",
    "campaign_checks",
    "declaring",
    "held_laws",
    "run_checks",
]


CHECKS: tuple[Checking, ...] = tuple(c for d in DECLARED.values() for c in d.checks)
"""Every relation's check, as its equation declares it, in the equations' order."""


def run_checks(run: ClassifiedRun, braking: Braking | None, params: RigParameters
               ) -> list[Check]:
    """Every relation's checks of one run (``braking``: a braking run's filtered signals)."""
    return [c for checking in CHECKS for c in checking.on_run(run, braking, params)]


def campaign_checks(campaign: Campaign, params: RigParameters) -> list[Check]:
    """Every relation's checks of ``campaign`` as a whole (its braking runs together, its
    equations' libraries)."""
    return [c for checking in CHECKS for c in checking.on_campaign(campaign, params)]


def held_laws(params: RigParameters) -> list[str]:
    """Each equation whose generic slot ``params`` fills, with its law written out ('the
    wheel: J_w·ω̇ = r·F_x − T_b − 148 N m·[P > 0.5 bar]')."""
    return [f"the {library.equation}: {law}" for library in LIBRARIES
            if (law := library.held_law(params)) is not None]
