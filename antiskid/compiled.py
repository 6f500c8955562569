"""The closed loop of :func:`antiskid.closed_loop.closed_loop` in one compiled call.

The same step functions — plant, actuator, loading device, sensors' wheel channel (its
delay and its ripple with the wheel's angle) and the controller — called in the same order,
but inside one numba loop instead of one Python call per block and step: a 60 m/s stop in
~7 ms instead of ~60 ms, which is what a Monte Carlo of thousands of stops needs. The record
equals the block-by-block loop's to the last bit (test, a ripple included), so a case found
here replays the same in the graph.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from numba import njit

from landing_gear_sim.model import keys as K
from landing_gear_sim.model.actuator import actuator_matrices, actuator_state, actuator_step
from landing_gear_sim.model.integrate import STOP_REASONS, SimulationResult
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.plant import (
    N_CHANNELS,
    N_STATES,
    SPEED,
    loading_step,
    plant_step,
    record,
)
from landing_gear_sim.model.runspec import RunSpec, build_scenario
from landing_gear_sim.model.sensors import SensorModel

from .closed_loop import CONTROLLERS, controller_arrays
from .slip import slip_step
from .threshold import threshold_step

TIME_COLUMN, CURRENT_COLUMN, WHEEL_COLUMN = 0, 1, 3


@njit(cache=True)
def _encoder(out, k, runout, angle, reads):
    """The encoder's reading of sample ``k`` into ``reads[k]``, at the wheel angle advanced by
    the trapezoid (``angle``: a 1-array), as the plant block reads it."""
    wheel = out[k, WHEEL_COLUMN]
    if k > 0:
        angle[0] += 0.5 * (wheel + out[k - 1, WHEEL_COLUMN]) * (
            out[k, TIME_COLUMN] - out[k - 1, TIME_COLUMN])
    reads[k] = wheel * (1.0 + runout[0] * math.cos(angle[0] + runout[1])
                        + runout[2] * math.cos(2.0 * angle[0] + runout[3]))


@njit(cache=True)
def _wheel_read(out, reads, k, delay_s, kept):
    """The wheel channel at sample ``k`` read ``delay_s`` early, from the encoder's readings
    so far (as the plant block reads it from its recent history)."""
    if delay_s <= 0.0:
        return reads[k]
    first = max(0, k + 1 - kept)
    times = out[first:k + 1, TIME_COLUMN]
    return np.interp(out[k, TIME_COLUMN] - delay_s, times, reads[first:k + 1])


@njit(cache=True)
def _control(kind, settings, state, time_to_brake_s, wheel_rad_s, flywheel_rad_s):
    if kind == 0:
        return threshold_step(settings, state, time_to_brake_s, wheel_rad_s)
    return slip_step(settings, state, time_to_brake_s, wheel_rad_s, flywheel_rad_s)


@njit(cache=True)
def closed_loop_kernel(p, matrices, step_s, initial_speed, stop_speed, start_s, flywheel_r,
                       delay_s, kept, runout, kind, settings, state, out):
    """A rig test under control; fill ``out`` (n, N_CHANNELS); return (rows, stop code).
    ``runout``: the encoder's e₁, φ₁, e₂, φ₂ (SensorModel.runout)."""
    reads = np.empty(out.shape[0])
    angle = np.zeros(1)
    ripples = runout[0] != 0.0 or runout[2] != 0.0
    x = np.zeros(N_STATES)
    x[SPEED] = initial_speed
    xa = actuator_state(matrices)
    xl = np.zeros(1)
    work = np.zeros((5, N_STATES))
    pressure, load = 0.0, 0.0
    n = out.shape[0]
    for k in range(n):
        t = k * step_s
        record(p, x, t, 0.0, pressure, load, out[k])
        flywheel = x[SPEED] / flywheel_r  # the encoder reads the rim speed on the flywheel
        if ripples:
            _encoder(out, k, runout, angle, reads)
        else:  # two cosines a step would cost a fifth of a stop's time
            reads[k] = out[k, WHEEL_COLUMN]
        wheel = _wheel_read(out, reads, k, delay_s, kept)
        current = _control(kind, settings, state, start_s - t, wheel, flywheel)
        out[k, CURRENT_COLUMN] = current
        if k == n - 1:
            break
        if stop_speed > 0.0 and x[SPEED] < stop_speed:
            return k + 1, 1
        next_pressure = actuator_step(p, matrices, xa, current)
        next_load = loading_step(p, xl, t, flywheel * flywheel_r, step_s)
        plant_step(p, x, pressure, next_pressure, load, next_load, step_s, work)
        pressure, load = next_pressure, next_load
    return n, 0


def compiled_closed_loop(rig: RigParameters, kind: str,
                         values: Mapping[str, object] | None = None,
                         rate_hz: float = 0.0) -> SimulationResult:
    """:func:`~antiskid.closed_loop.closed_loop` of controller ``kind`` (settings
    ``values``), compiled: the same record, noise-free sensors."""
    scenario = build_scenario(RunSpec(profile="external", rate_hz=rate_hz), rig)
    settings, state = controller_arrays(kind, rig, scenario.step_s, values)
    vector = rig.vector()
    sensors = SensorModel.of(rig)
    delay_s = sensors.wheel_delay_s
    out = np.empty((scenario.current_a.size, N_CHANNELS))
    rows, stop = closed_loop_kernel(
        vector, actuator_matrices(vector, scenario.step_s), scenario.step_s,
        scenario.initial_speed_m_s, scenario.stop_speed_m_s,
        rig.number(K.RIG_TEST_BRAKE_START_S), rig.number(K.FLYWHEEL_RADIUS_M), delay_s,
        math.ceil(delay_s / scenario.step_s) + 2, np.array(sensors.runout),
        CONTROLLERS.index(kind), settings, state, out)
    return SimulationResult(scenario, rig, out[:rows].copy(), STOP_REASONS[stop])
