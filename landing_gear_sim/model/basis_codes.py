"""The vocabulary of the equations' generic slots (issue 41, :mod:`.basis`): the signals an
equation may see, the shapes a signal goes through, and the codes of their products, in
plain Python. What reads a code without evaluating it (a params file's notes, a law's
name for a term) imports this and not the compiled evaluation, which loads numba.
"""

from __future__ import annotations

import numpy as np

# The signals an equation may see (one tuple of N_SIGNALS floats; an equation leaves at 0
# what it does not see). Each has a floor: below it, a step counts the signal as absent and
# a dead zone passes nothing (a noisy zero is not a signal).
(OMEGA, SPEED, PRESSURE, LOAD, SLIP, BRAKE_ENERGY, WHEEL_ANGLE, CONTACT_TIME, CURVE,
 RUN_TIME, PRESSURE_RATE, VALVE_ERROR, VALVE_CURRENT) = range(13)
N_SIGNALS = 13
SIGNALS: tuple[tuple[str, str], ...] = (
    ("ω", "rad/s"), ("v", "m/s"), ("P", "Pa"), ("F_z", "N"), ("λ", "-"), ("E_b", "J"),
    ("θ", "rad"), ("t_c", "s"), ("μ_B", "-"), ("t", "s"), ("Ṗ", "Pa/s"), ("ΔP", "Pa"),
    ("e", "A"))
"""Each signal's symbol and SI unit, by index (μ_B: the tyre's calibrated curve at the
slip, so a term may scale it: a friction that falls with speed is μ_B·v; t: the time since
the run's first sample, as a channel that drifts counts it; Ṗ and ΔP: the valve's pressure
rate and what its static map asks beyond the pressure, μ·P_static − P, the states of A(s);
e: the valve's current beyond its dead-band, I − I0, the static map's variable)."""
FLOORS = np.array([1.0, 0.5, 0.5e5, 1000.0, 0.005, 1e4, 0.0, 0.0, 0.01, 0.0, 1e5, 0.5e5,
                   0.01])
"""Each signal's floor [its SI unit]: 1 rad/s, 0.5 m/s, 0.5 bar, 1 kN, 0.5 % slip, 10 kJ,
1 bar/s, 0.5 bar, 10 mA."""

# The shapes a signal goes through; parameter-free, or scaled by the signal's floor.
(IDENTITY, SIGN, SIGNED_SQUARE, SQUARE, CUBE, STEP, DEAD_ZONE, SIGNED_ROOT, COS1, SIN1,
 COS2, SIN2) = range(12)
N_SHAPES = 12
FACTOR = 16  # a factor's code: signal * FACTOR + shape
SECOND = 256  # a term's code: first factor + SECOND * (second factor + 1); < SECOND: one
assert SECOND * (SECOND + 1) == 256 * 257  # parameters.CODE_LIMIT
SLOT_TERMS = 3  # terms per equation's slot


def factor_code(signal: int, shape: int) -> int:
    """The code of one factor: ``signal`` through ``shape``."""
    if not (0 <= signal < N_SIGNALS and 0 <= shape < N_SHAPES):
        raise ValueError(f"no factor of signal {signal} and shape {shape}")
    return signal * FACTOR + shape


def product_code(first: int, second: int | None = None) -> int:
    """The code of a term: one factor's code, or the product of two."""
    return first if second is None else first + SECOND * (second + 1)


def factors(code: int) -> tuple[int, ...]:
    """The factor codes of a term's ``code`` (one or two)."""
    whole = int(code)
    first = whole % SECOND
    return (first,) if whole < SECOND else (first, whole // SECOND - 1)
