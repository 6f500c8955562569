"""A user's datasheet (issue 43): a params file naming only what differs from the bundled
reference rig is read over it by every command, and what came from it is said."""

from __future__ import annotations

import pytest

from landing_gear_sim.calibration.plausibility import check_units, unit_notes
from landing_gear_sim.calibration.runs import classify_all
from landing_gear_sim.cli import main
from landing_gear_sim.errors import ParameterError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.datasheet import datasheet_values
from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.parameters import load_parameters

DIFFERS = {"actuator": {"map_k1_pa_per_a": 24e6, "map_k2_pa_per_a2": 4e6,
                        "max_pressure_pa": 2e7},
           "brake": {"gain_n_m_per_pa": 0.0045}}


def _datasheet(tmp_path, sections=DIFFERS):
    import yaml

    path = tmp_path / "datasheet.yaml"
    path.write_text(yaml.safe_dump({"/**": {"ros__parameters": sections}}))
    return path


def test_a_datasheet_naming_what_differs_is_read_over_the_reference_rig(reference, tmp_path):
    path = _datasheet(tmp_path)
    with pytest.raises(ParameterError, match="is missing"):  # alone it is no whole set
        load_parameters([path])
    params = load_parameters([path], over_reference=True)
    assert params.number(K.ACTUATOR_MAP_K1_PA_PER_A) == 24e6
    assert params.number(K.BRAKE_GAIN_N_M_PER_PA) == 0.0045
    assert params.number(K.WHEEL_INERTIA_KG_M2) == reference.number(K.WHEEL_INERTIA_KG_M2)
    assert set(datasheet_values(params)) == {
        K.BRAKE_GAIN_N_M_PER_PA, K.ACTUATOR_MAP_K1_PA_PER_A, K.ACTUATOR_MAP_K2_PA_PER_A2,
        K.ACTUATOR_MAX_PRESSURE_PA}
    assert datasheet_values(reference) == {}


def test_the_cli_takes_a_datasheet_where_it_once_said_configuration_is_missing(tmp_path,
                                                                              capsys):
    path = _datasheet(tmp_path)
    assert main(["params", "--config", str(path)]) == 0
    shown = capsys.readouterr().out
    assert "configuration" in shown and "24000000" in shown.replace(".0", "")


def test_another_rigs_valve_is_plausible_under_its_datasheet_and_said_without(reference,
                                                                             tmp_path):
    """An actuator run of a rig whose map gives over three times the reference's pressure,
    no unit's factor: under the datasheet it is the rig's; without it, another valve whose
    map the runs give, said in a note (issue 64: a real valve's step log had been refused
    as a unit error; it had been refused here too)."""
    rig = load_parameters([_datasheet(tmp_path)], over_reference=True)
    scenario = sc.actuator_test(rig, sc.quasi_static_ramp(rig.number(
        K.ACTUATOR_MAX_CURRENT_A)), 20.0, "actuator_ramp")
    runs = classify_all([simulate(rig, scenario).to_run(noise=7)])
    check_units(runs, reference)
    assert any("another valve" in note and "quasi-static ramp" in note
               for note in unit_notes(runs, reference)), unit_notes(runs, reference)
    check_units(runs, rig)
    assert not any("another valve" in note for note in unit_notes(runs, rig))
