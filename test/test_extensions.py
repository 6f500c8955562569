"""Model extensions of the diagnosis catalogue: actuator delay, pressure-sensor offset."""

from __future__ import annotations

import numpy as np
import pytest

from landing_gear_sim.errors import ParameterError
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.actuator import actuator_pressure
from landing_gear_sim.model.integrate import simulate


def _actuator_run(params, rate_hz: float = 1000.0):
    profile = sc.steps_then_sweep()
    return simulate(params, sc.actuator_test(params, profile, 12.0, rate_hz=rate_hz))


def test_whole_step_delay_shifts_the_pressure_exactly(reference):
    plain = _actuator_run(reference)
    delayed = _actuator_run(reference.replace({"elements.actuator_delay": True,
                                               "actuator.delay_s": 0.008}))
    assert np.array_equal(delayed.pressure_pa[8:], plain.pressure_pa[:-8])
    assert np.all(delayed.pressure_pa[:8] == 0.0)


def test_fractional_delay_is_exact_between_samples(reference):
    """2.5 ms at 1 kHz equals the undelayed response on a 2 kHz grid shifted by 5 samples."""
    delayed = _actuator_run(reference.replace({"elements.actuator_delay": True,
                                               "actuator.delay_s": 0.0025}))
    held = delayed.scenario.current_a
    fine = simulate(reference, sc.Scenario("fine", np.repeat(held, 2), 2000.0, False, 0.0, 0.0))
    k = np.arange(10, delayed.pressure_pa.size)
    assert np.allclose(delayed.pressure_pa[k], fine.pressure_pa[2 * k - 5], rtol=0, atol=1e-3)


def test_delay_switched_off_is_ignored(reference):
    plain = _actuator_run(reference)
    off = _actuator_run(reference.replace({"actuator.delay_s": 0.02}))
    assert np.array_equal(plain.pressure_pa, off.pressure_pa)


def test_delay_slows_a_braking_run_down(reference):
    scenario = sc.rig_test(reference, sc.oscillating(**sc.OSC_LOW))
    plain = simulate(reference, scenario)
    delayed = simulate(reference.replace({"elements.actuator_delay": True,
                                          "actuator.delay_s": 0.008}), scenario)
    k = round(2.5 * 1000)
    assert delayed.pressure_pa[k + 8] == pytest.approx(plain.pressure_pa[k], rel=1e-9)
    assert not np.array_equal(delayed.wheel_speed_rad_s, plain.wheel_speed_rad_s)


@pytest.mark.parametrize("offset_pa", [-0.8e5, 1.2e5])
def test_pressure_sensor_offset_shifts_only_the_measurement(reference, offset_pa):
    offset = reference.replace({"elements.pressure_sensor_offset": True,
                                "sensors.pressure_offset_pa": offset_pa})
    scenario = sc.constant_pressure_test(reference, 30e5)
    plain, shifted = simulate(reference, scenario), simulate(offset, scenario)
    assert np.array_equal(plain.wheel_speed_rad_s, shifted.wheel_speed_rad_s)  # physics same
    measured = shifted.to_run().pressure_pa - plain.to_run().pressure_pa
    assert np.allclose(measured, offset_pa)


def test_only_an_offset_may_be_negative(reference):
    assert reference.replace({"sensors.pressure_offset_pa": -1e4}).number(
        "sensors.pressure_offset_pa") == -1e4
    with pytest.raises(ParameterError, match=r"actuator\.delay_s.*must not be negative"):
        reference.replace({"actuator.delay_s": -0.001})


RELAXED = {"elements.tire_relaxation": True, "tyre.relaxation_length_m": 0.5}
FADING = {"elements.brake_fade": True, "brake.fade_fraction": 0.3,
          "brake.fade_energy_j": 2e6}


def _burckhardt(params, slip):
    t1, t2, t3 = (params.number(f"friction.theta{i}") for i in (1, 2, 3))
    return t1 * (1 - np.exp(-t2 * slip)) - t3 * slip


def test_relaxed_tyre_force_follows_the_first_order_law(reference):
    relaxed = reference.replace(RELAXED)
    result = simulate(relaxed, sc.rig_test(relaxed, sc.oscillating(**sc.OSC_LOW)))
    k = np.arange(2500, 6000)
    rate = np.gradient(result.longitudinal_force_n, 1e-3)[k]
    steady = result.vertical_load_n[k] * _burckhardt(relaxed, result.slip[k])
    law = result.hub_speed_m_s[k] / 0.5 * (steady - result.longitudinal_force_n[k])
    assert np.sqrt(np.mean((rate - law) ** 2)) < 0.02 * np.sqrt(np.mean(law ** 2))
    assert np.max(np.abs(steady - result.longitudinal_force_n[k])) > 500.0  # it does lag


def test_short_relaxation_length_tends_to_the_plain_tyre(reference):
    scenario = sc.rig_test(reference, sc.oscillating(**sc.OSC_HIGH))
    plain = simulate(reference, scenario)
    short = simulate(reference.replace({**RELAXED, "tyre.relaxation_length_m": 0.002}),
                     scenario)
    n = min(len(plain), len(short))
    assert np.max(np.abs(plain.wheel_speed_rad_s[:n] - short.wheel_speed_rad_s[:n])) < 0.5


def test_relaxation_needs_a_length(reference):
    with pytest.raises(ParameterError, match=r"relaxation_length_m' must be > 0 when"):
        reference.replace({"elements.tire_relaxation": True})


def test_faded_brake_torque_follows_the_absorbed_energy(reference):
    fading = reference.replace(FADING)
    result = simulate(fading, sc.constant_pressure_test(fading, 30e5))
    expected = 1.5e-3 * np.maximum(result.pressure_pa, 0) * (
        1 - 0.3 * (1 - np.exp(-result.brake_energy_j / 2e6)))
    assert np.allclose(result.brake_torque_n_m, expected, rtol=1e-12, atol=1e-9)
    plain = simulate(reference, sc.constant_pressure_test(reference, 30e5))
    assert result.time_s[-1] > 1.1 * plain.time_s[-1]  # a fading brake stops later


def test_a_valve_with_play_sees_the_current_half_the_play_late_each_way(reference):
    """The play operator: on a slow ramp up the valve sees i − w/2, on the way down
    i + w/2, so the pressure is the play-free valve's at those currents."""
    ramp = np.concatenate([np.linspace(0.0, 1.0, 20000), np.linspace(1.0, 0.0, 20000)])
    width = 0.04
    pressure = actuator_pressure(reference.replace({"actuator.backlash_a": width}), ramp,
                                 1000.0)
    up, down = slice(6000, 14000), slice(26000, 34000)
    for part, shift in ((up, -width / 2), (down, width / 2)):
        expected = actuator_pressure(reference, ramp + shift, 1000.0)[part]
        np.testing.assert_allclose(pressure[part], expected, rtol=1e-9, atol=1e-3)
    play_free = actuator_pressure(reference, ramp, 1000.0)
    assert pressure[down].mean() - play_free[down].mean() > 1e5  # ~k1·w/2: a bar and more


def test_fade_fraction_below_one(reference):
    with pytest.raises(ParameterError, match="fade_fraction' must be < 1"):
        reference.replace({"brake.fade_fraction": 1.0})


@pytest.mark.parametrize("extension", [RELAXED, FADING])
def test_extensions_match_the_tight_radau_reference(reference, extension):
    from landing_gear_sim.model.reference import reference_solution

    extended = reference.replace(extension)
    scenario = sc.rig_test(extended, sc.oscillating(**sc.OSC_LOW))
    fast = simulate(extended, scenario)
    exact = reference_solution(extended, scenario, end_s=3.0)
    n = exact["time_s"].size
    error = fast.wheel_speed_rad_s[:n] - exact["wheel_speed_rad_s"]
    assert np.sqrt(np.mean(error ** 2)) < 1e-3 * 60.0 / 0.31


def test_energy_balance_holds_with_relaxation_and_fade(reference):
    extended = reference.replace({**RELAXED, **FADING})
    result = simulate(extended, sc.constant_pressure_test(extended, 30e5))
    mass = 3500.0
    lost = 0.5 * mass * (result.speed_m_s[0] ** 2 - result.speed_m_s[-1] ** 2)
    spent = (result.brake_energy_j[-1] + result.drag_energy_j[-1] + result.slip_energy_j[-1]
             + result.damping_energy_j[-1] + 0.75 * result.wheel_speed_rad_s[-1] ** 2
             + 0.5 * 272.9 * result.gear_rate_rad_s[-1] ** 2
             + 0.5 * 6.9e5 * result.gear_angle_rad[-1] ** 2)
    assert abs(lost - spent) < 1e-4 * lost
