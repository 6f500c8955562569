"""Physics of the rig model, each check able to fail: energy, equilibria, lock, numerics."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from landing_gear_sim.model import actuator, plant
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import run_kernel, simulate, simulate_batch
from landing_gear_sim.model.parameters import load_parameters
from landing_gear_sim.model.reference import reference_solution


@pytest.fixture(scope="module")
def run_30bar(reference):
    return simulate(reference, sc.constant_pressure_test(reference, 30e5))


@pytest.fixture(scope="module")
def run_45bar(reference):
    return simulate(reference, sc.constant_pressure_test(reference, 45e5))


def _energy_residual(result) -> tuple[float, float]:
    """(kinetic energy the flywheel lost, what the bookkeeping cannot account for) [J]."""
    p = result.params
    mass = p.number("flywheel.inertia_kg_m2") / p.number("flywheel.radius_m") ** 2
    lost = 0.5 * mass * (result.speed_m_s[0] ** 2 - result.speed_m_s[-1] ** 2)
    wheel = 0.5 * p.number("wheel.inertia_kg_m2") * (
        result.wheel_speed_rad_s[-1] ** 2 - result.wheel_speed_rad_s[0] ** 2)
    gear = 0.5 * p.number("gear_walk.inertia_kg_m2") * result.gear_rate_rad_s[-1] ** 2 \
        + 0.5 * p.number("gear_walk.stiffness_n_m_per_rad") * result.gear_angle_rad[-1] ** 2
    spent = (result.brake_energy_j[-1] + result.drag_energy_j[-1] + result.slip_energy_j[-1]
             + result.damping_energy_j[-1] + wheel + gear)
    return lost, lost - spent


def test_flywheel_energy_goes_to_brake_drag_slip_and_gear(run_30bar):
    lost, residual = _energy_residual(run_30bar)
    assert lost > 5e6  # a real stop from 60 m/s
    assert abs(residual) < 1e-5 * lost
    # the brake takes nearly all of it, the tyre a few percent
    assert 0.85 < run_30bar.brake_energy_j[-1] / lost < 0.99
    assert 0.005 < run_30bar.slip_energy_j[-1] / lost < 0.1


def test_energy_balance_holds_through_wheel_lock(run_45bar):
    lost, residual = _energy_residual(run_45bar)
    assert abs(residual) < 1e-3 * lost


def _equilibrium_slip(p, pressure_pa: float, speed_m_s: float) -> float:
    """Slip where the tyre torque equals the brake torque, from the datasheet formulas."""
    load = p.number("loading.static_load_n") - p.number("loading.lift_coeff_n_s2_per_m2") \
        * speed_m_s ** 2
    radius = p.number("wheel.unloaded_radius_m") - (
        p.number("radius.a_m_per_n2") * load ** 2 + p.number("radius.b_m_per_n") * load)
    t1, t2, t3 = (p.number(f"friction.theta{i}") for i in (1, 2, 3))
    needed = p.number("brake.gain_n_m_per_pa") * pressure_pa / (radius * load)
    peak = math.log(t1 * t2 / t3) / t2
    return brentq(lambda s: t1 * (1 - math.exp(-t2 * s)) - t3 * s - needed, 0.0, peak)


@pytest.mark.parametrize("time_s", [4.0, 7.0, 10.0])
def test_steady_slip_at_constant_pressure_sits_on_the_friction_curve(run_30bar, time_s):
    k = round(time_s * 1000)
    expected = _equilibrium_slip(run_30bar.params, 30e5, run_30bar.speed_m_s[k])
    # the small remainder is the wheel's own deceleration torque J_w ω̇ (~0.5 %)
    assert run_30bar.slip[k] == pytest.approx(expected, rel=0.02)
    assert run_30bar.pressure_pa[k] == pytest.approx(30e5, rel=1e-3)


def test_45_bar_locks_the_wheel_at_high_speed(run_45bar):
    locked = (run_45bar.wheel_speed_rad_s == 0.0) & (run_45bar.time_s > 2.0)
    assert locked.any()
    first = np.flatnonzero(locked)[0]
    assert run_45bar.speed_m_s[first] > 50.0
    assert run_45bar.slip[first] == pytest.approx(1.0)


def test_30_bar_never_locks(run_30bar):
    braking = run_30bar.time_s > 2.5
    assert run_30bar.wheel_speed_rad_s[braking].min() > 5.0
    assert run_30bar.slip[braking].max() < 0.1


def test_wheel_never_spins_backwards(run_30bar, run_45bar, reference):
    osc = simulate(reference, sc.rig_test(reference, sc.oscillating(**sc.OSC_LOW)))
    for result in (run_30bar, run_45bar, osc):
        assert result.wheel_speed_rad_s.min() >= 0.0


def test_run_stops_at_the_stop_speed(run_30bar):
    assert run_30bar.stop_reason == "stop speed reached"
    assert 2.9 < run_30bar.speed_m_s[-1] < 3.0
    assert run_30bar.speed_m_s[-2] >= 3.0


@pytest.mark.parametrize("rate_hz", [500.0, 2000.0])
def test_result_does_not_depend_on_the_output_rate(reference, run_30bar, rate_hz):
    other = simulate(reference, sc.constant_pressure_test(reference, 30e5, rate_hz))
    for time_s in (1.0, 3.0, 6.0, 10.0):
        a = run_30bar.wheel_speed_rad_s[round(time_s * 1000)]
        b = other.wheel_speed_rad_s[round(time_s * rate_hz)]
        assert b == pytest.approx(a, rel=2e-4)


def test_fixed_step_solution_matches_a_tight_radau_reference(reference):
    """Touch-down, spin-up and the brake application: the hard part of a run."""
    scenario = sc.rig_test(reference, sc.oscillating(**sc.OSC_LOW))
    fast = simulate(reference, scenario)
    exact = reference_solution(reference, scenario, end_s=3.0)
    n = exact["time_s"].size
    error = fast.wheel_speed_rad_s[:n] - exact["wheel_speed_rad_s"]
    initial_wheel_speed = 60.0 / reference.number("wheel.unloaded_radius_m")
    assert np.sqrt(np.mean(error ** 2)) < 1e-3 * initial_wheel_speed
    assert np.max(np.abs(fast.pressure_pa[:n] - exact["pressure_pa"])) < 10.0  # Pa


@pytest.mark.parametrize("contact, speed_m_s", [(True, 60.0), (False, 0.0)])
def test_stepping_the_blocks_one_by_one_equals_the_compiled_run(reference, contact, speed_m_s):
    """What the ROS nodes do (one block call per message) reproduces run_kernel bit for bit,
    also off the ground, where run_kernel skips the plant of a wheel at rest."""
    scenario = sc.rig_test(reference, sc.oscillating(**sc.OSC_LOW))
    current = scenario.current_a[:3000]
    p, h = reference.vector(), scenario.step_s
    matrices = actuator.actuator_matrices(p, h)
    expected = np.empty((current.size, plant.N_CHANNELS))
    # every argument given, as simulate gives them: a default left out is another signature
    # to compile (~8 s in a suite that starts cold)
    run_kernel(p, matrices, current, h, contact, speed_m_s, 0.0, np.zeros(0), expected, False)

    x, xa, xl = np.zeros(plant.N_STATES), actuator.actuator_state(matrices), np.zeros(1)
    x[plant.SPEED] = speed_m_s
    work, rows = np.zeros((5, plant.N_STATES)), np.empty_like(expected)
    pressure = load = 0.0
    for k, i_k in enumerate(current):
        plant.record(p, x, k * h, i_k, pressure, load, rows[k])
        next_pressure = actuator.actuator_step(p, matrices, xa, i_k)
        next_load = plant.loading_step(p, xl, k * h, x[plant.SPEED], h) if contact else 0.0
        plant.plant_step(p, x, pressure, next_pressure, load, next_load, h, work)
        pressure, load = next_pressure, next_load
    assert np.array_equal(rows, expected)


def test_batch_equals_single_runs(reference):
    sets = [reference.replace({"friction.theta1": t}) for t in (0.8, 0.95, 1.1)]
    scenario = sc.constant_pressure_test(reference, 30e5)
    batch = simulate_batch(sets, scenario)
    for params, result in zip(sets, batch, strict=True):
        assert np.array_equal(simulate(params, scenario).data, result.data)
    # below the skid pressure the brake torque sets the stop; grip only sets the slip
    assert len({r.time_s[-1] for r in batch}) == 1
    slips = [r.slip[5000] for r in batch]
    assert slips[0] > slips[1] > slips[2]


def test_batch_accepts_one_input_per_set(reference):
    scenario = sc.actuator_test(reference, sc.constant(0.5), 1.0)
    inputs = np.stack([np.full(1000, 0.3), np.full(1000, 0.6)])
    low, high = simulate_batch([reference, reference], scenario, inputs)
    assert low.pressure_pa[-1] < high.pressure_pa[-1]


def test_inputs_of_any_kind_share_one_compiled_batch_kernel(reference):
    """One set (a broadcast view of the scenario's current) and a caller's read-only inputs
    run the batch kernel compiled for the rest: each had been another type to numba, and
    compiled the parallel kernel again."""
    from landing_gear_sim.model.integrate import batch_kernel

    scenario = sc.actuator_test(reference, sc.constant(0.5), 0.2)
    frozen = np.full((2, scenario.current_a.size), 0.4)
    frozen.flags.writeable = False
    simulate_batch([reference, reference], scenario)
    simulate_batch([reference], scenario)
    simulate_batch([reference, reference], scenario, frozen)
    assert len(batch_kernel.signatures) == 1, batch_kernel.signatures


def test_switched_off_elements_leave_no_trace(reference):
    reduced = reference.without("gear_walk", "load_dependent_radius", "drag")
    result = simulate(reduced, sc.constant_pressure_test(reduced, 30e5))
    assert np.all(result.gear_angle_rad == 0.0)
    assert np.all(result.rolling_radius_m == reference.number("wheel.unloaded_radius_m"))
    assert result.drag_energy_j[-1] == 0.0
    assert np.array_equal(result.hub_speed_m_s, result.speed_m_s)


def test_actuator_without_dynamics_follows_the_static_map_at_once(reference):
    static = reference.without("actuator_dynamics")
    scenario = sc.actuator_test(static, sc.steps((0.2, 0.6), 0.5), 1.0)
    result = simulate(static, scenario)
    # P_{k+1} is the map of I_k: sample 501 already shows the 0.6 A step taken at 500
    before, expected = 7e6 * 0.1 + 1e6 * 0.01, 7e6 * 0.5 + 1e6 * 0.25
    assert result.pressure_pa[500] == pytest.approx(before)
    assert result.pressure_pa[501] == pytest.approx(expected)
    dynamic = simulate(reference, scenario)
    assert dynamic.pressure_pa[501] - before < 0.01 * (expected - before)


def test_actuator_follows_a_second_order_step_response(reference):
    scenario = sc.actuator_test(reference, sc.steps((0.0, 0.6), 0.5), 1.5)
    result = simulate(reference, scenario)
    final = 7e6 * 0.5 + 1e6 * 0.25
    zeta = reference.number("actuator.damping_ratio")
    overshoot = math.exp(-zeta * math.pi / math.sqrt(1 - zeta ** 2))
    assert result.pressure_pa.max() == pytest.approx(final * (1 + overshoot), rel=1e-3)
    assert result.pressure_pa[-1] == pytest.approx(final, rel=1e-4)
    assert np.all(result.speed_m_s == 0.0) and np.all(result.vertical_load_n == 0.0)


def test_aircraft_configuration_brakes_the_aircraft_mass(reference):
    aircraft = load_parameters(overrides={"configuration": "aircraft",
                                          "drag.coeff_n_s2_per_m2": 0.7})
    rig = simulate(reference, sc.constant_pressure_test(reference, 30e5))
    plane = simulate(aircraft, sc.constant_pressure_test(aircraft, 30e5))
    assert plane.stop_reason == "stop speed reached"
    assert plane.wheel_speed_rad_s.min() >= 0.0
    # 3680 kg against the rig's 3500 kg-equivalent flywheel, more drag: similar stop
    assert plane.time_s[-1] == pytest.approx(rig.time_s[-1], rel=0.15)
    # the J_θ coupling of eqs. (5)-(6) changes the gear motion
    assert not np.allclose(plane.gear_angle_rad[:5000], rig.gear_angle_rad[:5000])


def test_a_load_cell_with_crosstalk_reads_part_of_the_vertical_load(reference, run_30bar):
    """sensors.crosstalk_fx_per_fz: the F_x channel reads F_x + c F_z (offline and in the
    plant node's samples alike); the calibration takes it off again."""
    from landing_gear_sim.model.blocks import PlantBlock
    from landing_gear_sim.model.sensors import SensorModel

    leaky = reference.replace({"sensors.crosstalk_fx_per_fz": 0.02}, "test")
    read = simulate(leaky, run_30bar.scenario).to_run()
    assert np.allclose(read.longitudinal_force_n,
                       run_30bar.longitudinal_force_n + 0.02 * run_30bar.vertical_load_n)
    sensors = SensorModel.of(leaky)
    assert np.allclose(sensors.true_longitudinal(read.longitudinal_force_n,
                                                 read.vertical_load_n),
                       run_30bar.longitudinal_force_n)
    block = PlantBlock(leaky, run_30bar.scenario)
    for _ in range(1500):
        block.advance(2e6, 1e5)
    sample = block.sample()
    row = block.record(0.0)
    assert sample.longitudinal_force_n == pytest.approx(row[7] + 0.02 * row[6])


def test_a_wheel_channel_out_of_step_reads_the_same_offline_and_in_the_node(reference,
                                                                           run_30bar):
    """sensors.wheel_speed_delay_s: the wheel channel reads ω(t − d), the same value from the
    plant node's recent samples as from the whole offline run."""
    late = reference.replace({"sensors.wheel_speed_delay_s": 0.0205}, "test")
    offline = simulate(late, run_30bar.scenario).to_run()
    truth = run_30bar.wheel_speed_rad_s
    assert np.allclose(offline.wheel_speed_rad_s[:21], truth[0])
    assert np.allclose(offline.wheel_speed_rad_s[100:],
                       0.5 * (truth[79:-21] + truth[80:-20]))
    assert np.array_equal(_node_wheel_readings(late, run_30bar, 3000),
                          offline.wheel_speed_rad_s[:3000])


def _node_wheel_readings(params, run, samples: int) -> list[float]:
    """The plant node's wheel channel over the first ``samples`` of ``run``'s inputs."""
    from landing_gear_sim.model.blocks import PlantBlock

    block = PlantBlock(params, run.scenario)
    readings = []
    for _ in range(samples):
        readings.append(block.sample().wheel_speed_rad_s)
        block.advance(run.pressure_pa[block.step_index + 1],
                      run.vertical_load_n[block.step_index + 1])
    return readings


def test_a_wheel_encoder_with_run_out_ripples_with_the_angle_the_same_offline_and_in_the_node(
        reference, run_30bar):
    """sensors.wheel_runout_*: the encoder reads ω (1 + e₁ cos(θ + φ₁) + e₂ cos(2θ + φ₂)), θ
    the wheel's angle since the first sample; the plant node, reading sample by sample (and
    out of step), gives what the whole offline run gives."""
    from scipy.integrate import cumulative_trapezoid

    wobbly = reference.replace({"sensors.wheel_runout_1": 0.01,
                                "sensors.wheel_runout_1_phase_rad": 0.7,
                                "sensors.wheel_runout_2": 0.004,
                                "sensors.wheel_runout_2_phase_rad": -2.0}, "test")
    offline = simulate(wobbly, run_30bar.scenario).to_run()
    truth = run_30bar.wheel_speed_rad_s
    angle = cumulative_trapezoid(truth, run_30bar.time_s, initial=0.0)
    expected = truth * (1 + 0.01 * np.cos(angle + 0.7) + 0.004 * np.cos(2 * angle - 2.0))
    np.testing.assert_allclose(offline.wheel_speed_rad_s, expected, rtol=1e-9)
    late = wobbly.replace({"sensors.wheel_speed_delay_s": 0.0205}, "test")
    offline_late = simulate(late, run_30bar.scenario).to_run()
    np.testing.assert_array_equal(_node_wheel_readings(late, run_30bar, 3000),
                                  offline_late.wheel_speed_rad_s[:3000])
