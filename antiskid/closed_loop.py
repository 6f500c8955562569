"""A controller against the rig model, offline: the same blocks the node graph steps.

:func:`make_controller` is what the ``antiskid_controller`` node calls too, so the node
and an offline run give the same current for the same speeds. :func:`closed_loop` steps
the blocks one exchange at a time, as the graph does; :func:`compiled_closed_loop` runs
the same step functions in one compiled loop (numba), ~9 times faster, for Monte Carlo
and benchmarks — the two agree to the last bit (test).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import fields
from typing import Any

import numpy as np

from landing_gear_sim.model import keys as K
from landing_gear_sim.model.blocks import ActuatorBlock, LoadingBlock, PlantBlock
from landing_gear_sim.model.integrate import SimulationResult
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.runspec import RunSpec, build_scenario

from .errors import ControllerError
from .slip import SlipParams, slip_state, slip_step, slip_vector
from .threshold import ThresholdParams, threshold_state, threshold_step, threshold_vector

CONTROLLERS = ("threshold", "slip")
ControllerStep = Callable[[float, float, float], float]
"""(time [s], wheel speed [rad/s], flywheel speed [rad/s]) at t_k → current [A] over
[t_k, t_k+1). The current is 0 before the rig procedure's braking start."""

SURFACES: dict[str, tuple[float, float, float]] = {
    "wet": (0.857, 33.822, 0.347),   # Burckhardt's wet asphalt
    "snow": (0.1946, 94.129, 0.0646),  # Burckhardt's snow: the low-friction case
}
"""Friction curves (ϑ1, ϑ2, ϑ3) other than the rig's own (``dry``)."""


def settings_type(kind: str) -> type[ThresholdParams] | type[SlipParams]:
    if kind not in CONTROLLERS:
        raise ControllerError(f"unknown controller {kind!r}; choose from {', '.join(CONTROLLERS)}")
    return ThresholdParams if kind == "threshold" else SlipParams


def controller_settings(kind: str, values: Mapping[str, Any] | None = None,
                        ) -> ThresholdParams | SlipParams:
    """Validated settings of controller ``kind`` (defaults for keys not given)."""
    kind_type = settings_type(kind)
    known = {f.name for f in fields(kind_type)}
    unknown = sorted(set(values or {}) - known)
    if unknown:
        raise ControllerError(f"{kind}: unknown setting {unknown[0]!r}; known: "
                              f"{', '.join(sorted(known))}")
    return kind_type(**(values or {}))


def make_controller(kind: str, rig: RigParameters, step_s: float,
                    values: Mapping[str, object] | None = None) -> ControllerStep:
    """A controller of ``kind`` with its state, ready to be stepped once per sample.

    It brakes from ``rig_test.brake_start_s`` (the rig procedure) on.
    """
    settings, state = controller_arrays(kind, rig, step_s, values)
    start_s = rig.number(K.RIG_TEST_BRAKE_START_S)
    if kind == "threshold":
        return lambda t, wheel, flywheel: threshold_step(settings, state, start_s - t, wheel)
    return lambda t, wheel, flywheel: slip_step(settings, state, start_s - t, wheel, flywheel)


def controller_arrays(kind: str, rig: RigParameters, step_s: float,
                      values: Mapping[str, object] | None = None,
                      ) -> tuple[np.ndarray, np.ndarray]:
    """The validated settings and the initial state of controller ``kind`` as the
    compiled step functions take them (float arrays)."""
    settings = controller_settings(kind, values)
    wheel_r = rig.number(K.WHEEL_UNLOADED_RADIUS_M)
    if isinstance(settings, ThresholdParams):
        return threshold_vector(settings), threshold_state(settings, wheel_r, step_s)
    return slip_vector(settings), slip_state(wheel_r, rig.number(K.FLYWHEEL_RADIUS_M), step_s)


def with_surface(rig: RigParameters, surface: str) -> RigParameters:
    """The rig on another runway surface (``dry`` is the rig's own friction curve)."""
    if surface == "dry":
        return rig
    if surface not in SURFACES:
        raise ControllerError(f"unknown surface {surface!r}; choose dry, {', '.join(SURFACES)}")
    t1, t2, t3 = SURFACES[surface]
    return rig.replace({K.FRICTION_THETA1: t1, K.FRICTION_THETA2: t2, K.FRICTION_THETA3: t3},
                       f"surface {surface}")


def closed_loop(rig: RigParameters, controller: ControllerStep,
                rate_hz: float = 0.0) -> SimulationResult:
    """A rig test (touch-down, spin-up, braking from ``rig_test.brake_start_s``) under control."""
    scenario = build_scenario(RunSpec(profile="external", rate_hz=rate_hz), rig)
    plant = PlantBlock(rig, scenario)
    actuator = ActuatorBlock(rig, scenario.step_s)
    loading = LoadingBlock(rig, scenario.step_s, True)
    rows = []
    while True:
        sample = plant.sample()
        current = controller(sample.time_s, sample.wheel_speed_rad_s,
                             sample.flywheel_speed_rad_s)
        rows.append(plant.record(current))
        if plant.finished():
            break
        pressure = actuator.step(current)
        plant.advance(pressure, loading.step(sample.step, sample.flywheel_speed_rad_s))
    reason = "end of input" if plant.step_index >= plant.n_steps - 1 else "stop speed reached"
    return SimulationResult(scenario, rig, np.array(rows), reason)


def constant_pressure_baseline(rig: RigParameters, margin: float = 0.98,
                               iterations: int = 10) -> tuple[float, SimulationResult]:
    """The stop at a constant pressure just below the skid pressure (no lock above 5 m/s).

    The skid pressure is found by bisection between 0 and the valve's maximum; the
    baseline brakes at ``margin`` times it. Returns (pressure [Pa], the simulated stop).
    """
    from landing_gear_sim.model.integrate import simulate
    from landing_gear_sim.model.scenario import constant_pressure_test

    from .metrics import braking_metrics

    def locks(pressure_pa: float) -> bool:
        result = simulate(rig, constant_pressure_test(rig, pressure_pa))
        return braking_metrics(result.to_run(), rig).lock_events > 0

    low, high = 0.0, rig.number(K.ACTUATOR_MAX_PRESSURE_PA)
    if not locks(high):
        low = high
    for _ in range(iterations if low < high else 0):
        middle = 0.5 * (low + high)
        low, high = (low, middle) if locks(middle) else (middle, high)
    pressure = margin * low
    return pressure, simulate(rig, constant_pressure_test(rig, pressure))
