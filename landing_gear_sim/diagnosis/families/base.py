"""What every family of discovered terms shares (issue 29): the evidence a family is shown,
what it proposes, how tests hide its effect, and the interface itself.

A family extends one equation of the rig's model (the valve, the wheel, a channel's
measurement) by a term the catalogue lacks, held in a slot of the model (its ``keys``). It
is called for by the relations it explains (:class:`~..consistency.Relation`), proposes
candidates from what the campaign shows (a relation's reading, a sparse regression on its
library of terms), and writes its law with the fitted values, evaluating it through the
model's own parameters. Each family also says how to hide its effect in a generated
campaign (:class:`Hidden`): the tests and the benchmark parametrise over the registry.
"""

from __future__ import annotations

import abc
import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.runs import ClassifiedRun, Selector
from landing_gear_sim.diagnosis.catalogue import Candidate
from landing_gear_sim.diagnosis.findings import Signature
from landing_gear_sim.diagnosis.library import Campaign
from landing_gear_sim.diagnosis.relations import Check, Relation, violations
from landing_gear_sim.model.parameters import RigParameters

DISCOVERED = "discovered"
DECIMATE = 100  # samples: a balance's residual is smooth; BIC must not count it 100x


@dataclass(frozen=True)
class Evidence:
    """What a family is shown: the campaign's runs, the model the search starts from, its
    relation checks and its residual signatures."""

    runs: Sequence[ClassifiedRun]
    model: RigParameters
    checks: Sequence[Check]
    signatures: Sequence[Signature]

    def violated(self, relation: Relation) -> list[Check]:
        """The violated checks of ``relation``, strongest first."""
        return [c for c in violations(self.checks) if c.relation == relation]

    @functools.cached_property
    def braking(self) -> list[br.Braking]:
        """The braking runs' filtered signals under the model (prepared once, when a
        family asks)."""
        return [br.prepare(r, self.model) for r in self.runs if r.braking]

    @property
    def campaign(self) -> Campaign:
        """The runs as the equations' libraries read them."""
        return Campaign(self.runs, self.braking)


@dataclass(frozen=True)
class Proposal:
    """A candidate a family proposes, and where its fit starts (None: the model searched
    from; a model calibrated again with the term when the calibration read it into other
    parameters)."""

    candidate: Candidate
    start: RigParameters | None = None


@dataclass(frozen=True)
class Hidden:
    """How a test or a benchmark hides one of the family's effects (case ``name``) in a
    campaign of the project's generator: ``draw`` the parameters (from an RNG and the
    datasheet); the diagnosis must answer ``discovered`` with ``family`` and carry ``slot``'s
    value as its contract parameter ``key`` within ``tolerance`` (relative unless
    ``absolute``); ``light``: the campaign needs the stops at a lighter static load."""

    name: str
    family: str
    draw: Callable[[np.random.Generator, RigParameters], dict[str, float]]
    slot: str
    key: str
    tolerance: float
    absolute: bool = False
    light: bool = False

    def slot_of(self, rig: RigParameters) -> str:
        """The slot that holds the value hidden in ``rig`` (of a ripple's two orders, the
        one drawn)."""
        return self.slot if self._first(rig) else self.slot.replace("_1", "_2")

    def key_of(self, rig: RigParameters) -> str:
        """The finding's contract parameter for the value hidden in ``rig``."""
        return self.key if self._first(rig) else self.key.replace("_1", "_2")

    def _first(self, rig: RigParameters) -> bool:
        return rig.number(self.slot) != 0.0 or "_1" not in self.slot


class Family(abc.ABC):
    """One family of terms the catalogue lacks (see the module docstring): ``name`` in the
    registry, ``reports`` the family a finding names (several mechanisms may share one:
    an encoder's ripple and a disc's run-out are both ``wheel_angle``). ``rank`` orders the
    registry: a family accepted at one rank ends the search, unless its model leaves a
    later family's relation violated; families of one rank are all scored and the better
    kept (a drift through runs in rising pressure order reads as a pressure law, and the
    reverse)."""

    name: ClassVar[str]
    reports: ClassVar[str]
    equation: ClassVar[str]
    keys: ClassVar[tuple[str, ...]]
    relations: ClassVar[tuple[Relation, ...]]
    hidden: ClassVar[tuple[Hidden, ...]]
    rank: ClassVar[int]
    words: ClassVar[dict[str, str]] = {}
    """Each family it reports, physically, as the verdict's sentence says it (none: an
    equation's own family, 'the <equation>'s law lacks a term the runs show')."""

    @abc.abstractmethod
    def propose(self, evidence: Evidence) -> list[Proposal]:
        """The candidates the evidence calls for (none when it does not)."""

    @abc.abstractmethod
    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        """The extended law with the values of ``params``."""

    def reason(self, evidence: Evidence) -> str:
        """What called for the family, in words: its violated relations (up to two)."""
        broken = [c for c in violations(evidence.checks) if c.relation in self.relations]
        return "; ".join(c.describe() for c in broken[:2])


def term_candidate(family: Family, keys: Sequence[str], start: Sequence[float],
                   bounds: Sequence[tuple[float, float]], free: Sequence[str],
                   runs: tuple[Selector, ...], channels: tuple[str, ...],
                   held_out: tuple[Selector, ...] = (), names: Sequence[str] | None = None,
                   reports: str = "", settings: Sequence[tuple[str, float]] = ()
                   ) -> Candidate:
    """A discovered candidate of ``family`` (reported as ``reports``, default the family's):
    its slot ``keys`` fitted from ``start`` within ``bounds`` with the model parameters
    ``free`` on ``runs``, checked on ``held_out`` (none: half the fitting runs), compared on
    ``channels``; contract ``names`` default to the keys' last part; ``settings``: set,
    not fitted, in every model it is fitted from (a slot's basis codes)."""
    contract = tuple(zip(names or [k.split(".")[1] for k in keys], keys, strict=True))
    off = all(low <= 0.0 <= high for low, high in bounds)
    return Candidate(cause=DISCOVERED, element=None, keys=tuple(keys), starts=(tuple(start),),
                     bounds=tuple(bounds), free=tuple(free), runs=runs, channels=channels,
                     held_out=held_out, contract=contract, family=reports or family.reports,
                     neutral=(0.0,) * len(keys) if off else (), settings=tuple(settings))
