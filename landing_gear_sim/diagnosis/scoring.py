"""Scoring a candidate: fit it and its null on some runs, check both on the others.

ΔBIC = n_eff ln(RSS_candidate / RSS_null) + k ln(n_eff), with n_eff the sample count
corrected for the residual's autocorrelation (simulation errors are smooth: 1 kHz
samples are far from independent). A candidate is accepted only if ΔBIC < BIC_THRESHOLD
*and* it also improves runs it was not fitted on by HELD_OUT_THRESHOLD (same
log-likelihood measure, no penalty: nothing was fitted there) by at least
MIN_GAIN_POINTS of fit on a channel it compares (as logged, or with the logger's noise
filtered out: see :func:`worth`), with no key parameter at the edge of its range.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from landing_gear_sim.calibration.braking import lowpass
from landing_gear_sim.calibration.measured import channel_words, simulate_all
from landing_gear_sim.calibration.runs import (
    ClassifiedRun,
    RunKind,
    classify_all,
    select,
    setup_of,
)
from landing_gear_sim.calibration.statistics import effective_count
from landing_gear_sim.diagnosis import catalogue
from landing_gear_sim.diagnosis.catalogue import (
    Candidate,
    CandidateFit,
    fit_candidate,
    key_parameters,
)
from landing_gear_sim.diagnosis.findings import Finding, Signature
from landing_gear_sim.diagnosis.objective import Scales, scaled_error
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.run import SIGNALS, Run

BIC_THRESHOLD = -10.0  # "very strong" evidence (Kass & Raftery 1995)
HELD_OUT_THRESHOLD = -10.0
# ... and worth having: held-out fit gain on the channel it helps most [% points] (the mean
# over the channels let a channel the logger made noise-dominated hide a gear walk: a
# 256-line encoder's wheel speed gained 0.01 points, the load cell's F_x 0.18)
MIN_GAIN_POINTS = 0.1
# ... where the logger's noise lets it show: a counting encoder's steps are most of a wheel
# channel's error (fit 83 % under the true model through 256 lines), so a 4 ms skew the
# held-out runs confirmed (by 179) gained 0.09 points as logged; a rig's dynamics lie below
DENOISED_HZ = 50.0
# ... and no worse elsewhere: no channel it is compared on may lose more held-out fit than
# it gains on its best, beyond this many points (a 64-count encoder's campaign named a
# tyre whose friction peak moves with speed tire_relaxation, held out: the force channel
# 85.8 → 86.1 %, the wheel's 34.0 → 28.0 %, the log-likelihood better by 64 on the force
# channel's many more effective samples)
MAX_LOSS_POINTS = 1.0


def channel_fits(runs: Sequence[Run], simulated: Sequence[Run], channels: Sequence[str],
                 smooth_hz: float | None = None) -> dict[str, float]:
    """Fit % per channel of ``simulated`` against ``runs``, pooled (each run's own mean
    removed); with ``smooth_hz``, of both low-passed there (zero phase)."""
    errors, spreads, _ = _pooled_squares(runs, simulated, channels, smooth_hz)
    return {c: round(100.0 * (1.0 - math.sqrt(errors[c] / spreads[c])), 2)
            for c in channels if spreads[c] > 0}


def channel_rmse(runs: Sequence[Run], simulated: Sequence[Run], channels: Sequence[str]
                 ) -> dict[str, float]:
    """RMSE per channel of ``simulated`` against ``runs``, pooled [the channel's SI unit]."""
    errors, _, count = _pooled_squares(runs, simulated, channels)
    return {c: math.sqrt(errors[c] / count) for c in channels}


def _pooled_squares(runs: Sequence[Run], simulated: Sequence[Run], channels: Sequence[str],
                    smooth_hz: float | None = None
                    ) -> tuple[dict[str, float], dict[str, float], int]:
    """Per channel, the squared errors of ``simulated`` and the squared spread of ``runs``
    about each run's mean, summed over the runs, and the samples summed over."""
    errors: dict[str, float] = dict.fromkeys(channels, 0.0)
    spreads: dict[str, float] = dict.fromkeys(channels, 0.0)
    for run, sim in zip(runs, simulated, strict=True):
        for c in channels:
            y, model = getattr(run, c), getattr(sim, c)
            if smooth_hz is not None:
                cutoff = min(smooth_hz, 0.4 * run.rate_hz)
                y, model = (lowpass(v, run.rate_hz, cutoff) for v in (y, model))
            errors[c] += float(np.sum((y - model) ** 2))
            spreads[c] += float(np.sum((y - y.mean()) ** 2))
    return errors, spreads, sum(len(run) for run in runs)


def log_ratio(candidate: np.ndarray, null: np.ndarray) -> float:
    """n_eff ln(RSS_candidate / RSS_null), n_eff from the null's residual."""
    return effective_count(null) * math.log(float(candidate @ candidate) / float(null @ null))


def split_runs(candidate: Candidate, runs: Sequence[Run]
               ) -> tuple[list[ClassifiedRun], list[ClassifiedRun]]:
    """Runs to fit the candidate on, and runs kept to check it.

    Actuator effects are checked on the braking runs' pressure. Otherwise the runs
    of each class alternate between the two sets, the one that slides furthest first and
    to fitting, the rest by length (the shorter to fitting), so both see every kind of test
    and no held-out run slides beyond what was fitted; with none to spare, an actuator
    run's later part is held out in time (:func:`_held_out_in_time`).
    """
    classified = classify_all(runs)
    own = select(classified, candidate.runs) or select(
        classified, [setup_of(kind) for kind in candidate.runs])
    others = select(classified, candidate.held_out)
    if own and others:
        return own, others
    fit: list[ClassifiedRun] = []
    held: list[ClassifiedRun] = []
    by_class: dict[RunKind, list[ClassifiedRun]] = {}
    for r in own or others:
        by_class.setdefault(r.kind, []).append(r)
    for members in by_class.values():
        for i, r in enumerate(_widest_first(members)):
            (fit if i % 2 == 0 else held).append(r)
    if not held:
        return _held_out_in_time(fit)
    return fit, held


def _widest_first(members: list[ClassifiedRun]) -> list[ClassifiedRun]:
    """The runs of one class, the braking run that slides furthest first, the rest by
    length. A held-out run sliding beyond every fitted one tests an extrapolation no
    friction law passes (U01: a magic-formula tyre fitted on stops below 0.15 slip and
    checked on one sliding to 0.6: every curve, the plain one too, went wild there)."""
    by_length = sorted(members, key=len)
    if not by_length[0].braking:
        return by_length
    widest = max(by_length, key=slip_reach)
    return [widest, *(r for r in by_length if r is not widest)]


SLIP_REACH_PERCENTILE = 99.0  # of a stop's braked samples: a lock shows, a count's step not
TURNING = 0.2  # of the flywheel's top speed: below it the speeds' ratio is noise


def slip_reach(run: ClassifiedRun) -> float:
    """How far the wheel slides behind the flywheel while braking: the wheel's speed over
    the flywheel's, as a fraction below its free-rolling value (the radii cancel: no
    parameter needed to rank a class's stops)."""
    flywheel = run.flywheel_speed_rad_s
    turning = flywheel > TURNING * max(float(flywheel.max()), 1e-9)
    ratio = run.wheel_speed_rad_s[turning] / flywheel[turning]
    braked = run.time_s[turning] >= run.brake_start_s
    if braked.all() or not braked.any():
        return 0.0
    free = float(np.percentile(ratio[~braked], 90.0))  # spun up, not before touchdown
    if free <= 0.0:
        return 0.0
    return float(np.percentile(1.0 - ratio[braked] / free, SLIP_REACH_PERCENTILE))


SETTLED_SPLIT_S = 0.5  # a run cut in time is cut where the current has held this long
CUT_FIRST, CUT_LATER = "before", "after"  # a run cut in time: its parts' names' suffixes


def _held_out_in_time(fit: list[ClassifiedRun]
                      ) -> tuple[list[ClassifiedRun], list[ClassifiedRun]]:
    """With no run of a kind to spare, the longest actuator run's later part held out in
    time (fit on its first transitions, check on the rest): cut nearest its middle (within
    its middle 80 %) where the current has held SETTLED_SPLIT_S, so the held-out part
    starts settled, as a simulation of a run does. Braking runs are not cut (a stop is one
    piece)."""
    cuttable = [r for r in fit if not r.braking]
    if not cuttable:
        return fit, []
    run = max(cuttable, key=len)
    width = max(1, round(SETTLED_SPLIT_S * run.rate_hz))
    held_still = np.convolve(np.diff(run.current_a, prepend=run.current_a[0]) != 0.0,
                             np.ones(width), mode="full")[:len(run)] == 0
    candidates = np.flatnonzero(held_still[len(run) // 10: 9 * len(run) // 10]) + len(run) // 10
    if candidates.size == 0:
        return fit, []
    cut = int(candidates[np.argmin(np.abs(candidates - len(run) // 2))])
    first, later = (ClassifiedRun.of(run.part(part, part_name(run.name, which)))
                    for part, which in ((slice(0, cut), CUT_FIRST), (slice(cut, None),
                                                                     CUT_LATER)))
    return [first if r is run else r for r in fit], [later]


def part_name(run: str, which: str) -> str:
    """The name of a part of ``run`` cut in time ('stop (first part)')."""
    return f"{run} ({which})"


def whole_run(name: str) -> str:
    """The run a part cut in time was cut from (a whole run's name: itself)."""
    for which in (CUT_FIRST, CUT_LATER):
        name = name.removesuffix(f" ({which})")
    return name


@dataclass(frozen=True)
class Scored:
    """A scored candidate: its finding and its fit."""

    finding: Finding
    fit: CandidateFit


def _names(runs: Sequence[Run]) -> tuple[str, ...]:
    return tuple(r.name for r in runs)


def score_candidate(candidate: Candidate, runs: Sequence[Run], model: RigParameters,
                    datasheet: RigParameters, scales: Scales,
                    signatures: Sequence[Signature], start: RigParameters | None = None,
                    ended: Mapping[str, float] | None = None) -> Scored:
    """Fit ``candidate`` and its null on the fitting runs; compare both on held-out runs.
    The candidate's fit starts from ``start`` when given (a model calibrated again with
    it), and from where it ``ended`` when fitted before; its null's from ``model`` (the
    best the runs give without it)."""
    fit_runs, held_runs = split_runs(candidate, runs)
    scales = {**scales, **{(part.name, channel): value for part in (*fit_runs, *held_runs)
                           for (name, channel), value in scales.items()
                           if whole_run(part.name) == name != part.name}}  # a run cut in time
    sub = _as_fitting(candidate, fit_runs)
    if candidate.settings:
        model = model.replace(dict(candidate.settings), f"{candidate.family}'s terms")
        start = start and start.replace(dict(candidate.settings), f"{candidate.family}'s terms")
    with_it = fit_candidate(sub, fit_runs, start or model, datasheet, scales=scales,
                            ended=ended)
    without = _null_fit(sub, fit_runs, model, datasheet, scales)
    if candidate.neutral and with_it.cost > without.cost:
        with_it = _from_null(sub, fit_runs, without, scales)
    k = len(candidate.keys)
    n_eff = effective_count(without.residual)
    delta_bic = log_ratio(with_it.residual, without.residual) + k * math.log(n_eff)
    held = _held_out(candidate, held_runs, with_it, without, scales)
    at_bound = _at_bound(candidate, with_it)
    beyond = candidate.reach(with_it.values, fit_runs, with_it.params) if candidate.reach \
        else ""
    rejected = _rejection(delta_bic, held, at_bound, beyond)
    accepted = not rejected
    reason = _reason(rejected, with_it)
    parameters = key_parameters(candidate, with_it.params)
    std = key_std(candidate, with_it)
    evidence = _evidence(candidate, delta_bic, held, fit_runs, held_runs, signatures) \
        + ("; a key parameter sits at the edge of its range" if at_bound else "") \
        + (f"; not accepted: {beyond}" if beyond else "")
    finding = Finding(cause=candidate.cause, parameters=parameters, std=std, evidence=evidence,
                      fit_before=held.before, fit_after=held.after,
                      rmse_before=held.rmse_before, rmse_after=held.rmse_after,
                      delta_bic=round(delta_bic, 1),
                      held_out=None if held.delta is None else round(held.delta, 1),
                      accepted=accepted, fitted_on=_names(fit_runs),
                      checked_on=_names(held_runs), family=candidate.family, reason=reason)
    return Scored(finding, with_it)


def _reason(rejected: str, fit: CandidateFit) -> str:
    """Why the candidate is rejected (or that it meets every rule), and that its fit
    stopped on its budget when it did: its values may not be its optimum's."""
    stopped = (f"; its fit stopped at its budget of {catalogue.MAX_ITERATIONS} evaluations, "
               "not on its tolerance") if fit.stopped else ""
    return (rejected or ACCEPTED) + stopped


_NULLS: dict[str, CandidateFit] = {}
NULLS_KEPT = 32


def forget_null_fits() -> None:
    """Drop the null fits kept (:func:`_null_fit`): a diagnosis shares its own, and a
    process that diagnoses many campaigns (a bench, a Dask worker) need not carry them."""
    _NULLS.clear()


def _null_fit(candidate: Candidate, runs: Sequence[Run], model: RigParameters,
              datasheet: RigParameters, scales: Scales) -> CandidateFit:
    """``candidate``'s null fitted on ``runs``, once: candidates that re-fit the same base
    parameters on the same runs share it (a family's proposals, each of a discovery's
    ranks: 4 s of a 37 s diagnosis re-fitted the same null)."""
    key = _null_key(candidate, runs, model, datasheet, scales)
    if key not in _NULLS:
        if len(_NULLS) >= NULLS_KEPT:
            _NULLS.pop(next(iter(_NULLS)))
        _NULLS[key] = fit_candidate(candidate, runs, model, datasheet, null=True,
                                    scales=scales)
    fit = _NULLS[key]
    # the model's own slot codes (no term acts through them in a null)
    return replace(fit, candidate=candidate,
                   params=model.replace(fit.values, f"fit {candidate.cause}"))


def _null_key(candidate: Candidate, runs: Sequence[Run], model: RigParameters,
              datasheet: RigParameters, scales: Scales) -> str:
    """What a null fit depends on, hashed: the parameters it frees, the channels and runs
    it fits (their data), the model it starts from and the datasheet bounding it."""
    digest = hashlib.blake2b(digest_size=20)
    free = [k for k in candidate.free if k not in candidate.keys]
    names = {r.name for r in runs}
    digest.update(json.dumps([free, list(candidate.channels), [str(f) for f in candidate.runs],
                              _acting(model, free), _acting(datasheet, free),
                              sorted((f"{n}/{c}", v) for (n, c), v in scales.items()
                                     if n in names)], default=str).encode())
    for run in runs:
        digest.update(run.name.encode())
        for name in ("time_s", *SIGNALS):
            digest.update(np.ascontiguousarray(getattr(run, name)).tobytes())
    return digest.hexdigest()


def _acting(params: RigParameters, free: Sequence[str]) -> dict[str, object]:
    """``params``' values less the codes of slot terms whose coefficient is 0 and not
    fitted: no term (a family's proposals set their terms' codes, and their nulls are one
    fit)."""
    def idle(key: str) -> bool:
        coefficient = f"{key[:-5]}_coeff"
        return (key.endswith("_code") and coefficient not in free
                and params.values.get(coefficient, 1.0) == 0.0)

    return {k: v for k, v in params.values.items() if not idle(k)}


ACCEPTED = "meets every rule (ΔBIC, held-out gain, parameters within range)"


def _rejection(delta_bic: float, held: HeldOut, at_bound: bool, beyond: str) -> str:
    """Why a candidate is not accepted, in words: the first of the rules it fails ('': it
    meets them all; a 'no' beside numbers that seem to meet the stated rule once had no
    reason: its gain on the channel it helps was below MIN_GAIN_POINTS)."""
    if delta_bic >= BIC_THRESHOLD:
        return f"no: ΔBIC {delta_bic:+.0f} is not below {BIC_THRESHOLD:g}"
    if held.delta is None:
        return "no: no held-out run to check it on"
    if not math.isfinite(held.delta):  # nan passed every comparison below: accepted once
        return "no: its model diverges on the held-out runs"
    if held.delta >= HELD_OUT_THRESHOLD:
        return (f"no: the held-out runs improve by {-held.delta:+.0f}, not by more than "
                f"{-HELD_OUT_THRESHOLD:g}")
    if held.gain < MIN_GAIN_POINTS:
        return (f"no: it gains {held.gain:.2f} fit-% points on the held-out runs' channel it "
                f"helps most, below {MIN_GAIN_POINTS:g}")
    if (worse := _worsened(held)):
        return f"no: {worse}"
    if at_bound:
        return "no: a key parameter sits at the edge of its range"
    if beyond:
        return f"no: {beyond}"
    return ""


def fit_changes(before: Mapping[str, float], after: Mapping[str, float]) -> dict[str, float]:
    """What a candidate changes in each channel's fit [% points]: after − before, over the
    channels both hold."""
    return {c: after[c] - before[c] for c in after if c in before}


def _worsened(held: HeldOut) -> str:
    """The held-out channel a candidate makes worse by more than it gains on its best and
    more than MAX_LOSS_POINTS, in words ('': none)."""
    changes = fit_changes(held.before, held.after)
    channel = min(changes, key=changes.__getitem__, default=None)
    if channel is None or -changes[channel] <= max(held.gain, MAX_LOSS_POINTS):
        return ""
    return (f"it makes the held-out runs' {channel_words(channel)} worse by "
            f"{-changes[channel]:.2f} fit-% points ({held.before[channel]:.1f} → "
            f"{held.after[channel]:.1f} %), more than it makes any channel better "
            f"(+{held.gain:.2f})")


@dataclass(frozen=True)
class HeldOut:
    """A candidate on the runs it was not fitted on: the log-likelihood change ``delta``
    (None: no such run), fit % per channel ``before`` and ``after`` as logged, and what it
    gains on the channel it helps most [% points], as logged or, where the logger's noise
    hides it, with that noise filtered out (``denoised``: that channel's fits then)."""

    delta: float | None = None
    before: dict[str, float] = field(default_factory=dict)
    after: dict[str, float] = field(default_factory=dict)
    gain: float = 0.0
    denoised: tuple[str, float, float] | None = None
    rmse_before: dict[str, float] = field(default_factory=dict)
    rmse_after: dict[str, float] = field(default_factory=dict)


def _held_out(candidate: Candidate, runs: Sequence[Run], with_it: CandidateFit,
              without: CandidateFit, scales: Scales) -> HeldOut:
    if not runs:
        return HeldOut()
    channels = candidate.channels
    sim_with, sim_without = simulate_all(runs, with_it.params), simulate_all(runs, without.params)
    delta = log_ratio(scaled_error(runs, sim_with, channels, scales),
                      scaled_error(runs, sim_without, channels, scales))
    before, after = (channel_fits(runs, sim, channels) for sim in (sim_without, sim_with))
    rmse_before, rmse_after = (channel_rmse(runs, sim, [*after])
                               for sim in (sim_without, sim_with))
    logged = max(fit_changes(before, after).values(), default=0.0)
    if logged >= MIN_GAIN_POINTS:
        return HeldOut(delta, before, after, logged, None, rmse_before, rmse_after)
    clean_before, clean_after = (channel_fits(runs, sim, channels, DENOISED_HZ)
                                 for sim in (sim_without, sim_with))
    clean = fit_changes(clean_before, clean_after)
    best = max(clean, key=clean.__getitem__, default=None)
    if best is None or clean[best] <= logged:
        return HeldOut(delta, before, after, logged, None, rmse_before, rmse_after)
    return HeldOut(delta, before, after, clean[best],
                   (best, clean_before[best], clean_after[best]), rmse_before, rmse_after)


def _from_null(candidate: Candidate, runs: Sequence[ClassifiedRun], null: CandidateFit,
               scales: Scales) -> CandidateFit:
    """``candidate`` fitted again from its ``null``'s optimum, its keys where it is that
    null: from there it ends no worse. A fit that ended above its null had stalled (a gain
    law in pressure through a 64-line encoder: started where the datasheet's gain offset
    the term, three times the null's cost, ΔBIC +3815)."""
    return fit_candidate(replace(candidate, starts=(candidate.neutral,)), runs, null.params,
                         scales=scales)


def _at_bound(candidate: Candidate, fit: CandidateFit) -> bool:
    """A key pinned to the edge of its range: the data want the element off (or more
    than it can give) — not evidence for it. A key pinned at its neutral value while
    another carries the law is the element with a simpler law (a radius falling linearly
    with the load: its F_z² coefficient at 0), not the element off."""
    values = [fit.values[k] for k in candidate.keys]
    margins = [0.01 * (high - low) for low, high in candidate.bounds]
    neutral = candidate.neutral or (math.nan,) * len(values)  # none: every key is away
    away = [not abs(v - n) <= m for v, n, m in zip(values, neutral, margins, strict=True)]
    for i, (value, (low, high)) in enumerate(zip(values, candidate.bounds, strict=True)):
        pinned = not low + margins[i] < value < high - margins[i]
        if pinned and (away[i] or not any(away[:i] + away[i + 1:])):
            return True
    return False


def _as_fitting(candidate: Candidate, runs: Sequence[ClassifiedRun]) -> Candidate:
    """The candidate fitted on the setups of ``runs`` (its own kinds, or when the
    campaign has none of those, the kinds it is otherwise checked on)."""
    setups = tuple(sorted({r.kind.setup for r in runs}, key=lambda f: f.value))
    return replace(candidate, runs=setups)


def key_std(candidate: Candidate, fit: CandidateFit) -> dict[str, float]:
    if candidate.cause == "gear_walk":
        k, c = (fit.values[key] for key in candidate.keys)
        sk, sc = (fit.std[key] for key in candidate.keys)
        keys = key_parameters(candidate, fit.params)
        return {"frequency_hz": keys["frequency_hz"] * sk / (2 * k),
                "damping_ratio": keys["damping_ratio"] * math.hypot(sc / c, sk / (2 * k))}
    return {name: fit.std.get(key, 0.0) for name, key in candidate.contract}


def _evidence(candidate: Candidate, delta_bic: float, held: HeldOut,
              fit_runs: Sequence[Run], held_runs: Sequence[Run],
              signatures: Sequence[Signature]) -> str:
    channels = ", ".join(channel_words(c) for c in candidate.channels)
    words = [f"fitted on {len(fit_runs)} runs ({channels}): "
             f"ΔBIC {delta_bic:+.0f} against the same base parameters re-fitted without it"]
    if held.delta is None:
        words.append("no run left to check it on")
    else:
        gains = ", ".join(f"{channel_words(c)} {held.before[c]:.1f} → {held.after[c]:.1f} %"
                          for c in held.after)
        change = f"better by {-held.delta:.0f}" if held.delta < 0 else \
            f"worse by {held.delta:.0f}"
        words.append(f"on {len(held_runs)} held-out runs: {gains} "
                     f"(log-likelihood {change})")
        if held.denoised:
            channel, clean_before, clean_after = held.denoised
            words.append(f"below {DENOISED_HZ:g} Hz, where the logger's noise is out, "
                         f"{channel_words(channel)} {clean_before:.1f} → {clean_after:.1f} %")
    related = [s.describe() for s in signatures
               if s.channel in candidate.channels and not s.tentative]
    if related:
        words.append("residual before: " + "; ".join(related[:2]))
    return "; ".join(words)
