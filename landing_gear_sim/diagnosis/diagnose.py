"""Diagnose: why the model and the rig disagree (design.md section 5).

1. Calibrate the starting model on the campaign, so a parameter that is merely off
   is re-tuned, not reported as missing physics.
2. Score every candidate the starting model lacks: fit it (its own parameters and
   the base parameters it trades off against) on the runs that carry its signature,
   and fit the same base parameters without it (the *null*: the fair reference).
   ΔBIC = n_eff ln(RSS_candidate / RSS_null) + k ln(n_eff), with n_eff the sample
   count corrected for the residual's autocorrelation (simulation errors are
   smooth: 1 kHz samples are far from independent).
3. Accept the best candidate only if ΔBIC < BIC_THRESHOLD *and* it also improves
   runs it was not fitted on by HELD_OUT_THRESHOLD (same log-likelihood measure,
   no penalty: nothing was fitted there). Adopt it, re-score the candidates that
   had helped, repeat.
4. What remains: spectral lines, pressure lags and regressor correlations of the
   final residual that recur across runs and are large beside the sensor noise
   are reported as ``unexplained`` with that signature, never given a name.
"""

from __future__ import annotations

import math
import multiprocessing
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from landing_gear_sim.calibration.identify import classify, identify
from landing_gear_sim.calibration.validate import CHANNELS, braking_window, simulate_run
from landing_gear_sim.diagnosis import residuals as rs
from landing_gear_sim.diagnosis.catalogue import (
    CATALOGUE,
    Candidate,
    CandidateFit,
    Scales,
    fit_candidate,
    key_parameters,
    noise_scales,
    scaled_error,
    select_runs,
    simulate_all,
    switched_on,
)
from landing_gear_sim.errors import LandingGearSimError
from landing_gear_sim.model.parameters import ELEMENTS, RigParameters
from msg_tools.run import Run

Progress = Callable[[str], None]

BIC_THRESHOLD = -10.0  # "very strong" evidence (Kass & Raftery 1995)
HELD_OUT_THRESHOLD = -10.0
# ... and worth having: mean held-out fit gain over the compared channels [% points]
MIN_GAIN_POINTS = 0.1
MAX_ROUNDS = 4
FRICTION_CURVE = "friction_curve"
REMOVABLE = (*ELEMENTS, FRICTION_CURVE)


class DiagnosisError(LandingGearSimError):
    """The campaign cannot be diagnosed (no usable runs, unknown element)."""


@dataclass(frozen=True)
class Finding:
    """One cause (or unexplained structure) with its evidence.

    ``parameters`` are the key parameters (contract names, SI) and ``std`` their
    1-σ; ``fit_before``/``fit_after`` are fit % per channel on the held-out runs;
    ``delta_bic`` is BIC(with) − BIC(without) on the fitting runs (negative favours
    the extension) and ``held_out`` the same log-likelihood change on held-out runs.
    """

    cause: str
    parameters: dict[str, float]
    std: dict[str, float]
    evidence: str
    fit_before: dict[str, float]
    fit_after: dict[str, float]
    delta_bic: float | None
    held_out: float | None
    accepted: bool
    fitted_on: tuple[str, ...] = ()
    checked_on: tuple[str, ...] = ()

    def to_json(self) -> dict:
        return {"cause": self.cause, "parameters": self.parameters,
                "uncertainty": self.std, "evidence": self.evidence,
                "fit_before": self.fit_before, "fit_after": self.fit_after,
                "delta_bic": self.delta_bic, "held_out_delta": self.held_out,
                "fitted_on": list(self.fitted_on), "checked_on": list(self.checked_on)}


@dataclass(frozen=True)
class Signature:
    """Structure in the residual that recurs across runs.

    ``kind`` is "frequency" (value in Hz), "lag" (s, positive: measurement later) or
    "regressor" (correlation with the named signal); ``size`` compares it with the
    noise (peak power over floor; lag in samples; |correlation| over its band).
    """

    kind: str
    channel: str
    value: float
    size: float
    runs: tuple[str, ...]
    regressor: str = ""

    def describe(self) -> str:
        where = f"{self.channel} residual in {len(self.runs)} runs"
        if self.kind == "frequency":
            return f"spectral line at {self.value:.2f} Hz ({self.size:.0f}x the floor) in {where}"
        if self.kind == "lag":
            return (f"measured {self.channel} lags the simulation by {self.value * 1e3:.1f} ms"
                    f" in {len(self.runs)} runs")
        return (f"{where} correlates with {self.regressor} (r = {self.value:+.2f}, "
                f"{self.size:.1f}x its noise band)")


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

    def to_json(self) -> dict:
        return {"verdict": self.verdict, "findings": [f.to_json() for f in self.findings],
                "baseline": self.baseline,
                "candidates": [f.to_json() | {"accepted": f.accepted} for f in self.candidates],
                "signatures_before": [s.describe() for s in self.signatures_before],
                "signatures_after": [s.describe() for s in self.signatures_after],
                "problems": self.problems}


# --- fit % and information criteria -----------------------------------------------------

def channel_fits(runs: Sequence[Run], simulated: Sequence[Run], channels: Sequence[str]
                 ) -> dict[str, float]:
    """Fit % per channel of ``simulated`` against ``runs``, pooled (each run's own mean
    removed)."""
    errors: dict[str, float] = dict.fromkeys(channels, 0.0)
    spreads: dict[str, float] = dict.fromkeys(channels, 0.0)
    for run, sim in zip(runs, simulated, strict=True):
        for c in channels:
            y = getattr(run, c)
            errors[c] += float(np.sum((y - getattr(sim, c)) ** 2))
            spreads[c] += float(np.sum((y - y.mean()) ** 2))
    return {c: round(100.0 * (1.0 - math.sqrt(errors[c] / spreads[c])), 2)
            for c in channels if spreads[c] > 0}


def effective_count(residual: np.ndarray) -> float:
    """Samples worth of independent information: n (1 − ρ₁)/(1 + ρ₁) (AR(1) residual)."""
    r = residual - residual.mean()
    rho = float(np.clip(r[1:] @ r[:-1] / (r @ r), 0.0, 0.999)) if r @ r > 0 else 0.0
    return max(len(r) * (1 - rho) / (1 + rho), 2.0)


def log_ratio(candidate: np.ndarray, null: np.ndarray) -> float:
    """n_eff ln(RSS_candidate / RSS_null), n_eff from the null's residual."""
    return effective_count(null) * math.log(float(candidate @ candidate) / float(null @ null))


# --- candidates -------------------------------------------------------------------------

def split_runs(candidate: Candidate, runs: Sequence[Run]) -> tuple[list[Run], list[Run]]:
    """Runs to fit the candidate on, and runs kept to check it.

    Actuator effects are checked on the braking runs' pressure. Otherwise the runs
    of each class are sorted by length and alternate between the two sets (the
    shorter to fitting), so both see every kind of test.
    """
    own = select_runs(runs, candidate.runs) or select_runs(
        runs, tuple(kind.split("_")[0] for kind in candidate.runs))
    others = select_runs(runs, candidate.held_out)
    if own and others:
        return own, others
    fit: list[Run] = []
    held: list[Run] = []
    by_class: dict[str, list[Run]] = {}
    for r in own or others:
        by_class.setdefault(classify(r), []).append(r)
    for members in by_class.values():
        for i, r in enumerate(sorted(members, key=len)):
            (fit if i % 2 == 0 else held).append(r)
    return fit, held


@dataclass(frozen=True)
class _Scored:
    finding: Finding
    fit: CandidateFit


def _names(runs: Sequence[Run]) -> tuple[str, ...]:
    return tuple(r.name for r in runs)


def score_candidate(candidate: Candidate, runs: Sequence[Run], model: RigParameters,
                    datasheet: RigParameters, scales: Scales,
                    signatures: Sequence[Signature]) -> _Scored:
    """Fit ``candidate`` and its null on the fitting runs; compare both on held-out runs."""
    fit_runs, held_runs = split_runs(candidate, runs)
    sub = _as_fitting(candidate, fit_runs)
    with_it = fit_candidate(sub, fit_runs, model, datasheet, scales=scales)
    without = fit_candidate(sub, fit_runs, model, datasheet, null=True, scales=scales)
    k = len(candidate.keys)
    n_eff = effective_count(without.residual)
    delta_bic = log_ratio(with_it.residual, without.residual) + k * math.log(n_eff)
    held_delta = None
    before: dict[str, float] = {}
    after: dict[str, float] = {}
    if held_runs:
        channels = candidate.channels
        sim_with = simulate_all(held_runs, with_it.params)
        sim_without = simulate_all(held_runs, without.params)
        held_delta = log_ratio(scaled_error(held_runs, sim_with, channels, scales),
                               scaled_error(held_runs, sim_without, channels, scales))
        before = channel_fits(held_runs, sim_without, channels)
        after = channel_fits(held_runs, sim_with, channels)
    gain = float(np.mean([after[c] - before[c] for c in after])) if after else 0.0
    at_bound = _at_bound(candidate, with_it)
    accepted = (delta_bic < BIC_THRESHOLD and held_delta is not None
                and held_delta < HELD_OUT_THRESHOLD and gain >= MIN_GAIN_POINTS
                and not at_bound)
    parameters = key_parameters(candidate, with_it.params)
    std = _key_std(candidate, with_it)
    finding = Finding(candidate.cause, parameters, std,
                      _evidence(candidate, delta_bic, held_delta, before, after, fit_runs,
                                held_runs, signatures)
                      + ("; a key parameter sits at the edge of its range" if at_bound else ""),
                      before, after, round(delta_bic, 1),
                      None if held_delta is None else round(held_delta, 1), accepted,
                      _names(fit_runs), _names(held_runs))
    return _Scored(finding, with_it)


def _at_bound(candidate: Candidate, fit: CandidateFit) -> bool:
    """A key pinned to the edge of its range: the data want the element off (or more
    than it can give) — not evidence for it."""
    for key, (low, high) in zip(candidate.keys, candidate.bounds, strict=True):
        margin = 0.01 * (high - low)
        if not low + margin < fit.values[key] < high - margin:
            return True
    return False


def _as_fitting(candidate: Candidate, runs: Sequence[Run]) -> Candidate:
    """The candidate fitted on the kinds of ``runs`` (its own kinds, or when the campaign
    has none of those, the kinds it is otherwise checked on)."""
    kinds = tuple(sorted({classify(r).split("_")[0] for r in runs}))
    return replace(candidate, runs=kinds)


def _key_std(candidate: Candidate, fit: CandidateFit) -> dict[str, float]:
    if candidate.cause == "gear_walk":
        k, c = (fit.values[key] for key in candidate.keys)
        sk, sc = (fit.std[key] for key in candidate.keys)
        keys = key_parameters(candidate, fit.params)
        return {"frequency_hz": keys["frequency_hz"] * sk / (2 * k),
                "damping_ratio": keys["damping_ratio"] * math.hypot(sc / c, sk / (2 * k))}
    return {name: fit.std.get(key, 0.0) for name, key in candidate.contract}


def _evidence(candidate: Candidate, delta_bic: float, held: float | None,
              before: dict[str, float], after: dict[str, float], fit_runs: Sequence[Run],
              held_runs: Sequence[Run], signatures: Sequence[Signature]) -> str:
    words = [f"fitted on {len(fit_runs)} runs ({', '.join(candidate.channels)}): "
             f"ΔBIC {delta_bic:+.0f} against the same base parameters re-fitted without it"]
    if held is None:
        words.append("no run left to check it on")
    else:
        gains = ", ".join(f"{c} {before[c]:.1f} → {after[c]:.1f} %" for c in after)
        words.append(f"on {len(held_runs)} held-out runs: {gains} "
                     f"(log-likelihood change {held:+.0f})")
    related = [s.describe() for s in signatures if s.channel in candidate.channels]
    if related:
        words.append("residual before: " + "; ".join(related[:2]))
    return "; ".join(words)


# --- residual signatures ----------------------------------------------------------------

LINE_SIZE = 30.0  # a spectral line this far over the floor is structure, not noise
LAG_SAMPLES = 1.0  # a consistent lag of a sample or more
CORRELATION = 0.3  # |r| of the residual with a regressor ...
CORRELATION_BANDS = 3.0  # ... and that many times its noise band
# below 2 Hz a mis-calibrated model leaves a smooth trend, not a line
LINE_BAND_HZ = (2.0, 200.0)


def _regressors(run: Run, params: RigParameters) -> dict[str, np.ndarray]:
    speed = run.flywheel_speed_rad_s * params.number("flywheel.radius_m")
    wheel = run.wheel_speed_rad_s * params.number("wheel.unloaded_radius_m")
    smooth_pressure = np.convolve(run.pressure_pa, np.ones(20) / 20, mode="same")
    energy = np.cumsum(np.clip(run.pressure_pa, 0, None) * np.clip(run.wheel_speed_rad_s, 0, None))
    return {"vertical load": run.vertical_load_n, "speed": speed,
            "slip": 1.0 - wheel / np.maximum(speed, 1.0), "pressure": run.pressure_pa,
            "brake energy": energy, "pressure direction": np.sign(np.gradient(smooth_pressure))}


def find_signatures(runs: Sequence[Run], params: RigParameters) -> list[Signature]:
    """Structure of the residuals of ``params`` that recurs in at least two runs."""
    lines: dict[str, list[tuple[str, float, float]]] = {}
    lags: list[tuple[str, float]] = []
    correlations: dict[str, list[tuple[str, float, float]]] = {}
    for run in runs:
        simulated, _ = simulate_run(run, params)
        kind = classify(run)
        actuator = kind.startswith("actuator")
        channels = ["pressure_pa"] + ([] if actuator else ["wheel_speed_rad_s"])
        window = np.ones(len(run), bool) if actuator else braking_window(run, params)
        for channel in channels:
            if window.sum() < 2048:
                continue
            error = getattr(run, channel) - getattr(simulated, channel)
            for peak in rs.spectrum(error[window], run.rate_hz, band_hz=LINE_BAND_HZ).peaks[:3]:
                lines.setdefault(channel, []).append((run.name, peak.frequency_hz, peak.ratio))
            if channel == "wheel_speed_rad_s":
                for c in rs.regressor_correlations(error[window],
                                                   {k: v[window] for k, v in
                                                    _regressors(run, params).items()}):
                    correlations.setdefault(c.name, []).append((run.name, c.value, c.band))
        if np.ptp(run.pressure_pa) > 5e5:
            lags.append((run.name, rs.lag_samples(run.pressure_pa, simulated.pressure_pa, 50)
                         / run.rate_hz))
    return [*_recurring_lines(lines), *_consistent_lag(lags, runs),
            *_consistent_correlations(correlations)]


def _recurring_lines(lines: dict[str, list[tuple[str, float, float]]]) -> list[Signature]:
    out = []
    for channel, found in lines.items():
        strong = sorted((f for f in found if f[2] > LINE_SIZE), key=lambda f: -f[2])
        used: set[int] = set()
        for i, (_, freq, ratio) in enumerate(strong):
            if i in used:
                continue
            near = [j for j, f in enumerate(strong)
                    if j not in used and abs(f[1] - freq) <= max(0.5, 0.05 * freq)]
            names = {strong[j][0] for j in near}
            used.update(near)
            if len(names) >= 2:
                out.append(Signature("frequency", channel, freq, ratio, tuple(sorted(names))))
    return out


def _consistent_lag(lags: list[tuple[str, float]], runs: Sequence[Run]) -> list[Signature]:
    if len(lags) < 2:
        return []
    values = np.array([v for _, v in lags])
    rate = float(np.median([r.rate_hz for r in runs]))
    median = float(np.median(values))
    same_sign = np.mean(np.sign(values) == np.sign(median))
    if abs(median) * rate >= LAG_SAMPLES and same_sign >= 0.75:
        return [Signature("lag", "pressure_pa", median, abs(median) * rate,
                          tuple(n for n, _ in lags))]
    return []


def _consistent_correlations(found: dict[str, list[tuple[str, float, float]]]
                             ) -> list[Signature]:
    out = []
    for name, values in found.items():
        strong = [(run, r, band) for run, r, band in values
                  if abs(r) > max(CORRELATION_BANDS * band, CORRELATION)]
        if len(strong) < 2 or len(strong) < 0.6 * len(values):
            continue
        signs = {np.sign(r) for _, r, _ in strong}
        if len(signs) == 1:
            r = float(np.mean([r for _, r, _ in strong]))
            size = float(np.mean([abs(r) / band for _, r, band in strong]))
            out.append(Signature("regressor", "wheel_speed_rad_s", r, size,
                                 tuple(run for run, _, _ in strong), name))
    return sorted(out, key=lambda s: -abs(s.value))


def unexplained(signatures: Sequence[Signature], baseline: dict[str, float]) -> Finding:
    """The strongest remaining signature as an ``unexplained`` finding."""
    best = signatures[0]
    parameter = {"frequency": "frequency_hz", "lag": "lag_s", "regressor": "correlation"}
    return Finding("unexplained", {parameter[best.kind]: round(best.value, 6)}, {},
                   "no candidate of the catalogue explains: "
                   + "; ".join(s.describe() for s in signatures[:3]),
                   baseline, baseline, None, None, False, best.runs, ())


# --- driver -----------------------------------------------------------------------------

def starting_model(base: RigParameters, without: Sequence[str]) -> RigParameters:
    """``base`` with the elements of ``without`` removed (friction_curve: not calibrated)."""
    unknown = [w for w in without if w not in REMOVABLE]
    if unknown:
        raise DiagnosisError(f"--without {unknown[0]}: not a model element; choose from "
                             f"{', '.join(REMOVABLE)}")
    return base.without(*(w for w in without if w != FRICTION_CURVE))


def candidates_for(start: RigParameters, without: Sequence[str]) -> list[Candidate]:
    """Catalogue entries the starting model lacks."""
    return [c for c in CATALOGUE.values()
            if (c.element is not None and not start.has(c.element))
            or (c.element is None and FRICTION_CURVE in without)]


def diagnose(runs: Sequence[Run], base: RigParameters, without: Sequence[str] = (),
             progress: Progress | None = None) -> Diagnosis:
    """Calibrate, score the candidates, extend the model, report what remains."""
    say = progress or (lambda _msg: None)
    if not runs:
        raise DiagnosisError("no run to diagnose")
    start = starting_model(base, without)
    say(f"calibrating the starting model on {len(runs)} runs")
    calibration = identify(runs, start, progress=say, friction=FRICTION_CURVE not in without,
                           jackknife=False)
    problems = list(calibration.problems)
    calibrated = calibration.params
    baseline = _baseline(runs, calibrated)
    say("analysing the residuals of the calibrated model")
    before = find_signatures(runs, calibrated)
    scales = noise_scales(runs, tuple(CHANNELS))
    pending = candidates_for(start, without)
    model = calibrated
    accepted: list[_Scored] = []
    table: list[Finding] = []
    for round_ in range(1, MAX_ROUNDS + 1):
        if not pending:
            break
        say(f"round {round_}: fitting {', '.join(c.cause for c in pending)}")
        scored = []
        for outcome in _score_all(pending, runs, model, base, scales, before, say):
            if isinstance(outcome, str):
                problems.append(outcome)
            else:
                scored.append(outcome)
        table.extend(s.finding for s in scored)
        winners = [s for s in scored if s.finding.accepted]
        if not winners:
            break
        best = min(winners, key=lambda s: s.finding.delta_bic or 0.0)
        say(f"accepted {best.finding.cause}: {best.finding.evidence}")
        accepted.append(best)
        say(f"re-calibrating with {', '.join(s.finding.cause for s in accepted)}")
        model, accepted = _recalibrate(runs, start, accepted, without)
        pending = [CATALOGUE[s.finding.cause] for s in scored
                   if s is not best and (s.finding.delta_bic or 0.0) < 0]
    say("analysing the residuals of the extended model")
    after = find_signatures(runs, model)
    findings = [s.finding for s in accepted]
    if after:
        findings.append(unexplained(after, _baseline(runs, model)))
    verdict = findings[0].cause if findings else "none"
    return Diagnosis(verdict, findings, table, baseline, start, calibrated, model,
                     before, after, problems)


def _score_one(candidate: Candidate, runs: Sequence[Run], model: RigParameters,
               datasheet: RigParameters, scales: Scales,
               signatures: Sequence[Signature]) -> _Scored | str:
    try:
        return score_candidate(candidate, runs, model, datasheet, scales, signatures)
    except ValueError as exc:
        return f"{candidate.cause}: not scored ({exc})"


def _score_all(pending: Sequence[Candidate], runs: Sequence[Run], model: RigParameters,
               datasheet: RigParameters, scales: Scales, signatures: Sequence[Signature],
               say: Progress) -> list[_Scored | str]:
    """Score the candidates, in parallel processes when there are cores to spare (each
    fit is independent and single-threaded); in order of ``pending``."""
    workers = min(len(pending), os.cpu_count() or 1)
    if workers < 2:
        return [_score_one(c, runs, model, datasheet, scales, signatures) for c in pending]
    # fork: the children inherit the compiled physics instead of compiling it again
    context = multiprocessing.get_context("fork")
    with ProcessPoolExecutor(workers, mp_context=context) as pool:
        futures = {pool.submit(_score_one, c, runs, model, datasheet, scales, signatures): c
                   for c in pending}
        for future in as_completed(futures):
            say(f"  {futures[future].cause} scored")
        return [next(f for f, c in futures.items() if c is candidate).result()
                for candidate in pending]


def _recalibrate(runs: Sequence[Run], start: RigParameters, accepted: list[_Scored],
                 without: Sequence[str]) -> tuple[RigParameters, list[_Scored]]:
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
        std = {k: estimated[k].std if k in estimated else s.fit.std.get(k, 0.0)
               for k in candidate.keys}
        values = {k: model.number(k) for k in candidate.keys}
        final = replace(s.fit, params=model, values=values, std=std)
        finding = replace(s.finding, parameters=key_parameters(candidate, model),
                          std=_key_std(candidate, final))
        out.append(_Scored(finding, final))
    return model, out


def _baseline(runs: Sequence[Run], params: RigParameters) -> dict[str, float]:
    """Fit % per channel: pressure over every run, the rest over the braking runs."""
    simulated = simulate_all(runs, params)
    fits = channel_fits(runs, simulated, ("pressure_pa",))
    braking = [i for i, r in enumerate(runs) if classify(r).startswith("brake")]
    if braking:
        fits.update(channel_fits([runs[i] for i in braking], [simulated[i] for i in braking],
                                 tuple(c for c in CHANNELS if c != "pressure_pa")))
    return fits


# --- report -----------------------------------------------------------------------------

def report_sections(result: Diagnosis, runs: Sequence[Run], folder: Path
                    ) -> list[tuple[str, str]]:
    """HTML sections of the diagnosis page; figures are written into ``folder``.

    Simulates each run once with the starting (calibrated) and the extended model;
    the plotting functions only draw.
    """
    from landing_gear_sim.report.validation import (
        html_image,
        html_table,
        plot_before_after,
        plot_spectrum,
    )

    def fits(values: dict[str, float]) -> str:
        return ", ".join(f"{c}: {v:.2f} %" for c, v in values.items())

    findings = html_table(
        ["cause", "parameters (SI) ± 1σ", "ΔBIC", "held-out Δ", "held-out fit before",
         "after", "evidence"],
        [[f.cause, ", ".join(f"{k} = {v:.5g}" + (f" ± {f.std[k]:.2g}" if k in f.std else "")
                             for k, v in f.parameters.items()),
          _text(f.delta_bic), _text(f.held_out), fits(f.fit_before), fits(f.fit_after),
          f.evidence] for f in result.findings])
    candidates = html_table(
        ["cause", "accepted", "key parameters", "ΔBIC", "held-out Δ", "fitted on",
         "checked on"],
        [[f.cause, "yes" if f.accepted else "no",
          ", ".join(f"{k} = {v:.4g}" for k, v in f.parameters.items()), _text(f.delta_bic),
          _text(f.held_out), ", ".join(f.fitted_on), ", ".join(f.checked_on)]
         for f in result.candidates])
    verdict = (f"<p><b>Verdict: {result.verdict}</b>. Starting model: "
               f"{', '.join(result.start.sources)}. ΔBIC = BIC(with) − BIC(without) on the "
               f"fitting runs (accepted below {BIC_THRESHOLD:g}, and only if the held-out "
               f"runs improve by more than {-HELD_OUT_THRESHOLD:g} in the same "
               f"log-likelihood units).</p>")
    sections = [("Verdict", verdict + findings), ("Candidates", candidates),
                ("Starting model, calibrated: fit %", html_table(
                    ["channel", "fit %"], [[c, f"{v:.2f}"] for c, v in result.baseline.items()])),
                ("Residual structure", html_table(
                    ["model", "signature"],
                    [["calibrated starting model", s.describe()] for s in result.signatures_before]
                    + [["extended model", s.describe()] for s in result.signatures_after]))]
    for run in runs:
        kind = classify(run)
        channels = ("pressure_pa",) if kind.startswith("actuator") else (
            "pressure_pa", "wheel_speed_rad_s", "longitudinal_force_n")
        before, _ = simulate_run(run, result.calibrated)
        after, _ = simulate_run(run, result.extended)
        figure = plot_before_after(run, before, after, channels, folder / f"{run.name}.png")
        body = html_image(figure, folder)
        channel = channels[-2] if len(channels) > 1 else channels[0]
        window = (np.ones(len(run), bool) if kind.startswith("actuator")
                  else braking_window(run, result.calibrated))
        if window.sum() >= 2048:
            error = (getattr(run, channel) - getattr(before, channel))[window]
            spectrum = rs.spectrum(error, run.rate_hz, band_hz=LINE_BAND_HZ)
            unit = "Pa" if channel == "pressure_pa" else "rad/s"
            figure = plot_spectrum(spectrum, f"{run.name}: {channel} residual of the "
                                   "calibrated starting model", unit,
                                   folder / f"{run.name}_spectrum.png")
            body += html_image(figure, folder)
        sections.append((f"{run.name} ({kind})", body))
    return sections


def _text(value: float | None) -> str:
    return "-" if value is None else f"{value:+.1f}"
