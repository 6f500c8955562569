"""Ripples with the wheel's angle, read from a measured run (issue 14, the ``wheel_angle``
family): the wheel encoder's (run-out, an out-of-round or oval code wheel) and the brake
torque's (a disc's run-out or thickness variation).

A ripple once or twice per revolution chirps with the wheel's speed, so it is fitted in the
angle domain: the reading against cos(mθ), sin(mθ), θ the measured angle (the trapezoid
integral of the wheel channel itself), in the free rolling before the brake acts, where
the wheel's speed is smooth in time (a quadratic trend takes the flywheel's slow decay).
A run starts with the wheel at an angle of its own, so each run has its own phase: a
simulation of a measured run takes the phase from the run and the ripple's size from the
model (:func:`run_phases`).

The brake's ripple is read the same way from the wheel's torque balance while it brakes:
the brake torque r F_x − J_w ω̇ over the model's torque law (its own run-out left out),
against cos(mθ), sin(mθ) with a quadratic trend in time, on signals low-passed at
RIPPLE_FILTER_HZ (a ripple once per revolution is at 30 Hz at 60 m/s: the 20 Hz filter of
the calibration's torque balance would take it out). An encoder that ripples makes ω̇
ripple too: the model's encoder ripple is taken off the wheel channel first.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.plausibility import lattice_step
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.statistics import linear_std
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.sensors import RUNOUT_KEYS, SensorModel, wheel_angle_rad

ORDERS = (1, 2)  # ripples per revolution
LOADED_N = 5e3  # the wheel is on the flywheel
BEFORE_BRAKE_S = (1.0, 0.05)  # free rolling: from 1 s to 50 ms before the brake acts
MIN_SPEED_RAD_S = 20.0  # slower, a revolution outlasts the window's trend
MIN_SAMPLES = 200
TREND = 3  # columns of the quadratic trend in time
BRAKE_RUNOUT_KEYS = (K.BRAKE_RUNOUT_1, K.BRAKE_RUNOUT_1_PHASE_RAD, K.BRAKE_RUNOUT_2,
                     K.BRAKE_RUNOUT_2_PHASE_RAD)  # amplitudes: br.RUNOUT_AMPLITUDES
RIPPLE_FILTER_HZ = 150.0
NYQUIST_SHARE = 0.8  # a slower log: low-passed at this share of its Nyquist frequency
MAX_SLIP = 0.15  # beyond, a wheel on its way to lock: the torque balance's error dominates
COUNTER_PHASES = 48  # counted channel: counter phases drawn, σ to ~10 %
COUNTER_SEED = 0  # the same draw every time: a diagnosis repeats
COUNTER_EXCESS = 1.5  # a residual beyond this times the counter's own holds other noise


@dataclass(frozen=True)
class AngleRipple:
    """The wheel channel's ripple in one run's free rolling, per order of ORDERS: relative
    amplitude e [1], phase φ at the run's first sample [rad], 1-σ of e [1]; and the rms of
    what the fit left [1]."""

    amplitude: tuple[float, ...]
    phase_rad: tuple[float, ...]
    std: tuple[float, ...]
    residual_rms: float


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
    return reading / reading.mean() - 1.0, ripple_regressors(t, angle)


def ripple_regressors(centred_s: np.ndarray, angle_rad: np.ndarray) -> np.ndarray:
    """A quadratic trend in time (``centred_s``: time about the window's middle), then
    cos(mθ), sin(mθ) per order of ORDERS, (n, TREND + 2·len(ORDERS))."""
    waves = [f(m * angle_rad) for m in ORDERS for f in (np.cos, np.sin)]
    return np.column_stack([_trend(centred_s), *waves])


def _trend(centred_s: np.ndarray) -> np.ndarray:
    """The quadratic trend's columns, (n, TREND)."""
    return np.column_stack([np.ones_like(centred_s), centred_s, centred_s ** 2])


def angle_ripple(run: ClassifiedRun) -> AngleRipple | None:
    """The ripple of ``run``'s wheel channel per order (least squares), or None."""
    fitted = ripple_design(run)
    if fitted is None:
        return None
    return _fit(*fitted)


def checked_ripple(run: ClassifiedRun) -> AngleRipple | None:
    """:func:`angle_ripple` with the σ a consistency check holds it to: through a counting
    encoder the σ its counter gives (:func:`counting_std`). Only the check needs it, not
    the phase a simulation of the run takes (:func:`run_phases`, every simulation)."""
    ripple = angle_ripple(run)
    if ripple is None:
        return None
    counted = counting_std(run, ripple.residual_rms)
    return ripple if counted is None else dataclasses.replace(ripple, std=counted)


def counting_std(run: ClassifiedRun, residual_rms: float) -> tuple[float, ...] | None:
    """1-σ of each order's amplitude when the wheel channel is counted: the spread of the
    ripple fit over the run's free rolling without a ripple, counted through the run's own
    quantum at COUNTER_PHASES random counter phases. None for an analogue channel, or when
    the fit leaves more than the counter's noise (``residual_rms`` [1], beyond
    COUNTER_EXCESS times the counted one: noise of another kind; white σ then).

    A counter's error is the first difference of a bounded sawtooth in the angle itself:
    over whole revolutions it nearly cancels at the low orders. White-noise σ (and HAC, and
    prewhitening: no stationary model has it) put a 64-line encoder at 2 kHz at 0.45 % of
    ω where the counter gives 0.08-0.26 %, and a 0.64 % ripple did not show."""
    step = lattice_step(run.wheel_speed_rad_s)
    mask = free_rolling(run)
    if step is None or mask.sum() < MIN_SAMPLES:
        return None
    t = run.time_s[mask]
    estimates, spreads = [], []
    for read in _counted_without_ripple(t, run.wheel_speed_rad_s[mask], step / run.rate_hz):
        y = read / read.mean() - 1.0
        design = ripple_regressors(t - t.mean(), wheel_angle_rad(t, read))
        coef = np.linalg.lstsq(design, y, rcond=None)[0]
        estimates.append(coef[TREND:])
        spreads.append(float(np.std(y - design @ coef)))
    if residual_rms > COUNTER_EXCESS * float(np.mean(spreads)):
        return None
    components = np.sqrt(np.mean(np.square(estimates), axis=0)).reshape(len(ORDERS), 2)
    return tuple(float(v) for v in components.max(axis=1))


def _counted_without_ripple(t: np.ndarray, reading: np.ndarray, quantum_rad: float
                            ) -> list[np.ndarray]:
    """The speed ``reading`` [rad/s] at times ``t`` smoothed (quadratic trend) and counted
    again through ``quantum_rad`` per count, once per drawn counter phase."""
    trend = _trend(t - t.mean())
    smooth = trend @ np.linalg.lstsq(trend, reading, rcond=None)[0]
    counts = wheel_angle_rad(t, smooth) / quantum_rad
    phases = np.random.default_rng(COUNTER_SEED).uniform(size=COUNTER_PHASES)
    return [np.r_[smooth[0], np.diff(np.floor(counts + p)) * quantum_rad / np.diff(t)]
            for p in phases]


def run_phases(params: RigParameters, run: ClassifiedRun) -> RigParameters:
    """``params`` with the ripple's phases of ``run`` (its own start angle), when the model
    has a ripple and the run shows where it is."""
    ripple = angle_ripple(run)
    if ripple is None:
        return params
    return params.replace({RUNOUT_KEYS[1]: ripple.phase_rad[0],
                           RUNOUT_KEYS[3]: ripple.phase_rad[1]}, "the run's start angle")


def _fit(y: np.ndarray, design: np.ndarray) -> AngleRipple:
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    residual = y - design @ coef
    std = linear_std(design, residual, design.shape[1])
    pairs = [(coef[TREND + 2 * i], coef[TREND + 2 * i + 1]) for i in range(len(ORDERS))]
    return AngleRipple(tuple(math.hypot(c, s) for c, s in pairs),
                       tuple(math.atan2(-s, c) for c, s in pairs),
                       tuple(float(max(std[TREND + 2 * i], std[TREND + 2 * i + 1]))
                             for i in range(len(ORDERS))), float(np.std(residual)))


def has_brake_runout(params: RigParameters) -> bool:
    return any(params.number(k) != 0.0 for k in br.RUNOUT_AMPLITUDES)


def brake_ripple_design(run: ClassifiedRun, params: RigParameters,
                        prepared: br.Braking | None = None
                        ) -> tuple[np.ndarray, np.ndarray] | None:
    """The brake torque of ``run``'s torque balance over the model's (its run-out left out),
    minus 1, where the brake acts on a wheel away from lock, (m,), and the regressors
    (quadratic trend, then cos(mθ), sin(mθ) per order), (m, TREND + 2·len(ORDERS)); None
    when the run does not brake long enough (``prepared``: its filtered signals, if at hand)."""
    if not run.braking:
        return None
    b = prepared or br.prepare(run, params)
    angle = measured_angle_rad(run)
    sensors = SensorModel.of(params)
    wheel = run.wheel_speed_rad_s
    if sensors.ripples:  # the model's encoder ripple off the wheel channel first
        wheel = wheel / sensors.encoder(np.ones_like(angle), angle)
    rate = run.rate_hz
    cutoff = min(RIPPLE_FILTER_HZ, NYQUIST_SHARE * rate / 2)
    wheel = br.lowpass(wheel, rate, cutoff)
    force = br.lowpass(sensors.true_longitudinal(run.longitudinal_force_n, run.vertical_load_n,
                                                 br.run_time_s(run)), rate, cutoff)
    # the wheel's balance read at the ripple's bandwidth: its own wheel and F_x, the rest b's
    torque, _ = br.torque_balance(dataclasses.replace(
        b, wheel=wheel, wheel_rate=np.gradient(wheel, 1.0 / rate), force=force), params)
    _, energy = br.torque_balance(b, params)
    mask = br.braking_samples(b) & (wheel > MIN_SPEED_RAD_S) & (br.slip(b, params) < MAX_SLIP)
    if mask.sum() < MIN_SAMPLES:
        return None
    m = np.flatnonzero(mask)
    law = br.model_torque(dataclasses.replace(b, wheel=wheel), params, energy, m)
    t = run.time_s[m] - run.time_s[m].mean()
    return torque[m] / law - 1.0, ripple_regressors(t, angle[m])


def brake_ripple(run: ClassifiedRun, params: RigParameters,
                 prepared: br.Braking | None = None) -> AngleRipple | None:
    """The brake torque's ripple with the wheel's angle in ``run`` per order, or None."""
    fitted = brake_ripple_design(run, params, prepared)
    return None if fitted is None else _fit(*fitted)


def brake_run_phases(params: RigParameters, run: ClassifiedRun) -> RigParameters:
    """``params`` with the brake ripple's phases of ``run`` (its own start angle), when the
    run shows where it is. The phases do not depend on the ripple's size, so a fit of the
    size reads them once per run (:data:`_PHASES`)."""
    key = (id(run), params.replace(dict.fromkeys(BRAKE_RUNOUT_KEYS, 0.0), "key").vector()
           .tobytes())
    if key not in _PHASES:
        ripple = brake_ripple(run, params)
        if len(_PHASES) >= PHASES_KEPT:
            _PHASES.pop(next(iter(_PHASES)))
        _PHASES[key] = (run, None if ripple is None else ripple.phase_rad)
    phases = _PHASES[key][1]
    if phases is None:
        return params
    return params.replace({BRAKE_RUNOUT_KEYS[1]: phases[0], BRAKE_RUNOUT_KEYS[3]: phases[1]},
                          "the run's start angle")


PHASES_KEPT = 64
_PHASES: dict[tuple[int, bytes], tuple[ClassifiedRun, tuple[float, ...] | None]] = {}
"""Phases read, by run (its id; the run kept alive with them, so the id stays its own) and
by the model without its ripple's size."""
