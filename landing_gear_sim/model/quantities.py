"""The model's laws evaluated on arrays for one parameter set (calibration, metrics, plots).

Each function here calls the compiled law of :mod:`landing_gear_sim.model.elements`; none
restates it. Inputs and outputs are numpy arrays of the same shape, SI.
"""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np

from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.run import Run

Value = TypeVar("Value", float, np.ndarray)
"""A float or an array: the same law serves a node's one sample and a run's arrays."""

PEAK_GRID = np.linspace(0.0, 1.0, 20001)  # slip grid on which the friction peak is sought


def rolling_radius_at(params: RigParameters, load_n: np.ndarray) -> np.ndarray:
    """Rolling radius of eq. (9) at each vertical load [N] → [m], same shape; r0 when the
    ``load_dependent_radius`` element is off. The compiled law itself, once per sample."""
    load = np.asarray(load_n, dtype=float)
    return el.rolling_radii(params.vector(), load.ravel()).reshape(load.shape)


def friction_at(params: RigParameters, slip: np.ndarray) -> np.ndarray:
    """Burckhardt μ(λ) of the parameter set at each slip λ ≥ 0 (eq. 11)."""
    return el.burckhardt_mu(*friction_coefficients(params), np.asarray(slip, dtype=float))


def curve_at(params: RigParameters, slip: np.ndarray, speed_m_s: np.ndarray) -> np.ndarray:
    """μ_B(λ) of the surface under the tyre at each sample (λ ≥ 0; the second surface below
    the change speed), the plant's curve: :func:`~landing_gear_sim.model.elements.
    tyre_curve`."""
    return el.tyre_curves(params.vector(), np.ascontiguousarray(slip, dtype=float),
                          np.ascontiguousarray(speed_m_s, dtype=float))


def tyre_friction_at(params: RigParameters, slip: np.ndarray, speed_m_s: np.ndarray,
                     load_n: np.ndarray) -> np.ndarray:
    """The plant's μ(λ, v, F_z) at each sample: the curve under the tyre, its load factor
    and the tyre's slot (:func:`~landing_gear_sim.model.elements.tyre_friction`)."""
    return el.tyre_frictions(params.vector(), np.ascontiguousarray(slip, dtype=float),
                             np.ascontiguousarray(speed_m_s, dtype=float),
                             np.ascontiguousarray(load_n, dtype=float))


def load_factor_at(params: RigParameters, load_n: np.ndarray) -> np.ndarray:
    """μ's factor 1 − κ (F_z − F_ref) for the tyre's load sensitivity at each vertical load
    [N], same shape (ones when κ = 0)."""
    return np.asarray(el.load_factor(params.vector(), np.asarray(load_n, dtype=float)))


def friction_coefficients(params: RigParameters) -> tuple[float, float, float]:
    """(ϑ1, ϑ2, ϑ3) of the Burckhardt curve."""
    t1, t2, t3 = (params.number(f"friction.theta{i}") for i in (1, 2, 3))
    return t1, t2, t3


def peak_friction(params: RigParameters) -> tuple[float, float]:
    """Peak μ of the friction curve and the slip where it occurs."""
    mu = friction_at(params, PEAK_GRID)
    best = int(np.argmax(mu))
    return float(mu[best]), float(PEAK_GRID[best])


def rim_speed_m_s(params: RigParameters, flywheel_speed_rad_s: Value) -> Value:
    """Flywheel rim (vehicle) speed ω_f R_f [m/s] from the flywheel encoder [rad/s]."""
    return flywheel_speed_rad_s * params.number(K.FLYWHEEL_RADIUS_M)


def flywheel_speed_rad_s(params: RigParameters, rim_speed: Value) -> Value:
    """Flywheel encoder speed [rad/s] of a rim speed [m/s] (inverse of rim_speed_m_s)."""
    return rim_speed / params.number(K.FLYWHEEL_RADIUS_M)


def slip_at(params: RigParameters, vehicle_speed_m_s: np.ndarray,
            wheel_speed_rad_s: np.ndarray, load_n: np.ndarray) -> np.ndarray:
    """Slip λ of eq. (1) with the rolling radius at each load (no gear-walk correction:
    the vehicle speed stands in for the hub speed)."""
    radius = rolling_radius_at(params, load_n)
    return el.slip_ratio(np.asarray(vehicle_speed_m_s, dtype=float),
                         np.asarray(wheel_speed_rad_s, dtype=float), radius)


def gear_walk_modes(params: RigParameters) -> tuple[float, float]:
    """Gear alone: natural frequency √(k_θ/J)/2π [Hz] and damping ratio c_θ/(2√(k_θ J))."""
    k = params.number(K.GEAR_WALK_STIFFNESS_N_M_PER_RAD)
    j = params.number(K.GEAR_WALK_INERTIA_KG_M2)
    c = params.number(K.GEAR_WALK_DAMPING_N_M_S_PER_RAD)
    return math.sqrt(k / j) / (2 * math.pi), c / (2 * math.sqrt(k * j))


STATIC_LOAD = K.LOADING_STATIC_LOAD_N
REFERENCE_LOAD = K.FRICTION_REFERENCE_LOAD_N


def reference_load_n(params: RigParameters) -> float:
    """F_ref, the vertical load at which the friction curve holds [N] (0 in the file: the
    static load; the plant's :func:`~landing_gear_sim.model.elements.load_factor` reads it
    the same way)."""
    return params.number(REFERENCE_LOAD) or params.number(STATIC_LOAD)


def at_static_load(params: RigParameters, static_load_n: float,
                   source: str = "static load") -> RigParameters:
    """The set with the loading device at ``static_load_n`` [N]: the friction curve's
    reference load stays where it was (a tyre's load sensitivity acts between the two)."""
    return params.replace({STATIC_LOAD: static_load_n,
                           REFERENCE_LOAD: reference_load_n(params)}, source)


def logged_or_set_load_n(run: Run, params: RigParameters) -> np.ndarray:
    """The run's vertical load [N], or where the logger had no load cell the loading
    device's set point F_z0 − :func:`load_taken_at` at the flywheel's speed (the static load
    alone left a stop's slip rms 29 % off: the radius follows the load the lift takes off)."""
    if "vertical_load_n" not in run.absent:
        return run.vertical_load_n
    static = np.full(len(run), params.number(K.LOADING_STATIC_LOAD_N))
    if "flywheel_speed_rad_s" in run.absent:
        return static
    return static - load_taken_at(params, run.time_s - run.time_s[0],
                                  rim_speed_m_s(params, run.flywheel_speed_rad_s))


def load_taken_at(params: RigParameters, run_time_s: np.ndarray, speed_m_s: np.ndarray
                  ) -> np.ndarray:
    """What the loading device's set point F_z0 loses at each sample [N]: the lift and the
    loading equation's slot (:func:`~landing_gear_sim.model.elements.load_taken`), at the
    speed and the time since the model's touch-down (``run_time_s``: since the run's first
    sample)."""
    contact = np.maximum(np.asarray(run_time_s, dtype=float)
                         - params.number(K.RIG_TEST_TOUCHDOWN_S), 0.0)
    speed = np.asarray(speed_m_s, dtype=float)
    return el.loads_taken(params.vector(), np.ascontiguousarray(speed),
                          np.ascontiguousarray(contact))


def flywheel_resistance_at(params: RigParameters, speed_m_s: np.ndarray, load_n: np.ndarray,
                           with_drag: bool = True) -> np.ndarray:
    """What resists the flywheel beside F_x at each sample [N] (its drag, unless
    ``with_drag`` is False, and its slots: :func:`~landing_gear_sim.model.elements.
    flywheel_resistance`)."""
    return el.flywheel_resistances(
        params.vector(), np.ascontiguousarray(speed_m_s, dtype=float),
        np.ascontiguousarray(load_n, dtype=float), with_drag)
