"""The wheel encoder's ripple with the wheel's angle, read from a measured run (issue 14,
the ``wheel_angle`` family: run-out, an out-of-round or oval code wheel).

A ripple once or twice per revolution chirps with the wheel's speed, so it is fitted in the
angle domain: the reading against cos(mθ), sin(mθ), θ the measured angle (the trapezoid
integral of the wheel channel itself), in the free rolling before the brake acts, where
the wheel's speed is smooth in time (a quadratic trend takes the flywheel's slow decay).
A run starts with the wheel at an angle of its own, so each run has its own phase: a
simulation of a measured run takes the phase from the run and the ripple's size from the
model (:func:`run_phases`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.statistics import linear_std
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.sensors import RUNOUT_KEYS, wheel_angle_rad

ORDERS = (1, 2)  # ripples per revolution
LOADED_N = 5e3  # the wheel is on the flywheel
BEFORE_BRAKE_S = (1.0, 0.05)  # free rolling: from 1 s to 50 ms before the brake acts
MIN_SPEED_RAD_S = 20.0  # slower, a revolution outlasts the window's trend
MIN_SAMPLES = 200
TREND = 3  # columns of the quadratic trend in time


@dataclass(frozen=True)
class AngleRipple:
    """The wheel channel's ripple in one run's free rolling, per order of ORDERS: relative
    amplitude e [1], phase φ at the run's first sample [rad], 1-σ of e [1]."""

    amplitude: tuple[float, ...]
    phase_rad: tuple[float, ...]
    std: tuple[float, ...]


def measured_angle_rad(run: ClassifiedRun) -> np.ndarray:
    """The wheel's angle since the run's first sample, from its wheel channel [rad], (n,)."""
    return wheel_angle_rad(run.time_s, run.wheel_speed_rad_s)


def free_rolling(run: ClassifiedRun) -> np.ndarray:
    """Samples of free rolling before the brake acts, the wheel loaded and turning, (n,)."""
    t = run.time_s
    return ((t > run.brake_start_s - BEFORE_BRAKE_S[0])
            & (t < run.brake_start_s - BEFORE_BRAKE_S[1])
            & (run.vertical_load_n > LOADED_N) & (run.wheel_speed_rad_s > MIN_SPEED_RAD_S))


def ripple_design(run: ClassifiedRun) -> tuple[np.ndarray, np.ndarray] | None:
    """The wheel reading relative to its mean in free rolling, (m,), and the regressors
    (quadratic trend, then cos(mθ), sin(mθ) per order), (m, TREND + 2·len(ORDERS)); None
    when the run has too little free rolling."""
    mask = free_rolling(run) if run.braking else np.zeros(len(run), dtype=bool)
    if mask.sum() < MIN_SAMPLES:
        return None
    angle = measured_angle_rad(run)[mask]
    reading = run.wheel_speed_rad_s[mask]
    t = run.time_s[mask] - run.time_s[mask].mean()
    waves = [f(m * angle) for m in ORDERS for f in (np.cos, np.sin)]
    return reading / reading.mean() - 1.0, np.column_stack([np.ones_like(t), t, t * t, *waves])


def angle_ripple(run: ClassifiedRun) -> AngleRipple | None:
    """The ripple of ``run``'s wheel channel per order (least squares), or None."""
    fitted = ripple_design(run)
    if fitted is None:
        return None
    y, design = fitted
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    std = linear_std(design, y - design @ coef, design.shape[1])
    pairs = [(coef[TREND + 2 * i], coef[TREND + 2 * i + 1]) for i in range(len(ORDERS))]
    return AngleRipple(tuple(math.hypot(c, s) for c, s in pairs),
                       tuple(math.atan2(-s, c) for c, s in pairs),
                       tuple(float(max(std[TREND + 2 * i], std[TREND + 2 * i + 1]))
                             for i in range(len(ORDERS))))


def run_phases(params: RigParameters, run: ClassifiedRun) -> RigParameters:
    """``params`` with the ripple's phases of ``run`` (its own start angle), when the model
    has a ripple and the run shows where it is."""
    ripple = angle_ripple(run)
    if ripple is None:
        return params
    return params.replace({RUNOUT_KEYS[1]: ripple.phase_rad[0],
                           RUNOUT_KEYS[3]: ripple.phase_rad[1]}, "the run's start angle")
