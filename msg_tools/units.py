"""Units accepted in column-mapping files and units rows, as factors to SI."""

from __future__ import annotations

import math

PA_PER_BAR = 1e5
"""Pascal per bar: the one conversion between the unit users read and SI inside."""

PSI_PA = 6894.757293168361
RPM_RAD_S = 2 * math.pi / 60

UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3, "us": 1e-6},
    "current": {"A": 1.0, "mA": 1e-3},
    "pressure": {"bar": PA_PER_BAR, "mbar": 100.0, "Pa": 1.0, "kPa": 1e3, "MPa": 1e6,
                 "psi": PSI_PA},
    "speed": {"rad/s": 1.0, "rpm": RPM_RAD_S, "deg/s": math.pi / 180, "Hz": 2 * math.pi},
    "force": {"N": 1.0, "kN": 1e3, "lbf": 4.4482216152605},
}

ANGLE_UNITS: dict[str, float] = {"rad": 1.0, "deg": math.pi / 180, "rev": 2 * math.pi}
"""Units of an encoder position that is differentiated into a speed."""

QUANTITY: dict[str, str] = {
    "time_s": "time", "current_a": "current", "pressure_pa": "pressure",
    "wheel_speed_rad_s": "speed", "flywheel_speed_rad_s": "speed",
    "vertical_load_n": "force", "longitudinal_force_n": "force",
}
"""Run field → physical quantity (which units it accepts)."""

_ALIASES = {"sec": "s", "µs": "us", "μs": "us", "1/min": "rpm", "r/min": "rpm",
            "rad s-1": "rad/s", "rad/sec": "rad/s", "°/s": "deg/s"}


def unit_names(units: dict[str, float]) -> str:
    return ", ".join(units)


def parse_unit(text: str, quantity: str) -> str | None:
    """The unit of ``quantity`` written as ``text`` in a units row (``[ms]``, ``(bar)``,
    ``sec``), or None if it names none of them."""
    name = text.strip().strip("[]()").strip()
    name = _ALIASES.get(name, name)
    units = UNITS[quantity]
    if name in units:
        return name
    return {unit.lower(): unit for unit in units}.get(name.lower())


DISPLAY: dict[str, tuple[str, float]] = {
    "s": ("ms", 1e3), "A": ("mA", 1e3), "Pa": ("bar", 1.0 / PA_PER_BAR),
    "N m/Pa": ("N m/bar", PA_PER_BAR), "1/N": ("%/kN", 1e5), "1": ("%", 100.0),
    "N": ("kN", 1e-3), "1/run": ("%/run", 100.0), "Pa/A": ("bar/A", 1.0 / PA_PER_BAR),
    "Pa/A^2": ("bar/A²", 1.0 / PA_PER_BAR), "Pa/A^3": ("bar/A³", 1.0 / PA_PER_BAR),
    "1/Pa": ("1/bar", PA_PER_BAR), "s/Pa": ("ms/bar", 1e3 * PA_PER_BAR),
    "1/Pa^2": ("1/bar²", PA_PER_BAR ** 2), "J": ("MJ", 1e-6),
}
"""SI unit -> the unit a brake engineer reads a term's value in, and the factor to it."""

DISPLAY_UNITS: dict[str, tuple[float, str]] = {
    "pressure_pa": (1 / PA_PER_BAR, "bar"), "wheel_speed_rad_s": (1.0, "rad/s"),
    "flywheel_speed_rad_s": (1.0, "rad/s"), "vertical_load_n": (1e-3, "kN"),
    "longitudinal_force_n": (1e-3, "kN")}
"""Run channel (SI) → (factor, unit) its figures, tables and sentences show it in."""


def display(value_si: float, unit: str, spec: str = ".4g") -> str:
    """``value_si`` [``unit``] as a brake engineer reads it, e.g. 0.0047 s -> '4.7 ms'
    (``spec``: the number's format); a unit without a display one is kept."""
    shown, factor = DISPLAY.get(unit, (unit, 1.0))
    return f"{value_si * factor:{spec}} {shown}"


def signed(value_si: float, unit: str = "", spec: str = ".3g") -> str:
    """``value_si`` as the next term of a law written out: '+ 4.7 ms', '− 0.034' (a true
    minus sign and the magnitude as :func:`display` shows it; ``unit`` '' for a number)."""
    magnitude = display(abs(value_si), unit, spec) if unit else format(abs(value_si), spec)
    return f"{'−' if value_si < 0 else '+'} {magnitude}"
