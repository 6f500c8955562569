"""The plant's own derivatives (issue 61): a dual pass of the compiled run loop gives each
channel's derivative with respect to each parameter, as central differences of whole
simulations do, and its values are the plain simulation's to the bit."""

from __future__ import annotations

import numpy as np
import pytest

from landing_gear_sim.errors import ParameterError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.basis import (
    CURVE,
    IDENTITY,
    OMEGA,
    PRESSURE,
    SIGN,
    SPEED,
    VALVE_ERROR,
    factor_code,
    product_code,
)
from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.sensitivity import simulate_with_sensitivities

# the dual kernels compile once per lane count and process: on one worker, once in all
pytestmark = pytest.mark.xdist_group("dual_kernels")

TOLERANCE = 1e-4  # relative, of the channel's largest derivative over the run
STEP = 1e-5  # relative step of the central differences


def _central(params: RigParameters, scenario: sc.Scenario, key: str, rows: int
             ) -> np.ndarray:
    """d channels / d ``key`` by central differences of two whole simulations, (rows, C)."""
    h = STEP * abs(params.number(key))
    up = simulate(params.replace({key: params.number(key) + h}), scenario)
    down = simulate(params.replace({key: params.number(key) - h}), scenario)
    n = min(rows, len(up), len(down))
    return (up.data[:n] - down.data[:n]) / (2 * h)


def _agrees(params: RigParameters, scenario: sc.Scenario, keys: list[str],
            channels: list[int]) -> dict[str, float]:
    """Each key's largest relative disagreement with central differences over
    ``channels`` (column numbers of a simulation record)."""
    found = simulate_with_sensitivities(params, scenario, keys)
    rows = len(found.result)
    errors = {}
    for j, key in enumerate(keys):
        expected = _central(params, scenario, key, rows)
        n = len(expected) - 20  # a run's last samples: the perturbed ones stop elsewhere
        worst = 0.0
        for c in channels:
            scale = np.max(np.abs(expected[:n, c]))
            if scale > 0.0:
                worst = max(worst, float(np.max(np.abs(found.tangents[:n, c, j]
                                                       - expected[:n, c])) / scale))
        errors[key] = worst
    return errors


@pytest.fixture(scope="module")
def braking_rig(reference: RigParameters) -> RigParameters:
    """A rig with a delayed valve, a fading brake and a wheel torque in its slot."""
    return reference.replace({
        "elements.actuator_delay": True, K.ACTUATOR_DELAY_S: 0.0063,
        "elements.brake_fade": True, K.BRAKE_FADE_FRACTION: 0.1,
        K.BRAKE_FADE_ENERGY_J: 3e6, K.WHEEL_TERMS[0][0]: float(factor_code(OMEGA, SIGN)),
        K.WHEEL_TERMS[0][1]: 40.0, K.RIG_TEST_MAX_DURATION_S: 6.0})


BRAKING_KEYS = [K.BRAKE_GAIN_N_M_PER_PA, K.FRICTION_THETA1, K.FRICTION_THETA2,
                K.WHEEL_INERTIA_KG_M2, K.ACTUATOR_NATURAL_FREQUENCY_HZ,
                K.ACTUATOR_DAMPING_RATIO, K.ACTUATOR_DELAY_S, K.WHEEL_TERMS[0][1],
                K.DRAG_COEFF_N_S2_PER_M2, K.BRAKE_FADE_ENERGY_J]
"""Ten keys: passes of eight lanes. The braking tests take more than four keys each, so
that one compilation of the dual kernel (~25 s) serves them all."""


def test_a_braking_runs_derivatives_are_those_of_central_differences(braking_rig):
    scenario = sc.rig_test(braking_rig, sc.oscillating(0.55, 0.2, 3.0), "brake_osc")
    channels = [2, 3, 4, 6, 7]  # pressure, wheel speed, speed, vertical load, F_x
    errors = _agrees(braking_rig, scenario, BRAKING_KEYS, channels)
    assert max(errors.values()) < TOLERANCE, errors


def test_an_actuator_sweeps_derivatives_are_those_of_central_differences(reference):
    # a valve stiffer at pressure (c P·ΔP): a spool's friction (sgn Ṗ) chatters at rest,
    # where no difference of two simulations is a derivative
    stiffening = product_code(factor_code(PRESSURE, IDENTITY), factor_code(VALVE_ERROR, IDENTITY))
    rig = reference.replace({
        "elements.actuator_delay": True, K.ACTUATOR_DELAY_S: 0.0081,
        K.VALVE_TERMS[0][0]: float(stiffening), K.VALVE_TERMS[0][1]: 2.5e-8})
    scenario = sc.actuator_test(rig, sc.steps_then_sweep(), 12.0, "actuator_sweep")
    keys = [K.ACTUATOR_NATURAL_FREQUENCY_HZ, K.ACTUATOR_DAMPING_RATIO, K.ACTUATOR_GAIN,
            K.ACTUATOR_DELAY_S, K.ACTUATOR_MAP_K1_PA_PER_A, K.ACTUATOR_MAP_K2_PA_PER_A2,
            K.VALVE_TERMS[0][1]]
    errors = _agrees(rig, scenario, keys, [2])
    assert max(errors.values()) < TOLERANCE, errors


def test_the_dual_pass_gives_the_plain_simulation_to_the_bit(braking_rig):
    scenario = sc.rig_test(braking_rig, sc.oscillating(0.55, 0.2, 3.0), "brake_osc")
    found = simulate_with_sensitivities(braking_rig, scenario, BRAKING_KEYS)
    plain = simulate(braking_rig, scenario)
    assert np.array_equal(found.result.data, plain.data)
    assert found.result.stop_reason == plain.stop_reason


def test_more_keys_than_lanes_take_more_passes_with_the_same_derivatives(braking_rig):
    scenario = sc.rig_test(braking_rig.replace({K.RIG_TEST_MAX_DURATION_S: 1.5}),
                           sc.constant(0.5), "short")
    keys = [K.BRAKE_GAIN_N_M_PER_PA, K.FRICTION_THETA1, K.FRICTION_THETA2, K.FRICTION_THETA3,
            K.WHEEL_INERTIA_KG_M2, K.ACTUATOR_NATURAL_FREQUENCY_HZ, K.ACTUATOR_DAMPING_RATIO,
            K.ACTUATOR_DELAY_S, K.DRAG_COEFF_N_S2_PER_M2]
    many = simulate_with_sensitivities(braking_rig, scenario, keys)  # 8 lanes, then 1
    # the last eight in one pass: the ninth key's lane sits elsewhere, in another pass (eight
    # lanes, as the braking tests compile: a count of its own had cost a compilation, ~30 s)
    few = simulate_with_sensitivities(braking_rig, scenario, keys[1:])
    assert many.tangents.shape[2] == len(keys)
    # a number recorded among duals (the time) has derivatives 0, not 0·whatever the output
    # buffer held: that had read NaN
    assert np.all(np.isfinite(many.tangents)) and np.all(np.isfinite(few.tangents))
    assert np.allclose(many.tangents[:, :, 1:], few.tangents, rtol=0.0, atol=0.0)


def test_an_unknown_parameter_is_refused_by_name(reference):
    scenario = sc.actuator_test(reference, sc.constant(0.5), 0.1)
    with pytest.raises(ParameterError, match=r"brake\.gian"):
        simulate_with_sensitivities(reference, scenario, ["brake.gian"])


@pytest.fixture(scope="module")
def logged_runs(reference, tmp_path_factory) -> list:
    """A campaign's oscillating stop and actuator sweep, logged by a rig whose pressure
    transducer reads an offset, whose wheel channel is late and whose brake wears."""
    from landing_gear_sim.calibration.campaign import generate_campaign
    from landing_gear_sim.calibration.runs import classify_all
    from msg_tools.io import read_campaign

    folder = tmp_path_factory.mktemp("logged")
    rig = reference.replace({"elements.pressure_sensor_offset": True,
                             K.SENSORS_PRESSURE_OFFSET_PA: -4e4,
                             K.SENSORS_WHEEL_SPEED_DELAY_S: 0.0023,
                             K.BRAKE_GAIN_DRIFT_PER_RUN: -0.01})
    generate_campaign(folder, rig, 3, ["brake_osc_high", "actuator_steps_sweep"])
    return [r for r in classify_all(read_campaign(folder).runs)]


def test_a_logged_runs_derivatives_hold_through_its_load_its_wear_and_its_logger(
        reference, logged_runs):
    """The whole path from a set to what the logger reads (the run's load and wear before
    the plant, the transducer's offset, a channel out of step and the valve's pressure
    after a stop after it): the plant's own derivatives carried through it agree with
    central differences of :func:`simulate_run`."""
    from landing_gear_sim.calibration.measured import (
        CHANNELS,
        simulate_run,
        simulate_run_with_sensitivities,
    )

    # the transducer's slot c·P at 0, where a fit starts it: its step is the key's span's
    model = reference.replace({"elements.pressure_sensor_offset": True,
                               K.PRESSURE_TERMS[0][0]: float(factor_code(PRESSURE, IDENTITY)),
                               K.PRESSURE_TERMS[0][1]: 0.0,
                               K.SENSORS_PRESSURE_OFFSET_PA: -3e4,
                               K.SENSORS_WHEEL_SPEED_DELAY_S: 0.0021,
                               K.BRAKE_GAIN_DRIFT_PER_RUN: -0.008,
                               "elements.actuator_delay": True, K.ACTUATOR_DELAY_S: 0.0043})
    keys = [K.BRAKE_GAIN_N_M_PER_PA, K.FRICTION_THETA1, K.SENSORS_PRESSURE_OFFSET_PA,
            K.SENSORS_WHEEL_SPEED_DELAY_S, K.BRAKE_GAIN_DRIFT_PER_RUN, K.ACTUATOR_DELAY_S,
            K.ACTUATOR_NATURAL_FREQUENCY_HZ, K.PRESSURE_TERMS[0][1]]
    worst = {}
    for run in logged_runs:
        found = simulate_run_with_sensitivities(run, model, keys,
                                                [1.0] * (len(keys) - 1) + [0.1])
        assert found is not None
        logged, derivatives = found
        assert np.array_equal(logged.pressure_pa, simulate_run(run, model)[0].pressure_pa)
        for j, key in enumerate(keys):
            h = 1e-5 * abs(model.number(key)) or 1e-6
            up = simulate_run(run, model.replace({key: model.number(key) + h}))[0]
            down = simulate_run(run, model.replace({key: model.number(key) - h}))[0]
            for channel in CHANNELS if run.braking else ["pressure_pa"]:
                expected = (getattr(up, channel) - getattr(down, channel)) / (2 * h)
                scale = np.max(np.abs(expected))
                if scale > 0.0:
                    error = np.max(np.abs(derivatives[channel][:, j] - expected)) / scale
                    worst[(run.name, key, channel)] = float(error)
    assert max(worst.values()) < TOLERANCE, sorted(worst.items(), key=lambda kv: -kv[1])[:5]


def test_a_delay_of_whole_steps_has_the_derivative_of_a_longer_one(reference):
    """At a whole number of steps the matrices' layout changes with the delay: its
    derivative is the one a delay a little longer has (forward differences)."""
    rig = reference.replace({"elements.actuator_delay": True, K.ACTUATOR_DELAY_S: 0.006})
    scenario = sc.actuator_test(rig, sc.steps_then_sweep(), 8.0, "whole_steps")
    # beside ω_n and ζ, as the delay's candidate fits it (four lanes, as the fit test
    # compiles them)
    found = simulate_with_sensitivities(rig, scenario, [K.ACTUATOR_DELAY_S,
                                                        K.ACTUATOR_NATURAL_FREQUENCY_HZ,
                                                        K.ACTUATOR_DAMPING_RATIO])
    h = 1e-8
    longer = simulate(rig.replace({K.ACTUATOR_DELAY_S: 0.006 + h}), scenario)
    expected = (longer.pressure_pa - found.result.pressure_pa) / h
    error = np.max(np.abs(found.of("pressure_pa")[:, 0] - expected)) / np.max(np.abs(expected))
    assert error < TOLERANCE, error


@pytest.fixture
def model_derivatives(monkeypatch):
    """Fits on the model's own derivatives (off in the product: see
    ``differences.MODEL_DERIVATIVES``)."""
    from landing_gear_sim.calibration import differences

    monkeypatch.setattr(differences, "MODEL_DERIVATIVES", True)


def test_derivatives_that_are_not_finite_end_the_fit_with_the_reason(model_derivatives):
    """A diverging candidate: its residual is finite where its derivatives are not. The
    solver is never given a NaN Jacobian to walk on; the fit ends with an error that its
    candidate's scoring reports as the reason it was not scored."""
    from landing_gear_sim.calibration.differences import Objective
    from landing_gear_sim.errors import IdentificationError

    def derivatives(u):
        return np.ones(3), np.array([[1.0], [np.nan], [1.0]])

    objective = Objective(lambda points: [np.ones(3) for _ in points], derivatives=derivatives)
    with pytest.raises(IdentificationError, match="not finite"):
        objective.jac(np.array([0.5]))


def test_where_the_plant_cannot_differentiate_a_fit_takes_differences(model_derivatives):
    """None from the model's derivatives (a disc's run-out phases fitted per run): the
    objective's Jacobian is forward differences from then on, as scipy's are."""
    from landing_gear_sim.calibration.differences import Objective

    calls = []

    def residuals(points):
        return [np.array([2.0 * u[0], u[0] ** 2]) for u in points]

    def derivatives(u):
        calls.append(u)
        return None

    objective = Objective(residuals, derivatives=derivatives)
    jacobian = objective.jac(np.array([0.5]))
    assert np.allclose(jacobian, [[2.0], [1.0]], rtol=1e-3)
    objective.jac(np.array([0.25]))
    assert len(calls) == 1


def test_a_term_at_zero_being_fitted_has_its_terms_derivative(reference):
    """A fit starts a slot's coefficient (or a disc's run-out) at 0, where the plant skips a
    term that adds nothing: the plant's derivative there is still the term's own (it had
    read 0, and a discovered law lost its terms)."""
    speed_term = float(factor_code(OMEGA, IDENTITY))
    rig = reference.replace({
        K.WHEEL_TERMS[1][0]: speed_term, K.WHEEL_TERMS[1][1]: 0.0,
        K.TYRE_TERMS[0][0]: float(product_code(factor_code(CURVE, IDENTITY),
                                               factor_code(SPEED, IDENTITY))),
        K.TYRE_TERMS[0][1]: 0.0, K.RIG_TEST_MAX_DURATION_S: 5.0})
    keys = [K.WHEEL_TERMS[1][1], K.TYRE_TERMS[0][1], K.BRAKE_RUNOUT_1]
    found = simulate_with_sensitivities(rig, sc.rig_test(rig, sc.oscillating(0.55, 0.2, 3.0)),
                                        keys + BRAKING_KEYS[:5])  # eight lanes, as compiled
    scenario = sc.rig_test(rig, sc.oscillating(0.55, 0.2, 3.0))
    for j, key in enumerate(keys):
        h = 1e-7
        up = simulate(rig.replace({key: h}), scenario)
        # central where the key may be negative; a run-out may not: forward there
        down = found.result if key == K.BRAKE_RUNOUT_1 else simulate(
            rig.replace({key: -h}), scenario)
        n = min(len(up), len(down), len(found.result)) - 20
        span = h if key == K.BRAKE_RUNOUT_1 else 2 * h
        expected = (up.wheel_speed_rad_s[:n] - down.wheel_speed_rad_s[:n]) / span
        got = found.of("wheel_speed_rad_s")[:n, j]
        assert np.max(np.abs(expected)) > 0.0, key
        assert np.max(np.abs(got - expected)) / np.max(np.abs(expected)) < TOLERANCE, key


def test_a_fit_on_the_plants_derivatives_reaches_the_differences_optimum_in_fewer_passes(
        reference, tmp_path, monkeypatch):
    """The valve's delay, ω_n and ζ fitted on two actuator runs: the same optimum as with
    forward differences, for fewer simulations of the runs (a dual pass counted as one)."""
    from landing_gear_sim.calibration import differences
    from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
    from landing_gear_sim.calibration.identify import identify
    from landing_gear_sim.diagnosis import catalogue
    from msg_tools.io import read_campaign

    rig = rig_like(reference, np.random.default_rng(26)).replace(
        {"elements.actuator_delay": True, K.ACTUATOR_DELAY_S: 0.008})
    generate_campaign(tmp_path, rig, 26, ["actuator_ramp", "actuator_steps_sweep"])
    runs = read_campaign(tmp_path).runs
    calibrated = identify(runs, reference, jackknife=False).params
    passes = {"plain": 0, "dual": 0}
    plain, dual = catalogue.scaled_residuals, catalogue.scaled_residuals_and_jacobian

    def counted_plain(runs, trials, *args, **kwargs):
        passes["plain"] += len(trials)
        return plain(runs, trials, *args, **kwargs)

    def counted_dual(*args, **kwargs):
        passes["dual"] += 1
        return dual(*args, **kwargs)

    monkeypatch.setattr(catalogue, "scaled_residuals", counted_plain)
    monkeypatch.setattr(catalogue, "scaled_residuals_and_jacobian", counted_dual)
    delay = catalogue.CATALOGUE["actuator_delay"]
    by_differences = catalogue.fit_candidate(delay, runs, calibrated)
    spent = dict(passes)
    monkeypatch.setattr(differences, "MODEL_DERIVATIVES", True)
    by_plant = catalogue.fit_candidate(delay, runs, calibrated)
    assert passes["dual"] > 0
    assert (passes["plain"] - spent["plain"]) + passes["dual"] < spent["plain"]
    for key, value in by_differences.values.items():
        assert by_plant.values[key] == pytest.approx(value, abs=by_differences.std[key]), key
    assert by_plant.cost <= by_differences.cost * (1 + 1e-3)
