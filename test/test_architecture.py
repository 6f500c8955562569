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
PACKAGES = ("landing_gear_sim", "antiskid", "msg_tools")
# a budget points at a file to look at, never where to cut it: a module is one concept (the
# valve's, its static map and A(s) with their libraries and checks, is 486 lines)
MAX_LINES = 600


def test_no_module_is_longer_than_a_reader_can_hold():
    long = {str(path.relative_to(ROOT)): n
            for package in PACKAGES
            for path in (ROOT / package).rglob("*.py")
            if (n := len(path.read_text().splitlines())) > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def _module_map() -> dict[str, set[str]]:
    """docs/architecture.md's module map: the modules it lists under each folder."""
    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = page[page.index("## Where things are"):page.index("## The contracts")]
    listed: dict[str, set[str]] = {}
    for folder, table in re.findall(r"^`([\w/]+)/`\n\n(.*?)(?=^`|\Z)", section, re.M | re.S):
        listed[folder] = set(re.findall(r"^\| `(\w+\.py)` \|", table, re.M))
    return listed


def test_the_architecture_page_lists_every_module_of_the_packages():
    listed = _module_map()
    missing = sorted(str(path.relative_to(ROOT)) for package in PACKAGES
                     for path in (ROOT / package).rglob("*.py")
                     if path.name not in ("__init__.py", "__main__.py")
                     and path.name not in listed.get(str(path.parent.relative_to(ROOT)), set()))
    assert not missing, f"modules docs/architecture.md does not list: {missing}"


def test_every_module_the_architecture_page_names_exists():
    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    gone = [f"{folder}/{name}" for folder, names in _module_map().items() for name in names
            if not (ROOT / folder / name).is_file()]
    sources = [str(p.relative_to(ROOT)) for p in ROOT.rglob("*.py") if ".venv" not in p.parts]
    gone += [path for path in set(re.findall(r"`([\w/]+\.py)`", page))
             if not any(s == path or s.endswith("/" + path) for s in sources)]
    assert not gone, f"docs/architecture.md names modules that do not exist: {gone}"


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
