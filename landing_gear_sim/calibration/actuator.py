"""Actuator identification (paper Section IV-C): the valve's static map from a quasi-static
ramp; A(s) from steps and a sweep — H1 frequency response with coherence (Welch), a
second-order fit to it, refined by an output-error fit in the time domain."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.signal
from scipy.optimize import OptimizeResult, least_squares

from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.slots import Slot, map_signals
from landing_gear_sim.calibration.statistics import Estimate, covariance_std, input_timing_std_s
from landing_gear_sim.errors import IdentificationError
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.actuator import actuator_pressure, second_order_response
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.scenario import logged_to_held
from landing_gear_sim.model.sensors import SensorModel
from landing_gear_sim.processes import map_threads
from msg_tools.run import Run
from msg_tools.units import PA_PER_BAR

STATIC_MAP = (K.ACTUATOR_DEADBAND_CURRENT_A, K.ACTUATOR_MAP_K1_PA_PER_A,
              K.ACTUATOR_MAP_K2_PA_PER_A2, K.ACTUATOR_MAX_PRESSURE_PA)
FRF_BAND_HZ = (0.5, 100.0)  # the sweep's band
MIN_COHERENCE = 0.8  # FRF bins fitted: the measured pressure follows the valve there


@dataclass(frozen=True)
class FrfEstimate:
    """Empirical actuator frequency response (static-map pressure → measured pressure) and
    the model's A(s) beside it; arrays of shape (n,) over ``frequency_hz``."""

    run: str
    frequency_hz: np.ndarray
    response: np.ndarray  # complex H1
    coherence: np.ndarray
    model: np.ndarray  # complex A(j 2π f) of the parameter set compared


def fit_static_map(runs: Sequence[Run], p: RigParameters) -> list[Estimate]:
    """Dead-band, k1, k2, saturation from quasi-static ramps (paper Fig. 8), beside the
    map's k3 and slot of ``p`` (read around, as the other calibrations read around
    theirs)."""
    current = np.concatenate([r.current_a for r in runs])
    pressure = np.concatenate([_true_pressure(r, p) for r in runs])
    return _fit_map(current, pressure, p, STATIC_MAP, tuple(r.name for r in runs),
                    "static-map least squares")


SETTLED_TIME_CONSTANTS = 5.0  # a hold is settled this many of A(s)'s 1/(ζ ω_n) after its step
MIN_HELD_SAMPLES = 20  # a hold's settled part shorter than this is no level


def held_levels(runs: Sequence[ClassifiedRun], p: RigParameters
                ) -> tuple[np.ndarray, np.ndarray]:
    """The settled samples of the runs' held commands: (current [A], the pressure behind the
    channel [Pa]). A hold's samples count from its later half, and from
    SETTLED_TIME_CONSTANTS of the datasheet's A(s) after its step (a slow valve's delay is
    in neither)."""
    settle_s = SETTLED_TIME_CONSTANTS / (
        2 * math.pi * p.number(K.ACTUATOR_NATURAL_FREQUENCY_HZ)
        * p.number(K.ACTUATOR_DAMPING_RATIO))
    currents, pressures = [], []
    for run in runs:
        command, true = run.command_a, _true_pressure(run, p)
        edges = np.concatenate([[0], np.flatnonzero(np.diff(command)) + 1, [command.size]])
        for first, end in itertools.pairwise(edges.tolist()):
            start = first + max(round(settle_s * run.rate_hz), (end - first) // 2)
            if end - start >= MIN_HELD_SAMPLES:
                currents.append(command[start:end])
                pressures.append(true[start:end])
    if not currents:
        return np.zeros(0), np.zeros(0)
    return np.concatenate(currents), np.concatenate(pressures)


def fit_map_to_holds(runs: Sequence[ClassifiedRun], p: RigParameters) -> list[Estimate]:
    """k1 (and k2 where two levels above the dead-band tell them apart) from the settled
    pressures of held commands (:func:`held_levels`): a step log's map, where no ramp was
    run. The dead-band and the saturation stay the datasheet's (a few levels do not show
    them). Without it a step log was judged on the reference's map, and a delay fitted
    on one step was checked on another 3 % of map off."""
    current, pressure = held_levels(runs, p)
    deadband = p.number(K.ACTUATOR_DEADBAND_CURRENT_A)
    levels = np.unique(np.round(current[current > deadband], 3))
    if levels.size == 0:
        raise IdentificationError("no held command above the dead-band to read the map at")
    keys = STATIC_MAP[1:3] if levels.size >= 2 else STATIC_MAP[1:2]
    return _fit_map(current, pressure, p, keys, tuple(r.name for r in runs),
                    f"settled pressures of {levels.size} held commands")


def _true_pressure(run: Run, p: RigParameters) -> np.ndarray:
    """The pressure behind ``run``'s channel as ``p``'s transducer reads it [Pa]."""
    return np.asarray(SensorModel.of(p).true_pressure(run.pressure_pa,
                                                      run.time_s - run.time_s[0]))


def _fit_map(current: np.ndarray, pressure: np.ndarray, p: RigParameters,
             keys: Sequence[str], names: tuple[str, ...], method: str) -> list[Estimate]:
    """The map's ``keys`` (of STATIC_MAP) by least squares on (current, true pressure)
    samples, the others kept at ``p``'s."""
    max_current, k3 = (p.number(k) for k in (K.ACTUATOR_MAX_CURRENT_A,
                                             K.ACTUATOR_EXTRA_MAP_PA_PER_A3))
    values = np.array([p.number(k) for k in STATIC_MAP])
    free = np.array([k in keys for k in STATIC_MAP])
    scale = np.array([p.number(k) or 1.0 for k in STATIC_MAP])
    scale[0] = max(scale[0], 0.05)

    def residual(theta: np.ndarray) -> np.ndarray:
        trial = values.copy()
        trial[free] = theta * scale[free]
        deadband, k1, k2, max_pressure = trial
        return (el.valve_map(current, max_current, deadband, k1, k2, k3, max_pressure,
                             _map_slot(p, current, max_current, deadband))
                - pressure) / PA_PER_BAR

    fit = least_squares(residual, values[free] / scale[free], x_scale="jac")
    std = covariance_std(fit, int(free.sum())) * scale[free]
    return [Estimate(k, float(v), float(e), names, method)
            for k, v, e in zip(keys, fit.x * scale[free], std, strict=True)]


def _map_slot(p: RigParameters, current: np.ndarray, max_current: float, deadband: float
              ) -> np.ndarray | float:
    """The map's slot of ``p`` at ``current`` with the dead-band tried [Pa] (0.0: none)."""
    if not Slot.STATIC_MAP.occupied(p):
        return 0.0
    return Slot.STATIC_MAP.value_of(p, map_signals(el.valve_excess(current, max_current,
                                                                    deadband)))


def actuator_frf(run: Run, params: RigParameters) -> FrfEstimate:
    """H1 = P_yu/P_uu and coherence, u = static-map pressure of ``params``, y = measured
    pressure; with the A(s) of ``params`` at the same frequencies."""
    vector = params.vector()
    u = np.array([el.valve_static_pressure(vector, i) for i in run.current_a])
    y = run.pressure_pa
    fs = run.rate_hz
    nperseg = min(4096, u.size // 4)
    f, puu = scipy.signal.welch(u - u.mean(), fs, nperseg=nperseg)
    _, pyu = scipy.signal.csd(u - u.mean(), y - y.mean(), fs, nperseg=nperseg)
    # bands the input does not excite (a short log's) have no power: no H1 and no
    # coherence there (NaN), which the fit leaves out, and no warning on the terminal
    with np.errstate(divide="ignore", invalid="ignore"):
        _, coherence = scipy.signal.coherence(u, y, fs, nperseg=nperseg)
        h1 = pyu / puu  # scipy's csd(u, y) is already the cross-spectrum of H1
    model = second_order_response(f, params.number(K.ACTUATOR_NATURAL_FREQUENCY_HZ),
                                  params.number(K.ACTUATOR_DAMPING_RATIO), 1.0)
    return FrfEstimate(run.name, f, h1, coherence, model)


def fit_actuator_dynamics(runs: Sequence[Run], p: RigParameters
                          ) -> tuple[list[Estimate], FrfEstimate, list[str]]:
    """ω_n and ξ of A(s), and its transport delay when ``p`` has one: an FRF fit and a
    search of the dead time for a start, then output error on the measured pressure. A
    model without a delay gets a note when the valve answers clearly later than A(s) can
    (its ω_n and ζ absorb it: a 4x slower valve's 2.98 Hz read 1.98 Hz)."""
    run = max(runs, key=len)
    f_frf, zeta_frf = _frf_fit(actuator_frf(run, p), p)
    residual = _time_residual(run, p if p.has("actuator_delay") else p.replace(
        {"elements.actuator_delay": True, K.ACTUATOR_DELAY_S: 0.0}, "a delay tried"))
    wn = 2 * math.pi * f_frf
    delayed = least_squares(residual, [wn, zeta_frf, _dead_time_s(residual, wn, zeta_frf)],
                            x_scale=[wn, 0.1, DELAY_SCALE_S],
                            bounds=([1.0, 0.05, 0.0], [2000.0, 3.0, MAX_DELAY_S]))
    notes: list[str] = []
    keys: tuple[str, ...]
    if p.has("actuator_delay"):
        fit, keys = delayed, DYNAMICS_KEYS
    else:
        fit = least_squares(lambda theta: residual([*theta, 0.0]), [wn, zeta_frf],
                            x_scale=[wn, 0.1], bounds=([1.0, 0.05], [2000.0, 3.0]))
        keys = DYNAMICS_KEYS[:2]
        notes = _late_note(fit.cost, delayed, run.rate_hz)
    std = covariance_std(fit, len(keys))
    if len(keys) == 3:  # a delay is known no better than when the logger saw the steps
        std[2] = math.hypot(std[2], input_timing_std_s([run]))
    scale = (1 / (2 * math.pi), 1.0, 1.0)
    estimates = [Estimate(key, float(fit.x[i] * scale[i]), float(std[i] * scale[i]),
                          (run.name,), f"output error on pressure ({method})")
                 for i, (key, method) in enumerate(zip(keys, (
                     f"FRF fit gave {f_frf:.2f} Hz", f"FRF fit gave {zeta_frf:.3f}",
                     "started from the dead time searched"), strict=False))]
    fitted = p.replace({e.key: e.value for e in estimates}, "identify")
    return estimates, actuator_frf(run, fitted), notes


DYNAMICS_KEYS = (K.ACTUATOR_NATURAL_FREQUENCY_HZ, K.ACTUATOR_DAMPING_RATIO, K.ACTUATOR_DELAY_S)
MAX_DELAY_S = 0.5  # the longest dead time looked for
DELAY_GRID_S = 0.01  # the dead time's search step (its fit refines it)
DELAY_SCALE_S = 0.01
LATE_SHARE = 0.2  # a delay that takes this share of the pressure's squared error is said
LATE = "later than A(s) alone can"  # the note's words, which a diagnosis that tests a delay drops


def _frf_fit(frf: FrfEstimate, p: RigParameters) -> tuple[float, float]:
    """ω_n [Hz] and ζ of a second-order A(s) fitted to the FRF's coherent band."""
    f, h1 = frf.frequency_hz, frf.response
    band = ((f >= FRF_BAND_HZ[0]) & (f <= FRF_BAND_HZ[1]) & (frf.coherence > MIN_COHERENCE)
            & np.isfinite(h1))
    f0 = p.number(K.ACTUATOR_NATURAL_FREQUENCY_HZ)
    weight = np.sqrt(frf.coherence[band])

    def frf_residual(theta: np.ndarray) -> np.ndarray:
        diff = (second_order_response(f[band], theta[0] * f0, theta[1], 1.0) - h1[band]) * weight
        return np.concatenate([diff.real, diff.imag])

    fit = least_squares(frf_residual, [1.0, p.number(K.ACTUATOR_DAMPING_RATIO)],
                        bounds=([0.1, 0.05], [10.0, 3.0]))
    return float(fit.x[0] * f0), float(fit.x[1])


def _time_residual(run: Run, p: RigParameters) -> Callable[[Sequence[float]], np.ndarray]:
    """The pressure's error [bar] of A(s) at (ω_n [rad/s], ζ, delay [s]), as the channel
    of ``p`` reads it (a late one too)."""
    sensors = SensorModel.of(p)
    held = logged_to_held(run.current_a)

    def residual(theta: Sequence[float]) -> np.ndarray:
        trial = p.replace({K.ACTUATOR_NATURAL_FREQUENCY_HZ: theta[0] / (2 * math.pi),
                           K.ACTUATOR_DAMPING_RATIO: theta[1], K.ACTUATOR_DELAY_S: theta[2]})
        read = sensors.pressure_channel(run.time_s, actuator_pressure(trial, held, run.rate_hz))
        return (read - run.pressure_pa) / PA_PER_BAR

    return residual


def _dead_time_s(residual: Callable[[Sequence[float]], np.ndarray], wn: float,
                 zeta: float) -> float:
    """The delay of least squared error on a grid, at the FRF's ω_n and ζ: a sweep's error
    has a valley every period of its frequency, and a local fit keeps to the one it starts
    in (on step logs of 50–150 ms delays a start from 0 ended in the same place, worst
    1.3 %)."""
    grid = np.arange(0.0, MAX_DELAY_S, DELAY_GRID_S)
    costs = map_threads(lambda delay: float(np.sum(residual([wn, zeta, delay]) ** 2)), grid)
    return float(grid[int(np.argmin(costs))])


def _late_note(plain_cost: float, delayed: OptimizeResult, rate_hz: float) -> list[str]:
    """A note when A(s) with a delay leaves clearly less error than A(s) alone."""
    delay = float(delayed.x[2])
    if delay < 2.0 / rate_hz or delayed.cost > (1.0 - LATE_SHARE) * plain_cost:
        return []
    return [f"actuator dynamics A(s): the pressure follows the valve's current "
            f"{1e3 * delay:.0f} ms {LATE} (a delay takes "
            f"{100 * (1 - delayed.cost / plain_cost):.0f} % of its squared error); the model "
            "has no delay, so ω_n and ζ absorb it: `diagnose` tests an actuator_delay, or a "
            "datasheet with elements.actuator_delay: true has identify fit it"]
