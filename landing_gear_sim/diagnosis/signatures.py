"""Residual signatures: structure in the residuals of a model that recurs across runs.

Spectral lines of the pressure and wheel-speed residuals over the running-median floor
(:mod:`~landing_gear_sim.diagnosis.residuals`), a pressure lag consistent over the runs,
and a wheel-speed residual correlated with load, speed, slip, pressure, brake energy or
pressure direction in most runs. What the final model leaves is reported as an
``unexplained`` finding with its signature, never given a name.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.runs import ClassifiedRun, braking_window
from landing_gear_sim.diagnosis import residuals as rs
from landing_gear_sim.diagnosis.equations.placing import Place
from landing_gear_sim.diagnosis.findings import Finding, Signature, SignatureKind
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.elements import slip_ratio
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import rim_speed_m_s
from msg_tools.run import Run
from msg_tools.units import PA_PER_BAR

LINE_SIZE = 30.0  # a spectral line this far over the floor is structure, not noise
LAG_SAMPLES = 1.0  # a consistent lag of a sample or more ...
TIMING_FILTER_HZ = 50.0
LAG_Z = 4.0  # ... that many standard errors of the runs' median from zero
MAD_TO_STD = 1.4826  # σ of normal values from their median absolute deviation
MEDIAN_EFFICIENCY = 1.2533  # a median's standard error over a mean's (normal values)
CORRELATION = 0.3  # |r| of the residual with a regressor ...
CORRELATION_BANDS = 3.0  # ... and that many times its noise band
# below 2 Hz a mis-calibrated model leaves a smooth trend, not a line
LINE_BAND_HZ = (2.0, 200.0)
MIN_SPECTRUM_SAMPLES = 2048  # one Welch segment: a shorter window shows no line
LAG_PRESSURE_SPAN_PA = 5 * PA_PER_BAR  # a run whose pressure moves this much shows a lag
# ... and a run shows its timing where the model's transitions (sample to sample) stand out
# of the channel's noise there: rms over the error's std; a 64-line encoder's stops at
# constant pressure read 0.006-0.03 (lags of 0.0 or ±14 ms for a 20 ms skew), its cycling
# stops 0.35-1.0
TIMING_SNR = 0.2


def _regressors(run: Run, model: Run, params: RigParameters) -> dict[str, np.ndarray]:
    """What the wheel-speed residual may depend on. Nothing here is read from the measured
    wheel channel (its noise would correlate with itself: slip read from a counting
    encoder's wheel speed correlated with the residual at r = −0.77 on a null campaign):
    where the wheel speed enters, the ``model``'s simulation of it does."""
    speed = rim_speed_m_s(params, run.flywheel_speed_rad_s)
    wheel = model.wheel_speed_rad_s
    slip = slip_ratio(speed, wheel, params.number(K.WHEEL_UNLOADED_RADIUS_M))
    smooth_pressure = np.convolve(run.pressure_pa, np.ones(20) / 20, mode="same")
    energy = np.cumsum(np.clip(run.pressure_pa, 0, None) * np.clip(wheel, 0, None))
    return {"vertical load": run.vertical_load_n, "speed": speed,
            "slip": slip, "pressure": run.pressure_pa,
            "brake energy": energy, "pressure direction": np.sign(np.gradient(smooth_pressure))}


@dataclass(frozen=True)
class RunEvidence:
    """One run as the diagnosis saw it: measured, simulated by the calibrated starting model
    (``before``) and by the extended one (``after``), and the starting model's residual
    spectrum on ``channel`` (wheel speed in a braking run, pressure otherwise; None when the
    window is too short for one)."""

    run: ClassifiedRun
    before: Run
    after: Run
    channel: str
    spectrum: rs.Spectrum | None


def run_evidence(run: ClassifiedRun, before: Run, after: Run, params: RigParameters
                 ) -> RunEvidence:
    """The evidence of one run (``params``: the calibrated starting model of ``before``)."""
    channel = "wheel_speed_rad_s" if run.braking else "pressure_pa"
    window = _window(run, params)
    spectrum = None
    if window.sum() >= MIN_SPECTRUM_SAMPLES:
        error = (getattr(run, channel) - getattr(before, channel))[window]
        spectrum = rs.spectrum(error, run.rate_hz, band_hz=LINE_BAND_HZ)
    return RunEvidence(run, before, after, channel, spectrum)


def _window(run: ClassifiedRun, params: RigParameters) -> np.ndarray:
    """The samples whose residual carries structure: the braking phase, or all of an
    actuator run."""
    return braking_window(run, params) if run.braking else np.ones(len(run), bool)


def find_signatures(runs: Sequence[ClassifiedRun], params: RigParameters,
                    simulated: Sequence[Run], tentative: bool = False) -> list[Signature]:
    """Structure of the residuals of ``params`` (``simulated``: the runs simulated with it)
    that recurs in at least two runs (with ``tentative``, also the lags too scattered to
    report, which may call for a candidate)."""
    lines: dict[str, list[tuple[str, float, float]]] = {}
    lags: dict[str, list[tuple[str, float]]] = {}
    correlations: dict[str, list[tuple[str, float, float]]] = {}
    for run, model in zip(runs, simulated, strict=True):
        channels = ["pressure_pa"] + (["wheel_speed_rad_s"] if run.braking else [])
        window = _window(run, params)
        for channel in channels:
            if window.sum() < MIN_SPECTRUM_SAMPLES:
                continue
            error = getattr(run, channel) - getattr(model, channel)
            for peak in rs.spectrum(error[window], run.rate_hz, band_hz=LINE_BAND_HZ).peaks[:3]:
                lines.setdefault(channel, []).append((run.name, peak.frequency_hz, peak.ratio))
            if channel == "wheel_speed_rad_s":
                for c in rs.regressor_correlations(error[window],
                                                   {k: v[window] for k, v in
                                                    _regressors(run, model, params).items()}):
                    correlations.setdefault(c.name, []).append((run.name, c.value, c.band))
        for channel, timed in _timed_channels(run, window).items():
            read, predicted = (_timing(getattr(x, channel), channel, run.rate_hz)[timed]
                               for x in (run, model))
            if _shows_timing(read, predicted):
                lags.setdefault(channel, []).append(
                    (run.name, rs.lag_samples(read, predicted, 50) / run.rate_hz))
    found = [*_recurring_lines(lines),
             *(s for channel, found in lags.items() for s in _consistent_lag(channel, found, runs)),
             *_consistent_correlations(correlations)]
    return [s for s in found if tentative or not s.tentative]


def _timing(values: np.ndarray, channel: str, rate_hz: float) -> np.ndarray:
    """What a channel's timing is read from: the wheel channel low-passed (zero phase) at
    TIMING_FILTER_HZ, so that a counting encoder's steps (98 rad/s at 1 kHz for 64 lines)
    do not make the lag (a 256-line encoder read −5 ms under the very model that made the
    log); the pressure as it is."""
    if channel != "wheel_speed_rad_s":
        return values
    return br.lowpass(values, rate_hz, min(TIMING_FILTER_HZ, 0.4 * rate_hz))


def _shows_timing(read: np.ndarray, predicted: np.ndarray) -> bool:
    """Whether the model's transitions stand out of the channel's noise (TIMING_SNR)."""
    transitions = np.diff(predicted)
    noise = float(np.std(np.diff(read) - transitions))
    return float(np.sqrt(np.mean(transitions**2))) >= TIMING_SNR * noise


def _timed_channels(run: ClassifiedRun, window: np.ndarray) -> dict[str, np.ndarray]:
    """The channels whose timing ``run`` shows, with the samples that show it: the pressure
    where it moves (the whole run), the wheel in a stop's ``window``."""
    timed = {"pressure_pa": np.ones(len(run), dtype=bool)} \
        if np.ptp(run.pressure_pa) > LAG_PRESSURE_SPAN_PA else {}
    if run.braking and window.sum() >= MIN_SPECTRUM_SAMPLES:
        # a logger channel out of step with the others (20 ms once gave 'none')
        timed["wheel_speed_rad_s"] = window
    return timed


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
                out.append(Signature(SignatureKind.FREQUENCY, channel, freq, ratio,
                                     tuple(sorted(names))))
    return out


def _consistent_lag(channel: str, lags: list[tuple[str, float]], runs: Sequence[Run]
                    ) -> list[Signature]:
    """A lag the runs agree on: a sample or more, of one sign in most runs; *tentative*
    unless LAG_Z standard errors of the runs' median from zero. The error is robust (from
    the median absolute deviation: a smoothly decelerating wheel reads any error in its
    speed as a lag, −24 to +2 ms over the stops of one null campaign) and no smaller than
    the log's own timing, a period/√12 per run. A tentative lag is never reported, but may
    call for a candidate, which held-out runs then judge (a 5.5 ms skew read 1 to 8 ms over
    the stops: too scattered to report, enough to try)."""
    if len(lags) < 2:
        return []
    values = np.array([v for _, v in lags])
    rate = float(np.median([r.rate_hz for r in runs]))
    median = float(np.median(values))
    same_sign = np.mean(np.sign(values) == np.sign(median))
    spread = MAD_TO_STD * float(np.median(np.abs(values - median)))
    error = MEDIAN_EFFICIENCY * max(spread, 1.0 / (rate * math.sqrt(12.0))) / math.sqrt(
        values.size)
    if abs(median) * rate >= LAG_SAMPLES and same_sign >= 0.75:
        return [Signature(SignatureKind.LAG, channel, median, abs(median) * rate,
                          tuple(n for n, _ in lags), tentative=abs(median) < LAG_Z * error)]
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
            out.append(Signature(SignatureKind.REGRESSOR, "wheel_speed_rad_s", r, size,
                                 tuple(run for run, _, _ in strong), name))
    return sorted(out, key=lambda s: -abs(s.value))


def window_regressors(run: ClassifiedRun, model: Run, params: RigParameters
                      ) -> dict[str, np.ndarray]:
    """What a braking run's wheel-speed residual is correlated with, over its window."""
    window = _window(run, params)
    return {k: v[window] for k, v in _regressors(run, model, params).items()}


def unexplained(signatures: Sequence[Signature], baseline: dict[str, float],
                places: Sequence[Place | None] = ()) -> Finding:
    """The strongest remaining signature as an ``unexplained`` finding, each with the
    equation it lives in where ``places`` (:func:`~.equations.locate_all`) tell."""
    best = signatures[0]
    where = list(places) + [None] * (len(signatures) - len(places))
    words = [s.describe() + (f" — {place.describe()}" if place else "")
             for s, place in zip(signatures[:3], where, strict=False)]
    equation = where[0].equation.value if where[0] else _channel_equation(best.channel)
    return Finding(cause="unexplained", parameters={best.kind.parameter: round(best.value, 6)},
                   std={}, evidence="no candidate of the catalogue explains: "
                   + "; ".join(words), fit_before=baseline, fit_after=baseline, delta_bic=None,
                   held_out=None, accepted=False, fitted_on=best.runs, equation=equation,
                   channel=best.channel)


def _channel_equation(channel: str) -> str:
    """Where a signature no equation's error carries lives: its channel's measurement (a
    lag is the channel's own timing)."""
    return {"pressure_pa": "pressure channel", "wheel_speed_rad_s": "wheel channel"}.get(
        channel, channel)
