"""The three rig blocks as stateful objects, one call per exchange step.

These are what the ROS nodes hold: each wraps the compiled step function of
:mod:`landing_gear_sim.model.plant` that :func:`landing_gear_sim.model.integrate.run_kernel`
calls, so a graph run and an offline run of the same inputs agree. No ROS here.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.model import actuator, plant, quantities
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.scenario import Scenario, step_time
from landing_gear_sim.model.sensors import SensorModel, late


@dataclass(frozen=True)
class SensorSample:
    """What the rig's sensors read at one sample instant (SI, gauge pressure)."""

    step: int
    time_s: float
    pressure_pa: float
    wheel_speed_rad_s: float
    flywheel_speed_rad_s: float
    vertical_load_n: float
    longitudinal_force_n: float


class ActuatorBlock:
    """Valve static map + A(s) (+ delay): current held over a step → pressure at its end."""

    def __init__(self, params: RigParameters, step_s: float) -> None:
        self._p = params.vector()
        self._matrices = actuator.actuator_matrices(self._p, step_s)
        self._state = actuator.actuator_state(self._matrices)

    def step(self, current_a: float) -> float:
        """Pressure applied to the brake at the end of the step [Pa, gauge]."""
        return float(actuator.actuator_step(self._p, self._matrices, self._state, current_a))


class LoadingBlock:
    """Loading device (lift map + servo): flywheel speed at t_k → vertical force at t_{k+1}."""

    def __init__(self, params: RigParameters, step_s: float, contact: bool) -> None:
        self._p = params.vector()
        self._step_s = step_s
        self._contact = contact
        self._params = params
        self._state = np.zeros(1)

    def step(self, step: int, flywheel_speed_rad_s: float) -> float:
        """Vertical force at the end of step ``step`` [N] (0 when the wheel is off)."""
        if not self._contact:
            return 0.0
        speed = quantities.rim_speed_m_s(self._params, flywheel_speed_rad_s)
        t = step_time(step, self._step_s)
        return float(plant.loading_step(self._p, self._state, t, speed, self._step_s))


class History:
    """A channel ``delay_s`` out of step (:func:`~landing_gear_sim.model.sensors.late`), read
    one sample at a time from the recent samples it keeps (a value as it is when in step)."""

    def __init__(self, delay_s: float, step_s: float) -> None:
        self._delay_s = delay_s
        kept = math.ceil(delay_s / step_s) + 2 if delay_s > 0.0 else 1
        self._samples: deque[tuple[float, float]] = deque(maxlen=kept)

    def read(self, time_s: float, value: float) -> float:
        """The channel's reading at ``time_s``, where the true value is ``value``."""
        if self._delay_s <= 0.0:
            return value
        if not self._samples or self._samples[-1][0] < time_s:
            self._samples.append((time_s, value))
        times, values = (np.array(column) for column in zip(*self._samples, strict=True))
        return float(late(times, values, self._delay_s)[-1])


class PlantBlock:
    """Wheel, tyre, gear walk, flywheel and sensors of one scenario, advanced step by step.

    ``noise`` (a numpy Generator, or None) adds the ``sensors.*`` white noise to
    what :meth:`sample` returns; the state itself is never noisy.
    """

    def __init__(self, params: RigParameters, scenario: Scenario,
                 noise: np.random.Generator | None = None) -> None:
        self._p = params.vector()
        self._scenario = scenario
        self._noise = noise
        self._x = np.zeros(plant.N_STATES)
        self._x[plant.SPEED] = scenario.initial_speed_m_s if scenario.contact else 0.0
        self._work = np.zeros((5, plant.N_STATES))
        self._row = np.empty(plant.N_CHANNELS)
        self._params = params
        self._sensors = SensorModel.of(params)
        # a channel out of step reads its recent samples (none when in step)
        self._wheel_history = History(self._sensors.wheel_delay_s, scenario.step_s)
        self._pressure_history = History(self._sensors.pressure_delay_s, scenario.step_s)
        self._wheel_angle = (0.0, 0.0, 0.0)  # time [s], speed [rad/s], angle [rad] last read
        self.step_index = 0
        self.pressure_pa = 0.0
        self.load_n = 0.0

    @property
    def step_s(self) -> float:
        return self._scenario.step_s

    @property
    def n_steps(self) -> int:
        """Samples of the scenario's input (the run's longest length)."""
        return int(self._scenario.current_a.size)

    def finished(self) -> bool:
        """The run ends at this sample: end of input, or below the stop speed (as offline)."""
        s = self._scenario
        below = s.contact and s.stop_speed_m_s > 0.0 and self._x[plant.SPEED] < s.stop_speed_m_s
        return below or self.step_index >= self.n_steps - 1

    def record(self, current_a: float = 0.0) -> np.ndarray:
        """The full simulation record row of the current sample (see plant.CHANNELS)."""
        t = step_time(self.step_index, self.step_s)
        plant.record(self._p, self._x, t, current_a, self.pressure_pa, self.load_n, self._row)
        return self._row.copy()

    def sample(self) -> SensorSample:
        """Sensor readings of the current sample."""
        row = self.record()
        sensors, rng = self._sensors, self._noise
        return SensorSample(
            step=self.step_index, time_s=float(row[0]),
            pressure_pa=float(sensors.pressure(self._pressure_history.read(row[0], row[2]),
                                               rng, row[0])),
            wheel_speed_rad_s=float(sensors.speed(self._wheel_read(row[0], row[3]), rng)),
            flywheel_speed_rad_s=float(sensors.speed(
                quantities.flywheel_speed_rad_s(self._params, row[4]), rng)),
            vertical_load_n=float(sensors.force(row[6], rng)),
            longitudinal_force_n=float(sensors.longitudinal(row[7], row[6], rng, row[0])))

    def _wheel_read(self, time_s: float, wheel_rad_s: float) -> float:
        """The wheel channel's noise-free reading now (out of step: from recent samples)."""
        if self._sensors.ripples:
            wheel_rad_s = self._encoder(time_s, wheel_rad_s)
        return self._wheel_history.read(time_s, wheel_rad_s)

    def _encoder(self, time_s: float, wheel_rad_s: float) -> float:
        """The encoder's reading at the wheel's angle, advanced by the trapezoid from the
        last sample read (the increments :func:`~landing_gear_sim.model.sensors.wheel_angle_rad`
        sums offline)."""
        last_s, last_rad_s, angle = self._wheel_angle
        if time_s > last_s:
            angle += 0.5 * (wheel_rad_s + last_rad_s) * (time_s - last_s)
        self._wheel_angle = (time_s, wheel_rad_s, angle)
        return float(self._sensors.encoder(wheel_rad_s, angle))

    def advance(self, next_pressure_pa: float, next_load_n: float) -> None:
        """Integrate to the next sample with inputs ramping to the given end values."""
        plant.plant_step(self._p, self._x, self.pressure_pa, next_pressure_pa, self.load_n,
                         next_load_n, self.step_s, self._work)
        self.pressure_pa, self.load_n = next_pressure_pa, next_load_n
        self.step_index += 1
