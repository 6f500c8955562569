"""package.xml as rosdep and colcon read it."""

from __future__ import annotations

import os
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
