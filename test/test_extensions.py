"""Model extensions of the diagnosis catalogue: actuator delay, pressure-sensor offset."""

from __future__ import annotations

import numpy as np
import pytest

from landing_gear_sim import scenario as sc
from landing_gear_sim.errors import ParameterError
from landing_gear_sim.integrate import simulate


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
