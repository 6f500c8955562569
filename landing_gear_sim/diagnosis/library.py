"""An equation's library of terms, the base every equation's is written on (issues 29, 41).

A :class:`Library` is one equation of the rig: the runs that carry its error
(:meth:`Library.sources`), its error there beside its terms and the terms the calibration owns
(:meth:`Library.rows`, regression :class:`~.selection.Rows`), its law with terms written in,
and its relation, checked by selecting the terms the error needs (:mod:`~.selection`). The
equations themselves are in :mod:`~.equations`, one module each.
"""

from __future__ import annotations

import abc
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Generic, TypeVar

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.slots import Slot, seen
from landing_gear_sim.diagnosis.equations import Equation
from landing_gear_sim.diagnosis.relations import Check, Relation
from landing_gear_sim.diagnosis.selection import (
    MIN_EFFECT,
    Fitted,
    Rows,
    Selected,
    Term,
    fit_terms,
    floor_of,
    input_noise_of,
    significant,
    term_columns,
)
from landing_gear_sim.diagnosis.terms import BasisTerm, term_of, written_term
from landing_gear_sim.model.parameters import RigParameters

EDGE_S = 0.5  # the zero-phase filter's ends are left out

S = TypeVar("S")  # what a library reads one run's rows from: a braking run's signals, ...


@dataclass(frozen=True)
class Campaign:
    """What the libraries read: a campaign's runs, and its braking runs' filtered signals
    under the model (prepared once)."""

    runs: Sequence[ClassifiedRun]
    braking: Sequence[br.Braking]


class Library(abc.ABC, Generic[S]):
    """One equation's generic slot (see the module docstring): its ``terms``, the relation
    that says whether its error needs them, the unit of its law and its error, the runs it reads
    (``phase``, in words), and the sign its terms are written with in its law (−1: they
    oppose, as a bearing's friction)."""

    equation: Equation
    relation: Relation
    terms: tuple[Term[S], ...]
    unit: str
    phase: str
    error_unit: str = ""  # its error's, when not the law's (a balance integrated over time)
    sign: float = -1.0
    slot: Slot | None = None  # the generic slot its basis terms take places in
    min_effect: float = MIN_EFFECT  # of the equation's scale: below it a term does not matter

    @abc.abstractmethod
    def sources(self, campaign: Campaign, params: RigParameters) -> list[S]:
        """What each run that carries the equation's error gives to read it from."""

    @abc.abstractmethod
    def rows(self, source: S, params: RigParameters,
             terms: Sequence[Term[S]] | None = None) -> Rows | None:
        """The regression rows of one run on ``terms`` (default: the library's; None: the
        run has no samples to give)."""

    @abc.abstractmethod
    def law(self, written: str, params: RigParameters) -> str:
        """The equation with its slot's terms ``written`` out in it."""

    def written(self, params: RigParameters) -> str:
        """The terms its slot holds in ``params``, as its law writes them ('− 148 N m·[P >
        0.5 bar]'); '' when it holds none."""
        return " ".join(written_term(self.sign * params.number(coeff), term, self.unit)
                        for _, coeff, term in self._held(params))

    def held_law(self, params: RigParameters) -> str | None:
        """Its law with the terms its slot holds in ``params`` (None: it holds none)."""
        return self.law(self.written(params), params) if self._held(params) else None

    def _held(self, params: RigParameters) -> list[tuple[str, str, BasisTerm]]:
        """The code key, coefficient key and basis function of each place its slot fills."""
        return [(code, coeff, term_of(round(params.number(code))))
                for code, coeff in (self.slot.keys if self.slot else ())
                if params.number(coeff) != 0.0]

    def select(self, campaign: Campaign, params: RigParameters) -> list[Selected]:
        """The library's terms the equation's error needs under ``params``."""
        return self._kept(campaign, params, *self._fit(campaign, params))

    def check(self, campaign: Campaign, params: RigParameters) -> Check | None:
        """The equation's relation over the campaign: what its terms explain jointly (None:
        no run to tell)."""
        return self._check(*self._fit(campaign, params))

    def _kept(self, campaign: Campaign, params: RigParameters, rows: list[Rows],
              fitted: Fitted | None) -> list[Selected]:
        """The fitted terms, when they matter jointly (none: they do not)."""
        return fitted.selected if fitted and significant(fitted, rows, self.min_effect) \
            else []

    def _check(self, rows: list[Rows], fitted: Fitted | None) -> Check | None:
        if fitted is None or not fitted.selected:
            return None
        named = ", ".join(s.term.name for s in fitted.selected)
        return Check(self.relation, "campaign", f"{self.phase}, {named}", fitted.effect,
                     fitted.effect / max(fitted.z, 1e-12), floor_of(rows, self.min_effect),
                     self.error_unit or self.unit, input_noise_of(rows))

    def _fit(self, campaign: Campaign, params: RigParameters
             ) -> tuple[list[Rows], Fitted | None]:
        """The error's rows over the campaign and the library fitted to them (None: no row)."""
        rows = self._rows(campaign, params)
        return rows, fit_terms(self.terms, rows) if rows else None

    def _rows(self, campaign: Campaign, params: RigParameters) -> list[Rows]:
        return [r for s in self.sources(campaign, params)
                if (r := self.rows(s, params)) is not None]


class BrakingLibrary(Library[br.Braking]):
    """A library read from the braking runs."""

    phase = "braking runs"

    def sources(self, campaign: Campaign, params: RigParameters) -> list[br.Braking]:
        return list(campaign.braking)


def thinned(mask: np.ndarray, rate_hz: float) -> np.ndarray:
    """The indices of ``mask`` away from the filter's ends, one per half period of its
    cut-off (the signals are low-passed there: closer samples carry no news)."""
    index = np.flatnonzero(mask)
    edge = round(EDGE_S * rate_hz)
    index = index[(index > edge) & (index < mask.size - edge)]
    return index[::max(1, round(rate_hz / (2 * br.FILTER_HZ)))]


def about_run_mean(error: np.ndarray, terms: np.ndarray, owned: np.ndarray, scale: float
                    ) -> Rows:
    """Rows about their run's mean (each run's own constant: a static load, a speed's
    start)."""
    return Rows(error - error.mean(), terms - terms.mean(axis=0), owned - owned.mean(axis=0),
                scale)


def torque_rows(b: br.Braking, params: RigParameters, index: np.ndarray, slot: Slot,
                terms: Sequence[Term[br.Braking]], factor: float = 1.0) -> Rows:
    """The wheel's torque balance less the model's brake torque at the samples ``index`` of
    ``b``, regressed on ``terms`` (times ``factor``) beside the model's torque (k_b's share);
    the equation's scale is the mean brake torque. The pressure is taken in step (a late
    channel's error is its own family's)."""
    b = br.in_step(b, params)
    torque, energy = br.torque_balance(b, params)
    model = br.model_torque(b, params, energy, index)
    measured = seen(slot, br.measured_signals(b, params, energy)[index])
    return Rows(torque[index] - model, factor * term_columns(terms, b, params, index, measured),
                model[:, None], float(np.mean(np.abs(model))))
