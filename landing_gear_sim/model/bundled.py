"""Where the bundled reference rig's params files are: the source tree, an install prefix's
``share/``, a ROS workspace's, a virtual environment's."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from landing_gear_sim.errors import ParameterError


def default_config_dir() -> Path:
    """The bundled ``config/`` folder: source tree, then the install prefix's ``share/``."""
    package = Path(__file__).resolve().parents[1]  # landing_gear_sim/
    share = Path("share") / "landing_gear_sim" / "config"
    # source tree, this copy's prefix (<prefix>/lib/pythonX.Y/site-packages/…), ROS, venv
    own_prefix = [package.parents[3] / share] if len(package.parents) > 3 else []
    candidates = [
        package.parent / "config",
        *own_prefix,
        *(Path(p) / share for p in _ament_prefixes()),
        Path(sys.prefix) / share,
    ]
    for candidate in candidates:
        if (candidate / "reference_rig.yaml").is_file():
            return candidate
    raise ParameterError(
        "cannot find the bundled config/reference_rig.yaml (looked in "
        + ", ".join(str(c) for c in candidates) + ")"
    )


def _ament_prefixes() -> list[str]:
    return [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]


def default_config_files() -> list[Path]:
    """The params files that define the reference rig."""
    return [default_config_dir() / "reference_rig.yaml"]
