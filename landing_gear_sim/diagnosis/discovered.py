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
from dataclasses import replace

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.identify import Progress
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.catalogue import Candidate, Scales
from landing_gear_sim.diagnosis.consistency import (
    FREE_ROLLING,
    FRICTION_IN_LOAD,
    GAIN_IN_PRESSURE,
    GAIN_IN_SPEED,
    LOAD_UNIT_N,
    RUN_DRIFT,
    VALVE_DIRECTION,
    WHEEL_ANGLE,
    Check,
    check_campaign,
    violations,
)
from landing_gear_sim.diagnosis.discovery import (
    backlash_candidate,
    channel_candidate,
    discovered_candidate,
    drift_candidate,
    families,
    load_candidate,
    runout_candidate,
    select_brake_terms,
    select_channel_terms,
    select_runout_orders,
    skew_candidate,
    term_formula,
)
from landing_gear_sim.diagnosis.findings import Signature, SignatureKind
from landing_gear_sim.diagnosis.scoring import Scored, score_candidate
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
    if WHEEL_ANGLE in broken and (scored is None or not scored.finding.accepted):
        orders = select_runout_orders(runs)
        if orders:
            scored = _score_discovered(runout_candidate(orders), runs, model, datasheet,
                                       scales, signatures, say)
    lags = [s.value for s in signatures if s.kind is SignatureKind.LAG
            and s.channel == "wheel_speed_rad_s" and s.value > 0]
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


CALLED_FOR = {"input_history": (VALVE_DIRECTION,), "wheel_angle": (WHEEL_ANGLE,),
              "channel_crosstalk": (FREE_ROLLING,), "run_drift": (RUN_DRIFT,),
              "load": (FRICTION_IN_LOAD,)}
"""The relations whose violation calls for each family (the brake-gain laws: their own)."""


def _called_for(scored: Scored, checks: Sequence[Check]) -> Scored:
    """The finding's evidence led by what called for it: the violated relations of its
    family (up to two), or for a skew the wheel channel's lag."""
    family = scored.finding.family
    relations = CALLED_FOR.get(family, (GAIN_IN_SPEED, GAIN_IN_PRESSURE))
    broken = [c.describe() for c in violations(checks) if c.relation in relations][:2]
    reason = ("the wheel channel lags the model's consistently (residual signature)"
              if family == "channel_skew" else "; ".join(broken))
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


def rival(runs: Sequence[ClassifiedRun], model: RigParameters, datasheet: RigParameters,
           scales: Scales, signatures: Sequence[Signature], say: Progress) -> Scored | None:
    """The discovered term the calibrated ``model`` calls for, to be scored beside the
    catalogue's first winners: a law the catalogue lacks may be fitted nearly as well by a
    catalogued effect (a torque not linear in pressure by brake fade), and only the
    comparison tells them apart. None when no relation is violated."""
    checks = check_campaign(runs, model)
    if not violations(checks):
        return None
    return discover(runs, model, datasheet, scales, signatures, checks, say)


def beats(rival: Scored, winners: Sequence[Scored], runs: Sequence[ClassifiedRun]) -> bool:
    """Whether the discovered rival, accepted on its own, explains the campaign better than
    the best catalogued winner: by ΔBIC, or — since a catalogued effect may bend in sample
    to a law it is not (brake fade to a torque not linear in pressure) — on the held-out
    runs and in the relations the rig measures twice, where it cannot."""
    best = min(winners, key=lambda s: s.finding.delta_bic or 0.0)
    if not rival.finding.accepted:
        return False
    if (rival.finding.delta_bic or 0.0) < (best.finding.delta_bic or 0.0):
        return True
    if rival.finding.held_out is None or best.finding.held_out is None \
            or rival.finding.held_out >= best.finding.held_out:
        return False
    return _violated_under(rival, runs) < _violated_under(best, runs)


def _score_discovered(candidate: Candidate, runs: Sequence[ClassifiedRun],
                      model: RigParameters, datasheet: RigParameters, scales: Scales,
                      signatures: Sequence[Signature], say: Progress) -> Scored | None:
    say(f"fitting a discovered term: {families(candidate)}")
    try:
        scored = score_candidate(candidate, runs, model, datasheet, scales, signatures)
    except IdentificationError:
        return None
    finding = replace(scored.finding, family=families(candidate),
                      term=term_formula(candidate, scored.fit.params))
    return Scored(finding, scored.fit)
