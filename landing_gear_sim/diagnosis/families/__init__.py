"""Families of terms the catalogue lacks, as plug-ins (issue 29): one module per family, an
ordered registry.

Each family (:class:`~.base.Family`) extends one equation of the rig's model — the valve,
the wheel's torque balance, a channel's measurement — by a term held in a slot of the model,
says which violated relations call for it, proposes candidates from what the campaign shows
and writes its law with the fitted values; it also says how to hide its effect in a
generated campaign, so that the tests and the benchmark parametrise over :data:`REGISTRY`.
The diagnosis tries them in this order (:func:`~..discovered.discovered`): the valve and the
channels first, since what they misread distorts every other relation, then the wheel's
equation; last the equations' generic slots (:mod:`.equation_terms`), for what no named
family holds. Adding a family: one module here (its words included: the report reads
them from the registry), its line below (and its import), its row in docs/diagnosis.md and
in docs/architecture.md's module table (both tested against the code); a slot the model lacks,
in the model too. :mod:`.valve_direction` was added that way.
"""

from __future__ import annotations

from landing_gear_sim.diagnosis.families import (
    channel_crosstalk,
    disc_runout,
    encoder_ripple,
    equation_terms,
    gain_law,
    input_history,
    load,
    pressure_skew,
    run_drift,
    valve_direction,
    valve_dynamics,
    wheel_skew,
)
from landing_gear_sim.diagnosis.families.base import (
    DISCOVERED,
    Evidence,
    Family,
    Hidden,
    Proposal,
)

REGISTRY: tuple[Family, ...] = tuple(sorted((
    input_history.FAMILY,
    pressure_skew.FAMILY,
    encoder_ripple.FAMILY,
    disc_runout.FAMILY,
    wheel_skew.FAMILY,
    channel_crosstalk.FAMILY,
    gain_law.FAMILY,
    run_drift.FAMILY,
    load.FAMILY,
    equation_terms.VALVE_FAMILY,
    valve_dynamics.FAMILY,
    valve_direction.FAMILY,
    equation_terms.WHEEL_FAMILY,
    equation_terms.TYRE_FAMILY,
    equation_terms.FX_CHANNEL_FAMILY,
    equation_terms.PRESSURE_CHANNEL_FAMILY,
    equation_terms.FLYWHEEL_FAMILY,
    equation_terms.LOADING_FAMILY,
), key=lambda f: f.rank))
"""Every family, in the order the diagnosis tries them (by rank; one rank: in this order)."""

HIDDEN: dict[str, tuple[Family, Hidden]] = {
    h.name: (f, h) for f in REGISTRY for h in f.hidden}
"""Every family's hidden effects by case name (tests, bench/detection.py)."""

EQUATIONS: dict[str, str] = {f.reports: f.equation for f in REGISTRY}
"""The equation each family's discovered findings extend, by the family they report."""

__all__ = ["DISCOVERED", "EQUATIONS", "HIDDEN", "REGISTRY", "Evidence", "Family", "Hidden",
           "Proposal"]
