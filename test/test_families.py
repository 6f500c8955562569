"""The families of discovered terms as plug-ins (issue 29): one module each, an ordered
registry, every family extending an equation through a slot of the model's schema, and a
schema that only ever grows at its end (the compiled physics caches its indices)."""

from __future__ import annotations

import numpy as np
import pytest

from landing_gear_sim.diagnosis.catalogue import CATALOGUE
from landing_gear_sim.diagnosis.families import HIDDEN, REGISTRY
from landing_gear_sim.diagnosis.families.base import term_candidate
from landing_gear_sim.diagnosis.families.equation_terms import EquationTerms
from landing_gear_sim.diagnosis.findings import Finding
from landing_gear_sim.diagnosis.relations import Relation
from landing_gear_sim.model.parameters import INDEX, SPECS
from msg_tools.units import signed

SPEC_BY_KEY = {spec.key: spec for spec in SPECS}

FROZEN = ['configuration', 'elements.gear_walk', 'elements.load_dependent_radius',
    'elements.actuator_dynamics', 'elements.drag', 'elements.actuator_delay',
    'elements.pressure_sensor_offset', 'elements.tire_relaxation', 'elements.brake_fade',
    'flywheel.radius_m', 'flywheel.inertia_kg_m2', 'drag.coeff_n_s2_per_m2',
    'wheel.unloaded_radius_m', 'wheel.inertia_kg_m2', 'radius.a_m_per_n2', 'radius.b_m_per_n',
    'radius.c_m', 'friction.theta1', 'friction.theta2', 'friction.theta3', 'gear_walk.length_m',
    'gear_walk.inertia_kg_m2', 'gear_walk.stiffness_n_m_per_rad',
    'gear_walk.damping_n_m_s_per_rad', 'aircraft.mass_kg', 'aircraft.wheel_mass_kg',
    'aircraft.gear_mass_kg', 'brake.gain_n_m_per_pa', 'brake.fade_fraction',
    'brake.fade_energy_j', 'tyre.relaxation_length_m', 'actuator.max_current_a',
    'actuator.deadband_current_a', 'actuator.map_k1_pa_per_a', 'actuator.map_k2_pa_per_a2',
    'actuator.max_pressure_pa', 'actuator.gain', 'actuator.natural_frequency_hz',
    'actuator.damping_ratio', 'actuator.delay_s', 'loading.static_load_n',
    'loading.lift_coeff_n_s2_per_m2', 'loading.servo_time_constant_s',
    'loading.touchdown_ramp_s', 'rig_test.initial_speed_m_s', 'rig_test.touchdown_s',
    'rig_test.brake_start_s', 'rig_test.brake_ramp_s', 'rig_test.stop_speed_m_s',
    'rig_test.max_duration_s', 'sensors.pressure_noise_pa', 'sensors.speed_noise_rad_s',
    'sensors.force_noise_n', 'sensors.pressure_offset_pa', 'simulation.output_rate_hz',
    'brake.gain_slope_wheel_speed_s_per_rad', 'brake.gain_slope_pressure_per_pa',
    'sensors.crosstalk_fx_per_fz', 'sensors.wheel_speed_delay_s', 'friction.change_speed_m_s',
    'friction.after_theta1', 'friction.after_theta2', 'friction.after_theta3',
    'actuator.backlash_a', 'brake.gain_drift_per_run', 'friction.load_sensitivity_per_n',
    'friction.reference_load_n', 'sensors.wheel_runout_1', 'sensors.wheel_runout_1_phase_rad',
    'sensors.wheel_runout_2', 'sensors.wheel_runout_2_phase_rad', 'brake.fade_shape',
    'sensors.pressure_delay_s', 'brake.runout_1', 'brake.runout_1_phase_rad', 'brake.runout_2',
    'brake.runout_2_phase_rad']


def test_the_schema_only_grows_at_its_end():
    """numba caches each compiled module with the parameter indices it saw: a key inserted
    or moved shifts them, and a module that did not change would run with the wrong
    physics. New keys go last."""
    keys = [s.key for s in SPECS]
    assert keys[:len(FROZEN)] == FROZEN


def test_every_family_extends_an_equation_through_slots_of_the_schema():
    names = [f.name for f in REGISTRY]
    assert len(set(names)) == len(names)
    assert [f.rank for f in REGISTRY] == sorted(f.rank for f in REGISTRY)
    for family in REGISTRY:
        assert family.keys and all(key in INDEX for key in family.keys), family.name
        assert all(isinstance(r, Relation) for r in family.relations), family.name
        assert family.equation and family.hidden, family.name
        assert not {family.reports} & set(CATALOGUE), family.name
        generic = isinstance(family, EquationTerms) and family.library.slot is not None
        for hidden in family.hidden:
            # a generic slot's effects are drawn in the equation's named slot, found in it
            assert hidden.slot in INDEX and (generic or hidden.slot in family.keys), hidden.name


@pytest.mark.parametrize("case", sorted(HIDDEN))
def test_a_family_writes_its_law_from_the_models_values(reference, case):
    """The formula is the model's slot read back, never a copy of a number: change the slot,
    the law changes."""
    family, hidden = HIDDEN[case]
    rig = reference.replace(hidden.draw(np.random.default_rng(1), reference), "hidden")
    slot = hidden.slot_of(rig)
    if isinstance(family, EquationTerms) and family.library.slot is not None:
        slot, rig = family.placed(rig, hidden.key, rig.number(slot))
    candidate = term_candidate(family, (slot,), (rig.number(slot),), ((-1.0, 1.0),), (),
                               (), ())
    law = family.formula(candidate, rig)
    assert law and law != family.formula(candidate, rig.replace(
        {slot: 2 * rig.number(slot)}, "doubled"))
    assert candidate.family == family.reports and candidate.cause == "discovered"
    if SPEC_BY_KEY[slot].signed:  # a term of either sign is written with its own
        flipped = family.formula(candidate, rig.replace({slot: -rig.number(slot)}, "flipped"))
        assert abs(flipped.count("−") - law.count("−")) == 1, (law, flipped)


def test_a_term_of_a_law_is_written_with_its_sign_and_display_unit():
    assert signed(0.0047, "s") == "+ 4.7 ms"
    assert signed(-0.034) == "− 0.034"
    assert signed(-1.2e-5, "1/N", ".2f") == "− 1.20 %/kN"
    assert signed(0.02, "1", ".2f") == "+ 2.00 %"
    assert signed(-1.87e6, "Pa/A^3") == "− 18.7 bar/A³"


def test_candidates_and_findings_take_keywords_only():
    with pytest.raises(TypeError):
        Finding("unexplained", {}, {}, "", {}, {}, None, None, False)  # type: ignore[misc]
    assert all(c.family == "" for c in CATALOGUE.values())


def test_the_law_table_of_the_architecture_names_code_that_exists():
    """docs/architecture.md says where each law lives; every owner it names exists."""
    import importlib
    import re
    from pathlib import Path

    page = (Path(__file__).resolve().parents[1] / "docs" / "architecture.md").read_text()
    table = page[page.index("| law or conversion | owner |"):page.index("- **SI inside")]
    owners = re.findall(r"`((?:model|calibration|msg_tools)\.[\w.]+)`", table)
    assert len(owners) >= 15
    for owner in owners:
        module, name = owner.rsplit(".", 1)
        package = module if module.startswith("msg_tools") else f"landing_gear_sim.{module}"
        assert hasattr(importlib.import_module(package), name), owner


def test_the_diagnosis_contract_lists_the_registry_in_its_order():
    from pathlib import Path

    page = (Path(__file__).resolve().parents[1] / "docs" / "diagnosis.md").read_text()
    rows = [line.split("|")[2].strip(" `") for line in page.splitlines()
            if line.startswith("| ") and line.split("|")[1].strip().isdigit()]
    assert rows == [f.name for f in REGISTRY]
