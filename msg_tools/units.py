"""Units accepted in column-mapping files, as factors to SI."""

from __future__ import annotations

import math

PA_PER_BAR = 1e5
"""Pascal per bar: the one conversion between the unit users read and SI inside."""

UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3, "us": 1e-6},
    "current": {"A": 1.0, "mA": 1e-3},
    "pressure": {"bar": PA_PER_BAR, "Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "psi": 6894.757293168361},
    "speed": {"rad/s": 1.0, "rpm": 2 * math.pi / 60, "deg/s": math.pi / 180,
              "Hz": 2 * math.pi},
    "force": {"N": 1.0, "kN": 1e3, "lbf": 4.4482216152605},
}

QUANTITY: dict[str, str] = {
    "time_s": "time", "current_a": "current", "pressure_pa": "pressure",
    "wheel_speed_rad_s": "speed", "flywheel_speed_rad_s": "speed",
    "vertical_load_n": "force", "longitudinal_force_n": "force",
}
"""Run field → physical quantity (which units it accepts)."""
