"""The rig run that would settle what a campaign leaves open (issue 64): each explanation
simulated on the runs the rig can make, and the run whose predictions differ most against
the logger's noise.

An explanation is a fitted model (the calibrated one, a candidate the runs could not check,
one of a group of alike explanations). Each run of :data:`PROPOSED` is simulated once, by
the first explanation, as the template every explanation is then simulated on as a measured
run is (:func:`~landing_gear_sim.calibration.measured.simulate_run`: the same current, the
same logging). Two explanations are as far apart on a run as the evidence it would give
between them: the log-likelihood ratio Σ d²/2σ² of their predictions' difference d in the
channel that tells them apart best, σ the campaign's own logger noise in that channel
(:data:`SETTLES`, on Kass & Raftery's scale, is decisive). A run settles a group when it
tells every pair apart, so a run's score is its closest pair's. Only runs of the kinds the
campaign has are proposed: a valve's step log has no wheel to brake.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from landing_gear_sim.calibration.measured import channel_words, channels_of, simulate_run
from landing_gear_sim.calibration.noise import noise_std
from landing_gear_sim.calibration.runs import ClassifiedRun, Selector, classified, matches
from landing_gear_sim.diagnosis.misfit import equation_of
from landing_gear_sim.diagnosis.scoring import BIC_THRESHOLD
from landing_gear_sim.errors import LandingGearSimError
from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.runspec import PROFILES, RunSpec, build_scenario
from msg_tools.run import Run
from msg_tools.units import PA_PER_BAR

SETTLES = -BIC_THRESHOLD
"""A log-likelihood ratio past which a run tells two explanations apart ("very strong"
evidence, the diagnosis's own ΔBIC threshold)."""


@dataclass(frozen=True)
class Explanation:
    """One way the campaign could be: a name in words, the model it stands for, and the
    kinds of run its candidate is fitted or checked on (empty: any; a run of another kind
    would not settle it: a tyre's relaxation is fitted on constant-pressure stops only)."""

    name: str
    params: RigParameters
    kinds: tuple[Selector, ...] = ()


@dataclass(frozen=True)
class Proposal:
    """A run the rig can make: its :class:`RunSpec` (what ``campaign --profile`` takes)
    and what it is, in words."""

    spec: RunSpec
    words: str

    @property
    def options(self) -> str:
        """The ``campaign`` options that write it."""
        found = f"--profile {self.spec.profile}"
        if self.spec.profile == "constant":
            found += f" --pressure-bar {self.spec.pressure_pa / PA_PER_BAR:g}"
        if self.spec.contact != "auto":
            found += " --rig" if self.spec.contact == "rig" else " --actuator-only"
        return found


PROPOSED: tuple[Proposal, ...] = (
    *(Proposal(RunSpec("constant", pressure_pa=bar * PA_PER_BAR),
               f"a stop at a constant {bar} bar") for bar in (10, 20, 30, 40)),
    Proposal(RunSpec("osc-low"), "a stop with the current oscillating slowly"),
    Proposal(RunSpec("osc-high"), "a stop with the current oscillating fast"),
    Proposal(RunSpec("steps"), "steps of current with the wheel held off the flywheel"),
    Proposal(RunSpec("steps", contact="rig"), "steps of current while the wheel brakes"),
    Proposal(RunSpec("sweep"), "a sine sweep of current with the wheel held off the flywheel"),
    Proposal(RunSpec("ramp"), "a slow ramp of current with the wheel held off the flywheel"),
)
"""The runs proposed: the profiles the rig and the generator run."""


@dataclass(frozen=True)
class Apart:
    """How far two explanations' predictions are apart on a run, in the channel that tells
    them apart best: the evidence the run would give (log-likelihood ratio) and the RMS of
    the difference over the logger's noise."""

    first: str
    second: str
    channel: str
    evidence: float
    rms_over_noise: float


@dataclass(frozen=True)
class NextRun:
    """The proposed run and how far it sets the explanations apart (its closest pair)."""

    proposal: Proposal
    explanations: tuple[str, ...]
    closest: Apart

    @property
    def settles(self) -> bool:
        return self.closest.evidence >= SETTLES

    @property
    def equation(self) -> str:
        """The equation whose channel tells the closest pair apart."""
        return equation_of(self.closest.channel)

    def command(self, folder: str = "out/next_run") -> str:
        return f"landing-gear-sim campaign {folder} {self.proposal.options}"

    def sentence(self) -> str:
        """What to run next, in words."""
        names = " from ".join(f"'{n}'" for n in (self.closest.first, self.closest.second))
        apart = (f"{self.proposal.words} ({self.command()}): it would tell {names} by the "
                 f"{channel_words(self.closest.channel)}, in the {self.equation}'s equation, "
                 f"{self.closest.rms_over_noise:.2g} times the logger's noise (RMS), a "
                 f"log-likelihood ratio of {self.closest.evidence:.3g}")
        if self.settles:
            return f"the run that would settle it: {apart}"
        return (f"no run the rig can make tells them apart decisively; the closest: {apart}"
                f" (under {SETTLES:g})")

    def to_json(self) -> dict[str, object]:
        return {"profile": self.proposal.spec.profile, "options": self.proposal.options,
                "words": self.proposal.words, "command": self.command(),
                "explanations": list(self.explanations), "channel": self.closest.channel,
                "equation": self.equation, "log_likelihood_ratio": self.closest.evidence,
                "rms_over_noise": self.closest.rms_over_noise, "settles": self.settles}


def next_run(explanations: Sequence[Explanation], campaign: Sequence[ClassifiedRun]
             ) -> NextRun | None:
    """The run of :data:`PROPOSED` (of the kinds ``campaign`` has) that tells the
    ``explanations`` apart best against the campaign's logger noise; None for fewer than
    two explanations or no run to propose."""
    if len(explanations) < 2:
        return None
    noise, rate_hz = _noise(campaign), _rate_hz(campaign)
    made = [(p, t) for p in _of_kinds(campaign)
            if (t := _template(p.spec, explanations[0].params, rate_hz)) is not None]
    # runs every explanation's fit reads, where there are any: a run another kind would
    # tell them apart by eye and leave the diagnosis as it was
    read = [(p, t) for p, t in made if all(
        not e.kinds or matches(t.kind, e.kinds) for e in explanations)] or made
    best: NextRun | None = None
    for proposal, template in read:
        closest = _closest(explanations, template, noise)
        if closest is not None and (best is None or closest.evidence > best.closest.evidence):
            best = NextRun(proposal, tuple(e.name for e in explanations), closest)
    return best


def _of_kinds(campaign: Sequence[ClassifiedRun]) -> list[Proposal]:
    """The proposals a rig that made ``campaign`` can make: braking ones only where it
    braked."""
    brakes = any(r.braking for r in campaign)
    return [p for p in PROPOSED
            if brakes or (not PROFILES[p.spec.profile][1] and p.spec.contact != "rig")]


def _noise(campaign: Sequence[ClassifiedRun]) -> dict[str, float]:
    """Each channel's logger noise, the median over the runs that log it."""
    seen: dict[str, list[float]] = {}
    for run in campaign:
        for channel in channels_of(run):
            seen.setdefault(channel, []).append(noise_std(getattr(run, channel)))
    return {c: float(np.median(v)) for c, v in seen.items()}


def _rate_hz(campaign: Sequence[ClassifiedRun]) -> float:
    return float(np.median([r.rate_hz for r in campaign]))


def _closest(explanations: Sequence[Explanation], template: ClassifiedRun,
             noise: dict[str, float]) -> Apart | None:
    """The pair of ``explanations`` that the run ``template`` tells apart least; None
    where an explanation cannot simulate it (its valve's range, or a candidate that
    diverges there: its run would tell nothing of the rig)."""
    try:
        predicted = [simulate_run(template, e.params)[0] for e in explanations]
    except LandingGearSimError:
        return None
    channels = [c for c in channels_of(template) if c in noise]
    if not channels or not all(np.all(np.isfinite(getattr(p, c)))
                               for p in predicted for c in channels):
        return None
    pairs = [_apart(a, b, channels, noise, predicted[i], predicted[j])
             for (i, a), (j, b) in itertools.combinations(enumerate(explanations), 2)]
    return min(pairs, key=lambda p: p.evidence)


def _template(spec: RunSpec, params: RigParameters, rate_hz: float) -> ClassifiedRun | None:
    """The run ``spec`` as ``params`` make it, without noise: the input every explanation
    is simulated on (None: ``params`` cannot make it, a pressure beyond the valve's)."""
    try:
        scenario = build_scenario(replace(spec, rate_hz=rate_hz), params)
    except LandingGearSimError:
        return None
    return classified(simulate(params, scenario).to_run())


def _apart(first: Explanation, second: Explanation, channels: Sequence[str],
           noise: dict[str, float], a: Run, b: Run) -> Apart:
    """How far ``a`` and ``b`` (their predictions) are apart, in their most telling
    channel."""
    def of(channel: str) -> Apart:
        difference = (getattr(a, channel) - getattr(b, channel)) / noise[channel]
        evidence = 0.5 * float(np.sum(difference ** 2))
        rms = math.sqrt(float(np.mean(difference ** 2)))
        return Apart(first.name, second.name, channel, evidence, rms)

    return max((of(c) for c in channels), key=lambda p: p.evidence)
