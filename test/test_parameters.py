"""The params-file loader: reference values, layering, and a clear error for each bad value."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from landing_gear_sim.errors import ParameterError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.bundled import default_config_dir
from landing_gear_sim.model.parameters import (
    INDEX,
    N_PARAMS,
    SPECS,
    load_parameters,
    parse_assignment,
)

REFERENCE = default_config_dir() / "reference_rig.yaml"


def _write_variant(tmp_path: Path, key: str, value: object, drop: bool = False) -> Path:
    """The reference file with one key changed (or removed)."""
    document = yaml.safe_load(REFERENCE.read_text())
    section = document["/**"]["ros__parameters"]
    *parents, leaf = key.split(".")
    for part in parents:
        section = section[part]
    if drop:
        del section[leaf]
    else:
        section[leaf] = value
    path = tmp_path / "variant.yaml"
    path.write_text(yaml.safe_dump(document))
    return path


def test_reference_rig_holds_the_datasheet_in_si(reference):
    assert reference.configuration == "rig"
    assert reference.number("brake.gain_n_m_per_pa") * 1e5 == pytest.approx(150.0)
    assert reference.number("actuator.map_k1_pa_per_a") / 1e5 == pytest.approx(70.0)
    assert reference.number("gear_walk.stiffness_n_m_per_rad") == 6.9e5
    wn = math.sqrt(6.9e5 / reference.number("gear_walk.inertia_kg_m2")) / (2 * math.pi)
    assert wn == pytest.approx(8.0, abs=0.05)
    assert all(reference.has(e) for e in ("gear_walk", "drag", "actuator_dynamics"))


def test_vector_packs_every_key_at_its_index(reference):
    vector = reference.vector()
    assert vector.shape == (N_PARAMS,)
    assert vector[INDEX["friction.theta2"]] == 28.0
    assert vector[INDEX["configuration"]] == 0.0
    assert np.all(np.isfinite(vector))


@pytest.mark.parametrize(("value", "fragment"), [
    (-3500.0, "must not be negative"),
    (float("nan"), "must be finite"),
    (float("inf"), "must be finite"),
    (0.0, "must be > 0"),
    ("heavy", "must be a number"),
    (True, "must be a number"),
])
def test_bad_value_names_key_and_file(tmp_path, value, fragment):
    path = _write_variant(tmp_path, "flywheel.inertia_kg_m2", value)
    with pytest.raises(ParameterError) as error:
        load_parameters([path])
    message = str(error.value)
    assert "flywheel.inertia_kg_m2" in message
    assert str(path) in message
    assert fragment in message


def test_missing_value_names_key_and_files(tmp_path):
    path = _write_variant(tmp_path, "friction.theta3", None, drop=True)
    with pytest.raises(ParameterError, match=r"'friction.theta3' is missing.*variant.yaml"):
        load_parameters([path])


def test_unknown_key_is_an_error_with_a_suggestion(tmp_path):
    path = _write_variant(tmp_path, "friction.theta_1", 0.9)
    with pytest.raises(ParameterError, match=r"unknown parameter 'friction.theta_1'.*theta1"):
        load_parameters([path])


def test_bad_choice_and_bool_are_errors(tmp_path):
    with pytest.raises(ParameterError, match=r"configuration.*rig, aircraft"):
        load_parameters([_write_variant(tmp_path, "configuration", "truck")])
    with pytest.raises(ParameterError, match=r"elements\.drag.*true or false"):
        load_parameters([_write_variant(tmp_path, "elements.drag", "yes please")])


@pytest.mark.parametrize(("text", "fragment"), [
    ("not: [valid", "not valid YAML"),
    ("- just\n- a list\n", "not a ROS 2 params file"),
    ("plant:\n  params: {}\n", "no 'ros__parameters'"),
])
def test_malformed_file_is_a_one_line_error(tmp_path, text, fragment):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ParameterError, match=fragment) as error:
        load_parameters([path])
    assert "\n" not in str(error.value)


def test_a_file_in_another_encoding_is_a_one_line_error(tmp_path):
    """A params file is read as UTF-8 (YAML's own, and the extended model's laws are
    written in it); a datasheet saved in Latin-1 had raised a UnicodeDecodeError."""
    path = tmp_path / "datasheet.yaml"
    path.write_bytes("# Fr\u00e9quence du servo-valve\n/**:\n  ros__parameters: {}\n"
                     .encode("latin-1"))
    with pytest.raises(ParameterError, match=r"datasheet\.yaml: not UTF-8 text") as error:
        load_parameters([path])
    assert "\n" not in str(error.value)


def test_missing_file_is_named(tmp_path):
    with pytest.raises(ParameterError, match=r"nowhere\.yaml: cannot read"):
        load_parameters([tmp_path / "nowhere.yaml"])


def test_overlay_switches_to_aircraft_and_keeps_the_rest(reference):
    aircraft = load_parameters([REFERENCE, default_config_dir() / "aircraft.yaml"])
    assert aircraft.configuration == "aircraft"
    assert aircraft.number("drag.coeff_n_s2_per_m2") == 0.7
    assert aircraft.number("friction.theta1") == reference.number("friction.theta1")


def test_ros_style_exponent_is_read_as_a_number(tmp_path):
    path = tmp_path / "overlay.yaml"
    path.write_text("/**:\n  ros__parameters:\n    gear_walk:\n      stiffness_n_m_per_rad: 7e5\n")
    params = load_parameters([REFERENCE, path])
    assert params.number("gear_walk.stiffness_n_m_per_rad") == 7e5


def test_sections_of_other_nodes_are_ignored(tmp_path):
    path = tmp_path / "with_controller.yaml"
    path.write_text("antiskid_controller:\n  ros__parameters:\n    type: slip\n")
    assert load_parameters([REFERENCE, path]).number("friction.theta1") == 0.95


def test_written_file_loads_back_identically(tmp_path, reference):
    changed = reference.replace({"friction.theta1": 0.8123456789}).without("gear_walk")
    changed.to_yaml(tmp_path / "out.yaml")
    again = load_parameters([tmp_path / "out.yaml"])
    assert np.array_equal(again.vector(), changed.vector())


def test_overrides_and_without_are_validated(reference):
    with pytest.raises(ParameterError, match="must not be negative"):
        reference.replace({"wheel.inertia_kg_m2": -1.0})
    with pytest.raises(ParameterError, match="unknown element 'tyre_wear'"):
        reference.without("tyre_wear")
    assert parse_assignment("friction.theta1=0.8") == ("friction.theta1", 0.8)
    with pytest.raises(ParameterError, match="KEY=VALUE"):
        parse_assignment("friction.theta1")


def test_every_spec_has_a_unit_and_description():
    assert len({s.key for s in SPECS}) == len(SPECS)
    assert all(s.unit and s.description for s in SPECS)


def test_a_params_file_written_before_the_gain_slopes_and_crosstalk_still_loads(tmp_path):
    """Keys added to the schema later default to 'no such term' in older files."""
    from landing_gear_sim.model.bundled import default_config_files

    text = default_config_files()[0].read_text()
    later = ("gain_slope", "crosstalk", "wheel_speed_delay")
    older = "\n".join(line for line in text.splitlines() if not any(k in line for k in later))
    (tmp_path / "older.yaml").write_text(older + "\n")
    params = load_parameters([tmp_path / "older.yaml"])
    assert params.number("brake.gain_slope_wheel_speed_s_per_rad") == 0.0
    assert params.number("brake.gain_slope_pressure_per_pa") == 0.0
    assert params.number("sensors.crosstalk_fx_per_fz") == 0.0
    assert params.number("sensors.wheel_speed_delay_s") == 0.0


def test_set_reads_an_exponent_without_a_dot_as_ros_does():
    """`--set friction.load_sensitivity_per_n=1e-5` was refused ('must be a number, got
    1e-5'): PyYAML reads an exponent without a dot as text, ROS reads a double."""
    params = load_parameters(overrides=dict([parse_assignment(
        "friction.load_sensitivity_per_n=1e-5"), parse_assignment("radius.b_m_per_n=5E-7")]))
    assert params.number("friction.load_sensitivity_per_n") == 1e-5
    assert params.number("radius.b_m_per_n") == 5e-7


def test_every_schema_key_is_a_constant_of_the_keys_module_in_the_schemas_order():
    constants = [(name, value) for name, value in vars(K).items()
                 if name.isupper() and isinstance(value, str)]
    slots = [key for name, value in vars(K).items() if name.endswith("_TERMS")
             for pair in value for key in pair]
    assert [value for _, value in constants] + slots == [spec.key for spec in SPECS]
    assert all(name == value.replace(".", "_").upper() for name, value in constants)


def test_the_schema_order_is_only_appended_to():
    """A key moved or inserted before the last shifts the indices a cached compiled module
    still reads: wrong physics without a word."""
    frozen = [line for line in (Path(__file__).parent / "schema_order.txt").read_text()
              .splitlines() if line and not line.startswith("#")]
    assert [spec.key for spec in SPECS][:len(frozen)] == frozen
