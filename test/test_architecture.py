"""The house: module sizes, the exception tree, the schema page, the reference's limits."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from antiskid.errors import ControllerError
from landing_gear_sim import errors
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.parameters import SPECS
from landing_gear_sim.model.reference import reference_solution
from msg_tools.errors import RunFormatError

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 450


def test_no_module_is_longer_than_a_reader_can_hold():
    long = {str(path.relative_to(ROOT)): n
            for package in ("landing_gear_sim", "antiskid", "msg_tools")
            for path in (ROOT / package).rglob("*.py")
            if (n := len(path.read_text().splitlines())) > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines: {long}"


@pytest.mark.parametrize("error", [errors.ParameterError, errors.ScenarioError,
                                   errors.IdentificationError, errors.DiagnosisError,
                                   RunFormatError, ControllerError])
def test_every_data_error_is_a_project_error_and_a_value_error(error):
    assert issubclass(error, errors.LandingGearSimError)
    assert issubclass(error, ValueError)


def test_the_parameter_page_lists_exactly_the_schema():
    page = (ROOT / "docs" / "parameters.md").read_text()
    rows = dict(re.findall(r"^\| `([^`]+)` \| ([^|]+) \|", page, flags=re.MULTILINE))
    assert {key: unit.strip() for key, unit in rows.items()} == {s.key: s.unit for s in SPECS}


@pytest.mark.parametrize("change", [
    {"elements.actuator_delay": True, "actuator.delay_s": 0.005},
    {"elements.actuator_dynamics": False},
])
def test_reference_solution_refuses_what_it_does_not_model(reference, change):
    params = reference.replace(change, "test")
    with pytest.raises(errors.ParameterError, match="does not model"):
        reference_solution(params, sc.constant_pressure_test(params, 20e5), end_s=0.1)


def test_the_code_and_readme_cite_contracts_that_exist():
    cited = set()
    sources = [ROOT / "README.md", *ROOT.glob("landing_gear_sim/**/*.py"),
               *ROOT.glob("msg_tools/*.py"), *ROOT.glob("docs/*.md"), *ROOT.glob("config/*.yaml")]
    for path in sources:
        cited |= set(re.findall(r"docs/([\w-]+\.md)", path.read_text()))
    missing = {name for name in cited if not (ROOT / "docs" / name).is_file()}
    assert cited and not missing, f"cited but absent: {missing}"
