"""What both controllers share: checks of their settings."""

from __future__ import annotations

import math

from .errors import ControllerError


def check_positive(owner: str, **values: float) -> None:
    """Raise ControllerError naming the first value that is not finite and > 0."""
    for name, value in values.items():
        if not (math.isfinite(value) and value > 0):
            raise ControllerError(f"{owner}: {name} must be > 0, got {value}")
