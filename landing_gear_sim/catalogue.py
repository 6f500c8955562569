"""The diagnosis catalogue: candidate model extensions and their output-error fit.

Each candidate is a real model element (switched on with ``elements.<name>``) with
physical parameters. Fitting one means: switch it on, then fit its parameters,
together with the base parameters it trades off against, by simulating the runs
that carry its signature with their measured inputs (output error, not one-step
prediction). Residuals are scaled by each channel's sensor noise, estimated from
the measurement itself.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from msg_tools.run import Run

from .identify import classify, covariance_std
from .parameters import RigParameters
from .validate import simulate_run

DECIMATE = 2  # residual samples kept (the simulation itself runs at the full rate)


@dataclass(frozen=True)
class Candidate:
    """A model extension the diagnosis can propose.

    Attributes:
        cause: name in the diagnosis contract.
        element: the ``elements.<name>`` switch it turns on.
        keys: its own parameters, fitted.
        starts: start values tried for ``keys`` (multi-start: lags and frequencies
            have local minima).
        bounds: admissible range of each key.
        free: base-model parameters re-fitted with it (they could otherwise absorb
            or mask the effect).
        runs: run kinds that carry its signature ("actuator" and/or "brake").
        channels: measured channels compared.
    """

    cause: str
    element: str
    keys: tuple[str, ...]
    starts: tuple[tuple[float, ...], ...]
    bounds: tuple[tuple[float, float], ...]
    free: tuple[str, ...]
    runs: tuple[str, ...]
    channels: tuple[str, ...]


ACTUATOR = ("actuator.natural_frequency_hz", "actuator.damping_ratio")
FRICTION = ("friction.theta1", "friction.theta2", "friction.theta3")
STATIC_MAP = ("actuator.deadband_current_a", "actuator.map_k1_pa_per_a",
              "actuator.map_k2_pa_per_a2", "actuator.max_pressure_pa")

CATALOGUE: dict[str, Candidate] = {c.cause: c for c in (
    Candidate("actuator_delay", "actuator_delay", ("actuator.delay_s",),
              ((0.002,), (0.006,), (0.012,), (0.025,)), ((0.0, 0.06),), ACTUATOR,
              ("actuator",), ("pressure_pa",)),
    # an offset shifts the whole map while calibrating it: re-fit the map with it; the
    # stretches below the dead-band tell the two apart
    Candidate("pressure_sensor_offset", "pressure_sensor_offset",
              ("sensors.pressure_offset_pa",), ((0.0,),), ((-10e5, 10e5),), STATIC_MAP,
              ("actuator",), ("pressure_pa",)),
    Candidate("actuator_dynamics", "actuator_dynamics", ACTUATOR,
              ((8.0, 0.5), (15.0, 0.8)), ((1.0, 60.0), (0.1, 2.0)), (), ("actuator",),
              ("pressure_pa",)),
    Candidate("tire_relaxation", "tire_relaxation", ("tyre.relaxation_length_m",),
              ((0.1,), (0.4,), (1.0,)), ((0.005, 5.0),), FRICTION, ("brake",),
              ("wheel_speed_rad_s", "longitudinal_force_n")),
    Candidate("gear_walk", "gear_walk",
              ("gear_walk.stiffness_n_m_per_rad", "gear_walk.damping_n_m_s_per_rad"),
              ((6.9e5, 1372.0), (3e5, 1000.0), (1.5e6, 2000.0)),
              ((5e4, 2e7), (10.0, 5e4)), FRICTION, ("brake",),
              ("wheel_speed_rad_s", "longitudinal_force_n")),
    Candidate("brake_fade", "brake_fade", ("brake.fade_fraction", "brake.fade_energy_j"),
              ((0.1, 2e6), (0.3, 5e5)), ((0.0, 0.9), (1e4, 1e8)), ("brake.gain_n_m_per_pa",),
              ("brake",), ("wheel_speed_rad_s", "flywheel_speed_rad_s")),
    Candidate("drag", "drag", ("drag.coeff_n_s2_per_m2",), ((0.2,),), ((0.0, 5.0),),
              ("flywheel.inertia_kg_m2",), ("brake",), ("flywheel_speed_rad_s",)),
    Candidate("load_dependent_radius", "load_dependent_radius",
              ("radius.a_m_per_n2", "radius.b_m_per_n"), ((4e-12, 5e-7),),
              ((0.0, 1e-10), (0.0, 5e-6)), ("wheel.unloaded_radius_m",), ("brake",),
              ("wheel_speed_rad_s",)),
)}


@dataclass(frozen=True)
class CandidateFit:
    """A fitted candidate: the extended parameter set, values and 1-σ of the fitted keys,
    and the scaled residual (for information criteria)."""

    candidate: Candidate
    params: RigParameters
    values: dict[str, float]
    std: dict[str, float]
    residual: np.ndarray

    @property
    def cost(self) -> float:
        """Sum of squared noise-scaled residuals."""
        return float(self.residual @ self.residual)


def noise_std(values: np.ndarray) -> float:
    """Sensor-noise std of a 1 kHz channel: first differences are noise-dominated."""
    return float(np.std(np.diff(values)) / math.sqrt(2)) or 1.0


def select_runs(runs: Sequence[Run], kinds: Sequence[str]) -> list[Run]:
    """Runs whose class starts with one of ``kinds`` ("actuator", "brake")."""
    return [r for r in runs if classify(r).split("_")[0] in kinds]


def scaled_residual(runs: Sequence[Run], params: RigParameters, channels: Sequence[str],
                    scales: dict[tuple[str, str], float]) -> np.ndarray:
    """Simulation minus measurement over ``channels`` of ``runs``, divided by the noise."""
    parts = []
    for run in runs:
        simulated, _ = simulate_run(run, params)
        for channel in channels:
            error = getattr(simulated, channel) - getattr(run, channel)
            parts.append(error[::DECIMATE] / scales[(run.name, channel)])
    return np.concatenate(parts)


def fit_candidate(candidate: Candidate, runs: Sequence[Run], base: RigParameters,
                  datasheet: RigParameters | None = None) -> CandidateFit:
    """Switch ``candidate`` on in ``base`` and fit its keys plus its free base parameters.

    ``base`` is the model calibrated without the candidate; where the missing element
    distorted that calibration, the free parameters are also started from
    ``datasheet`` (the design values), and their window spans both.
    """
    chosen = select_runs(runs, candidate.runs)
    if not chosen:
        raise ValueError(f"{candidate.cause}: no {'/'.join(candidate.runs)} run to fit on")
    scales = {(r.name, c): noise_std(getattr(r, c)) for r in chosen
              for c in candidate.channels}
    switched = base.replace({f"elements.{candidate.element}": True,
                             **dict(zip(candidate.keys, candidate.starts[0], strict=True))},
                            f"candidate {candidate.cause}")
    free = [k for k in candidate.free if k not in candidate.keys]
    references = [base] + ([datasheet] if datasheet is not None else [])
    keys = [*candidate.keys, *free]
    lower = np.array([b[0] for b in candidate.bounds]
                     + [0.5 * min(r.number(k) for r in references) for k in free])
    upper = np.array([b[1] for b in candidate.bounds]
                     + [2.0 * max(r.number(k) for r in references) for k in free])
    span = upper - lower

    def residual(u: np.ndarray) -> np.ndarray:
        trial = switched.replace(dict(zip(keys, lower + u * span, strict=True)), "fit")
        return scaled_residual(chosen, trial, candidate.channels, scales)

    best = None
    for start in candidate.starts:
        for reference in references:
            values = np.array([*start, *(reference.number(k) for k in free)])
            u0 = np.clip((values - lower) / span, 1e-6, 1 - 1e-6)
            fit = least_squares(residual, u0, bounds=(0.0, 1.0), x_scale=0.01, diff_step=1e-4)
            if best is None or fit.cost < best.cost:
                best = fit
    assert best is not None
    values = lower + best.x * span
    std = covariance_std(best, len(keys)) * span
    fitted = switched.replace(dict(zip(keys, values, strict=True)), f"fit {candidate.cause}")
    return CandidateFit(candidate, fitted, dict(zip(keys, map(float, values), strict=True)),
                        dict(zip(keys, map(float, std), strict=True)), best.fun)


def gear_walk_key_parameters(params: RigParameters) -> dict[str, float]:
    """frequency_hz = √(k_θ/J)/2π and damping_ratio = c_θ/(2√(k_θ J)), gear alone."""
    k = params.number("gear_walk.stiffness_n_m_per_rad")
    j = params.number("gear_walk.inertia_kg_m2")
    c = params.number("gear_walk.damping_n_m_s_per_rad")
    return {"frequency_hz": math.sqrt(k / j) / (2 * math.pi),
            "damping_ratio": c / (2 * math.sqrt(k * j))}
