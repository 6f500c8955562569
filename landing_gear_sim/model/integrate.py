"""Run scenarios through the plant: one run, or a batch of parameter sets in one call.

The whole run loop is compiled (numba), calling the same block step functions
the ROS nodes call one at a time (:mod:`landing_gear_sim.model.plant`), so an offline
run and a graph run of the same inputs agree to the last bit.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from landing_gear_sim.model.actuator import (
    actuator_matrices,
    actuator_state,
    actuator_step,
    settled_state,
)
from landing_gear_sim.model.dual_arrays import rows_like, vector_like
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.plant import (
    CHANNELS,
    N_CHANNELS,
    N_STATES,
    SPEED,
    WHEEL_ANGLE,
    loading_step,
    plant_step,
    record,
)
from landing_gear_sim.model.quantities import flywheel_speed_rad_s
from landing_gear_sim.model.scenario import Scenario, held_to_logged
from landing_gear_sim.model.sensors import SensorModel
from msg_tools.run import Run

STOP_REASONS = ("end of input", "stop speed reached")


@njit(cache=True, nogil=True)  # runs simulate side by side on threads
def run_kernel(p, matrices, current, step_s, contact, initial_speed, stop_speed, angle, out,
               settled=False):
    """Simulate one run; fill ``out`` (n, N_CHANNELS); return (rows written, stop code).
    ``angle``: the wheel's measured angle at each step (n,), which the plant's angle takes
    at every exchange, or empty: the plant's own. ``settled``: the valve starts settled on
    ``current[0]`` (else at rest, as a rig test starts)."""
    x = vector_like(p, N_STATES)
    x[SPEED] = initial_speed if contact else 0.0
    xa = settled_state(p, matrices, current[0]) if settled else actuator_state(matrices)
    xl = vector_like(p, 1)
    work = rows_like(p, 5, N_STATES)
    pressure, load = xa[0], 0.0
    # a wheel off the ground at rest is a fixed point of the plant (every derivative is
    # exactly 0): stepping it only costs time (~80 % of an actuator run's simulation)
    at_rest = not contact and initial_speed == 0.0
    n = current.shape[0]
    follow = angle.shape[0] > 0
    for k in range(n):
        t = k * step_s
        if follow:
            x[WHEEL_ANGLE] = angle[k]
        record(p, x, t, current[k], pressure, load, out[k])
        if contact and stop_speed > 0.0 and x[SPEED] < stop_speed:
            return k + 1, 1
        if k == n - 1:
            break
        next_pressure = actuator_step(p, matrices, xa, current[k])
        next_load = loading_step(p, xl, t, x[SPEED], step_s) if contact else 0.0
        if not at_rest:
            plant_step(p, x, pressure, next_pressure, load, next_load, step_s, work)
        pressure, load = next_pressure, next_load
    return n, 0


@njit(cache=True)
def actuator_kernel(p, matrices, current, out, settled=False):
    """The pressure column ``run_kernel`` records, from the actuator alone (it does not
    depend on the wheel): ``out[0]`` at rest or ``settled`` on ``current[0]``, ``out[k+1]``
    after step k with ``current[k]``."""
    xa = settled_state(p, matrices, current[0]) if settled else actuator_state(matrices)
    out[0] = xa[0]
    for k in range(current.shape[0] - 1):
        out[k + 1] = actuator_step(p, matrices, xa, current[k])


@njit(cache=True, parallel=True)
def batch_kernel(p, matrices, current, step_s, contact, initial_speed, stop_speed, out, rows, stop,
                 settled=False):
    """``run_kernel`` over parameter sets ``p`` (m, N_PARAMS) in parallel; inputs (m, n)."""
    for i in prange(p.shape[0]):
        rows[i], stop[i] = run_kernel(p[i], matrices[i], current[i], step_s, contact,
                                      initial_speed, stop_speed, np.zeros(0), out[i], settled)


@dataclass(frozen=True)
class SimulationResult:
    """Sampled signals of one simulated run.

    ``data`` has shape (n, len(CHANNELS)); each channel is also an attribute,
    e.g. ``result.wheel_speed_rad_s`` (see :data:`landing_gear_sim.model.plant.CHANNELS`).
    """

    scenario: Scenario
    params: RigParameters
    data: np.ndarray
    stop_reason: str

    def __getattr__(self, name: str) -> np.ndarray:
        if name in CHANNELS:
            return self.data[:, CHANNELS.index(name)]
        raise AttributeError(name)

    def __len__(self) -> int:
        return int(self.data.shape[0])

    def sensed_pressure_to_end(self) -> np.ndarray:
        """Brake pressure as the transducer reads it (offset, no noise) over the whole
        input, (n,) [Pa]: after a stop at the stop speed the valve still follows its
        current, so a measured run's pressure goes on after the simulation stopped."""
        vector = self.params.vector()
        pressure = np.empty(self.scenario.current_a.size)
        actuator_kernel(vector, actuator_matrices(vector, self.scenario.step_s),
                        self.scenario.current_a, pressure, self.scenario.settled_start)
        times = np.arange(pressure.size) * self.scenario.step_s
        return SensorModel.of(self.params).pressure_channel(times, pressure)

    def to_run(self, noise: np.random.Generator | int | None = None,
               wheel_angle_rad: np.ndarray | None = None) -> Run:
        """The run as the rig's sensors would log it (data contract).

        The sensors are those of :class:`~landing_gear_sim.model.sensors.SensorModel`:
        the pressure offset when its element is on, and the ``sensors.*`` noise only when
        ``noise`` (a generator, or a seed for a reproducible one) is given. The wheel
        encoder ripples at ``wheel_angle_rad`` (one per sample; default: the simulated
        wheel's own angle).
        """
        rng = None if noise is None else np.random.default_rng(noise)
        sensors = SensorModel.of(self.params)
        return Run(
            name=self.scenario.name, source="simulation", time_s=self.time_s.copy(),
            current_a=held_to_logged(self.current_a),
            pressure_pa=sensors.pressure_channel(self.time_s, self.pressure_pa, rng),
            wheel_speed_rad_s=sensors.wheel_speed(self.time_s, self.wheel_speed_rad_s, rng,
                                                  wheel_angle_rad),
            flywheel_speed_rad_s=sensors.speed(flywheel_speed_rad_s(self.params, self.speed_m_s),
                                               rng),
            vertical_load_n=sensors.force(self.vertical_load_n, rng),
            longitudinal_force_n=sensors.longitudinal(self.longitudinal_force_n,
                                                      self.vertical_load_n, rng,
                                                      self.time_s - self.time_s[0]),
        )


BATCH_CHUNK = 16  # sets simulated at once: bounds the output buffer of a large batch


def compiled() -> bool:
    """The run loop is compiled in this process (or loaded from numba's cache): what a
    first run after an install or a change spends ~10 s on has been done."""
    return bool(run_kernel.signatures)


def simulate(params: RigParameters, scenario: Scenario) -> SimulationResult:
    """Simulate one scenario with one parameter set."""
    vector = params.vector()
    out = np.empty((scenario.current_a.size, N_CHANNELS))
    angle = np.zeros(0) if scenario.wheel_angle_rad is None else scenario.wheel_angle_rad
    rows, stop = run_kernel(vector, actuator_matrices(vector, scenario.step_s),
                            scenario.current_a, scenario.step_s, scenario.contact,
                            scenario.initial_speed_m_s, scenario.stop_speed_m_s, angle, out,
                            scenario.settled_start)
    return SimulationResult(scenario, params, out[:rows].copy(), STOP_REASONS[stop])


def simulate_batch(params: Sequence[RigParameters], scenario: Scenario,
                   current_a: np.ndarray | None = None) -> list[SimulationResult]:
    """Simulate one scenario for many parameter sets in one call (parallel over sets).

    Args:
        params: the parameter sets.
        scenario: shared timing, contact and stop rule.
        current_a: optional per-set inputs, shape (len(params), n); defaults to
            the scenario's current for every set.
    """
    inputs = scenario.current_a if current_a is None else np.asarray(current_a, dtype=float)
    inputs = np.broadcast_to(inputs, (len(params), inputs.shape[-1]))
    results: list[SimulationResult] = []
    for start in range(0, len(params), BATCH_CHUNK):
        chunk = list(params[start:start + BATCH_CHUNK])
        # a fresh writable copy: numba compiles a read-only array (a broadcast view, a
        # caller's frozen inputs) as another type, the parallel kernel once more (~10 s)
        results.extend(_simulate_chunk(chunk, scenario,
                                       np.array(inputs[start:start + len(chunk)], order="C")))
    return results


def _simulate_chunk(params: list[RigParameters], scenario: Scenario,
                    inputs: np.ndarray) -> list[SimulationResult]:
    vectors = np.stack([p.vector() for p in params])
    matrices = np.stack([actuator_matrices(v, scenario.step_s) for v in vectors])
    out = np.empty((len(params), inputs.shape[1], N_CHANNELS))
    rows = np.zeros(len(params), dtype=np.int64)
    stop = np.zeros(len(params), dtype=np.int64)
    batch_kernel(vectors, matrices, inputs, scenario.step_s, scenario.contact,
                 scenario.initial_speed_m_s, scenario.stop_speed_m_s, out, rows, stop,
                 scenario.settled_start)
    return [SimulationResult(scenario, p, out[i, : rows[i]].copy(), STOP_REASONS[stop[i]])
            for i, p in enumerate(params)]
