"""Diagnose: why the model and the rig disagree (docs/diagnosis.md).

1. Calibrate the starting model on the campaign, so a parameter that is merely off
   is re-tuned, not reported as missing physics.
2. Score every candidate the starting model lacks (:mod:`~landing_gear_sim.diagnosis.scoring`):
   fit it and its null on the runs that carry its signature, check both on the others.
3. Adopt the best accepted candidate, re-calibrate with it, re-score the candidates that
   had helped, repeat.
4. What remains in the residuals (:mod:`~landing_gear_sim.diagnosis.signatures`) is
   reported as ``unexplained`` with its signature, never given a name.
"""

from __future__ import annotations

import contextvars
import multiprocessing
import os
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field, replace

import numpy as np

from landing_gear_sim.calibration.actuator import LATE
from landing_gear_sim.calibration.identify import Progress, identify
from landing_gear_sim.calibration.measured import CHANNELS, simulate_all
from landing_gear_sim.calibration.runs import ClassifiedRun, classify_all, fully_logged
from landing_gear_sim.calibration.statistics import Estimate
from landing_gear_sim.diagnosis import discovered
from landing_gear_sim.diagnosis.catalogue import (
    CATALOGUE,
    Candidate,
    Scales,
    key_parameters,
    noise_scales,
    switched_on,
)
from landing_gear_sim.diagnosis.consistency import (
    check_campaign,
    coarse_channels,
    inconsistent,
    unchecked_relations,
    under_floor,
)
from landing_gear_sim.diagnosis.equations import locate_all
from landing_gear_sim.diagnosis.findings import Finding, Signature
from landing_gear_sim.diagnosis.identifiability import actuator_calibrated, untestable
from landing_gear_sim.diagnosis.local import LocalGain, local_gains
from landing_gear_sim.diagnosis.relations import Check, structural
from landing_gear_sim.diagnosis.rig_bounds import scaled_to_rig
from landing_gear_sim.diagnosis.scoring import (
    BIC_THRESHOLD,
    CUT_LATER,
    HELD_OUT_THRESHOLD,
    Scored,
    channel_fits,
    forget_null_fits,
    key_std,
    score_candidate,
)
from landing_gear_sim.diagnosis.signatures import (
    RunEvidence,
    find_signatures,
    run_evidence,
    unexplained,
    window_regressors,
)
from landing_gear_sim.diagnosis.start import FRICTION_CURVE, starting_model
from landing_gear_sim.errors import DiagnosisError, IdentificationError
from landing_gear_sim.model.datasheet import datasheet_values
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.processes import busy_counter, pool_worker, single_threaded_blas, working
from msg_tools.run import Run

MAX_ROUNDS = 4
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
                "datasheet": datasheet_values(self.start)}


class Consistency:
    """The consistency checks of the models a diagnosis reads them under, each computed
    once (:func:`check_campaign`). A round computes its model's while its candidates fit
    (:meth:`meanwhile`): the calibrated model's are always read, and the last round's model
    is the final one."""

    def __init__(self, runs: Sequence[ClassifiedRun]) -> None:
        self._runs = runs
        self._done: list[tuple[RigParameters, list[Check]]] = []

    def of(self, model: RigParameters) -> list[Check]:
        """The checks under ``model``."""
        for done, checks in self._done:
            if done is model:
                return checks
        checks = check_campaign(self._runs, model)
        self._done.append((model, checks))
        return checks

    def meanwhile(self, model: RigParameters) -> Callable[[], object]:
        """A task computing the checks under ``model``, for :func:`_score_all`."""
        return lambda: self.of(model)


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
    say = progress or (lambda _msg: None)
    kept, left_out = fully_logged(classify_all(runs), "the diagnosis")  # once: kinds read
    runs = kept
    if not runs:
        raise DiagnosisError("no run to diagnose" + (f" ({'; '.join(left_out)})"
                                                      if left_out else ""))
    start = starting_model(base, without)
    say(f"calibrating the starting model on {len(runs)} runs")
    calibration = identify(runs, start, progress=say, friction=FRICTION_CURVE not in without,
                           jackknife=False)
    problems = [*left_out, *calibration.problems]
    calibrated = calibration.params
    simulated_before = simulate_all(runs, calibrated)
    baseline = baseline_fits(runs, simulated_before)
    say("analysing the residuals of the calibrated model")
    tried = _interpretable(find_signatures(runs, calibrated, simulated_before, tentative=True),
                           runs)
    before = [s for s in tried if not s.tentative]
    scales = noise_scales(runs, tuple(CHANNELS))
    pending, skipped = _testable(scaled_to_rig(candidates_for(start, without), runs, start),
                                 runs, problems, say)
    model = calibrated
    consistency = Consistency(runs)
    accepted: list[Scored] = []
    table: list[Finding] = []
    ended: dict[str, dict[str, float]] = {}  # where each candidate's fit ended, by cause
    for round_ in range(1, MAX_ROUNDS + 1):
        if not pending:
            break
        say(f"round {round_}: fitting {', '.join(c.cause for c in pending)}")
        scored = []
        for outcome in _score_all(pending, runs, model, base, scales, before, say,
                                  consistency.meanwhile(model), ended):
            if isinstance(outcome, str):
                problems.append(outcome)
            else:
                scored.append(outcome)
        winners = [s for s in scored if s.finding.accepted]
        best = min(winners, key=lambda s: s.finding.delta_bic or 0.0) if winners else None
        table.extend(replace(s.finding, round=round_, reason=_round_reason(s, best))
                     for s in scored)
        if best is None:
            break
        say(f"accepted {best.finding.cause}: {best.finding.evidence}")
        accepted.append(best)
        say(f"re-calibrating with {', '.join(s.finding.cause for s in accepted)}")
        model, accepted = _recalibrate(runs, start, accepted, without)
        ended = {s.finding.cause: s.fit.values for s in scored}
        pending = tried_again(scored, best)
    say("checking the relations the rig measures twice")
    checks, calibrated_checks = consistency.of(model), consistency.of(calibrated)
    problems.extend(unchecked_relations(runs, calibrated_checks))
    problems.extend(coarse_channels(runs, calibrated_checks))
    story = discovered.Story(runs, calibrated, base, scales, tried, calibrated_checks, say)
    found = story.extend(accepted, model, checks)
    if found is not None:
        table.extend(found.tried)
        if found.scored is not None:
            model = found.scored.fit.params
            accepted = [*(_refreshed(s, model) for s in found.kept), found.scored]
            checks = consistency.of(model)
    say("analysing the residuals of the extended model")
    simulated_after = simulate_all(runs, model)
    after = _interpretable(find_signatures(runs, model, simulated_after), runs)
    findings = [s.finding for s in accepted]
    unchecked = _unchecked(table) if not accepted else []
    problems.extend(f"{f.cause} ({_in_words(f.parameters)}): fits the runs it was fitted on "
                    f"better (ΔBIC {f.delta_bic:+.0f}) but no run is left to check it on: one "
                    f"more run like {(*f.fitted_on, 'those')[0]} would settle it"
                    for f in unchecked)
    problems.extend(_unsettled_in_time(table) if not accepted else [])
    if accepted or not (skipped or unchecked):
        if after:
            places = locate_all(after, runs, model, simulated_after,
                                lambda run, sim: window_regressors(run, sim, model))
            findings.append(unexplained(after, baseline_fits(runs, simulated_after), places))
        if broken := structural(checks):
            findings.append(inconsistent(broken))
        verdict = findings[0].cause if findings else "none"
    else:
        # not 'none' (a catalogued effect may hide in what could not be tested), and no
        # 'unexplained' either: an untested candidate may be what the residual shows
        verdict = INCONCLUSIVE
    problems.extend(under_floor(checks))
    if any(f.cause == "actuator_delay" for f in table):  # the calibration's hint, answered
        problems = [p for p in problems if LATE not in p]
    evidence = [run_evidence(*sims, calibrated)
                for sims in zip(runs, simulated_before, simulated_after, strict=True)]
    return Diagnosis(verdict, findings, table, baseline, start, calibrated, model,
                     before, after, problems, evidence, checks, calibrated_checks,
                     calibration.estimates, local_gains(runs, calibrated),
                     local_gains(runs, model))


def _testable(candidates: Sequence[Candidate], runs: Sequence[ClassifiedRun],
              problems: list[str], say: Progress) -> tuple[list[Candidate], list[str]]:
    """The candidates the runs can identify, and the causes of the others that could hide
    in what the runs show; every other noted in ``problems``."""
    testable, skipped = [], []
    for candidate in candidates:
        reason = untestable(candidate, runs)
        if reason:
            problems.append(f"{candidate.cause}: {reason}")
            say(f"{candidate.cause}: skipped, {reason}")
            skipped.append(candidate.cause)
        else:
            testable.append(candidate)
    return testable, [c for c in skipped if _could_show(CATALOGUE[c], runs)]


def tried_again(scored: Sequence[Scored], best: Scored) -> list[Candidate]:
    """The candidates of a round tried again on the model with its ``best``: every other
    that met the evidence (ΔBIC below the threshold). A cause masked by another shows once
    that one is in (I02's offset: ΔBIC −46 beside the delay, −5622 once it was in); one short
    of the evidence is not tried again: in the plans of bench/detection.py (stops 56, 57)
    none of the six so tried grew significant, and I01's relaxation (ΔBIC −2, then +12)
    cost 3.8 s of its 15."""
    return [CATALOGUE[s.finding.cause] for s in scored
            if s is not best and (s.finding.delta_bic or 0.0) < BIC_THRESHOLD]


def _round_reason(scored: Scored, best: Scored | None) -> str:
    """A candidate's reason in its round: one that meets every rule but another explained
    more is tried again in the next round, on the model with that one."""
    if best is None or scored is best or not scored.finding.accepted:
        return scored.finding.reason
    return (f"meets every rule, but {best.finding.cause} explains more (ΔBIC "
            f"{best.finding.delta_bic:+.0f}): tried again on the model with it")


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


def _score_one(candidate: Candidate, runs: Sequence[ClassifiedRun], model: RigParameters,
               datasheet: RigParameters, scales: Scales,
               signatures: Sequence[Signature], ended: Mapping[str, float] | None = None
               ) -> Scored | str:
    try:
        with working():
            return score_candidate(candidate, runs, model, datasheet, scales, signatures,
                                   ended=ended)
    except IdentificationError as exc:
        return f"{candidate.cause}: not scored ({exc})"


def _score_all(pending: Sequence[Candidate], runs: Sequence[ClassifiedRun], model: RigParameters,
               datasheet: RigParameters, scales: Scales, signatures: Sequence[Signature],
               say: Progress, meanwhile: Callable[[], object] = lambda: None,
               ended: Mapping[str, Mapping[str, float]] | None = None) -> list[Scored | str]:
    """Score the candidates, in parallel processes when there are cores to spare (each
    fit is independent and single-threaded), each also from where it ``ended`` in a round
    before (by cause); in order of ``pending``. ``meanwhile`` runs in this process as they
    fit (its work is serial: the fits' threads leave room for it)."""
    ended = ended or {}
    workers = min(len(pending), os.cpu_count() or 1)
    if workers < 2 or multiprocessing.current_process().daemon:
        # a daemonic process (a Dask worker's) may not have children
        meanwhile()
        return [_score_one(c, runs, model, datasheet, scales, signatures,
                           ended.get(c.cause)) for c in pending]
    # fork: the children inherit the compiled physics instead of compiling it again
    context = multiprocessing.get_context("fork")
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=pool_worker,
                               initargs=(busy_counter(),))
    side = ThreadPoolExecutor(1)
    try:
        # the costliest first (more fitted parameters: more simulations per step), so the
        # last to finish is a short one
        futures = {pool.submit(_score_one, c, runs, model, datasheet, scales, signatures,
                               ended.get(c.cause)): c
                   for c in sorted(pending, key=lambda c: -len({*c.keys, *c.free}))}
        # on a thread only once the workers are forked: a fork while it holds a lock (an
        # import's) would leave the child waiting on it; numpy's error state goes with it
        beside = side.submit(contextvars.copy_context().run, meanwhile)
        for future in as_completed(futures):
            say(f"  {futures[future].cause} scored")
        results = [next(f for f, c in futures.items() if c is candidate).result()
                   for candidate in pending]
        beside.result()
    except BaseException:
        # Ctrl-C or SIGTERM: the workers' fits could run for minutes; an executor's exit
        # would wait for them
        for child in multiprocessing.active_children():
            child.terminate()
        pool.shutdown(wait=False, cancel_futures=True)
        side.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()
    side.shutdown()
    return results


def _recalibrate(runs: Sequence[ClassifiedRun], start: RigParameters, accepted: list[Scored],
                 without: Sequence[str]) -> tuple[RigParameters, list[Scored]]:
    """Calibrate the starting model again with the accepted elements in it: what they
    had distorted is re-tuned, and identify estimates the keys it knows (the fade, the
    drag, A(s)). The findings take the final values."""
    seed = start
    for s in accepted:
        seed = switched_on(s.fit.candidate, seed).replace(
            {k: s.fit.values[k] for k in s.fit.candidate.keys}, "accepted")
    friction = FRICTION_CURVE not in without or any(
        s.finding.cause == FRICTION_CURVE for s in accepted)
    calibration = identify(runs, seed, friction=friction, jackknife=False)
    model = calibration.params
    estimated = {e.key: e for e in calibration.estimates}
    out = []
    for s in accepted:
        candidate = s.fit.candidate
        # keys identify does not estimate keep their candidate-fit values (a polish on
        # all runs after the re-calibration drove the relaxation length to its bound:
        # the re-fitted friction curve had absorbed it)
        reported = {*candidate.keys, *(key for _, key in candidate.contract)}
        std = {k: estimated[k].std if k in estimated else s.fit.std.get(k, 0.0)
               for k in reported}
        values = {k: model.number(k) for k in reported}
        final = replace(s.fit, params=model, values=values, std=std)
        finding = replace(s.finding, parameters=key_parameters(candidate, model),
                          std=key_std(candidate, final))
        out.append(Scored(finding, final))
    return model, out


def _refreshed(scored: Scored, model: RigParameters) -> Scored:
    """A cause kept beside a discovered term, with its values in the final ``model`` (the
    term's fit may have freed them: a delay beside a channel's skew)."""
    candidate = scored.fit.candidate
    return Scored(replace(scored.finding, parameters=key_parameters(candidate, model)),
                  replace(scored.fit, params=model))


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
