"""Linearisation and frequency responses (paper Fig. 7)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from landing_gear_sim.model.linear import (
    frequency_response,
    linearise,
    operating_point,
    resonance_hz,
)

FREQUENCIES = np.logspace(-1, 2, 1500)


@pytest.mark.parametrize("speed", [10.0, 30.0, 60.0])
def test_gear_walk_gives_a_resonance_near_8_hz(reference, speed):
    with_gw = frequency_response(reference, speed, FREQUENCIES)
    assert resonance_hz(with_gw) == pytest.approx(8.0, abs=1.0)
    assert resonance_hz(frequency_response(reference.without("gear_walk"), speed,
                                           FREQUENCIES)) is None


def test_resonance_grows_as_speed_falls(reference):
    def peak_over_dc(speed: float) -> float:
        response = frequency_response(reference, speed, FREQUENCIES)
        return float(np.abs(response.slip).max() / abs(response.slip[0]))

    assert peak_over_dc(10.0) > peak_over_dc(30.0) > peak_over_dc(60.0) > 1.0


def test_static_gain_matches_the_friction_slope(reference):
    """At DC, dλ/dT_b = 1 / (r F_z μ'(λ0)) from the torque balance r F_z μ(λ) = T_b."""
    point = operating_point(reference, 30.0, slip=0.05)
    t1, t2, t3 = (reference.number(f"friction.theta{i}") for i in (1, 2, 3))
    slope = t1 * t2 * math.exp(-t2 * 0.05) - t3
    load = point.vertical_load_n
    radius = 0.31 - (4e-12 * load ** 2 + 5e-7 * load)
    response = frequency_response(reference, 30.0, np.array([1e-3]))
    assert abs(response.slip[0]) == pytest.approx(1 / (radius * load * slope), rel=1e-3)


def test_wheel_mode_is_stable_and_faster_at_low_speed(reference):
    def wheel_pole(speed: float) -> float:
        model = linearise(reference.without("gear_walk"), operating_point(
            reference.without("gear_walk"), speed))
        return float(np.linalg.eigvals(model.a).real.min())

    assert wheel_pole(10.0) < wheel_pole(60.0) < 0.0


def test_decel_response_is_a_differentiator_at_low_frequency(reference):
    response = frequency_response(reference, 30.0, np.array([0.1, 0.2]))
    assert abs(response.decel[1]) / abs(response.decel[0]) == pytest.approx(2.0, rel=0.01)
    assert np.degrees(np.angle(response.decel[0])) == pytest.approx(90.0, abs=2.0)
