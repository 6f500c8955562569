"""The discovered term a campaign calls for (issue 14), chosen and scored.

The relations the calibrated model violates say where to look
(:mod:`~landing_gear_sim.diagnosis.consistency`); the libraries and candidates of
:mod:`~landing_gear_sim.diagnosis.discovery` say what to try; each is scored exactly like a
catalogue candidate. In round 1 the term the calibrated model calls for is also scored
beside the catalogue's winners (:func:`rival`), so that a law the catalogue lacks is never
reported under the name of a catalogued effect that bent to it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.identify import Progress
from landing_gear_sim.calibration.measured import CHANNELS, channels_of, simulate_all
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.catalogue import Candidate, Scales, scaled_error
from landing_gear_sim.diagnosis.consistency import (
    BRAKE_ANGLE,
    FREE_ROLLING,
    FRICTION_IN_LOAD,
    GAIN_IN_PRESSURE,
    GAIN_IN_SPEED,
    LOAD_UNIT_N,
    PRESSURE_TIMING,
    RUN_DRIFT,
    VALVE_DIRECTION,
    WHEEL_ANGLE,
    Check,
    check_campaign,
    violations,
)
from landing_gear_sim.diagnosis.discovery import (
    backlash_candidate,
    brake_runout_candidate,
    channel_candidate,
    discovered_candidate,
    drift_candidate,
    families,
    load_candidate,
    pressure_skew_candidate,
    pressure_skew_start,
    runout_candidate,
    select_brake_runout_orders,
    select_brake_terms,
    select_channel_terms,
    select_runout_orders,
    skew_candidate,
    term_formula,
)
from landing_gear_sim.diagnosis.findings import Finding, Signature, SignatureKind
from landing_gear_sim.diagnosis.scoring import (
    HELD_OUT_THRESHOLD,
    Scored,
    log_ratio,
    score_candidate,
)
from landing_gear_sim.diagnosis.signatures import find_signatures
from landing_gear_sim.errors import IdentificationError
from landing_gear_sim.model.parameters import RigParameters


def discover(runs: Sequence[ClassifiedRun], model: RigParameters, datasheet: RigParameters,
              scales: Scales, signatures: Sequence[Signature], checks: Sequence[Check],
              say: Progress) -> Scored | None:
    """A discovered term, scored, when relations among ``checks`` (of ``model``) are
    violated and the sparse regression keeps a term, or the wheel channel lags the model
    (None otherwise): the channels first (what they misread distorts the brake-gain
    relations too), then the brake torque."""
    broken = {c.relation for c in violations(checks)}
    scored = None
    excess = [c.deviation for c in violations(checks) if c.relation == VALVE_DIRECTION]
    if excess and max(excess) > 0:  # the valve first: what it misreads reaches every run
        scored = _score_discovered(backlash_candidate(max(excess), model), runs, model,
                                   datasheet, scales, signatures, say)
    late = [c.deviation for c in violations(checks) if c.relation == PRESSURE_TIMING]
    if late and late[0] > 0 and (scored is None or not scored.finding.accepted):
        scored = _score_discovered(pressure_skew_candidate(late[0], model), runs, model,
                                   datasheet, scales, signatures, say,
                                   pressure_skew_start(runs, model, late[0]))
    if WHEEL_ANGLE in broken and (scored is None or not scored.finding.accepted):
        orders = select_runout_orders(runs)
        if orders:
            scored = _score_discovered(runout_candidate(orders), runs, model, datasheet,
                                       scales, signatures, say)
    if BRAKE_ANGLE in broken and (scored is None or not scored.finding.accepted):
        orders = select_brake_runout_orders(runs, model)
        if orders:
            scored = _score_discovered(brake_runout_candidate(orders), runs, model, datasheet,
                                       scales, signatures, say)
    lags = _wheel_lags(signatures)
    if lags and (scored is None or not scored.finding.accepted):
        scored = _score_discovered(skew_candidate(lags[0]), runs, model, datasheet, scales,
                                   signatures, say)
    libraries = {FREE_ROLLING, GAIN_IN_SPEED, GAIN_IN_PRESSURE}  # relations they explain
    # filtered once for both libraries, and only when one of them will be asked
    braking = [br.prepare(r, model) for r in runs if r.braking] if broken & libraries else []
    if FREE_ROLLING in broken and (scored is None or not scored.finding.accepted):
        channels = select_channel_terms(runs, braking, model)
        if channels:
            scored = _score_discovered(channel_candidate(channels), runs, model, datasheet,
                                       scales, signatures, say)
    if scored is None or not scored.finding.accepted:
        for candidate in _gain_candidates(runs, braking, model, checks):
            scored = _better(scored, _score_discovered(candidate, runs, model, datasheet,
                                                       scales, signatures, say), runs)
    friction = [c for c in violations(checks) if c.relation == FRICTION_IN_LOAD]
    if friction and (scored is None or not scored.finding.accepted):
        candidate = load_candidate(-friction[0].deviation / LOAD_UNIT_N, model)
        scored = _better(scored, _score_discovered(candidate, runs, model, datasheet, scales,
                                                   signatures, say), runs)
    return None if scored is None else _called_for(scored, checks)


CALLED_FOR = {"input_history": (VALVE_DIRECTION,), "wheel_angle": (WHEEL_ANGLE, BRAKE_ANGLE),
              "channel_skew": (PRESSURE_TIMING,),
              "channel_crosstalk": (FREE_ROLLING,), "run_drift": (RUN_DRIFT,),
              "load": (FRICTION_IN_LOAD,)}
"""The relations whose violation calls for each family (the brake-gain laws: their own)."""


def _called_for(scored: Scored, checks: Sequence[Check]) -> Scored:
    """The finding's evidence led by what called for it: the violated relations of its
    family (up to two), or for a skew the wheel channel's lag."""
    family = scored.finding.family
    relations = CALLED_FOR.get(family, (GAIN_IN_SPEED, GAIN_IN_PRESSURE))
    broken = [c.describe() for c in violations(checks) if c.relation in relations][:2]
    reason = "; ".join(broken) or (
        "the wheel channel lags the model's consistently (residual signature)"
        if family == "channel_skew" else "")
    if not reason:
        return scored
    finding = replace(scored.finding, evidence=f"called for by {reason}; "
                      + scored.finding.evidence)
    return Scored(finding, scored.fit)


def _gain_candidates(runs: Sequence[ClassifiedRun], braking: Sequence[br.Braking],
                     model: RigParameters, checks: Sequence[Check]) -> list[Candidate]:
    """The brake gain's law in speed and pressure, and its drift from run to run, as the
    violated relations call for them: both are scored when both are (pressure levels in
    run order make a drift look like a pressure law, and the reverse)."""
    broken = {c.relation: c for c in reversed(violations(checks))}
    candidates = []
    if GAIN_IN_SPEED in broken or GAIN_IN_PRESSURE in broken:
        terms = select_brake_terms(braking, model)
        if terms:
            candidates.append(discovered_candidate(terms))
    if RUN_DRIFT in broken:
        candidates.append(drift_candidate(broken[RUN_DRIFT].deviation,
                                          sum(r.braking for r in runs)))
    return candidates


def _better(first: Scored | None, second: Scored | None,
            runs: Sequence[ClassifiedRun]) -> Scored | None:
    """The accepted one; of two accepted, the one that leaves fewer relations violated, then
    the one that predicts the held-out runs better (a drift through a campaign in rising
    pressure order fits a pressure law nearly as well in sample: ΔBIC −94 against −115
    once, held out −144 against −101); of two not accepted, the lower ΔBIC."""
    if first is None or second is None:
        return first or second
    both = first.finding.accepted and second.finding.accepted
    def rank(s: Scored) -> tuple[bool, int, float]:
        if not both:
            return not s.finding.accepted, 0, s.finding.delta_bic or 0.0
        held_out = s.finding.held_out if s.finding.held_out is not None else math.inf
        return False, _violated_under(s, runs), held_out
    return min(first, second, key=rank)


def _violated_under(scored: Scored, runs: Sequence[ClassifiedRun]) -> int:
    """How many relations the model ``scored`` fitted leaves violated."""
    return len(violations(check_campaign(runs, scored.fit.params)))


@dataclass(frozen=True)
class Extension:
    """What the story's extension scored (``tried``, for the table), the catalogued causes
    it keeps, and the discovered term it accepted (None: none)."""

    tried: list[Finding]
    kept: list[Scored]
    scored: Scored | None


@dataclass(frozen=True)
class Story:
    """The campaign as the diagnosis reads it: its runs, the calibrated starting model with
    its residual ``signatures`` and relation ``checks``, and what scoring needs."""

    runs: Sequence[ClassifiedRun]
    calibrated: RigParameters
    datasheet: RigParameters
    scales: Scales
    signatures: Sequence[Signature]
    checks: Sequence[Check]
    say: Progress

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
            found = self._discover(self.calibrated, self.checks, self.signatures)
            return None if found is None else Extension(
                [found.finding], [], found if found.finding.accepted else None)
        signatures = find_signatures(self.runs, model, simulate_all(self.runs, model))
        if not violations(checks) and not _wheel_lags(signatures):
            return None
        tried = []
        rival = self._discover(self.calibrated, self.checks, self.signatures)
        if rival is not None:
            tried.append(rival.finding)
            if explains_more(rival, accepted, model, self.runs, self.scales):
                self.say(f"a discovered term explains more than {_causes(accepted)}: "
                         f"{rival.finding.term}")
                return Extension(tried, [], rival)
        beside = self._discover(model, checks, signatures)
        if beside is not None:
            tried.append(beside.finding)
            if beside.finding.accepted:
                return Extension(tried, accepted, beside)
        return Extension(tried, accepted, None)

    def _discover(self, model: RigParameters, checks: Sequence[Check],
                  signatures: Sequence[Signature]) -> Scored | None:
        return discover(self.runs, model, self.datasheet, self.scales, signatures, checks,
                        self.say)


def _causes(accepted: Sequence[Scored]) -> str:
    return ", ".join(s.finding.cause for s in accepted)


def _wheel_lags(signatures: Sequence[Signature]) -> list[float]:
    """The wheel channel's consistent lags behind the model (later: positive)."""
    return [s.value for s in signatures if s.kind is SignatureKind.LAG
            and s.channel == "wheel_speed_rad_s" and s.value > 0]


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


def _score_discovered(candidate: Candidate, runs: Sequence[ClassifiedRun],
                      model: RigParameters, datasheet: RigParameters, scales: Scales,
                      signatures: Sequence[Signature], say: Progress,
                      start: RigParameters | None = None) -> Scored | None:
    say(f"fitting a discovered term: {families(candidate)}")
    try:
        scored = score_candidate(candidate, runs, model, datasheet, scales, signatures, start)
    except IdentificationError:
        return None
    finding = replace(scored.finding, family=families(candidate),
                      term=term_formula(candidate, scored.fit.params))
    return Scored(finding, scored.fit)
