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
from dataclasses import dataclass

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


@dataclass
class SlipState:
    """Integrator [A], speed estimate [m/s], rolling radius [m] and its learning, last slip."""

    wheel_radius_m: float
    flywheel_radius_m: float
    step_s: float
    integral_a: float = math.nan
    speed_m_s: float = math.nan
    slip: float = 0.0
    radius_sum_m: float = 0.0
    radius_count: int = 0


def slip_state(wheel_radius_m: float, flywheel_radius_m: float, step_s: float) -> SlipState:
    return SlipState(wheel_radius_m, flywheel_radius_m, step_s)


def learn_radius(params: SlipParams, state: SlipState, wheel_speed_rad_s: float,
                 speed_m_s: float, time_to_brake_s: float) -> None:
    """Before braking: average r = v/ω over the last ``radius_learn_s`` of free rolling."""
    if 0.0 < time_to_brake_s <= params.radius_learn_s and wheel_speed_rad_s > 1.0:
        state.radius_sum_m += speed_m_s / wheel_speed_rad_s
        state.radius_count += 1
    elif time_to_brake_s <= 0.0 and state.radius_count:
        state.wheel_radius_m = state.radius_sum_m / state.radius_count
        state.radius_count = 0


def slip_step(params: SlipParams, state: SlipState, time_to_brake_s: float,
              wheel_speed_rad_s: float, flywheel_speed_rad_s: float) -> float:
    """One step: speeds at t_k → valve current [A] held over [t_k, t_k+1); 0 before braking."""
    speed = flywheel_speed_rad_s * state.flywheel_radius_m
    state.speed_m_s = speed
    learn_radius(params, state, wheel_speed_rad_s, speed, time_to_brake_s)
    if time_to_brake_s > 0.0:
        return 0.0
    if math.isnan(state.integral_a):
        state.integral_a = params.initial_current_a
    if speed < params.min_speed_m_s:  # slip is meaningless near standstill: hold
        return min(max(state.integral_a, 0.0), params.max_current_a)
    state.slip = float(slip_ratio(speed, wheel_speed_rad_s, state.wheel_radius_m))
    error = params.slip_setpoint - state.slip  # > 0: room for more brake
    kp, ki = params.kp_per_m_s * speed, params.ki_per_m_s * speed
    candidate = state.integral_a + ki * error * state.step_s
    output = candidate + kp * error
    if 0.0 <= output <= params.max_current_a or (output > params.max_current_a) != (error > 0):
        state.integral_a = min(max(candidate, 0.0), params.max_current_a)
    return min(max(state.integral_a + kp * error, 0.0), params.max_current_a)
