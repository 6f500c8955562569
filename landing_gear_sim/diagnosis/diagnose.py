"""Diagnose: why the model and the rig disagree (docs/diagnosis.md). The stages:

1. Calibrate the starting model on the campaign, so a parameter that is merely off
   is re-tuned, not reported as missing physics (:func:`_calibrated_start`).
2. Search the catalogue in rounds (:mod:`~landing_gear_sim.diagnosis.rounds`): score every
   candidate the starting model lacks, adopt the best accepted one, re-calibrate with it,
   re-score the candidates that had helped, repeat.
3. Extend the model by a term of the rig's equations where their relations call for one
   (:mod:`~landing_gear_sim.diagnosis.discovered`, :mod:`~landing_gear_sim.diagnosis.
   equations`).
4. Judge the verdict (:func:`_verdict`): what remains in the residuals
   (:mod:`~landing_gear_sim.diagnosis.signatures`) or in the relations is reported as
   ``unexplained`` in the equation that carries it, never given a name.
"""
from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from landing_gear_sim.calibration import differences
from landing_gear_sim.calibration.actuator import LATE
from landing_gear_sim.calibration.identify import Identification, Progress, identify
from landing_gear_sim.calibration.measured import CHANNELS, Simulations, simulate_all
from landing_gear_sim.calibration.runs import ClassifiedRun, classify_all, fully_logged
from landing_gear_sim.calibration.statistics import Estimate
from landing_gear_sim.diagnosis import discovered, rounds
from landing_gear_sim.diagnosis.alike import Alike, alike_groups, explanation_of, name_of
from landing_gear_sim.diagnosis.catalogue import (
    CATALOGUE,
    Candidate,
    Scales,
    noise_scales,
)
from landing_gear_sim.diagnosis.consistency import (
    coarse_channels,
    inconsistent,
    unchecked_relations,
    under_floor,
)
from landing_gear_sim.diagnosis.equations.placing import locate_all
from landing_gear_sim.diagnosis.families import EQUATIONS
from landing_gear_sim.diagnosis.findings import Finding, Signature, approximations
from landing_gear_sim.diagnosis.identifiability import actuator_calibrated, untestable
from landing_gear_sim.diagnosis.local_gain import LocalGain, local_gains
from landing_gear_sim.diagnosis.misfit import misfit_finding, misfits
from landing_gear_sim.diagnosis.next_run import Explanation, NextRun, next_run
from landing_gear_sim.diagnosis.relations import Check, structural
from landing_gear_sim.diagnosis.rig_bounds import scaled_to_rig
from landing_gear_sim.diagnosis.scoring import (
    BIC_THRESHOLD,
    CUT_LATER,
    HELD_OUT_THRESHOLD,
    Scored,
    channel_fits,
    forget_null_fits,
)
from landing_gear_sim.diagnosis.signatures import (
    RunEvidence,
    find_signatures,
    run_evidence,
    unexplained,
    window_regressors,
)
from landing_gear_sim.diagnosis.start import FRICTION_CURVE, starting_model
from landing_gear_sim.errors import DiagnosisError
from landing_gear_sim.model.datasheet import datasheet_values
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.sensitivity import prepare_kernels
from landing_gear_sim.processes import single_threaded_blas
from msg_tools.run import Run

INCONCLUSIVE = "inconclusive"  # the verdict when the campaign cannot test every candidate


@dataclass
class Diagnosis:
    """Result of :func:`diagnose`."""

    verdict: str
    findings: list[Finding]
    candidates: list[Finding]
    baseline: dict[str, float]
    start: RigParameters
    calibrated: RigParameters
    extended: RigParameters
    signatures_before: list[Signature]
    signatures_after: list[Signature]
    problems: list[str] = field(default_factory=list)
    evidence: list[RunEvidence] = field(default_factory=list)
    """Per run: the simulations compared and the residual spectrum (for the report)."""
    consistency: list[Check] = field(default_factory=list)
    """The relations the rig measures twice, checked under the extended model."""
    consistency_calibrated: list[Check] = field(default_factory=list)
    """The same under the calibrated starting model: what called for an extension."""
    estimates: tuple[Estimate, ...] = ()
    """The starting model's calibration on the campaign: value and 1-σ per parameter."""
    local_before: list[LocalGain] = field(default_factory=list)
    """k_b re-estimated per band and along each run, over the calibrated model's gain."""
    local_after: list[LocalGain] = field(default_factory=list)
    """The same over the extended model's gain."""
    alike: list[Alike] = field(default_factory=list)
    """Findings with the explanations the campaign cannot tell from them."""
    next_run: NextRun | None = None
    """The rig run that would settle what the campaign leaves open (its first group of alike
    explanations, or what an ``inconclusive`` verdict could not test)."""

    def to_json(self) -> dict[str, object]:
        return {"verdict": self.verdict, "findings": [f.to_json() for f in self.findings],
                "baseline": self.baseline,
                "candidates": [f.to_json() | {"accepted": f.accepted} for f in self.candidates],
                "signatures_before": [s.describe() for s in self.signatures_before],
                "signatures_after": [s.describe() for s in self.signatures_after],
                "consistency": [c.to_json() for c in self.consistency],
                "consistency_calibrated": [c.to_json() for c in self.consistency_calibrated],
                "local_gains": {"calibrated": [g.to_json() for g in self.local_before],
                                "extended": [g.to_json() for g in self.local_after]},
                "problems": self.problems,
                "alike": [group.to_json() for group in self.alike],
                "next_run": None if self.next_run is None else self.next_run.to_json(),
                "datasheet": datasheet_values(self.start)}


def candidates_for(start: RigParameters, without: Sequence[str]) -> list[Candidate]:
    """Catalogue entries the starting model lacks."""
    return [c for c in CATALOGUE.values()
            if (c.element is not None and not start.has(c.element))
            or (c.element is None and FRICTION_CURVE in without)]


def diagnose(runs: Sequence[Run], base: RigParameters, without: Sequence[str] = (),
             progress: Progress | None = None) -> Diagnosis:
    """Calibrate, score the candidates, extend the model, report what remains."""
    # a candidate model that diverges (a valve fitted on one apply, run on a release) scores
    # inf and is rejected: its overflow is not the user's to read
    with single_threaded_blas(), np.errstate(over="ignore", invalid="ignore"):
        try:
            return _diagnose(runs, base, without, progress)
        finally:
            forget_null_fits()


def _diagnose(runs: Sequence[Run], base: RigParameters, without: Sequence[str],
              progress: Progress | None) -> Diagnosis:
    """The diagnosis as its stages: calibrate the starting model, search the catalogue in
    rounds, extend the model by a discovered term, judge the verdict."""
    say = progress or (lambda _msg: None)
    if differences.MODEL_DERIVATIVES:
        _prepare_derivatives(base, say)
    start = _calibrated_start(runs, base, without, say)
    search = rounds.search(start.runs, start.start, start.without, start.calibrated, base,
                           start.scales, start.before, start.pending, start.problems, say)
    say("checking the relations the rig measures twice")
    checks = search.consistency.of(search.model)
    calibrated_checks = search.consistency.of(start.calibrated)
    start.problems.extend(unchecked_relations(start.runs, calibrated_checks))
    start.problems.extend(coarse_channels(start.runs, calibrated_checks))
    story = discovered.Story(start.runs, start.calibrated, base, start.scales, start.tried,
                             calibrated_checks, say, Simulations(start.runs))
    model, accepted, checks, extension = _extended(story, search, checks)
    say("analysing the residuals of the extended model")
    simulated_after = story.simulations.of(model)
    after = _interpretable(find_signatures(start.runs, model, simulated_after), start.runs)
    verdict, findings = _verdict(start, search.table, accepted, model, checks,
                                 simulated_after, after)
    groups = alike_groups(search.rounds, accepted, extension.rivals if extension else (),
                          start.runs, say)
    settling = groups[0].next_run if groups else (
        _settling(start, search, extension.tried if extension else [], say)
        if verdict == INCONCLUSIVE else None)
    start.problems.extend(under_floor(checks))
    problems = _answered(start.problems, search.table)
    evidence = [run_evidence(*sims, start.calibrated) for sims in
                zip(start.runs, start.simulated, simulated_after, strict=True)]
    return Diagnosis(verdict, findings, search.table, start.baseline, start.start,
                     start.calibrated, model, start.before, after, problems, evidence, checks,
                     calibrated_checks, start.calibration.estimates,
                     local_gains(start.runs, start.calibrated), local_gains(start.runs, model),
                     groups, settling)


DERIVATIVES_NOTE_AFTER_S = 2.0  # loading them from numba's cache takes a fraction of that


def _prepare_derivatives(base: RigParameters, say: Progress) -> None:
    """The plant's derivatives compiled before the fits' processes fork, saying so when that
    takes its minute (once after an install) rather than on every run."""
    note = threading.Timer(DERIVATIVES_NOTE_AFTER_S, lambda: say(
        "compiling the plant's derivatives for this machine (once after an install, ~1 min)"))
    note.daemon = True
    note.start()
    try:
        prepare_kernels(base)
    finally:
        note.cancel()


@dataclass
class _Start:
    """What the search starts from: the runs, the starting model (and the elements it was
    started without) and its calibration on them, their simulations and fits, the residual
    signatures, the noise scales, the candidates the runs can test (and those they cannot
    that could hide in what they show), and the problems noted so far."""

    runs: Sequence[ClassifiedRun]
    start: RigParameters
    without: Sequence[str]
    calibration: Identification
    simulated: list[Run]
    baseline: dict[str, float]
    tried: list[Signature]
    scales: Scales
    pending: list[Candidate]
    skipped: list[str]
    problems: list[str]

    @property
    def calibrated(self) -> RigParameters:
        return self.calibration.params

    @property
    def before(self) -> list[Signature]:
        """The signatures found under the calibrated model, the tentative ones left out."""
        return [s for s in self.tried if not s.tentative]


def _calibrated_start(runs: Sequence[Run], base: RigParameters, without: Sequence[str],
                      say: Progress) -> _Start:
    """Classify the runs, calibrate the starting model on them, read its residuals, and
    choose the candidates the runs can test."""
    kept, left_out = fully_logged(classify_all(runs), "the diagnosis")  # once: kinds read
    if not kept:
        raise DiagnosisError("no run to diagnose" + (f" ({'; '.join(left_out)})"
                                                      if left_out else ""))
    start = starting_model(base, without)
    say(f"calibrating the starting model on {len(kept)} runs")
    calibration = identify(kept, start, progress=say, friction=FRICTION_CURVE not in without,
                           jackknife=False)
    problems = [*left_out, *calibration.problems]
    simulated = simulate_all(kept, calibration.params)
    baseline = baseline_fits(kept, simulated)
    say("analysing the residuals of the calibrated model")
    tried = _interpretable(find_signatures(kept, calibration.params, simulated,
                                           tentative=True), kept)
    scales = noise_scales(kept, tuple(CHANNELS))
    pending, skipped = _testable(scaled_to_rig(candidates_for(start, without), kept, start),
                                 kept, problems, say)
    pending = _evidenced(pending, kept, calibration.params, problems, say)
    return _Start(kept, start, without, calibration, simulated, baseline, tried, scales,
                  pending, skipped, problems)


def _extended(story: discovered.Story, search: rounds.Search, checks: list[Check]
              ) -> tuple[RigParameters, list[Scored], list[Check], discovered.Extension | None]:
    """The model extended by a discovered term where the equations call for one (the
    search's own otherwise), its accepted causes, its relations' checks, and the extension
    (None: no term was called for)."""
    model, accepted = search.model, search.accepted
    found = story.extend(accepted, model, checks)
    if found is None:
        return model, accepted, checks, None
    search.table.extend(s.finding for s in found.tried)
    if found.scored is None:
        return model, accepted, checks, found
    model = found.scored.fit.params
    accepted = [*(rounds.refreshed(s, model) for s in found.kept), found.scored]
    return model, accepted, search.consistency.of(model), found


def _settling(start: _Start, search: rounds.Search, terms: Sequence[Scored], say: Progress
              ) -> NextRun | None:
    """The run that would settle an ``inconclusive`` verdict: the model as calibrated
    against every candidate (catalogued, or a discovered term of ``terms``) that fitted
    better but could not be confirmed, as fitted. One the runs could not test has no size
    to simulate it at: the notes name the run it needs."""
    fitted = {name_of(s.finding): s for r in search.rounds for s in r.scored}  # its last round
    fitted |= {name_of(s.finding): s for s in terms}
    open_ = {name: s for name, s in fitted.items() if not s.finding.accepted
             and s.finding.delta_bic is not None and s.finding.delta_bic < BIC_THRESHOLD}
    explanations = [Explanation("the model as calibrated", start.calibrated),
                    *(explanation_of(s) for s in open_.values())]
    if len(explanations) < 2:
        return None
    say("simulating the runs that would settle it")
    return next_run(explanations, start.runs)


def _verdict(start: _Start, table: list[Finding], accepted: list[Scored],
             model: RigParameters, checks: list[Check], simulated_after: list[Run],
             after: list[Signature]) -> tuple[str, list[Finding]]:
    """The verdict and its findings: the accepted causes, then what remains unexplained in
    the residuals and the relations; ``inconclusive`` where a candidate the runs could not
    test may be what they show."""
    findings = [s.finding for s in accepted]
    unchecked = _unchecked(table) if not accepted else []
    start.problems.extend(
        f"{f.cause} ({_in_words(f.parameters)}): fits the runs it was fitted on better "
        f"(ΔBIC {f.delta_bic:+.0f}) but no run is left to check it on: one more run like "
        f"{(*f.fitted_on, 'those')[0]} would settle it" for f in unchecked)
    start.problems.extend(_unsettled_in_time(table) if not accepted else [])
    if not accepted and (start.skipped or unchecked):
        # not 'none' (a catalogued effect may hide in what could not be tested), and no
        # 'unexplained' either: an untested candidate may be what the residual shows
        return INCONCLUSIVE, findings
    if after:
        places = locate_all(after, start.runs, model, simulated_after,
                            lambda run, sim: window_regressors(run, sim, model))
        findings.append(unexplained(after, baseline_fits(start.runs, simulated_after), places))
    if broken := structural(checks):
        findings.append(inconsistent(broken))
    if not findings and (missed := misfits(start.runs, simulated_after)):
        findings.append(misfit_finding(missed, baseline_fits(start.runs, simulated_after)))
    findings = approximations(findings, EQUATIONS)
    return (findings[0].cause if findings else "none"), findings


def _answered(problems: list[str], table: Sequence[Finding]) -> list[str]:
    """``problems`` less the calibration's hint of a late valve, where the diagnosis tried
    the delay that answers it."""
    if any(f.cause == "actuator_delay" for f in table):
        return [p for p in problems if LATE not in p]
    return problems


def _testable(candidates: Sequence[Candidate], runs: Sequence[ClassifiedRun],
              problems: list[str], say: Progress) -> tuple[list[Candidate], list[str]]:
    """The candidates the runs can identify, and the causes of the others that could hide
    in what the runs show; every other noted in ``problems``."""
    testable, skipped = _set_aside(candidates, lambda c: untestable(c, runs), "skipped", "",
                                   problems, say)
    return testable, [c.cause for c in skipped if _could_show(c, runs)]


def _evidenced(candidates: Sequence[Candidate], runs: Sequence[ClassifiedRun],
               calibrated: RigParameters, problems: list[str], say: Progress
               ) -> list[Candidate]:
    """The candidates whose sign the runs may show under the ``calibrated`` model; every
    other noted in ``problems`` with what the runs show instead (a fit that cannot pass the
    evidence costs as much as one that can)."""
    shown, _ = _set_aside(candidates,
                          lambda c: c.evidence(runs, calibrated) if c.evidence else "",
                          "not fitted", "not fitted: ", problems, say)
    return shown


def _set_aside(candidates: Sequence[Candidate], why: Callable[[Candidate], str], said: str,
               noted: str, problems: list[str], say: Progress
               ) -> tuple[list[Candidate], list[Candidate]]:
    """The candidates ``why`` gives no reason against, and the others, each noted in
    ``problems`` (``noted`` and its reason) and said (``said``, its reason)."""
    kept, aside = [], []
    for candidate in candidates:
        reason = why(candidate)
        if reason:
            problems.append(f"{candidate.cause}: {noted}{reason}")
            say(f"{candidate.cause}: {said}, {reason}")
            aside.append(candidate)
        else:
            kept.append(candidate)
    return kept, aside


def _could_show(candidate: Candidate, runs: Sequence[ClassifiedRun]) -> bool:
    """Whether an untested ``candidate`` could be what the runs show: not one seen only in
    braking runs' channels when no run brakes (an actuator-only log's verdict is the
    valve's; a tyre's relaxation cannot hide in it)."""
    return any(r.braking for r in runs) or "pressure_pa" in candidate.channels


def _interpretable(signatures: list[Signature], runs: Sequence[ClassifiedRun]
                   ) -> list[Signature]:
    """Residual signatures that say something about the rig: a pressure residual left by
    an uncalibrated valve (no actuator runs) says only that the datasheet is off."""
    if actuator_calibrated(runs):
        return signatures
    return [s for s in signatures if s.channel != "pressure_pa"]


def _in_words(parameters: dict[str, float]) -> str:
    return ", ".join(f"{name} {value:.4g}" for name, value in parameters.items())


def _unchecked(table: Sequence[Finding]) -> list[Finding]:
    """Candidates the fitting runs support that no held-out run could confirm."""
    return [f for f in table if f.held_out is None and f.delta_bic is not None
            and f.delta_bic < BIC_THRESHOLD]


def _unsettled_in_time(table: Sequence[Finding]) -> list[str]:
    """What one more step run would settle: candidates the first transitions of a run cut
    in time support and its later ones do not (a single apply and release: a delay fitted
    on the apply, checked on a release unlike it)."""
    return [f"{f.cause} ({_in_words(f.parameters)}): fits {', '.join(f.fitted_on)} better "
            f"(ΔBIC {f.delta_bic:+.0f}) but not {', '.join(f.checked_on)}, held out in time, "
            "whose transitions may differ from those it was fitted on (a release unlike the "
            "apply); one more step run, with an apply and a release, would check it on "
            "transitions of both kinds" for f in table
            if not f.accepted and f.delta_bic is not None and f.delta_bic < BIC_THRESHOLD
            and f.held_out is not None and f.held_out >= HELD_OUT_THRESHOLD and f.checked_on
            and all(name.endswith(f" ({CUT_LATER})") for name in f.checked_on)]


def baseline_fits(runs: Sequence[ClassifiedRun], simulated: Sequence[Run]
                  ) -> dict[str, float]:
    """Fit % per channel of the simulations of ``runs``: pressure over every run, the rest
    over the braking runs."""
    fits = channel_fits(runs, simulated, ("pressure_pa",))
    braking = [i for i, r in enumerate(runs) if r.braking]
    if braking:
        fits.update(channel_fits([runs[i] for i in braking], [simulated[i] for i in braking],
                                 tuple(c for c in CHANNELS if c != "pressure_pa")))
    return fits
