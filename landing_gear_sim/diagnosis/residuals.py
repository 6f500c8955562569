"""Residual analysis: where and how a simulation misses a measurement (math only).

Every test here states its false-alarm level: a peak, a correlation or a lag is
reported only when it stands out of what noise alone would produce.

* spectrum peaks: Welch PSD against a running-median noise floor; a bin over the
  floor is F-distributed (Welch's equivalent dof for the bin, the median's for
  the floor), tested at a family-wise level over all bins (Bonferroni);
* normalised autocorrelation with ±z/√N bands for white residuals;
* lag between a measured and a simulated signal: cross-correlation of their
  derivatives, refined between samples by a parabola;
* correlation with candidate regressors, using the effective sample count of
  two autocorrelated series (Bartlett).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import scipy.ndimage
import scipy.signal
import scipy.stats

FALSE_ALARM = 0.01  # family-wise, per test
FLOOR_BINS = 31  # running-median width of the spectral noise floor
HANN_OVERLAP_CORRELATION = 0.167  # Welch (1967): Hann windows overlapping by half


@dataclass(frozen=True)
class SpectrumPeak:
    """A spectral line of the residual: frequency [Hz], power over the noise floor [-]."""

    frequency_hz: float
    ratio: float


@dataclass(frozen=True)
class Spectrum:
    """Welch PSD of a residual (unit²/Hz), its noise floor and the significant peaks."""

    frequency_hz: np.ndarray
    psd: np.ndarray
    floor: np.ndarray
    threshold: float
    peaks: tuple[SpectrumPeak, ...]


def spectrum(residual: np.ndarray, rate_hz: float, segment: int = 2048,
             band_hz: tuple[float, float] = (0.5, 200.0)) -> Spectrum:
    """Welch PSD and the peaks that stand above the running-median floor."""
    x = np.asarray(residual, dtype=float) - np.mean(residual)
    nperseg = min(segment, x.size)
    f, psd = scipy.signal.welch(x, rate_hz, nperseg=nperseg)
    segments = max(1, 2 * x.size // nperseg - 1)  # 50 % overlap
    dof = 2 * segments / (1 + 2 * HANN_OVERLAP_CORRELATION ** 2)  # Welch's equivalent dof
    # the DC bin and its neighbour are nearly emptied by detrending: keep them out of
    # the floor, or it sits low at the bottom of the band and raises false alarms there
    floor = np.empty_like(psd)
    floor[:2] = np.inf
    floor[2:] = scipy.ndimage.median_filter(psd[2:], size=FLOOR_BINS, mode="reflect")
    # median of χ²(ν)/ν is below 1: scale so the floor estimates the mean
    floor = floor / (scipy.stats.chi2.median(dof) / dof)
    inside = (f >= band_hz[0]) & (f <= band_hz[1]) & np.isfinite(floor)
    level = FALSE_ALARM / max(int(inside.sum()), 1)
    # bin / floor ~ F(ν, ν_floor); a median of M bins is worth (2/π) M of them
    floor_dof = 2 / np.pi * FLOOR_BINS * dof
    threshold = float(scipy.stats.f.isf(level, dof, floor_dof))
    ratio = np.where(np.isfinite(floor) & (floor > 0), psd / floor, 0.0)
    candidates = np.flatnonzero(inside & (ratio > threshold))
    peaks = [SpectrumPeak(float(f[i]), float(ratio[i])) for i in candidates
             if ratio[i] >= ratio[max(i - 1, 0)] and ratio[i] >= ratio[min(i + 1, f.size - 1)]]
    peaks.sort(key=lambda peak: -peak.ratio)
    return Spectrum(f, psd, floor, threshold, tuple(peaks))


@dataclass(frozen=True)
class Correlation:
    """Normalised correlation at lags 0..max (or −max..max), and its ±band (noise only)."""

    lags: np.ndarray
    values: np.ndarray
    band: float

    @property
    def outside(self) -> float:
        """Fraction of lags (zero excluded) whose value leaves the band."""
        mask = self.lags != 0
        return float(np.mean(np.abs(self.values[mask]) > self.band))


def autocorrelation(residual: np.ndarray, max_lag: int) -> Correlation:
    """Normalised autocorrelation, band ±z/√N for white residuals."""
    x = np.asarray(residual, dtype=float) - np.mean(residual)
    n = x.size
    full = scipy.signal.correlate(x, x, mode="full", method="fft")[n - 1: n + max_lag] / (x @ x)
    return Correlation(np.arange(max_lag + 1), full, _band(n))


def _band(n: int) -> float:
    return float(scipy.stats.norm.isf(FALSE_ALARM / 2) / np.sqrt(n))


def lag_samples(measured: np.ndarray, simulated: np.ndarray, max_lag: int) -> float:
    """How many samples ``measured`` lags ``simulated`` (positive: measured is later).

    Correlates the first differences (the transitions carry the timing), and
    refines the best integer lag with a parabola through its neighbours.
    """
    a = np.diff(np.asarray(simulated, dtype=float))
    b = np.diff(np.asarray(measured, dtype=float))
    full = scipy.signal.correlate(b, a, mode="full", method="fft")
    centre = a.size - 1
    window = full[centre - max_lag: centre + max_lag + 1]
    k = int(np.argmax(window))
    shift = 0.0
    if 0 < k < window.size - 1:
        left, mid, right = window[k - 1], window[k], window[k + 1]
        denominator = left - 2 * mid + right
        shift = 0.5 * (left - right) / denominator if denominator != 0 else 0.0
    return float(k - max_lag + shift)


@dataclass(frozen=True)
class RegressorCorrelation:
    """Correlation of the residual with a candidate signal, and its null band."""

    name: str
    value: float
    band: float

    @property
    def significant(self) -> bool:
        return abs(self.value) > self.band


def effective_samples(a: np.ndarray, b: np.ndarray, max_lag: int = 2000) -> float:
    """Bartlett's effective sample count for the correlation of two autocorrelated series."""
    n = len(a)
    lag = min(max_lag, n - 1)
    ra = autocorrelation(a, lag).values
    rb = autocorrelation(b, lag).values
    total = 1.0 + 2.0 * float(np.sum(ra[1:] * rb[1:]))
    return max(n / max(total, 1.0), 3.0)


def regressor_correlations(residual: np.ndarray, candidates: Mapping[str, np.ndarray]
                           ) -> list[RegressorCorrelation]:
    """Correlation of the residual with each candidate (load, speed, slip, ...), best first."""
    out = []
    for name, signal in candidates.items():
        if np.ptp(signal) == 0:
            continue
        value = float(np.corrcoef(residual, signal)[0, 1])
        n_eff = effective_samples(residual, signal)
        out.append(RegressorCorrelation(name, value, _band(int(n_eff))))
    return sorted(out, key=lambda c: -abs(c.value) / c.band)
