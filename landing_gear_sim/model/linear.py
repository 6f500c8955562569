"""Linearisation about a constant-speed operating point and the frequency responses
G_λ(jω) (brake torque → slip) and G_η(jω) (brake torque → normalised wheel deceleration),
as in paper Fig. 7. No plotting here: see :mod:`landing_gear_sim.report.figures`.

The speed is frozen (a slowly varying parameter, as in the paper), so the
linear states are the gear-walk angle and rate, and the wheel speed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.plant import (
    ANGLE,
    ANGLE_RATE,
    N_STATES,
    OMEGA,
    SPEED,
    TYRE_FORCE,
    derivatives,
    tyre_state,
    wheel_extra,
)


def linear_states(params: RigParameters) -> tuple[int, ...]:
    """Plant states of the linear model: θ, θ̇, ω, and the relaxed tyre force if modelled."""
    return (ANGLE, ANGLE_RATE, OMEGA, *((TYRE_FORCE,) if params.has("tire_relaxation") else ()))


@dataclass(frozen=True)
class OperatingPoint:
    """Equilibrium at constant speed: wheel turning at the slip the brake torque holds."""

    speed_m_s: float
    slip: float
    vertical_load_n: float
    pressure_pa: float
    state: np.ndarray  # plant state, shape (N_STATES,)


@dataclass(frozen=True)
class LinearModel:
    """ẋ = A x + B u, y = C x + D u with u = brake torque [N m], y = (λ, η).

    States (θ [rad], θ̇ [rad/s], ω [rad/s] and, with tyre relaxation, F_x [N]); shapes
    A (n, n), B (n,), C (2, n), D (2,).
    """

    point: OperatingPoint
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray


@dataclass(frozen=True)
class FrequencyResponse:
    """G_λ and G_η at ``frequency_hz`` (n,), complex, per N m of brake torque."""

    frequency_hz: np.ndarray
    slip: np.ndarray
    decel: np.ndarray
    speed_m_s: float
    gear_walk: bool


def operating_point(params: RigParameters, speed_m_s: float, slip: float = 0.05) -> OperatingPoint:
    """The equilibrium at ``speed_m_s`` with the brake holding ``slip`` (load from the lift map)."""
    p = params.vector()
    load = el.vertical_load_reference(p, np.inf, speed_m_s)
    radius = el.rolling_radius(p, load)
    x = np.zeros(N_STATES)
    x[SPEED], x[OMEGA] = speed_m_s, speed_m_s * (1.0 - slip) / radius
    force = load * el.tyre_friction(p, slip, speed_m_s, load)
    x[TYRE_FORCE] = force
    if params.has("gear_walk"):
        x[ANGLE] = params.number(K.GEAR_WALK_LENGTH_M) * force / params.number(
            K.GEAR_WALK_STIFFNESS_N_M_PER_RAD)
    gain = params.number(K.BRAKE_GAIN_N_M_PER_PA)
    pressure = 0.0
    for _ in range(2):  # a slot's term may read the pressure it balances
        pressure = (radius * force - wheel_extra(p, x, pressure, load, slip)) / gain
    return OperatingPoint(speed_m_s, slip, load, pressure, x)


def linearise(params: RigParameters, point: OperatingPoint) -> LinearModel:
    """Central-difference Jacobians of the plant at ``point``, speed frozen."""
    p = params.vector()
    gain = params.number(K.BRAKE_GAIN_N_M_PER_PA)
    states = list(linear_states(params))
    steps = {ANGLE: 1e-6, ANGLE_RATE: 1e-5, OMEGA: 1e-5 * max(point.state[OMEGA], 1.0),
             TYRE_FORCE: 1e-3 * max(abs(point.state[TYRE_FORCE]), 1.0)}

    def rates(x: np.ndarray, torque: float) -> np.ndarray:
        dx = np.zeros(N_STATES)
        derivatives(p, x, torque / gain, point.vertical_load_n, dx)
        return dx[states]

    def outputs(x: np.ndarray, torque: float) -> np.ndarray:
        radius, _, slip, _ = tyre_state(p, x, point.vertical_load_n)
        return np.array([slip, -rates(x, torque)[states.index(OMEGA)] * radius
                         / el.GRAVITY_M_S2])

    torque = point.pressure_pa * gain
    n = len(states)
    a, c = np.zeros((n, n)), np.zeros((2, n))
    for j, state in enumerate(states):
        h = steps[state]
        up, down = point.state.copy(), point.state.copy()
        up[state] += h
        down[state] -= h
        a[:, j] = (rates(up, torque) - rates(down, torque)) / (2 * h)
        c[:, j] = (outputs(up, torque) - outputs(down, torque)) / (2 * h)
    dt = 1e-3 * max(torque, 1.0)
    b = (rates(point.state, torque + dt) - rates(point.state, torque - dt)) / (2 * dt)
    d = (outputs(point.state, torque + dt) - outputs(point.state, torque - dt)) / (2 * dt)
    return LinearModel(point, a, b, c, d)


def frequency_response(params: RigParameters, speed_m_s: float, frequency_hz: np.ndarray,
                       slip: float = 0.05) -> FrequencyResponse:
    """G_λ(jω), G_η(jω) at ``speed_m_s`` for the frequencies given [Hz]."""
    model = linearise(params, operating_point(params, speed_m_s, slip))
    frequencies = np.asarray(frequency_hz, dtype=float)
    identity = np.eye(model.a.shape[0])
    response = np.array([
        model.c @ np.linalg.solve(2j * np.pi * f * identity - model.a, model.b) + model.d
        for f in frequencies
    ])
    return FrequencyResponse(frequencies, response[:, 0], response[:, 1], speed_m_s,
                             params.has("gear_walk"))


def resonance_hz(response: FrequencyResponse, band_hz: tuple[float, float] = (2.0, 30.0)
                 ) -> float | None:
    """Frequency of the largest local maximum of |G_λ| inside ``band_hz``, or None."""
    magnitude = np.abs(response.slip)
    inside = (response.frequency_hz >= band_hz[0]) & (response.frequency_hz <= band_hz[1])
    peaks = [i for i in np.flatnonzero(inside)[1:-1]
             if magnitude[i] > magnitude[i - 1] and magnitude[i] >= magnitude[i + 1]]
    if not peaks:
        return None
    return float(response.frequency_hz[max(peaks, key=lambda i: magnitude[i])])
