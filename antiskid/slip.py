"""Slip control: gain-scheduled PI on the wheel slip with anti-windup.

λ = (v − ω r)/v needs the rolling radius r and a speed reference v. r shrinks with the
load (a few %, as much as the set-point's margin to the friction peak), so the controller
learns it while the wheel rolls free before braking (r = v/ω averaged over
``radius_learn_s``), starting from the unloaded radius. The speed reference is the
flywheel encoder (the rig). An estimate from the wheel speed alone (the aircraft case) is
not offered: a peak hold falling at a fixed deceleration locked the wheel on dry, wet and
snow alike (no fixed rate fits all three), and a continuous slip controller never lets
the wheel re-synchronise to correct it. The threshold logic needs no speed reference.

Near the set-point the slip responds to the current like an integrator whose gain falls as
1/v (λ̇ ≈ r k/(J v) · Δi), so the PI gains grow with v (``kp = kp_per_m_s · v``) to keep the
crossover — and the damping — the same from 60 m/s down to the stop. The integrator is
clamped to the valve's range and frozen while the output saturates (anti-windup).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from numba import njit

from landing_gear_sim.model.elements import slip_ratio

from .common import check_positive
from .errors import ControllerError


@dataclass(frozen=True)
class SlipParams:
    """Set-point [-], PI gains per m/s of speed [A per unit slip / (m/s)], limits."""

    slip_setpoint: float = 0.12
    kp_per_m_s: float = 0.012
    ki_per_m_s: float = 0.08
    min_speed_m_s: float = 3.0
    max_current_a: float = 1.0
    initial_current_a: float = 0.3
    radius_learn_s: float = 0.5

    def __post_init__(self) -> None:
        if not 0.0 < self.slip_setpoint < 1.0:
            raise ControllerError(f"slip: slip_setpoint must be in (0, 1), got "
                                  f"{self.slip_setpoint}")
        check_positive("slip", kp_per_m_s=self.kp_per_m_s, ki_per_m_s=self.ki_per_m_s,
                       min_speed_m_s=self.min_speed_m_s, max_current_a=self.max_current_a,
                       radius_learn_s=self.radius_learn_s)
        if not 0.0 <= self.initial_current_a <= self.max_current_a:
            raise ControllerError("slip: initial_current_a must be within [0, max_current_a]")


(P_SETPOINT, P_KP, P_KI, P_MIN_SPEED, P_MAX_CURRENT, P_INITIAL_CURRENT,
 P_RADIUS_LEARN) = range(7)
"""Indices of :func:`slip_vector` (the field order of SlipParams)."""

# The state, one float array so that the step compiles (numba): integrator [A] (nan until
# braking starts), speed estimate [m/s], rolling radius [m] and its learning sums, last slip
(S_INTEGRAL, S_SPEED, S_SLIP, S_RADIUS, S_RADIUS_SUM, S_RADIUS_COUNT, S_FLYWHEEL_RADIUS,
 S_STEP) = range(8)
N_STATE = 8


def slip_vector(params: SlipParams) -> np.ndarray:
    """The settings as the compiled step reads them (field order of SlipParams)."""
    return np.array([getattr(params, f.name) for f in fields(params)], dtype=float)


def slip_state(wheel_radius_m: float, flywheel_radius_m: float, step_s: float) -> np.ndarray:
    """Initial state (N_STATE,): radius not learnt yet, integrator not started."""
    state = np.zeros(N_STATE)
    state[S_INTEGRAL] = math.nan
    state[S_RADIUS], state[S_FLYWHEEL_RADIUS], state[S_STEP] = (
        wheel_radius_m, flywheel_radius_m, step_s)
    return state


@njit(cache=True)
def learn_radius(p, s, wheel_speed_rad_s, speed_m_s, time_to_brake_s):
    """Before braking: average r = v/ω over the last ``radius_learn_s`` of free rolling."""
    if 0.0 < time_to_brake_s <= p[P_RADIUS_LEARN] and wheel_speed_rad_s > 1.0:
        s[S_RADIUS_SUM] += speed_m_s / wheel_speed_rad_s
        s[S_RADIUS_COUNT] += 1.0
    elif time_to_brake_s <= 0.0 and s[S_RADIUS_COUNT] > 0.0:
        s[S_RADIUS] = s[S_RADIUS_SUM] / s[S_RADIUS_COUNT]
        s[S_RADIUS_COUNT] = 0.0


@njit(cache=True)
def slip_step(p, s, time_to_brake_s, wheel_speed_rad_s, flywheel_speed_rad_s):
    """One step: speeds at t_k → valve current [A] held over [t_k, t_k+1); 0 before braking.

    ``p``: :func:`slip_vector`; ``s``: :func:`slip_state`, updated in place.
    """
    speed = flywheel_speed_rad_s * s[S_FLYWHEEL_RADIUS]
    s[S_SPEED] = speed
    learn_radius(p, s, wheel_speed_rad_s, speed, time_to_brake_s)
    if time_to_brake_s > 0.0:
        return 0.0
    if math.isnan(s[S_INTEGRAL]):
        s[S_INTEGRAL] = p[P_INITIAL_CURRENT]
    limit = p[P_MAX_CURRENT]
    if speed < p[P_MIN_SPEED]:  # slip is meaningless near standstill: hold
        return min(max(s[S_INTEGRAL], 0.0), limit)
    s[S_SLIP] = slip_ratio(speed, wheel_speed_rad_s, s[S_RADIUS])
    error = p[P_SETPOINT] - s[S_SLIP]  # > 0: room for more brake
    kp, ki = p[P_KP] * speed, p[P_KI] * speed
    candidate = s[S_INTEGRAL] + ki * error * s[S_STEP]
    output = candidate + kp * error
    if 0.0 <= output <= limit or (output > limit) != (error > 0):
        s[S_INTEGRAL] = min(max(candidate, 0.0), limit)
    return min(max(s[S_INTEGRAL] + kp * error, 0.0), limit)
