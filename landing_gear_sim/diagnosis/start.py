"""The model a diagnosis starts from: the base set without the elements the user leaves out.

Apart from :mod:`~landing_gear_sim.diagnosis.diagnose` so that the command line can refuse a
misspelt element at once, without loading the numerical stack (issue 32).
"""

from __future__ import annotations

from collections.abc import Sequence

from landing_gear_sim.errors import DiagnosisError
from landing_gear_sim.model.parameters import ELEMENTS, RigParameters

FRICTION_CURVE = "friction_curve"
"""Not an element: the friction curve's calibration, which a diagnosis may start without."""
REMOVABLE = (*ELEMENTS, FRICTION_CURVE)


def starting_model(base: RigParameters, without: Sequence[str]) -> RigParameters:
    """``base`` with the elements of ``without`` removed (friction_curve: not calibrated)."""
    unknown = [w for w in without if w not in REMOVABLE]
    if unknown:
        raise DiagnosisError(f"--without {unknown[0]}: not a model element; choose from "
                             f"{', '.join(REMOVABLE)}")
    return base.without(*(w for w in without if w != FRICTION_CURVE))
