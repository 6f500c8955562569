"""Explanations a campaign cannot tell apart (issue 64): the verdict names them together.

Two candidates scored from the same model explain the data alike when each met the
evidence (ΔBIC and the held-out gain past their thresholds) and neither explains it
:data:`PREDICTS_BETTER` times better than the other, by ΔBIC or held out: the factor past
which the search already calls one predictor better.
A difference of BIC is not odds between two models that both miss the rig's law a little:
it is n ln(RSS₁/RSS₂), and at a campaign's 10⁵ samples residuals 0.1 % apart in their sum
of squares differ by 100.

The search keeps the better of the two (by ΔBIC in the catalogue's rounds, by relations and
gain among discovered terms); its rival stands beside it in an :class:`Alike` group, with
the rig run that would tell them apart (:mod:`~landing_gear_sim.diagnosis.next_run`).
A rival accepted later in its own right is another cause, not a rival.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.catalogue import CATALOGUE
from landing_gear_sim.diagnosis.findings import Finding
from landing_gear_sim.diagnosis.next_run import Explanation, NextRun, next_run
from landing_gear_sim.diagnosis.rounds import Round
from landing_gear_sim.diagnosis.scoring import BIC_THRESHOLD, HELD_OUT_THRESHOLD, Scored

PREDICTS_BETTER = 2.0
"""A gain this many times another's tells two explanations apart: within it they are alike,
and past it the discovery keeps the better predictor whatever their relations say."""


def met_evidence(finding: Finding) -> bool:
    """Whether ``finding`` met the evidence on both counts: ΔBIC and a held-out gain."""
    return (finding.delta_bic is not None and finding.delta_bic < BIC_THRESHOLD
            and finding.held_out is not None and finding.held_out < HELD_OUT_THRESHOLD)


def _within(first: float, second: float) -> bool:
    """Two gains (negative: better) within :data:`PREDICTS_BETTER` of each other."""
    small, large = sorted((abs(first), abs(second)))
    return large <= PREDICTS_BETTER * small


def cannot_tell_apart(first: Finding, second: Finding) -> bool:
    """Whether two candidates scored from the same model explain the campaign alike."""
    return (met_evidence(first) and met_evidence(second)
            and _within(first.delta_bic or 0.0, second.delta_bic or 0.0)
            and _within(first.held_out or 0.0, second.held_out or 0.0))


def name_of(finding: Finding) -> str:
    """A candidate's name: its cause, and a discovered term's family."""
    return f"{finding.cause} {finding.family}" if finding.family else finding.cause


@dataclass(frozen=True)
class Alike:
    """Explanations the campaign cannot tell apart: the one the verdict names first, then
    its rivals (each as scored from the same model), and the run that would settle it."""

    members: tuple[Finding, ...]
    next_run: NextRun | None = None

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(name_of(f) for f in self.members)

    def to_json(self) -> dict[str, object]:
        return {"names": list(self.names), "members": [f.to_json() for f in self.members],
                "next_run": None if self.next_run is None else self.next_run.to_json()}


def rivals(best: Scored, scored: Sequence[Scored], accepted_later: Sequence[str] = ()
           ) -> list[Scored]:
    """The candidates of ``scored`` (from the model ``best`` was scored from) that explain
    the campaign as ``best`` does; not one whose cause was accepted in its own right
    (``accepted_later``, by :func:`name_of`)."""
    return [s for s in scored if s is not best
            and name_of(s.finding) not in (name_of(best.finding), *accepted_later)
            and cannot_tell_apart(best.finding, s.finding)]


def alike_groups(rounds: Sequence[Round], accepted: Sequence[Scored],
                 discovered_rivals: Sequence[Scored], runs: Sequence[ClassifiedRun],
                 say: Callable[[str], None]) -> list[Alike]:
    """Each accepted cause (``accepted``, as the verdict states them) with the candidates of
    its round the campaign cannot tell from it, then the discovered term (the last accepted)
    with its ``discovered_rivals``; each group with the run of ``runs``' kinds that would
    tell them apart."""
    leaders = {name_of(s.finding): s.finding for s in accepted}
    pairs = [(r.best, found) for r in rounds
             if r.best is not None and name_of(r.best.finding) in leaders
             and (found := rivals(r.best, r.scored, list(leaders)))]
    if discovered_rivals:
        pairs.append((accepted[-1], list(discovered_rivals)))
    groups = []
    for best, others in pairs:
        names = [name_of(s.finding) for s in (best, *others)]
        say(f"{' or '.join(names)}: the campaign cannot tell them apart; simulating the runs "
            "that would")
        groups.append(Alike((leaders[names[0]], *(s.finding for s in others)),
                            next_run([explanation_of(s) for s in (best, *others)], runs)))
    return groups


def explanation_of(scored: Scored) -> Explanation:
    """A scored candidate as an explanation: its name, its fitted model, and the run kinds
    it reads, fitted on and checked on (a catalogued one's own: its fit's are the setups of
    the runs it was fitted on)."""
    candidate = CATALOGUE.get(scored.finding.cause, scored.fit.candidate)
    return Explanation(name_of(scored.finding), scored.fit.params,
                       (*candidate.runs, *candidate.held_out))
