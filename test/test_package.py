"""package.xml as rosdep and colcon read it."""

from __future__ import annotations

import ast
import os
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
ROSDISTRO = os.environ.get("ROSDISTRO_DIR")
DISTRO = "kilted"


def _dependency_keys() -> list[str]:
    tree = ET.parse(ROOT / "package.xml")
    tags = ("depend", "exec_depend", "build_depend", "test_depend")
    return [element.text.strip() for tag in tags for element in tree.getroot().iter(tag)]


@pytest.mark.skipif(ROSDISTRO is None, reason="set ROSDISTRO_DIR to a ros/rosdistro checkout "
                    "(CI has none: rosdep's index lives on GitHub)")
def test_every_dependency_key_resolves_in_rosdep_or_the_distribution():
    rosdistro = Path(ROSDISTRO)
    known: set[str] = set()
    for path in (rosdistro / "rosdep").glob("*.yaml"):
        known |= set(yaml.safe_load(path.read_text()) or {})
    distribution = yaml.safe_load((rosdistro / DISTRO / "distribution.yaml").read_text())
    for name, repository in distribution["repositories"].items():
        if "release" in repository:  # its packages, or the one named as the repository
            known |= set(repository["release"].get("packages", [name]))
    missing = [key for key in _dependency_keys() if key not in known]
    assert not missing, f"keys rosdep cannot resolve: {missing}"


PYTHON_KEYS = {"numpy": "python3-numpy", "scipy": "python3-scipy",
               "matplotlib": "python3-matplotlib", "yaml": "python3-yaml",
               "numba": "python3-numba", "sklearn": "python3-sklearn",
               "rosbags": "python3-rosbags-pip"}
"""Python modules -> their rosdep keys (a ROS package's key is its own name)."""
NO_KEY = {"threadpoolctl": "comes with python3-sklearn",
          "dask": "history and montecarlo only; no rosdep key (setup.py brings it)",
          "distributed": "the same", "pyarrow": "the formats extra, read only when asked",
          "h5py": "the same", "asammdf": "the same", "nptdms": "the same",
          "openpyxl": "the same",
          "mcap": "a cut .mcap recovered; no key of its own (rosdistro, Aug 2026: only "
                  "mcap-ros2-support); setup.py brings it"}
OWN = {"landing_gear_sim", "antiskid", "msg_tools"}


def _imported_modules() -> set[str]:
    found: set[str] = set()
    for folder in (*OWN, "launch"):
        for path in (ROOT / folder).rglob("*.py"):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.Import):
                    found |= {alias.name.split(".")[0] for alias in node.names}
                elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                    found.add(node.module.split(".")[0])
    return found - set(sys.stdlib_module_names) - OWN


def test_every_module_the_product_imports_is_a_dependency_of_the_package():
    """Issue 31: the launch file imported launch and launch_ros, which package.xml lacked,
    so rosdep would not install them."""
    keys = set(_dependency_keys())
    missing = sorted(module for module in _imported_modules() - set(NO_KEY)
                     if PYTHON_KEYS.get(module, module) not in keys)
    assert not missing, f"imported but not in package.xml: {missing}"
