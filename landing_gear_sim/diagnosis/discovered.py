"""The discovered term a campaign calls for (issues 14, 28, 29), chosen and scored.

The relations a model violates and its residual signatures say where to look
(:mod:`~landing_gear_sim.diagnosis.consistency`, :mod:`~landing_gear_sim.diagnosis.signatures`);
the families of :mod:`~landing_gear_sim.diagnosis.families` say what to try, in the
registry's order; each candidate is scored exactly like a catalogue candidate. The story
(:class:`Story`) decides whether a discovered term replaces the catalogued causes, stands
beside them, or is not sought at all.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

from landing_gear_sim.calibration.identify import Progress
from landing_gear_sim.calibration.measured import (
    CHANNELS,
    Simulations,
    channels_of,
    simulate_all,
)
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.alike import PREDICTS_BETTER, rivals
from landing_gear_sim.diagnosis.consistency import check_campaign
from landing_gear_sim.diagnosis.families import REGISTRY, Evidence, Family, Proposal
from landing_gear_sim.diagnosis.families.wheel_skew import wheel_lags
from landing_gear_sim.diagnosis.findings import Signature
from landing_gear_sim.diagnosis.objective import Scales, scaled_error
from landing_gear_sim.diagnosis.relations import Check, violations
from landing_gear_sim.diagnosis.scoring import (
    HELD_OUT_THRESHOLD,
    Scored,
    log_ratio,
    score_candidate,
)
from landing_gear_sim.diagnosis.signatures import find_signatures
from landing_gear_sim.errors import IdentificationError
from landing_gear_sim.model.parameters import RigParameters


@dataclass(frozen=True)
class Discovery:
    """The discovered term (None: no family called for) and the accepted terms the
    campaign cannot tell from it (:mod:`~landing_gear_sim.diagnosis.alike`)."""

    scored: Scored | None
    rivals: tuple[Scored, ...] = ()


def discovered(runs: Sequence[ClassifiedRun], model: RigParameters, datasheet: RigParameters,
               scales: Scales, signatures: Sequence[Signature], checks: Sequence[Check],
               say: Progress) -> Discovery:
    """A discovered term, scored, for what ``checks`` and ``signatures`` (of ``model``)
    show (None when no family is called for), with the terms the campaign cannot tell from
    it: the families of REGISTRY by rank, until one rank accepts a term that leaves no later
    family's relation violated (the better is kept: :func:`_better`). A wheel bearing's
    torque once read as a brake gain falling with the pressure (rank 6, held out −45) and
    left free rolling violated; its own equation's term, at rank 8, was never tried."""
    evidence = Evidence(runs, model, checks, signatures)
    violated = _Violated(runs)
    best: tuple[Family, Scored] | None = None
    accepted: list[Scored] = []
    for _, members in itertools.groupby(REGISTRY, key=lambda f: f.rank):
        group = list(members)
        if best is not None and best[1].finding.accepted:
            left = {c.relation for c in violated(best[1])}
            group = [f for f in group if left & set(f.relations)]
        for family in group:
            for proposal in family.propose(evidence):
                scored = _score_discovered(family, proposal, runs, model, datasheet, scales,
                                           signatures, say)
                if scored is not None and scored.finding.accepted:
                    accepted.append(scored)
                if scored is not None and (best is None or _better(best[1], scored, violated)
                                           is scored):
                    best = (family, scored)
    if best is None:
        return Discovery(None)
    return Discovery(_called_for(*best, evidence), _rivals(best[1], accepted, violated))


def _rivals(best: Scored, accepted: Sequence[Scored],
            violated: Callable[[Scored], list[Check]]) -> tuple[Scored, ...]:
    """The accepted terms the campaign cannot tell from ``best``: gains alike, measured
    alike (:func:`_alike`), and as many relations left violated (fewer would have told
    them apart)."""
    if not best.finding.accepted:
        return ()
    return tuple(s for s in rivals(best, accepted)
                 if _alike(best, s) and len(violated(s)) == len(violated(best)))


def _called_for(family: Family, scored: Scored, evidence: Evidence) -> Scored:
    """The finding's evidence led by what called for its family."""
    reason = family.reason(evidence)
    if not reason:
        return scored
    finding = replace(scored.finding, evidence=f"called for by {reason}; "
                      + scored.finding.evidence)
    return Scored(finding, scored.fit)


def _better(first: Scored | None, second: Scored | None,
            violated: Callable[[Scored], list[Check]]) -> Scored | None:
    """The accepted one; of two accepted, the one that predicts the held-out runs more than
    PREDICTS_BETTER times better, else the one that leaves fewer relations violated, then
    the better predictor (a drift through a campaign in rising pressure order fits a
    pressure law nearly as well in sample: ΔBIC −94 against −115 once, held out −144
    against −101; a valve's play, held out +5093, once lost to a spool's friction, +136,
    that left one relation fewer violated); of two not accepted, the lower ΔBIC. Gains
    outweigh relations only when measured alike (:func:`_alike`)."""
    if first is None or second is None:
        return first or second
    both = first.finding.accepted and second.finding.accepted
    def gain(s: Scored) -> float:
        return -s.finding.held_out if s.finding.held_out is not None else -math.inf
    if both and _alike(first, second) and max(gain(first), gain(second)) > PREDICTS_BETTER * max(
            min(gain(first), gain(second)), 0.0):
        return max(first, second, key=gain)
    def rank(s: Scored) -> tuple[bool, int, float]:
        if not both:
            return not s.finding.accepted, 0, s.finding.delta_bic or 0.0
        return False, len(violated(s)), -gain(s)
    return min(first, second, key=rank)


def _alike(first: Scored, second: Scored) -> bool:
    """Whether two held-out gains were measured on the same runs and channels: a pressure
    transducer's drift, its channel's term gaining 1054 on the pressure of three runs, lost
    to a wheel term gaining 7074 on the wheel speed of three others, which left three
    relations violated against the channel's two."""
    return (set(first.finding.checked_on) == set(second.finding.checked_on)
            and set(first.fit.candidate.channels) == set(second.fit.candidate.channels))


def _violated_under(scored: Scored, runs: Sequence[ClassifiedRun]) -> list[Check]:
    """The checks the model ``scored`` fitted leaves violated."""
    return violations(check_campaign(runs, scored.fit.params))


class _Violated:
    """:func:`_violated_under` of each scored model, once (a check of the campaign prepares
    every run again: seconds; the search asks it of the best model at every rank and of both
    models it compares)."""

    def __init__(self, runs: Sequence[ClassifiedRun]) -> None:
        self._runs = runs
        self._seen: dict[int, tuple[Scored, list[Check]]] = {}  # the model kept: ids stay

    def __call__(self, scored: Scored) -> list[Check]:
        if id(scored) not in self._seen:
            self._seen[id(scored)] = (scored, _violated_under(scored, self._runs))
        return self._seen[id(scored)][1]


@dataclass(frozen=True)
class Extension:
    """What the story's extension scored (``tried``: the table's, and what an
    ``inconclusive`` verdict leaves open), the catalogued causes it keeps, the discovered
    term it accepted (None: none) and the terms the campaign cannot tell from that one."""

    tried: list[Scored]
    kept: list[Scored]
    scored: Scored | None
    rivals: tuple[Scored, ...] = ()


@dataclass(frozen=True)
class Story:
    """The campaign as the diagnosis reads it: its runs, the calibrated starting model with
    its residual ``signatures`` and relation ``checks``, what scoring needs, and the runs'
    ``simulations`` under the models the diagnosis reads them under."""

    runs: Sequence[ClassifiedRun]
    calibrated: RigParameters
    datasheet: RigParameters
    scales: Scales
    signatures: Sequence[Signature]
    checks: Sequence[Check]
    say: Progress
    simulations: Simulations

    def extend(self, accepted: list[Scored], model: RigParameters, checks: Sequence[Check]
               ) -> Extension | None:
        """A discovered term for what the catalogued causes ``accepted`` (extended model
        ``model``, its ``checks``) leave unexplained, or for everything when there are none.

        A cause accepted on held-out runs is replaced only by a term that explains what it
        explained and more on held-out runs (:func:`explains_more`): a fade the model had
        explained was once replaced by a law in speed that had won by ΔBIC on other
        channels. Otherwise the term is sought beside the causes, from their model. Nothing
        is sought when the causes leave no relation violated and no lag."""
        if not accepted:
            alone = self._discover(self.calibrated, self.checks, self.signatures)
            term = alone.scored
            return None if term is None else Extension(
                [term], [], term if term.finding.accepted else None, alone.rivals)
        signatures = find_signatures(self.runs, model, self.simulations.of(model),
                                     tentative=True)
        if not violations(checks) and not wheel_lags(signatures):
            return None
        tried = []
        alone = self._discover(self.calibrated, self.checks, self.signatures)
        rival = alone.scored
        if rival is not None:
            tried.append(rival)
            if explains_more(rival, accepted, model, self.runs, self.scales):
                self.say(f"a discovered term explains more than {_causes(accepted)}: "
                         f"{rival.finding.term}")
                return Extension(tried, [], rival, alone.rivals)
        found = self._discover(model, checks, signatures)
        beside = found.scored
        if beside is not None:
            tried.append(beside)
            if beside.finding.accepted:
                return self._beside(tried, accepted, found, alone)
        return Extension(tried, accepted, None)

    def _beside(self, tried: list[Scored], accepted: list[Scored], found: Discovery,
                alone: Discovery) -> Extension:
        """The discovered term ``beside`` the causes that still earn their place beside it:
        each cause with an element is scored again from the extended model with its element
        off. A tyre's relaxation once fitted what a loading device's law, wrong in speed,
        left in the wheel channels (held out −2072 from the calibrated model); beside the
        law it is not needed. When no cause is left, the term fitted alone (``alone``)."""
        beside, rival = found.scored, alone.scored
        if beside is None:
            return Extension(tried, accepted, None)
        earns = [self._earns(s, beside.fit.params) for s in accepted]
        if all(earns):
            return Extension(tried, accepted, beside, found.rivals)
        kept = [s for s, e in zip(accepted, earns, strict=True) if e]
        dropped = [s for s, e in zip(accepted, earns, strict=True) if not e]
        self.say(f"{_causes(dropped)} not needed beside {beside.finding.term}")
        if not kept and rival is not None and rival.finding.accepted:
            return Extension(tried, [], rival, alone.rivals)
        params = beside.fit.params.replace(
            {f"elements.{s.fit.candidate.element}": False for s in dropped},
            "causes not needed beside the discovered term")
        return Extension(tried, kept, Scored(beside.finding, replace(beside.fit, params=params)),
                         found.rivals)

    def _earns(self, cause: Scored, extended: RigParameters) -> bool:
        """Whether ``cause`` is still accepted when scored from ``extended`` without it."""
        candidate = cause.fit.candidate
        if candidate.element is None:
            return True
        base = extended.replace({f"elements.{candidate.element}": False},
                                f"without {candidate.cause}")
        try:
            again = score_candidate(candidate, self.runs, base, self.datasheet, self.scales,
                                    self.signatures)
        except IdentificationError:
            return True
        return again.finding.accepted

    def _discover(self, model: RigParameters, checks: Sequence[Check],
                  signatures: Sequence[Signature]) -> Discovery:
        return discovered(self.runs, model, self.datasheet, self.scales, signatures, checks,
                        self.say)


def _causes(accepted: Sequence[Scored]) -> str:
    return ", ".join(s.finding.cause for s in accepted)


GIVE_BACK = 0.1


def explains_more(rival: Scored, accepted: Sequence[Scored], model: RigParameters,
                  runs: Sequence[ClassifiedRun], scales: Scales) -> bool:
    """Whether the discovered ``rival``, accepted on its own, predicts the runs it was not
    fitted on better than the causes ``accepted`` (their model ``model``, re-calibrated on
    every run) on every channel either compares — none worse by more than the evidence
    threshold or GIVE_BACK of what the causes explained — and better in all by more than
    the threshold."""
    if not rival.finding.accepted:
        return False
    held = [r for r in runs if r.name in rival.finding.checked_on]
    compared = {c for s in (rival, *accepted) for c in s.fit.candidate.channels}
    channels = [c for c in CHANNELS if c in compared]
    if not held or not channels:
        return False
    with_rival, with_causes = simulate_all(held, rival.fit.params), simulate_all(held, model)
    changes = []
    for channel in channels:
        own = [i for i, r in enumerate(held) if channel in channels_of(r)]
        if own:
            runs_, a, b = ([x[i] for i in own] for x in (held, with_rival, with_causes))
            changes.append(log_ratio(scaled_error(runs_, a, (channel,), scales),
                                     scaled_error(runs_, b, (channel,), scales)))
    # what the causes explained: their gain on their own held-out runs; the rival may give
    # back a tenth of it on a channel (a 4.7 ms skew for a 5 ms one: +93 on the pressure,
    # −7546 in all), no more
    explained = sum(abs(s.finding.held_out or 0.0) for s in accepted)
    return bool(changes) and max(changes) < max(-HELD_OUT_THRESHOLD, GIVE_BACK * explained) \
        and sum(changes) < HELD_OUT_THRESHOLD


def _score_discovered(family: Family, proposal: Proposal, runs: Sequence[ClassifiedRun],
                      model: RigParameters, datasheet: RigParameters, scales: Scales,
                      signatures: Sequence[Signature], say: Progress) -> Scored | None:
    candidate = proposal.candidate
    say(f"fitting a discovered term: {candidate.family}")
    try:
        scored = score_candidate(candidate, runs, model, datasheet, scales, signatures,
                                 proposal.start)
    except IdentificationError:
        return None
    finding = replace(scored.finding, term=family.formula(candidate, scored.fit.params))
    return Scored(finding, scored.fit)
