"""The equations' generic slots (issue 41): a sparse coefficient vector over a basis of terms.

An equation of the rig (the wheel's torque balance, the tyre's force law, the loading
device's set point) holds beside its law a slot of :data:`SLOT_TERMS` terms, each a
coefficient times one basis function of the signals the equation sees at that instant. A
basis function is written as a code: up to two factors, each a signal (:data:`SIGNALS`) put
through a shape (:data:`SHAPES`) — ``sgn ω``, ``[E_b > floor]``, ``λ³``, ``cos θ``,
``t_c``, ``ω·P``. The code and the coefficient are two parameters of the set
(``<equation>.term_<k>_code``, ``<equation>.term_<k>_coeff``), so a slot all zero is today's
arithmetic, and the offline simulator, the graph, the compiled loop and the reference ODE
all read the same law through :func:`slot_value`.

The diagnosis composes its libraries from the same codes (``diagnosis.terms``) and evaluates
them on measured arrays with :func:`term_values`: each basis function is written here once.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

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


@njit(cache=True, inline="always")
def shaped(shape, x, floor):
    """The signal value ``x`` through ``shape`` (``floor``: the signal's)."""
    if shape == IDENTITY:
        return x
    if shape == SIGN:
        return float(np.sign(x))
    if shape == SIGNED_SQUARE:
        return abs(x) * x
    if shape == SQUARE:
        return x * x
    if shape == CUBE:
        return x * x * x
    if shape == STEP:
        return 1.0 if x > floor else 0.0
    if shape == DEAD_ZONE:
        return float(np.sign(x)) * max(abs(x) - floor, 0.0)
    if shape == SIGNED_ROOT:
        return float(np.sign(x)) * math.sqrt(abs(x))
    if shape == COS1:
        return math.cos(x)
    if shape == SIN1:
        return math.sin(x)
    if shape == COS2:
        return math.cos(2.0 * x)
    if shape == SIN2:
        return math.sin(2.0 * x)
    return 0.0


@njit(cache=True, inline="always")
def factor_value(factor, signals):
    signal = factor // FACTOR
    if signal >= N_SIGNALS:  # no such signal (a params file's code out of the basis)
        return 0.0
    return shaped(factor % FACTOR, signals[signal], FLOORS[signal])


@njit(cache=True)
def term_value(code, signals):
    """The basis function ``code`` at ``signals`` (N_SIGNALS floats: a tuple, or a row)."""
    whole = int(code)
    value = factor_value(whole % SECOND, signals)
    if whole >= SECOND:
        value *= factor_value(whole // SECOND - 1, signals)
    return value


@njit(cache=True, inline="always")
def slot_acts(p, first):
    """Whether a term of the slot at ``p[first]`` has a coefficient (else it adds 0): a
    caller that asks first builds no signals and makes no call, and an unused slot cost a
    stop twice its time."""
    for k in range(SLOT_TERMS):  # noqa: SIM110 (a loop numba compiles to three compares)
        if p[first + 2 * k + 1] != 0.0:
            return True
    return False


@njit(cache=True)
def slot_value(p, first, signals):
    """An equation's slot: Σ coefficient·term over its SLOT_TERMS (code, coefficient) pairs
    at ``p[first]``, ``p[first + 1]``, … (0 with every coefficient 0: no term evaluated)."""
    total = 0.0
    for k in range(SLOT_TERMS):
        coeff = p[first + 2 * k + 1]
        if coeff != 0.0:
            total += coeff * term_value(p[first + 2 * k], signals)
    return total


@njit(cache=True)
def term_values(code, signals):
    """:func:`term_value` of each row of ``signals`` (n, N_SIGNALS)."""
    out = np.empty(signals.shape[0])
    for i in range(out.shape[0]):
        out[i] = term_value(code, signals[i])
    return out


@njit(cache=True)
def slot_values(p, first, signals):
    """:func:`slot_value` of each row of ``signals`` (n, N_SIGNALS)."""
    out = np.empty(signals.shape[0])
    for i in range(out.shape[0]):
        out[i] = slot_value(p, first, signals[i])
    return out


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
