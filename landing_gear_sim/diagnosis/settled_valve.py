"""Where an actuator run shows the valve's static map: the samples whose current has changed
slowly for a while, between the dead-band and saturation (issues 14, 29).

The relation "valve the same with the current rising and falling"
(:mod:`~landing_gear_sim.diagnosis.consistency`) and the valve equation's library
(:mod:`~landing_gear_sim.diagnosis.equation_library`) read the same samples: there the
valve's dynamics A(s) have settled, and what the model's pressure misses is its static map.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.signal

from landing_gear_sim.calibration.runs import ClassifiedRun, RunKind
from landing_gear_sim.diagnosis.relations import MIN_SAMPLES
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.actuator import actuator_pressure
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.scenario import NOISY_CURRENT_A, current_noise_a, logged_to_held
from landing_gear_sim.model.sensors import SensorModel
from msg_tools.units import PA_PER_BAR

PRESSURE_FLOOR_PA = 0.2 * PA_PER_BAR
SETTLED_S = 0.3  # after a current change the valve has settled
SLOW_A_S = 0.5  # slower current changes: A(s) errors leave no direction-locked residual
RATE_WINDOW_S = 0.3  # a noisy current's rate of change is its slope over this ...
RATE_NOISE_Z = 5.0  # ... and counted beyond this many σ of that average's noise
NOISE_WINDOW_S = 0.5  # a current log's noise is read in pieces this long ...
NOISE_QUANTILE = 0.2  # ... as this quantile of the pieces' estimates


@dataclass(frozen=True)
class Settled:
    """An actuator run under a model, (n,) arrays: the current the valve was fed [A], the
    model's pressure [Pa] and the measured one's excess over it as its channel reads it
    [Pa], which way the current last moved (±1, 0: not yet), and the settled samples
    (mask); the run's rate [Hz] and the time since its first sample [s]."""

    current_a: np.ndarray
    model_pa: np.ndarray
    residual_pa: np.ndarray
    direction: np.ndarray
    settled: np.ndarray
    rate_hz: float
    time_s: np.ndarray


def settled_valve(run: ClassifiedRun, params: RigParameters) -> Settled | None:
    """The run's settled samples under ``params`` (None: a run whose log cannot tell)."""
    noise = _log_noise_a(run)
    if _unreadable(run, noise):
        return None
    current = logged_to_held(run.command_a)
    model = actuator_pressure(params, current, run.rate_hz)
    residual = run.pressure_pa - SensorModel.of(params).pressure_channel(run.time_s, model)
    change = _current_rate(run, noise)
    last = np.maximum.accumulate(np.where(change != 0.0, np.arange(change.size), 0))
    window = max(1, round(SETTLED_S * run.rate_hz))
    fast = np.abs(change) > SLOW_A_S
    slow = np.convolve(fast, np.ones(window), mode="full")[:fast.size] == 0
    band = (model > 2 * PRESSURE_FLOOR_PA) & (model < 0.9 * params.number(
        K.ACTUATOR_MAX_PRESSURE_PA))
    # the samples the logger lost are a line drawn through them, not the valve
    return Settled(current, model, residual, np.sign(change[last]), slow & band & run.compared,
                   run.rate_hz, run.time_s - run.time_s[0])


def _unreadable(run: ClassifiedRun, noise_a: float) -> bool:
    """A fast actuator run whose current log is noisy: fed the log (a sweep to 100 Hz keeps
    it), a valve with play follows the noise both ways, and which way the current last
    moved means nothing (the quasi-static ramp, fed its denoised command, still tells)."""
    return run.kind is RunKind.ACTUATOR_DYNAMIC and noise_a > NOISY_CURRENT_A


def _log_noise_a(run: ClassifiedRun) -> float:
    """The current log's noise where the command is quietest [A]: a low quantile of the
    estimate over NOISE_WINDOW_S pieces (a clean log's 100 Hz sweep read as 1.2 mA of
    'noise' over the whole run, and the run went unchecked)."""
    width = max(MIN_SAMPLES, round(NOISE_WINDOW_S * run.rate_hz))
    pieces = [run.current_a[i:i + width] for i in range(0, run.current_a.size, width)]
    return float(np.quantile([current_noise_a(p) for p in pieces], NOISE_QUANTILE))


def _current_rate(run: ClassifiedRun, noise: float) -> np.ndarray:
    """How fast the valve's current changes [A/s], (n,); 0 where it holds. A noisy log's
    rate is the least-squares slope over RATE_WINDOW_S, counted only beyond RATE_NOISE_Z
    times that slope's noise (10 mA of noise made every sample a 'fast change' on its own,
    and the relation went unchecked)."""
    if noise <= NOISY_CURRENT_A:
        return np.diff(run.current_a, prepend=run.current_a[0]) * run.rate_hz
    width = 2 * round(RATE_WINDOW_S * run.rate_hz / 2) + 1
    slope = scipy.signal.savgol_filter(run.current_a, width, 1, deriv=1,
                                       delta=1.0 / run.rate_hz, mode="nearest")
    floor = RATE_NOISE_Z * noise * run.rate_hz * math.sqrt(12.0 / width ** 3)
    return np.where(np.abs(slope) > floor, slope, 0.0)
