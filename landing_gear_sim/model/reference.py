"""Tight-tolerance reference solution of the same model, for accuracy checks.

The continuous-time model (plant + actuator A(s) + loading servo, one state
vector) is integrated with ``scipy.integrate.solve_ivp`` (Radau, implicit) piece
by piece between the instants where the held current changes. It shares the
element functions and A(s) with the fast integrator, so a difference between the two
is integration error, not a different model. It refuses parameter sets with elements it
does not model (a transport delay, a static actuator); the wheel-lock clamp is not
modelled either: use it on runs that do not lock.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np
from scipy.integrate import solve_ivp

from landing_gear_sim.errors import ParameterError
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.actuator import actuator_system, valve_slot
from landing_gear_sim.model.parameters import INDEX, RigParameters
from landing_gear_sim.model.plant import (
    ANGLE,
    ANGLE_RATE,
    E_BRAKE,
    N_STATES,
    OMEGA,
    SPEED,
    TYRE_FORCE,
    derivatives,
)
from landing_gear_sim.model.scenario import Scenario


def reference_solution(params: RigParameters, scenario: Scenario, end_s: float | None = None,
                       rtol: float = 1e-9) -> dict[str, np.ndarray]:
    """Integrate ``scenario`` to ``end_s`` (default: its end) with Radau.

    Absolute tolerances are ``rtol`` times each state's full scale: a plain
    ``atol`` on the pressure rate [Pa/s] sits below its round-off and stalls Radau.

    Returns ``time_s``, ``wheel_speed_rad_s``, ``speed_m_s`` and ``pressure_pa``
    at the scenario's sample instants.
    """
    _check_modelled(params)
    p = params.vector()
    act_a, act_b = actuator_system(params)
    wn = 2 * np.pi * params.number(K.ACTUATOR_NATURAL_FREQUENCY_HZ)
    slot_b = np.array([0.0, wn * wn])  # the valve's slot's input: A(s) at unit gain
    tau = p[INDEX[K.LOADING_SERVO_TIME_CONSTANT_S]]
    x, dx = np.zeros(N_STATES), np.zeros(N_STATES)
    p_max = p[INDEX[K.ACTUATOR_MAX_PRESSURE_PA]]
    v_max = max(scenario.initial_speed_m_s, 1.0)
    load = p[INDEX[K.LOADING_STATIC_LOAD_N]]
    # Only states that act: an accumulator nothing depends on has a zero Jacobian
    # column, and Radau's finite-difference Jacobian then diverges.
    dynamic = [SPEED, ANGLE, ANGLE_RATE, OMEGA]
    scales = [v_max, 0.1, 1.0, v_max / p[INDEX[K.WHEEL_UNLOADED_RADIUS_M]]]
    if params.has("tire_relaxation"):
        dynamic, scales = [*dynamic, TYRE_FORCE], [*scales, load]
    if params.has("brake_fade"):
        dynamic, scales = [*dynamic, E_BRAKE], [*scales, 1e7]
    pressure_i, load_i = len(dynamic), len(dynamic) + 2  # pressure, its rate, the load
    scale = np.array([*scales, p_max, wn * p_max, load])

    def rhs(t: float, y: np.ndarray, current: float) -> np.ndarray:
        static = el.valve_static_pressure(p, current)
        vertical = y[load_i] if scenario.contact else 0.0
        x[dynamic] = y[:pressure_i]
        derivatives(p, x, y[pressure_i], vertical, dx)
        out = np.empty_like(y)
        out[:pressure_i] = dx[dynamic]
        pressure, rate = y[pressure_i], y[pressure_i + 1]
        out[pressure_i:load_i] = (act_a @ y[pressure_i:load_i] + act_b * static
                                  + slot_b * valve_slot(p, pressure, rate, static))
        reference = el.vertical_load_reference(p, t, y[0]) if scenario.contact else 0.0
        out[load_i] = (reference - y[load_i]) / tau
        return out

    n = scenario.current_a.size if end_s is None else round(end_s * scenario.rate_hz) + 1
    times = np.arange(n) * scenario.step_s
    y = np.zeros(load_i + 1)
    y[0] = scenario.initial_speed_m_s if scenario.contact else 0.0
    samples = np.empty((n, y.size))
    samples[0] = y
    changes = np.flatnonzero(np.diff(scenario.current_a[:n])) + 1
    bounds = np.unique(np.concatenate([[0], changes, [n - 1]]))
    for a, b in pairwise(bounds):
        sol = solve_ivp(rhs, (times[a], times[b]), y, method="Radau", rtol=rtol, atol=rtol * scale,
                        t_eval=times[a + 1: b + 1], args=(scenario.current_a[a],))
        samples[a + 1: b + 1] = sol.y.T
        y = sol.y[:, -1]
    return {"time_s": times, "wheel_speed_rad_s": samples[:, 3],
            "speed_m_s": samples[:, 0], "pressure_pa": samples[:, pressure_i]}


UNMODELLED = {"actuator_delay": True, "actuator_dynamics": False}
"""Element switches the reference cannot follow: with this value it would silently
solve another model."""


def _check_modelled(params: RigParameters) -> None:
    for element, unsupported in UNMODELLED.items():
        if params.has(element) == unsupported:
            state = "on" if unsupported else "off"
            raise ParameterError(f"the reference solution does not model elements.{element} "
                                 f"{state}; compare without it")
    if params.number(K.ACTUATOR_BACKLASH_A) > 0.0:
        raise ParameterError("the reference solution does not model the valve's "
                             "actuator.backlash_a; compare without it")
