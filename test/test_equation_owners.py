"""Each law once (issue 60): every reader of a balance follows its owner. A run is simulated
with a term in an equation's slot (drawn here, never seen by the code under test), and under
the model that holds the term every reader of that equation reads no error: the plant, the
calibration, the checks, the libraries and the wheel-angle fit. A reader that had copied the
balance and left the slot out reads the term as an error."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration import flywheel as fly
from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.calibration.measured import run_static_load_n, simulate_all
from landing_gear_sim.calibration.runs import classify_all
from landing_gear_sim.calibration.slots import Slot
from landing_gear_sim.calibration.wheel_angle import brake_ripple_design
from landing_gear_sim.diagnosis.equations import Equation
from landing_gear_sim.diagnosis.equations import registry as eq
from landing_gear_sim.diagnosis.equations.placing import equation_errors
from landing_gear_sim.diagnosis.equations.tyre import locked_samples, locked_sliding
from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.quantities import logged_or_set_load_n
from msg_tools.io import read_campaign

BRAKING = ("brake_const_20bar", "brake_const_30bar")


def _with_terms(params, slot: Slot, terms: list[tuple[int, float]]):
    values = {}
    for (code_key, coeff_key), (code, coeff) in zip(slot.keys, terms, strict=False):
        values[code_key], values[coeff_key] = float(code), coeff
    return params.replace(values, "terms")


def _campaign(folder, rig, seed: int, names=BRAKING):
    generate_campaign(folder, rig, seed, names)
    return classify_all(read_campaign(folder).runs)


def test_the_wheel_angle_fit_reads_the_wheel_the_torque_balance_reads(reference, tmp_path):
    """Pads that drag once applied (a wheel slot term, drawn here): under the model that
    holds them, the disc's run-out fit reads the brake's torque as the model's, as the
    torque balance does; its copy of the balance had left the slot out and read the drag
    as a brake weaker by its share."""
    rng = np.random.default_rng(6001)
    drag = float(rng.uniform(120.0, 200.0))
    code = basis.factor_code(basis.BRAKE_ENERGY, basis.STEP)
    rig = _with_terms(rig_like(reference, rng), Slot.WHEEL, [(code, drag)])
    for run in _campaign(tmp_path, rig, 6001):
        b = br.prepare(run, rig)
        torque, energy = br.torque_balance(b, rig)
        m = np.flatnonzero(br.braking_samples(b))
        balance = np.mean(torque[m] / br.model_torque(b, rig, energy, m) - 1.0)
        design = brake_ripple_design(run, rig)
        assert design is not None
        ripple, _ = design
        assert abs(balance) < 0.01, run.name
        assert abs(np.mean(ripple)) < 0.01, (run.name, np.mean(ripple), drag)


def test_every_reader_of_the_wheels_balance_follows_a_term_in_its_slot(reference, tmp_path):
    """The diagnosis's wheel error and library, and the F_x channel's free rolling, read the
    drawn term as the model's: no error beyond a per cent of the brake's torque."""
    rng = np.random.default_rng(6002)
    code = basis.product_code(basis.factor_code(basis.OMEGA, basis.SIGN),
                              basis.factor_code(basis.PRESSURE, basis.STEP))
    rig = _with_terms(rig_like(reference, rng), Slot.WHEEL,
                      [(code, float(rng.uniform(120.0, 200.0)))])
    runs = _campaign(tmp_path, rig, 6002)
    for b in (br.prepare(r, rig) for r in runs):
        rows = eq.WHEEL.rows(b, rig)
        assert rows is not None
        assert abs(np.mean(rows.error)) < 0.01 * rows.scale, b.run.name
        _, excess = br.free_rolling_excess(b, rig)
        assert abs(np.mean(excess)) < 30.0, b.run.name  # N; the term is 0 with no brake
    for run, simulated in zip(runs, simulate_all(runs, rig), strict=True):
        (wheel,) = [e for e in equation_errors(run, rig, simulated)
                    if e.equation is Equation.WHEEL]
        assert abs(np.mean(wheel.error)) < 30.0, run.name  # N m of a ~3 kN m brake


def test_every_reader_of_the_flywheels_balance_follows_a_term_in_its_slot(reference, tmp_path):
    """A bearing loaded by the tyre (c·sgn v·F_z, drawn here) in the plant: the calibration
    fits the flywheel's inertia and drag around it, and the balance's error, integrated and
    differentiated, and the library's rows read nothing of it under the model that holds
    it; under the model without it they read its force."""
    rng = np.random.default_rng(6003)
    c = float(rng.uniform(0.008, 0.015))
    code = basis.product_code(basis.factor_code(basis.SPEED, basis.SIGN),
                              basis.factor_code(basis.LOAD, basis.IDENTITY))
    rig = _with_terms(rig_like(reference, rng), Slot.FLYWHEEL, [(code, c)])
    runs = _campaign(tmp_path, rig, 6003)
    prepared = [br.prepare(r, rig) for r in runs]
    inertia, drag = fly.fit_flywheel(prepared, rig)
    assert inertia.value == pytest.approx(rig.number(K.FLYWHEEL_INERTIA_KG_M2), rel=0.02)
    assert drag.value == pytest.approx(rig.number(K.DRAG_COEFF_N_S2_PER_M2), abs=0.1)
    plain = rig.replace({K.FLYWHEEL_TERMS[0][1]: 0.0}, "without the term")
    for b in prepared:
        on = np.flatnonzero((b.time_s > b.start_s + 0.5) & (b.speed_m_s > 10.0))
        force = c * np.mean(b.load[on])
        assert abs(np.mean(fly.balance_error(b, rig)[on])) < 0.1 * force, b.run.name
        assert np.mean(fly.balance_error(b, plain)[on]) == pytest.approx(-force, rel=0.2)
        rows = eq.FLYWHEEL.rows(b, rig)
        assert rows is not None
        assert np.std(rows.error) < 0.2 * np.std(eq.FLYWHEEL.rows(b, plain).error)


def test_every_reader_of_the_loading_law_follows_a_term_in_its_slot(reference, tmp_path):
    """A cylinder that leaks (c·t_c, drawn here): a run's static load, the load a logger
    without a load cell is given, and the loading library read the plant's set point."""
    rng = np.random.default_rng(6004)
    leak = float(rng.uniform(60.0, 120.0))
    code = basis.factor_code(basis.CONTACT_TIME, basis.IDENTITY)
    rig = _with_terms(rig_like(reference, rng), Slot.LOADING, [(code, leak)])
    static = rig.number(K.LOADING_STATIC_LOAD_N)
    for run in _campaign(tmp_path, rig, 6004):
        assert run_static_load_n(run, rig) == pytest.approx(static, rel=2e-3), run.name
        b = br.prepare(run, rig)
        loaded = np.flatnonzero(b.time_s > b.start_s - 1.0)
        without_cell = dataclasses.replace(run, absent=("vertical_load_n",))
        set_load = logged_or_set_load_n(without_cell, rig)
        error = set_load[loaded] - b.load[loaded]
        assert abs(np.mean(error)) < 0.1 * leak * np.mean(b.time_s[loaded]), run.name
        rows = eq.LOADING.rows(b, rig)
        assert rows is not None
        assert abs(np.mean(rows.error)) < 0.002 * static


def test_the_locked_wheels_check_and_its_library_read_one_tyre(reference, tmp_path):
    """A rig that locks on a second surface below a change speed (drawn here): the locked
    wheel's check and the tyre's locked library read μ(λ = 1) of the surface under the
    tyre, so under the rig's own model neither reads an error."""
    rng = np.random.default_rng(6005)
    rig = rig_like(reference, rng).replace({
        K.FRICTION_THETA1: reference.number(K.FRICTION_THETA1) * 0.8,
        K.FRICTION_CHANGE_SPEED_M_S: 45.0,
        K.FRICTION_AFTER_THETA1: reference.number(K.FRICTION_THETA1) * 0.55,
        K.FRICTION_AFTER_THETA2: reference.number(K.FRICTION_THETA2),
        K.FRICTION_AFTER_THETA3: reference.number(K.FRICTION_THETA3)}, "slippery, then wet")
    runs = _campaign(tmp_path, rig, 6005, ("brake_const_30bar", "brake_const_40bar"))
    prepared = [br.prepare(r, rig) for r in runs]
    assert sum(locked_samples(b, rig).size for b in prepared) > 100
    check = locked_sliding(prepared, rig)
    assert check is not None and abs(check.deviation) < 0.01
    for b in prepared:
        rows = eq.LOCKED_TYRE.rows(b, rig)
        if rows is not None:
            assert abs(np.mean(np.abs(rows.error))) < 0.02, b.run.name
