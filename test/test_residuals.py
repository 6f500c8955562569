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


def test_white_residual_passes_and_correlated_fails_ljung_box():
    rejections = sum(rs.ljung_box(np.random.default_rng(s).normal(size=5000), 30)[1] < 0.01
                     for s in range(200))
    assert rejections <= 8
    ar = scipy.signal.lfilter([1.0], [1.0, -0.5], np.random.default_rng(1).normal(size=5000))
    assert rs.ljung_box(ar, 30)[1] < 1e-6
    assert rs.autocorrelation(ar, 30).outside > 0.05


def test_cross_correlation_shows_the_delay_of_an_input_in_the_residual():
    rng = np.random.default_rng(2)
    u = rng.normal(size=10000)
    residual = 0.3 * np.roll(u, 5) + rng.normal(size=u.size)
    xc = rs.cross_correlation(u, residual, 20)
    assert xc.lags[np.argmax(np.abs(xc.values))] == 5
    assert abs(xc.values[xc.lags == 5][0]) > xc.band
    unrelated = rs.cross_correlation(u, rng.normal(size=u.size), 20)
    assert unrelated.outside < 0.1


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


def test_phases_split_the_braking_part_of_a_run(reference):
    result = simulate(reference, sc.rig_test(reference, sc.oscillating(**sc.OSC_LOW)))
    phases = rs.run_phases(result.time_s, result.pressure_pa, result.speed_m_s, 2.0, RATE)
    braking = result.time_s >= 2.0
    exclusive = ["pressure rise", "release", "low speed", "steady braking"]
    counts = sum(phases[name].astype(int) for name in exclusive)
    assert np.all(counts[braking] == 1) and np.all(counts[~braking] == 0)
    assert all(phases[name].any() for name in exclusive)
    rms = rs.rms_by_phase(np.where(phases["release"], 1.0, 0.0), phases)
    assert rms["release"] == 1.0 and rms["steady braking"] == 0.0
