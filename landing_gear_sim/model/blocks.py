"""The three rig blocks as stateful objects, one call per exchange step.

These are what the ROS nodes hold: each wraps the compiled step function of
:mod:`landing_gear_sim.model.plant` that :func:`landing_gear_sim.model.integrate.run_kernel`
calls, so a graph run and an offline run of the same inputs agree. No ROS here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from landing_gear_sim.model import plant
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.scenario import Scenario


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


def step_time(step: int, step_s: float) -> float:
    """Time of exchange step ``step`` [s], computed as the offline run does."""
    return step * step_s


class ActuatorBlock:
    """Valve static map + A(s) (+ delay): current held over a step → pressure at its end."""

    def __init__(self, params: RigParameters, step_s: float) -> None:
        self._p = params.vector()
        self._matrices = plant.actuator_matrices(self._p, step_s)
        self._state = plant.actuator_state(self._matrices)

    def step(self, current_a: float) -> float:
        """Pressure applied to the brake at the end of the step [Pa, gauge]."""
        return float(plant.actuator_step(self._p, self._matrices, self._state, current_a))


class LoadingBlock:
    """Loading device (lift map + servo): flywheel speed at t_k → vertical force at t_{k+1}."""

    def __init__(self, params: RigParameters, step_s: float, contact: bool) -> None:
        self._p = params.vector()
        self._step_s = step_s
        self._contact = contact
        self._flywheel_radius_m = params.number("flywheel.radius_m")
        self._state = np.zeros(1)

    def step(self, step: int, flywheel_speed_rad_s: float) -> float:
        """Vertical force at the end of step ``step`` [N] (0 when the wheel is off)."""
        if not self._contact:
            return 0.0
        speed = flywheel_speed_rad_s * self._flywheel_radius_m
        t = step_time(step, self._step_s)
        return float(plant.loading_step(self._p, self._state, t, speed, self._step_s))


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
        self._flywheel_radius_m = params.number("flywheel.radius_m")
        self._offset_pa = (params.number("sensors.pressure_offset_pa")
                           if params.has("pressure_sensor_offset") else 0.0)
        self._noise_std = {key: params.number(f"sensors.{key}")
                           for key in ("pressure_noise_pa", "speed_noise_rad_s", "force_noise_n")}
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
        return SensorSample(
            step=self.step_index, time_s=float(row[0]),
            pressure_pa=self._sensed(row[2] + self._offset_pa, "pressure_noise_pa"),
            wheel_speed_rad_s=self._sensed(row[3], "speed_noise_rad_s"),
            flywheel_speed_rad_s=self._sensed(row[4] / self._flywheel_radius_m,
                                              "speed_noise_rad_s"),
            vertical_load_n=self._sensed(row[6], "force_noise_n"),
            longitudinal_force_n=self._sensed(row[7], "force_noise_n"))

    def advance(self, next_pressure_pa: float, next_load_n: float) -> None:
        """Integrate to the next sample with inputs ramping to the given end values."""
        plant.plant_step(self._p, self._x, self.pressure_pa, next_pressure_pa, self.load_n,
                         next_load_n, self.step_s, self._work)
        self.pressure_pa, self.load_n = next_pressure_pa, next_load_n
        self.step_index += 1

    def _sensed(self, value: float, key: str) -> float:
        std = self._noise_std[key]
        if self._noise is None or std <= 0.0:
            return float(value)
        return float(value + self._noise.normal(0.0, std))
