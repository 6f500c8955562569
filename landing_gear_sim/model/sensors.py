"""The rig's sensors: what the transducers read of the true state, written once.

Pressure transducer: the true gauge pressure plus ``sensors.pressure_offset_pa`` when the
``pressure_sensor_offset`` element is on, plus white noise. Encoders and the load cell:
the true value plus white noise; the load cell's longitudinal channel also reads
``sensors.crosstalk_fx_per_fz`` of the vertical load (0 on a clean channel), and the wheel
encoder's channel may be ``sensors.wheel_speed_delay_s`` out of step with the others (it
reads the wheel speed that much earlier, linearly interpolated; 0: in step). Noise is
drawn only when a random generator is given (``sensors.*_noise_*`` std; 0 means none), so a
simulation compared with a measurement is never noisy by accident. Values are floats or
arrays alike.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import Value


@dataclass(frozen=True)
class SensorModel:
    """Offset [Pa] and noise std (Pa, rad/s, N) of the rig's sensors."""

    pressure_offset_pa: float = 0.0
    pressure_noise_pa: float = 0.0
    speed_noise_rad_s: float = 0.0
    force_noise_n: float = 0.0
    fx_per_fz: float = 0.0
    wheel_delay_s: float = 0.0

    @classmethod
    def of(cls, params: RigParameters) -> SensorModel:
        offset = (params.number("sensors.pressure_offset_pa")
                  if params.has("pressure_sensor_offset") else 0.0)
        return cls(offset, params.number("sensors.pressure_noise_pa"),
                   params.number("sensors.speed_noise_rad_s"),
                   params.number("sensors.force_noise_n"),
                   params.number("sensors.crosstalk_fx_per_fz"),
                   params.number("sensors.wheel_speed_delay_s"))

    def pressure(self, true_pa: Value, rng: np.random.Generator | None = None) -> Value:
        """Transducer reading [Pa, gauge] of the true brake pressure."""
        return _noisy(true_pa + self.pressure_offset_pa, self.pressure_noise_pa, rng)

    def speed(self, true_rad_s: Value, rng: np.random.Generator | None = None) -> Value:
        """Encoder reading [rad/s]."""
        return _noisy(true_rad_s, self.speed_noise_rad_s, rng)

    def force(self, true_n: Value, rng: np.random.Generator | None = None) -> Value:
        """Load-cell reading [N]."""
        return _noisy(true_n, self.force_noise_n, rng)

    def wheel_speed(self, times_s: np.ndarray, true_rad_s: np.ndarray,
                    rng: np.random.Generator | None = None) -> np.ndarray:
        """Wheel-encoder channel [rad/s] of the samples at ``times_s`` (s, increasing; shape
        of ``true_rad_s``)."""
        return _noisy(self.out_of_step(times_s, true_rad_s), self.speed_noise_rad_s, rng)

    def out_of_step(self, times_s: np.ndarray, true_rad_s: np.ndarray) -> np.ndarray:
        """The wheel speed ``wheel_delay_s`` before each of ``times_s`` (the first sample's
        before the start), noise-free. Element k needs only the samples from
        ``times_s[k] − wheel_delay_s`` on: the plant node passes its recent history."""
        if self.wheel_delay_s <= 0.0:
            return true_rad_s
        return np.interp(times_s - self.wheel_delay_s, times_s, true_rad_s)

    def longitudinal(self, true_fx_n: Value, true_fz_n: Value,
                     rng: np.random.Generator | None = None) -> Value:
        """Load-cell F_x channel reading [N]: F_x plus its crosstalk from F_z."""
        return _noisy(true_fx_n + self.fx_per_fz * true_fz_n, self.force_noise_n, rng)

    def true_longitudinal(self, reading_n: Value, vertical_n: Value) -> Value:
        """The F_x behind a load-cell reading (its crosstalk from F_z removed) [N]."""
        return reading_n - self.fx_per_fz * vertical_n

    def true_pressure(self, reading_pa: Value) -> Value:
        """The brake pressure behind a transducer reading (the offset removed) [Pa]."""
        return reading_pa - self.pressure_offset_pa


def _noisy(value: Value, std: float, rng: np.random.Generator | None) -> Value:
    """``value`` plus N(0, std²) noise of its shape (a new array; a float stays a float)."""
    if rng is None or std <= 0.0:
        return value + 0.0
    size = None if np.ndim(value) == 0 else np.shape(value)
    noise: Any = rng.normal(0.0, std, size)  # a float when size is None
    return value + noise
