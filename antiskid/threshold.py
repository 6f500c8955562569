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

import math
from dataclasses import dataclass, fields

import numpy as np
from numba import njit

from landing_gear_sim.model.elements import GRAVITY_M_S2

from .common import check_positive
from .errors import ControllerError


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


(P_ETA_RELEASE, P_ETA_HOLD, P_ETA_REAPPLY, P_APPLY_RATE, P_REAPPLY_RATE, P_RELEASE_RATE,
 P_REAPPLY_FRACTION, P_MAX_CURRENT, P_ETA_FILTER, P_SLIP_RELEASE, P_INITIAL_DECEL,
 P_FLOOR) = range(12)
"""Indices of :func:`threshold_vector` (the field order of ThresholdParams)."""


# The controller's state, one float array so that the step compiles (numba) and runs
# inside the compiled closed loop as well as in the node: indices into it.
(S_FILTERED, S_ETA, S_PHASE, S_CURRENT, S_RELEASE_FROM, S_RELEASED, S_CYCLES, S_REFERENCE,
 S_DECEL, S_SYNC_TIME, S_SYNC_SPEED, S_TIME, S_RADIUS, S_STEP, S_TAU) = range(15)
N_STATE = 15
APPLY, RELEASE, HOLD = 0.0, 1.0, 2.0
PHASES = ("apply", "release", "hold")


def threshold_vector(params: ThresholdParams) -> np.ndarray:
    """The settings as the compiled step reads them (field order of ThresholdParams)."""
    return np.array([getattr(params, f.name) for f in fields(params)], dtype=float)


def threshold_state(params: ThresholdParams, wheel_radius_m: float,
                    step_s: float) -> np.ndarray:
    """Initial state (N_STATE,): applying from 0 A, nothing filtered, nothing synchronised."""
    state = np.zeros(N_STATE)
    state[S_FILTERED] = state[S_SYNC_TIME] = math.nan
    state[S_DECEL] = params.initial_decel_m_s2 / wheel_radius_m
    state[S_RADIUS], state[S_STEP], state[S_TAU] = wheel_radius_m, step_s, params.eta_filter_s
    return state


@njit(cache=True)
def _deceleration(s, wheel_speed_rad_s):
    """η = −ω̇ r / g through a first-order filter of time constant S_TAU (see common)."""
    if math.isnan(s[S_FILTERED]):
        s[S_FILTERED] = wheel_speed_rad_s
        return s[S_ETA]
    step_s = s[S_STEP]
    alpha = step_s / (s[S_TAU] + step_s)
    previous = s[S_FILTERED]
    s[S_FILTERED] += alpha * (wheel_speed_rad_s - s[S_FILTERED])
    s[S_ETA] = -(s[S_FILTERED] - previous) / step_s * s[S_RADIUS] / GRAVITY_M_S2
    return s[S_ETA]


@njit(cache=True)
def _reference(s, wheel_speed_rad_s):
    """Wheel-speed-only vehicle reference: peak hold falling at the learnt deceleration."""
    s[S_REFERENCE] = max(wheel_speed_rad_s, s[S_REFERENCE] - s[S_DECEL] * s[S_STEP])
    return (s[S_REFERENCE] - wheel_speed_rad_s) / max(s[S_REFERENCE], 1e-9)


@njit(cache=True)
def _resynchronised(s, wheel_speed_rad_s):
    """End of a spin-up: the wheel runs at the vehicle speed; learn the vehicle deceleration."""
    if not math.isnan(s[S_SYNC_TIME]):
        elapsed = s[S_TIME] - s[S_SYNC_TIME]
        if elapsed > 0.02:
            s[S_DECEL] = max((s[S_SYNC_SPEED] - wheel_speed_rad_s) / elapsed, 0.0)
    s[S_SYNC_TIME], s[S_SYNC_SPEED] = s[S_TIME], wheel_speed_rad_s
    s[S_REFERENCE] = wheel_speed_rad_s


@njit(cache=True)
def _next_phase(p, s, eta, slip, wheel_speed_rad_s):
    phase = s[S_PHASE]
    deep = p[P_SLIP_RELEASE] > 0 and slip > p[P_SLIP_RELEASE] and eta > p[P_ETA_HOLD]
    if phase == APPLY and (eta > p[P_ETA_RELEASE] or deep):
        s[S_PHASE], s[S_RELEASE_FROM] = RELEASE, s[S_CURRENT]
        s[S_RELEASED], s[S_CYCLES] = 1.0, s[S_CYCLES] + 1.0
    elif phase == RELEASE and (
            eta < p[P_ETA_HOLD]
            or s[S_CURRENT] <= p[P_FLOOR] * s[S_RELEASE_FROM]):
        s[S_PHASE] = HOLD
    elif phase == HOLD and eta > p[P_ETA_REAPPLY]:
        s[S_PHASE] = APPLY
        _resynchronised(s, wheel_speed_rad_s)
        s[S_CURRENT] = max(s[S_CURRENT], p[P_REAPPLY_FRACTION] * s[S_RELEASE_FROM])


@njit(cache=True)
def threshold_step(p, s, time_to_brake_s, wheel_speed_rad_s):
    """One step: wheel speed at t_k → valve current [A] held over [t_k, t_k+1); 0 before braking.

    ``p``: :func:`threshold_vector`; ``s``: :func:`threshold_state`, updated in place.
    """
    eta = _deceleration(s, wheel_speed_rad_s)
    s[S_TIME] += s[S_STEP]
    slip = _reference(s, wheel_speed_rad_s)
    if time_to_brake_s > 0.0:
        return 0.0
    _next_phase(p, s, eta, slip, wheel_speed_rad_s)
    if s[S_PHASE] == APPLY:
        rate = p[P_REAPPLY_RATE] if s[S_RELEASED] > 0.0 else p[P_APPLY_RATE]
        s[S_CURRENT] += rate * s[S_STEP]
    elif s[S_PHASE] == RELEASE:
        s[S_CURRENT] -= p[P_RELEASE_RATE] * s[S_STEP]
    s[S_CURRENT] = min(max(s[S_CURRENT], 0.0), p[P_MAX_CURRENT])
    return s[S_CURRENT]
