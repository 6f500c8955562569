"""Residual analysis: detections on known effects, and false alarms at the stated level."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal

from landing_gear_sim.diagnosis import residuals as rs
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate

RATE = 1000.0


def _smooth_noise(rng: np.random.Generator, n: int, cutoff_hz: float = 2.0) -> np.ndarray:
    sos = scipy.signal.butter(2, cutoff_hz / (RATE / 2), output="sos")
    return scipy.signal.sosfilt(sos, rng.normal(size=n))


def test_spectrum_finds_a_buried_line_at_its_frequency():
    rng = np.random.default_rng(0)
    t = np.arange(20000) / RATE
    residual = 0.15 * np.sin(2 * np.pi * 8.0 * t) + rng.normal(size=t.size)
    peaks = rs.spectrum(residual, RATE).peaks
    assert peaks and peaks[0].frequency_hz == pytest.approx(8.0, abs=0.5)


def test_spectrum_false_alarms_stay_near_the_stated_level():
    alarms = sum(bool(rs.spectrum(np.random.default_rng(s).normal(size=20000), RATE).peaks)
                 for s in range(200))
    assert alarms <= 8  # 1 % family-wise: expect ~2 of 200


def test_autocorrelation_leaves_its_band_only_for_a_correlated_residual():
    white = np.random.default_rng(3).normal(size=5000)
    ar = scipy.signal.lfilter([1.0], [1.0, -0.6], np.random.default_rng(4).normal(size=5000))
    assert rs.autocorrelation(white, 30).outside < 0.05
    assert rs.autocorrelation(ar, 30).outside > 0.05


@pytest.mark.parametrize("delay_s", [0.0034, 0.008])
def test_lag_estimate_recovers_an_actuator_delay_between_samples(reference, delay_s):
    scenario = sc.actuator_test(reference, sc.steps_then_sweep(), 12.0)
    plain = simulate(reference, scenario).pressure_pa
    delayed = simulate(reference.replace({"elements.actuator_delay": True,
                                          "actuator.delay_s": delay_s}), scenario).pressure_pa
    noisy = delayed + np.random.default_rng(3).normal(0, 1.5e4, delayed.size)
    assert rs.lag_samples(noisy, plain, 50) == pytest.approx(delay_s * RATE, abs=0.3)
    assert rs.lag_samples(plain, noisy, 50) == pytest.approx(-delay_s * RATE, abs=0.3)


def test_regressor_correlation_names_the_signal_in_the_residual():
    rng = np.random.default_rng(4)
    load, speed = _smooth_noise(rng, 20000), _smooth_noise(rng, 20000)
    residual = 0.5 * load / np.std(load) + rng.normal(size=20000)
    found = rs.regressor_correlations(residual, {"speed": speed, "load": load})
    assert found[0].name == "load" and found[0].significant


def test_smooth_unrelated_signals_are_not_called_correlated():
    """Two independent smooth series look correlated to a naive test; not to this one."""
    alarms = 0
    for s in range(60):
        rng = np.random.default_rng(100 + s)
        a, b = _smooth_noise(rng, 20000, 1.0), _smooth_noise(rng, 20000, 1.0)
        alarms += rs.regressor_correlations(a, {"b": b})[0].significant
    assert alarms <= 4
