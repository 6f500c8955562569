"""Actuator identification (paper Section IV-C): the valve's static map from a quasi-static
ramp; A(s) from steps and a sweep — H1 frequency response with coherence (Welch), a
second-order fit to it, refined by an output-error fit in the time domain."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.signal
from scipy.optimize import least_squares

from landing_gear_sim.calibration.statistics import Estimate, covariance_std
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.actuator import actuator_pressure, second_order_response
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.scenario import logged_to_held
from landing_gear_sim.model.sensors import SensorModel
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
    map's generic slot k3 of ``p`` (read around, as the other calibrations read around
    theirs)."""
    current = np.concatenate([r.current_a for r in runs])
    pressure = SensorModel.of(p).true_pressure(np.concatenate([r.pressure_pa for r in runs]))
    max_current, k3 = (p.number(k) for k in (K.ACTUATOR_MAX_CURRENT_A,
                                             K.ACTUATOR_EXTRA_MAP_PA_PER_A3))
    scale = np.array([p.number(k) or 1.0 for k in STATIC_MAP])
    scale[0] = max(scale[0], 0.05)

    def residual(theta: np.ndarray) -> np.ndarray:
        deadband, k1, k2, max_pressure = theta * scale
        return (el.valve_map(current, max_current, deadband, k1, k2, k3, max_pressure)
                - pressure) / PA_PER_BAR

    start = np.array([p.number(k) for k in STATIC_MAP]) / scale
    fit = least_squares(residual, start, x_scale="jac")
    std = covariance_std(fit, 4) * scale
    names = tuple(r.name for r in runs)
    return [Estimate(k, float(v), float(s), names, "static-map least squares")
            for k, v, s in zip(STATIC_MAP, fit.x * scale, std, strict=True)]


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
    _, coherence = scipy.signal.coherence(u, y, fs, nperseg=nperseg)
    with np.errstate(divide="ignore", invalid="ignore"):
        h1 = pyu / puu  # scipy's csd(u, y) is already the cross-spectrum of H1
    model = second_order_response(f, params.number(K.ACTUATOR_NATURAL_FREQUENCY_HZ),
                                  params.number(K.ACTUATOR_DAMPING_RATIO), 1.0)
    return FrfEstimate(run.name, f, h1, coherence, model)


def fit_actuator_dynamics(runs: Sequence[Run], p: RigParameters
                          ) -> tuple[list[Estimate], FrfEstimate]:
    """ω_n and ξ of A(s): FRF fit for a start, then output error on the measured pressure."""
    run = max(runs, key=len)
    frf = actuator_frf(run, p)
    f, h1 = frf.frequency_hz, frf.response
    band = ((f >= FRF_BAND_HZ[0]) & (f <= FRF_BAND_HZ[1]) & (frf.coherence > MIN_COHERENCE)
            & np.isfinite(h1))
    f0 = p.number(K.ACTUATOR_NATURAL_FREQUENCY_HZ)
    zeta0 = p.number(K.ACTUATOR_DAMPING_RATIO)
    weight = np.sqrt(frf.coherence[band])

    def frf_residual(theta: np.ndarray) -> np.ndarray:
        diff = (second_order_response(f[band], theta[0] * f0, theta[1], 1.0) - h1[band]) * weight
        return np.concatenate([diff.real, diff.imag])

    frf_fit = least_squares(frf_residual, [1.0, zeta0], bounds=([0.1, 0.05], [10.0, 3.0]))
    f_frf, zeta_frf = frf_fit.x[0] * f0, frf_fit.x[1]
    sensors = SensorModel.of(p)  # the model's pressure as its channel reads it (a late one)
    held = logged_to_held(run.current_a)

    def time_residual(theta: np.ndarray) -> np.ndarray:
        trial = p.replace({K.ACTUATOR_NATURAL_FREQUENCY_HZ: theta[0] / (2 * math.pi),
                           K.ACTUATOR_DAMPING_RATIO: theta[1]})
        read = sensors.pressure_channel(run.time_s, actuator_pressure(trial, held, run.rate_hz))
        return (read - run.pressure_pa) / PA_PER_BAR

    wn_frf = 2 * math.pi * f_frf
    fit = least_squares(time_residual, [wn_frf, zeta_frf], x_scale=[wn_frf, 0.1],
                        bounds=([1.0, 0.05], [2000.0, 3.0]))
    std = covariance_std(fit, 2)
    names = (run.name,)
    estimates = [
        Estimate(K.ACTUATOR_NATURAL_FREQUENCY_HZ, fit.x[0] / (2 * math.pi),
                 std[0] / (2 * math.pi), names,
                 f"output error on pressure (FRF fit gave {f_frf:.2f} Hz)"),
        Estimate(K.ACTUATOR_DAMPING_RATIO, fit.x[1], std[1], names,
                 f"output error on pressure (FRF fit gave {zeta_frf:.3f})"),
    ]
    fitted = p.replace({e.key: e.value for e in estimates}, "identify")
    return estimates, actuator_frf(run, fitted)
