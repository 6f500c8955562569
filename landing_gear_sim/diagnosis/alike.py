"""Explanations a campaign cannot tell apart (issue 64): the verdict names them together.

Two candidates scored from the same model explain the data alike when each met the
evidence (ΔBIC and the held-out gain past their thresholds) and neither explains it
:data:`~landing_gear_sim.diagnosis.discovered.PREDICTS_BETTER` times better than the other,
by ΔBIC or held out: the factor past which the search already calls one predictor better.
Differences of BIC are not odds between models that both miss the rig's law a little: a
late pressure channel and a torque that leads the pressure differ by hundreds in BIC on a
campaign of 10⁵ samples, for one that fits the pressure 98.5 % against 98.3 %.

The search keeps the better of the two (by ΔBIC in the catalogue's rounds, by relations and
gain among discovered terms); its rival stands beside it in an :class:`Alike` group, with
the rig run that would tell them apart (:mod:`~landing_gear_sim.diagnosis.next_run`).
A rival accepted later in its own right is another cause, not a rival.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from landing_gear_sim.diagnosis.findings import Finding
from landing_gear_sim.diagnosis.next_run import NextRun
from landing_gear_sim.diagnosis.scoring import BIC_THRESHOLD, HELD_OUT_THRESHOLD, Scored

ALIKE_FACTOR = 2.0
"""Two gains within this factor of each other do not tell their explanations apart (the
discovery's PREDICTS_BETTER)."""


def met_evidence(finding: Finding) -> bool:
    """Whether ``finding`` met the evidence on both counts: ΔBIC and a held-out gain."""
    return (finding.delta_bic is not None and finding.delta_bic < BIC_THRESHOLD
            and finding.held_out is not None and finding.held_out < HELD_OUT_THRESHOLD)


def _within(first: float, second: float) -> bool:
    """Two gains (negative: better) within :data:`ALIKE_FACTOR` of each other."""
    small, large = sorted((abs(first), abs(second)))
    return large <= ALIKE_FACTOR * small


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
