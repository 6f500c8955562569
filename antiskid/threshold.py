"""Deceleration-threshold anti-skid logic, driven by the wheel speed alone (paper Section II).

The industrial scheme: the valve current ramps up (APPLY) until the wheel is falling off
the friction peak — the normalised wheel deceleration η = −ω̇ r/g exceeds ``eta_release``,
or the wheel runs ``slip_release`` below a vehicle reference built from the wheel speed
itself (peak hold falling at the deceleration learnt between spin-ups) while still
decelerating — then ramps down fast (RELEASE) until the wheel stops decelerating
(η < ``eta_hold``) or the current is down to ``release_floor_fraction`` of its level (a
wheel that only follows the vehicle's deceleration would otherwise release to zero),
holds (HOLD) while the wheel spins back up, and re-applies when the spin-up is over
(η > ``eta_reapply``), from ``reapply_fraction`` of the last release level at the slow
``reapply_rate_a_s``. In closed loop this gives the limit cycle on the slip of the paper's
Fig. 1.

The defaults come from a grid search on the reference rig over dry, wet and snow
(bench/controllers.py): efficiency 0.86 / 0.86 / 0.94, no lock; neighbouring settings
stay lock-free, but a faster re-apply (0.8 A/s) or a higher floor with a higher
re-apply fraction locks the wheel — tune with the bench, not by hand.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .common import Deceleration, check_positive
from .errors import ControllerError

APPLY, RELEASE, HOLD = "apply", "release", "hold"


@dataclass(frozen=True)
class ThresholdParams:
    """Thresholds on η [-] and current rates [A/s]."""

    eta_release: float = 2.5
    eta_hold: float = 0.0
    eta_reapply: float = -0.5
    apply_rate_a_s: float = 1.5
    reapply_rate_a_s: float = 0.3
    release_rate_a_s: float = 6.0
    reapply_fraction: float = 0.95
    max_current_a: float = 1.0
    eta_filter_s: float = 0.005
    slip_release: float = 0.12
    initial_decel_m_s2: float = 5.0
    release_floor_fraction: float = 0.7

    def __post_init__(self) -> None:
        check_positive("threshold", apply_rate_a_s=self.apply_rate_a_s,
                       reapply_rate_a_s=self.reapply_rate_a_s,
                       release_rate_a_s=self.release_rate_a_s, max_current_a=self.max_current_a,
                       eta_filter_s=self.eta_filter_s)
        if not self.eta_reapply < self.eta_hold < self.eta_release:
            raise ControllerError("threshold: need eta_reapply < eta_hold < eta_release, got "
                                  f"{self.eta_reapply}, {self.eta_hold}, {self.eta_release}")
        if not 0.0 <= self.release_floor_fraction < 1.0:
            raise ControllerError("threshold: release_floor_fraction must be in [0, 1), got "
                                  f"{self.release_floor_fraction}")
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
    reference_rad_s: float = 0.0
    decel_rad_s2: float = 0.0
    synced_at: tuple[float, float] | None = None
    time_s: float = 0.0


def threshold_state(params: ThresholdParams, wheel_radius_m: float,
                    step_s: float) -> ThresholdState:
    return ThresholdState(Deceleration(wheel_radius_m, step_s, params.eta_filter_s),
                          decel_rad_s2=params.initial_decel_m_s2 / wheel_radius_m)


def _reference(state: ThresholdState, wheel_speed_rad_s: float) -> float:
    """Wheel-speed-only vehicle reference: peak hold falling at the learnt deceleration."""
    step_s = state.deceleration.step_s
    state.reference_rad_s = max(wheel_speed_rad_s,
                                state.reference_rad_s - state.decel_rad_s2 * step_s)
    return (state.reference_rad_s - wheel_speed_rad_s) / max(state.reference_rad_s, 1e-9)


def _resynchronised(state: ThresholdState, wheel_speed_rad_s: float) -> None:
    """End of a spin-up: the wheel runs at the vehicle speed; learn the vehicle deceleration."""
    if state.synced_at is not None:
        then, speed = state.synced_at
        if state.time_s - then > 0.02:
            state.decel_rad_s2 = max((speed - wheel_speed_rad_s) / (state.time_s - then), 0.0)
    state.synced_at = (state.time_s, wheel_speed_rad_s)
    state.reference_rad_s = wheel_speed_rad_s


def threshold_step(params: ThresholdParams, state: ThresholdState, time_to_brake_s: float,
                   wheel_speed_rad_s: float) -> float:
    """One step: wheel speed at t_k → valve current [A] held over [t_k, t_k+1); 0 before braking."""
    eta = state.deceleration.update(wheel_speed_rad_s)
    step_s = state.deceleration.step_s
    state.time_s += step_s
    slip = _reference(state, wheel_speed_rad_s)
    if time_to_brake_s > 0.0:
        return 0.0
    deep = params.slip_release > 0 and slip > params.slip_release and eta > params.eta_hold
    if state.phase == APPLY and (eta > params.eta_release or deep):
        state.phase, state.release_from_a = RELEASE, state.current_a
        state.released, state.cycles = True, state.cycles + 1
    elif state.phase == RELEASE and (
            eta < params.eta_hold
            or state.current_a <= params.release_floor_fraction * state.release_from_a):
        state.phase = HOLD
    elif state.phase == HOLD and eta > params.eta_reapply:
        state.phase = APPLY
        _resynchronised(state, wheel_speed_rad_s)
        state.current_a = max(state.current_a, params.reapply_fraction * state.release_from_a)
    if state.phase == APPLY:
        rate = params.reapply_rate_a_s if state.released else params.apply_rate_a_s
        state.current_a += rate * step_s
    elif state.phase == RELEASE:
        state.current_a -= params.release_rate_a_s * step_s
    state.current_a = min(max(state.current_a, 0.0), params.max_current_a)
    return state.current_a
