"""Deceleration-threshold anti-skid logic, driven by the wheel speed alone (paper Section II).

The industrial scheme: the valve current ramps up (APPLY) until the normalised wheel
deceleration η = −ω̇ r/g exceeds ``eta_release`` — the wheel is falling off the friction
peak — then ramps down fast (RELEASE) until the wheel stops decelerating
(η < ``eta_hold``), holds (HOLD) while the wheel spins back up, and re-applies when the
spin-up is over (η > ``eta_reapply``, i.e. wheel acceleration below −eta_reapply g), starting
from ``reapply_fraction`` of the current at which the last release began. In closed loop
this gives the limit cycle on the slip of the paper's Fig. 1.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .common import Deceleration, check_positive
from .errors import ControllerError

APPLY, RELEASE, HOLD = "apply", "release", "hold"


@dataclass(frozen=True)
class ThresholdParams:
    """Thresholds on η [-] and current rates [A/s]."""

    eta_release: float = 1.6
    eta_hold: float = 0.0
    eta_reapply: float = -0.5
    apply_rate_a_s: float = 1.5
    reapply_rate_a_s: float = 0.5
    release_rate_a_s: float = 6.0
    reapply_fraction: float = 0.9
    max_current_a: float = 1.0
    eta_filter_s: float = 0.005

    def __post_init__(self) -> None:
        check_positive("threshold", apply_rate_a_s=self.apply_rate_a_s,
                       reapply_rate_a_s=self.reapply_rate_a_s,
                       release_rate_a_s=self.release_rate_a_s, max_current_a=self.max_current_a,
                       eta_filter_s=self.eta_filter_s)
        if not self.eta_reapply < self.eta_hold < self.eta_release:
            raise ControllerError("threshold: need eta_reapply < eta_hold < eta_release, got "
                                  f"{self.eta_reapply}, {self.eta_hold}, {self.eta_release}")
        if not 0.0 < self.reapply_fraction <= 1.0:
            raise ControllerError("threshold: reapply_fraction must be in (0, 1], got "
                                  f"{self.reapply_fraction}")


@dataclass
class ThresholdState:
    """Phase, current command [A], the current at the last release start, and the η filter."""

    deceleration: Deceleration
    phase: str = APPLY
    current_a: float = 0.0
    release_from_a: float = field(default=0.0)
    released: bool = False
    cycles: int = 0


def threshold_state(params: ThresholdParams, wheel_radius_m: float,
                    step_s: float) -> ThresholdState:
    return ThresholdState(Deceleration(wheel_radius_m, step_s, params.eta_filter_s))


def threshold_step(params: ThresholdParams, state: ThresholdState, time_to_brake_s: float,
                   wheel_speed_rad_s: float) -> float:
    """One step: wheel speed at t_k → valve current [A] held over [t_k, t_k+1); 0 before braking."""
    eta = state.deceleration.update(wheel_speed_rad_s)
    if time_to_brake_s > 0.0:
        return 0.0
    step_s = state.deceleration.step_s
    if state.phase == APPLY and eta > params.eta_release:
        state.phase, state.release_from_a = RELEASE, state.current_a
        state.released, state.cycles = True, state.cycles + 1
    elif state.phase == RELEASE and eta < params.eta_hold:
        state.phase = HOLD
    elif state.phase == HOLD and eta > params.eta_reapply:
        state.phase = APPLY
        state.current_a = max(state.current_a, params.reapply_fraction * state.release_from_a)
    if state.phase == APPLY:
        rate = params.reapply_rate_a_s if state.released else params.apply_rate_a_s
        state.current_a += rate * step_s
    elif state.phase == RELEASE:
        state.current_a -= params.release_rate_a_s * step_s
    state.current_a = min(max(state.current_a, 0.0), params.max_current_a)
    return state.current_a
