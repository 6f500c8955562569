"""``wheel``, ``flywheel`` and ``loading device``: terms no named family holds, in the rig's
own equations (issue 29).

Each family is one equation's generic slot (:mod:`~..equations`): called for by the
equation's relation (its error needs a term of its library), it proposes the terms the
error's sparse regression keeps, started at their fit, fitted with the parameters the
calibration owns in the equation, and scored like any candidate. The finding is
``discovered`` with the equation as its family and the extended law written out, e.g.
``J_w·ω̇ = r·F_x − T_b − 62 N m``. They come after every named family (:data:`RANK`): what
is left when none of those is called for or accepted.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, ClassVar

import numpy as np

from landing_gear_sim.calibration.runs import RunKind, Selector
from landing_gear_sim.diagnosis.catalogue import (
    BRAKE_RUNS,
    FRICTION,
    PRESSURE,
    STATIC_MAP,
    WHEEL,
    Candidate,
)
from landing_gear_sim.diagnosis.equations import registry as eq
from landing_gear_sim.diagnosis.families.base import (
    Evidence,
    Family,
    Hidden,
    Proposal,
    term_candidate,
)
from landing_gear_sim.diagnosis.relations import Relation
from landing_gear_sim.diagnosis.selection import Selected
from landing_gear_sim.model import basis
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
        # a named family over an equation's slot reports its own name (a valve whose
        # release differs from its apply), a generic one its equation's
        cls.equation = str(cls.library.equation)
        cls.reports = cls.__dict__.get("reports", cls.equation)
        slot = cls.library.slot
        cls.keys = tuple(coeff for _, coeff in slot.keys) if slot else tuple(
            t.key for t in cls.library.terms)
        cls.relations = (cls.library.relation, *cls.also_breaks)

    @property
    def generic(self) -> bool:
        """Whether it is its equation's generic family (reported as the equation), not a
        named one over the same slot."""
        return self.reports == self.equation

    def propose(self, evidence: Evidence) -> list[Proposal]:
        """The kept terms, started at their fit, fitted with the parameters the calibration
        owns in the equation on the family's runs; a basis function takes a free place of
        the equation's generic slot."""
        if not evidence.violated(self.library.relation):
            return []
        chosen = self.library.select(evidence.campaign, evidence.model)
        return self._proposals(evidence, chosen)

    def _proposals(self, evidence: Evidence, chosen: list[Selected]) -> list[Proposal]:
        """A proposal of the terms ``chosen``, and one of each alternative the samples could
        not tell from them (:func:`_alternatives`)."""
        return [p for terms in _alternatives(chosen)
                if (p := self._proposal(evidence, terms)) is not None]

    def _proposal(self, evidence: Evidence, chosen: list[Selected]) -> Proposal | None:
        slot = self.library.slot
        if slot is None:
            keys, settings = [s.term.key for s in chosen], []
        else:
            places = [pair for pair in slot.keys if evidence.model.number(pair[1]) == 0.0]
            chosen = chosen[:len(places)]
            keys = [coeff for _, coeff in places[:len(chosen)]]
            settings = [(code, float(s.term.code or 0)) for (code, _), s in zip(
                places, chosen, strict=False)]
        if not chosen:
            return None
        bounds = [_bound(s) for s in chosen]
        return Proposal(term_candidate(
            self, keys, [float(np.clip(s.value, -0.9 * b, 0.9 * b)) for s, b in
                         zip(chosen, bounds, strict=True)],
            [(-b, b) for b in bounds], self.free, self.runs, self.channels,
            held_out=self.held_out, names=[s.term.name for s in chosen], settings=settings))

    def placed(self, params: RigParameters, name: str, value: float
               ) -> tuple[str, RigParameters]:
        """``params`` with the library's term ``name`` at ``value`` in the first place of
        the generic slot, and that place's coefficient key (how a finding holds it)."""
        slot = self.library.slot
        term = next(t for t in self.library.terms if t.name == name)
        if slot is None or term.code is None:
            raise ValueError(f"{self.name} has no generic slot for {name}")
        code, coeff = slot.keys[0]
        return coeff, params.replace({code: float(term.code), coeff: value}, name)

    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        if self.library.slot is None:
            sign = self.library.sign
            written = " ".join(f"{signed(sign * params.number(t.key), t.unit)}{t.symbol}"
                               for t in self.library.terms if t.key in candidate.keys)
        else:
            written = self.library.written(params)
        return self.library.law(written, params)


ALTERNATIVES = 1  # terms the samples could not tell apart, tried in its place (each costs a fit)


def _alternatives(chosen: list[Selected]) -> list[list[Selected]]:
    """``chosen``, and ``chosen`` with a term the regression's samples could not tell from
    one of them in its place (up to ALTERNATIVES): a fit of the runs tells them apart, and
    the search keeps the better (drag once applied, or while applied)."""
    found = [chosen]
    for i, selected in enumerate(chosen):
        for alike in selected.alike:
            found.append([*chosen[:i], replace(selected, term=alike, alike=()), *chosen[i + 1:]])
    return found[:ALTERNATIVES + 1]


BOUND_FACTOR = 10.0  # a basis term's coefficient within this many times its first fit


def _bound(selected: Selected) -> float:
    """A term's admissible magnitude: its own, or BOUND_FACTOR times its first fit."""
    if np.isfinite(selected.term.bound):
        return selected.term.bound
    return BOUND_FACTOR * abs(selected.value)


def _hidden(name: str, library: eq.Library[Any], key: str, span: tuple[float, float],
            term: str = "") -> Hidden:
    """An effect in ``library``'s slot ``key``, drawn in ``span`` (its SI unit), found within
    TOLERANCE as the coefficient of ``term`` (a basis function's name; default the key's)."""
    return Hidden(name, str(library.equation), lambda rng, datasheet: {key: rng.uniform(*span)},
                  key, term or key.split(".")[1], TOLERANCE)


class WheelTerms(EquationTerms):
    name = "wheel_equation"
    library = eq.WHEEL
    # the tyre pushes a bearing's torque in free rolling; left violated by a brake gain law
    # fitted in its place (rank 6), it has this family tried (discovered.discovered)
    also_breaks = (Relation.FREE_ROLLING,)
    free = (K.BRAKE_GAIN_N_M_PER_PA, *FRICTION)
    channels = WHEEL
    # drawn in the wheel's named slot (T₀ sgn ω, T₁ ω), found in its generic one
    hidden = (_hidden("wheel_bearing", eq.WHEEL, K.WHEEL_EXTRA_TORQUE_N_M, (40.0, 120.0),
                      "sgn ω"),
              _hidden("wheel_seal", eq.WHEEL, K.WHEEL_EXTRA_TORQUE_N_M_S_PER_RAD, (0.3, 0.8),
                      "ω"))


class FlywheelTerms(EquationTerms):
    name = "flywheel_equation"
    library = eq.FLYWHEEL
    free = (K.FLYWHEEL_INERTIA_KG_M2, K.DRAG_COEFF_N_S2_PER_M2)
    channels = ("flywheel_speed_rad_s", "wheel_speed_rad_s")
    # drawn in the flywheel's named slot (F₀ sgn v), found in its generic one
    hidden = (_hidden("flywheel_bearing", eq.FLYWHEEL, K.FLYWHEEL_EXTRA_FORCE_N,
                      (150.0, 400.0), "sgn v"),)


class LoadingTerms(EquationTerms):
    name = "loading_equation"
    library = eq.LOADING
    free = (K.LOADING_LIFT_COEFF_N_S2_PER_M2,)
    channels = ("vertical_load_n",)
    hidden = (_hidden("load_sag", eq.LOADING, K.LOADING_EXTRA_LOAD_N_S_PER_M, (20.0, 60.0),
                      "v"),)


class TyreTerms(EquationTerms):
    """The tyre's slot, read on the friction curve's samples, or, when only the locked
    wheel's relation is violated, where the wheel locks (:class:`~..LockedTyreLibrary`):
    a grip changing with speed that the curve's slip noise hides there (the plan's 1561,
    μ_B²·v through a 64-count encoder, had been left unexplained)."""

    name = "tyre_equation"
    library = eq.TYRE
    also_breaks = (Relation.LOCKED_SLIDING,)
    free = FRICTION
    channels = WHEEL
    # a friction that falls with the sliding speed (the seed paper's ref. [8]), drawn in
    # the tyre's generic slot as μ_B·v: 12-24 % less at 60 m/s
    hidden = (Hidden("tyre_speed", "tyre", lambda rng, datasheet: {
        K.TYRE_TERMS[0][0]: float(basis.product_code(
            basis.factor_code(basis.CURVE, basis.IDENTITY),
            basis.factor_code(basis.SPEED, basis.IDENTITY))),
        K.TYRE_TERMS[0][1]: rng.uniform(-0.004, -0.002)}, K.TYRE_TERMS[0][1], "μ_B·v",
        TOLERANCE),)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        if evidence.violated(self.library.relation) or not evidence.violated(
                Relation.LOCKED_SLIDING):
            return super().propose(evidence)
        chosen = eq.LOCKED_TYRE.select(evidence.campaign, evidence.model)
        return self._proposals(evidence, chosen)


class ValveTerms(EquationTerms):
    name = "valve_equation"
    library = eq.VALVE
    free = STATIC_MAP
    channels = PRESSURE
    runs = (RunKind.ACTUATOR_RAMP,)  # where the map lives: A(s) pulled k3 31 % off once
    held_out = BRAKE_RUNS
    # drawn in the map's named term (k3 e³), found in its generic slot
    hidden = (_hidden("valve_map_bend", eq.VALVE, K.ACTUATOR_EXTRA_MAP_PA_PER_A3,
                      (-4e6, -1.5e6), "e³"),)


class FxChannelTerms(EquationTerms):
    """The load cell's F_x channel (rank 5, with the named crosstalk: the channels first,
    since what they misread distorts every other relation). Its library keeps only the
    terms the flywheel's momentum balance carries too."""

    name = "fx_channel_equation"
    library = eq.FX_CHANNEL
    rank = 5
    also_breaks = (Relation.FREE_ROLLING, Relation.NO_CONTACT)
    free = (K.BRAKE_GAIN_N_M_PER_PA, K.FLYWHEEL_INERTIA_KG_M2, K.DRAG_COEFF_N_S2_PER_M2,
            *FRICTION)
    channels = (*WHEEL, "flywheel_speed_rad_s")
    hidden = (Hidden("fx_drift", "F_x channel", lambda rng, datasheet: {
        K.FX_TERMS[0][0]: float(basis.factor_code(basis.RUN_TIME, basis.IDENTITY)),
        K.FX_TERMS[0][1]: rng.uniform(20.0, 60.0)}, K.FX_TERMS[0][1], "t", TOLERANCE),)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        if not any(evidence.violated(r) for r in self.relations):
            return []
        return self._proposals(evidence, self.library.select(evidence.campaign,
                                                             evidence.model))


class PressureChannelTerms(EquationTerms):
    """The pressure channel (rank 5, with the channels: what they misread distorts every
    other relation). A term it keeps must show in the valve's settled pressure too: the
    valve's runs read the same channel, while a torque on the wheel leaves the valve alone
    (a drift of 0.05 bar/s had been named a wheel term, the valve left unexplained)."""

    name = "pressure_channel_equation"
    library = eq.PRESSURE_CHANNEL
    rank = 5
    also_breaks = (Relation.WHEEL_BALANCE, Relation.VALVE_DIRECTION)
    free = (K.BRAKE_GAIN_N_M_PER_PA, *STATIC_MAP)
    channels = (*PRESSURE, *WHEEL)
    runs = (RunKind.ACTUATOR_RAMP, *BRAKE_RUNS)
    hidden = (Hidden("pressure_drift", "pressure channel", lambda rng, datasheet: {
        K.PRESSURE_TERMS[0][0]: float(basis.factor_code(basis.RUN_TIME, basis.IDENTITY)),
        K.PRESSURE_TERMS[0][1]: rng.uniform(3e3, 8e3)}, K.PRESSURE_TERMS[0][1], "t",
        TOLERANCE),)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        if not any(evidence.violated(r) for r in self.relations):
            return []
        chosen = self.library.select(evidence.campaign, evidence.model)  # the valve reads
        return self._proposals(evidence, chosen)


VALVE_FAMILY = ValveTerms()
WHEEL_FAMILY = WheelTerms()
FLYWHEEL_FAMILY = FlywheelTerms()
LOADING_FAMILY = LoadingTerms()
TYRE_FAMILY = TyreTerms()
FX_CHANNEL_FAMILY = FxChannelTerms()
PRESSURE_CHANNEL_FAMILY = PressureChannelTerms()
