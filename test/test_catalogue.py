"""Candidate extensions fitted on campaigns that hide them (parameters unseen by the code)."""

from __future__ import annotations

import numpy as np
import pytest

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.calibration.identify import identify
from landing_gear_sim.diagnosis.catalogue import CATALOGUE, fit_candidate, gear_walk_key_parameters
from msg_tools.io import read_campaign

ACTUATOR_RUNS = ("actuator_ramp", "actuator_steps_sweep")
BRAKING_RUNS = ("brake_const_20bar", "brake_const_40bar", "brake_osc_low", "brake_osc_high")


def _hidden(reference, tmp_path, seed, effect, names):
    """Campaign of a rig off its datasheet, with ``effect(rng)`` switched on; and its truth."""
    rng = np.random.default_rng(seed)
    rig = rig_like(reference, rng)
    rig = rig.replace(effect(rng))
    generate_campaign(tmp_path, rig, seed, names)
    return read_campaign(tmp_path).runs, rig


@pytest.mark.parametrize("seed", [21, 22])
def test_actuator_delay_is_recovered_within_a_millisecond(reference, tmp_path, seed):
    runs, rig = _hidden(reference, tmp_path, seed, lambda rng: {
        "elements.actuator_delay": True, "actuator.delay_s": rng.uniform(0.002, 0.02)},
        ACTUATOR_RUNS)
    fit = fit_candidate(CATALOGUE["actuator_delay"], runs, identify(runs, reference).params)
    assert fit.values["actuator.delay_s"] == pytest.approx(rig.number("actuator.delay_s"),
                                                           abs=1e-3), seed
    assert fit.values["actuator.natural_frequency_hz"] == pytest.approx(
        rig.number("actuator.natural_frequency_hz"), rel=0.05)


def test_pressure_sensor_offset_is_recovered_within_20_percent(reference, tmp_path):
    runs, rig = _hidden(reference, tmp_path, 23, lambda rng: {
        "elements.pressure_sensor_offset": True,
        "sensors.pressure_offset_pa": rng.choice([-1, 1]) * rng.uniform(0.3e5, 1.5e5)},
        ACTUATOR_RUNS)
    fit = fit_candidate(CATALOGUE["pressure_sensor_offset"], runs,
                        identify(runs, reference).params)
    assert fit.values["sensors.pressure_offset_pa"] == pytest.approx(
        rig.number("sensors.pressure_offset_pa"), rel=0.2)


def test_gear_walk_is_rediscovered_from_a_model_without_it(reference, tmp_path):
    """The paper's story: start from the single-corner model, find the ~8 Hz gear walk."""
    runs, rig = _hidden(reference, tmp_path, 25, lambda rng: {
        "gear_walk.stiffness_n_m_per_rad": 6.9e5 * rng.uniform(0.7, 1.4)},
        ACTUATOR_RUNS + BRAKING_RUNS)
    start = identify(runs, reference.without("gear_walk")).params
    fit = fit_candidate(CATALOGUE["gear_walk"], runs, start, datasheet=reference)
    found, truth = gear_walk_key_parameters(fit.params), gear_walk_key_parameters(rig)
    assert found["frequency_hz"] == pytest.approx(truth["frequency_hz"], rel=0.05)


def test_the_right_candidate_explains_more_than_a_wrong_one(reference, tmp_path):
    runs, _ = _hidden(reference, tmp_path, 26, lambda rng: {
        "elements.actuator_delay": True, "actuator.delay_s": 0.008}, ACTUATOR_RUNS)
    calibrated = identify(runs, reference).params
    right = fit_candidate(CATALOGUE["actuator_delay"], runs, calibrated)
    wrong = fit_candidate(CATALOGUE["pressure_sensor_offset"], runs, calibrated)
    assert right.cost < 0.5 * wrong.cost
