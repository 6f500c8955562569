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

from landing_gear_sim.model.basis_codes import (  # noqa: F401 (re-exported: one basis)
    BRAKE_ENERGY,
    CONTACT_TIME,
    COS1,
    COS2,
    CUBE,
    CURVE,
    DEAD_ZONE,
    FACTOR,
    FLOORS,
    IDENTITY,
    LOAD,
    N_SHAPES,
    N_SIGNALS,
    OMEGA,
    PRESSURE,
    PRESSURE_RATE,
    RUN_TIME,
    SECOND,
    SIGN,
    SIGNALS,
    SIGNED_ROOT,
    SIGNED_SQUARE,
    SIN1,
    SIN2,
    SLIP,
    SLOT_TERMS,
    SPEED,
    SQUARE,
    STEP,
    VALVE_CURRENT,
    VALVE_ERROR,
    WHEEL_ANGLE,
    factor_code,
    factors,
    product_code,
)


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
