"""What both controllers measure: filtered wheel deceleration and a speed reference."""

from __future__ import annotations

import math
from dataclasses import dataclass

from landing_gear_sim.model.elements import GRAVITY_M_S2

from .errors import ControllerError


def check_positive(owner: str, **values: float) -> None:
    """Raise ControllerError naming the first value that is not finite and > 0."""
    for name, value in values.items():
        if not (math.isfinite(value) and value > 0):
            raise ControllerError(f"{owner}: {name} must be > 0, got {value}")


@dataclass
class Deceleration:
    """η = −ω̇ r / g from the wheel speed, differentiated through a first-order filter.

    ``time_constant_s`` trades noise for lag (5 ms: 32 Hz, well above the 8 Hz gear walk).
    """

    radius_m: float
    step_s: float
    time_constant_s: float = 0.005
    _speed: float = math.nan
    eta: float = 0.0

    def update(self, wheel_speed_rad_s: float) -> float:
        """Feed one sample [rad/s]; return η [-] (positive while the wheel slows down)."""
        if math.isnan(self._speed):
            self._speed = wheel_speed_rad_s
            return self.eta
        alpha = self.step_s / (self.time_constant_s + self.step_s)
        previous = self._speed
        self._speed += alpha * (wheel_speed_rad_s - self._speed)
        self.eta = -(self._speed - previous) / self.step_s * self.radius_m / GRAVITY_M_S2
        return self.eta
