"""Scenarios and open-loop current profiles."""

from __future__ import annotations

import numpy as np
import pytest

from landing_gear_sim.errors import ScenarioError
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import scenario as sc


@pytest.mark.parametrize("pressure_bar", [0.0, 5.0, 30.0, 45.0, 60.0])
def test_current_for_pressure_inverts_the_static_map(reference, pressure_bar):
    current = sc.current_for_pressure(reference, pressure_bar * 1e5)
    assert el.valve_static_pressure(reference.vector(), current) == pytest.approx(
        pressure_bar * 1e5, abs=1e-3)


def test_pressure_outside_the_valve_range_is_refused(reference):
    with pytest.raises(ScenarioError, match="outside the valve range"):
        sc.current_for_pressure(reference, 61e5)


def test_rig_test_is_idle_until_braking_then_ramps_in(reference):
    scenario = sc.rig_test(reference, sc.constant(0.6))
    t = np.arange(scenario.current_a.size) / scenario.rate_hz
    assert np.all(scenario.current_a[t < 2.0] == 0.0)
    assert scenario.current_a[round(2.05 * 1000)] == pytest.approx(0.3)
    assert np.all(scenario.current_a[t >= 2.1] == 0.6)
    assert scenario.contact and scenario.initial_speed_m_s == 60.0
    assert scenario.stop_speed_m_s == 3.0


def test_quasi_static_ramp_peaks_in_the_middle():
    t = sc.sample_times(20.0, 1000.0)
    current = sc.quasi_static_ramp(1.0, 20.0)(t)
    assert current[0] == 0.0 and current.max() == pytest.approx(1.0)
    assert t[np.argmax(current)] == pytest.approx(10.0, abs=1e-3)


def test_sweep_runs_from_half_a_hertz_to_a_hundred():
    t = sc.sample_times(20.0, 10000.0)
    current = sc.sine_sweep(0.5, 100.0, 20.0, 0.5, 0.1)(t)

    def crossings_per_second(window: slice) -> float:
        above = current[window] > 0.5
        return np.count_nonzero(above[1:] != above[:-1]) / 2 / (t[window][-1] - t[window][0])

    assert crossings_per_second(slice(0, 20000)) == pytest.approx(0.6, abs=0.3)
    assert crossings_per_second(slice(-2000, None)) == pytest.approx(97.0, rel=0.05)
    assert current.min() >= 0.4 - 1e-9 and current.max() <= 0.6 + 1e-9


def test_oscillating_profiles_stay_near_the_top_of_the_range():
    t = sc.sample_times(2.0, 1000.0)
    low, high = sc.oscillating(**sc.OSC_LOW)(t), sc.oscillating(**sc.OSC_HIGH)(t)
    assert low.max() == pytest.approx(0.75) and low.min() == pytest.approx(0.40, abs=1e-3)
    assert high.max() - high.min() < low.max() - low.min()


def test_recorded_current_is_held_between_samples():
    profile = sc.from_samples(np.array([0.0, 0.01, 0.02]), np.array([0.1, 0.2, 0.3]))
    assert list(profile(np.array([0.0, 0.005, 0.01, 0.019, 0.5]))) == [0.1, 0.1, 0.2, 0.2, 0.3]
    with pytest.raises(ScenarioError, match="strictly increasing"):
        sc.from_samples(np.array([0.0, 0.0, 0.1]), np.array([0.1, 0.2, 0.3]))


def test_scenario_rejects_nan_input():
    with pytest.raises(ScenarioError, match="NaN"):
        sc.Scenario("x", np.array([0.1, np.nan]), 1000.0, False, 0.0, 0.0)
