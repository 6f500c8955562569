"""The rig's sensors: what the transducers read of the true state, written once.

Pressure transducer: the true gauge pressure plus ``sensors.pressure_offset_pa`` when the
``pressure_sensor_offset`` element is on and its generic slot (``sensors.p_term_*``: a
transducer that drifts or bends), plus white noise. Encoders and the load cell:
the true value plus white noise; the load cell's longitudinal channel also reads
``sensors.crosstalk_fx_per_fz`` of the vertical load (0 on a clean channel), the pressure
channel may be ``sensors.pressure_delay_s`` and the wheel encoder's
``sensors.wheel_speed_delay_s`` out of step with the others (each reads its quantity that
much earlier, linearly interpolated; 0: in step), and the encoder's channel may ripple
once and twice per wheel revolution (``sensors.wheel_runout_*``: ω (1 + e cos(mθ + φ)), θ the
wheel angle since the run's first sample, the trapezoid integral of the sampled ω). Noise is
drawn only when a random generator is given (``sensors.*_noise_*`` std; 0 means none), so a
simulation compared with a measurement is never noisy by accident. Values are floats or
arrays alike.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
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
    runout: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0)  # e₁, φ₁ [rad], e₂, φ₂ [rad]
    pressure_delay_s: float = 0.0
    fx_terms: tuple[tuple[float, float], ...] = ()  # the F_x channel's slot: (code, coeff)
    p_terms: tuple[tuple[float, float], ...] = ()  # the pressure channel's slot

    @classmethod
    def of(cls, params: RigParameters) -> SensorModel:
        offset = (params.number(K.SENSORS_PRESSURE_OFFSET_PA)
                  if params.has("pressure_sensor_offset") else 0.0)
        return cls(offset, params.number(K.SENSORS_PRESSURE_NOISE_PA),
                   params.number(K.SENSORS_SPEED_NOISE_RAD_S),
                   params.number(K.SENSORS_FORCE_NOISE_N),
                   params.number(K.SENSORS_CROSSTALK_FX_PER_FZ),
                   params.number(K.SENSORS_WHEEL_SPEED_DELAY_S),
                   tuple(params.number(k) for k in RUNOUT_KEYS),
                   params.number(K.SENSORS_PRESSURE_DELAY_S),
                   _terms(params, K.FX_TERMS), _terms(params, K.PRESSURE_TERMS))

    @property
    def ripples(self) -> bool:
        """Whether the wheel encoder ripples with the wheel's angle."""
        return self.runout[0] != 0.0 or self.runout[2] != 0.0

    def pressure(self, true_pa: Value, rng: np.random.Generator | None = None,
                 time_s: float | np.ndarray = 0.0) -> Value:
        """Transducer reading [Pa, gauge] of the true brake pressure (in step: see
        :meth:`pressure_channel`; ``time_s``: since the run's first sample)."""
        read = true_pa + self.pressure_offset_pa + self.p_slot(time_s, true_pa)
        return _noisy(read, self.pressure_noise_pa, rng)

    def pressure_channel(self, times_s: np.ndarray, true_pa: np.ndarray,
                         rng: np.random.Generator | None = None) -> np.ndarray:
        """The pressure channel [Pa] of the samples at ``times_s``: the transducer's reading,
        ``pressure_delay_s`` out of step (see :func:`late`)."""
        return self.pressure(late(times_s, true_pa, self.pressure_delay_s), rng,
                             times_s - times_s[0])

    def speed(self, true_rad_s: Value, rng: np.random.Generator | None = None) -> Value:
        """Encoder reading [rad/s]."""
        return _noisy(true_rad_s, self.speed_noise_rad_s, rng)

    def force(self, true_n: Value, rng: np.random.Generator | None = None) -> Value:
        """Load-cell reading [N]."""
        return _noisy(true_n, self.force_noise_n, rng)

    def wheel_speed(self, times_s: np.ndarray, true_rad_s: np.ndarray,
                    rng: np.random.Generator | None = None,
                    angle_rad: np.ndarray | None = None) -> np.ndarray:
        """Wheel-encoder channel [rad/s] of the samples at ``times_s`` (s, increasing; shape
        of ``true_rad_s``), at the wheel angles ``angle_rad`` (default: the integral of
        ``true_rad_s``; a simulation of a measured run passes the measured angle)."""
        if angle_rad is None and self.ripples:
            angle_rad = wheel_angle_rad(times_s, true_rad_s)
        encoder = true_rad_s if angle_rad is None else self.encoder(true_rad_s, angle_rad)
        return _noisy(self.out_of_step(times_s, encoder), self.speed_noise_rad_s, rng)

    def encoder(self, true_rad_s: Value, angle_rad: Value) -> Value:
        """What the encoder reads of ``true_rad_s`` at the wheel angle ``angle_rad`` [rad/s]:
        its ripple once and twice per revolution, no delay, no noise."""
        e1, phase1, e2, phase2 = self.runout
        return true_rad_s * (1.0 + e1 * np.cos(angle_rad + phase1)
                             + e2 * np.cos(2.0 * angle_rad + phase2))

    def out_of_step(self, times_s: np.ndarray, true_rad_s: np.ndarray) -> np.ndarray:
        """The wheel speed ``wheel_delay_s`` before each of ``times_s`` (the first sample's
        before the start), noise-free. Element k needs only the samples from
        ``times_s[k] − wheel_delay_s`` on: the plant node passes its recent history."""
        return late(times_s, true_rad_s, self.wheel_delay_s)

    def longitudinal(self, true_fx_n: Value, true_fz_n: Value,
                     rng: np.random.Generator | None = None,
                     time_s: float | np.ndarray = 0.0) -> Value:
        """Load-cell F_x channel reading [N]: F_x plus its crosstalk from F_z and its generic
        slot (``time_s``: since the run's first sample)."""
        read = true_fx_n + self.fx_per_fz * true_fz_n + self.fx_slot(time_s, true_fz_n)
        return _noisy(read, self.force_noise_n, rng)

    def true_longitudinal(self, reading_n: Value, vertical_n: Value,
                          time_s: float | np.ndarray = 0.0) -> Value:
        """The F_x behind a load-cell reading (its crosstalk from F_z and its slot removed)
        [N]."""
        return reading_n - self.fx_per_fz * vertical_n - self.fx_slot(time_s, vertical_n)

    def fx_slot(self, time_s: float | np.ndarray, vertical_n: Value) -> Value:
        """What the F_x channel's generic slot adds to its reading [N]: Σ c_k φ_k(F_z, t),
        ``model.basis``'s, ``time_s`` since the run's first sample (0: no term)."""
        return _slot(self.fx_terms, basis.LOAD, vertical_n, time_s)

    def p_slot(self, time_s: float | np.ndarray, pressure_pa: Value) -> Value:
        """What the pressure channel's generic slot adds to its reading [Pa]: Σ c_k φ_k(P, t)
        (0: no term)."""
        return _slot(self.p_terms, basis.PRESSURE, pressure_pa, time_s)

    def true_pressure(self, reading_pa: Value, time_s: float | np.ndarray = 0.0) -> Value:
        """The brake pressure behind a transducer reading (the offset and the slot removed)
        [Pa]; ``time_s`` since the run's first sample."""
        pressure = reading_pa - self.pressure_offset_pa
        if not self.p_terms:
            return pressure
        true = pressure
        for _ in range(PRESSURE_INVERSIONS):  # a slot in P: its reading inverted in turn
            true = pressure - self.p_slot(time_s, true)
        return true


PRESSURE_INVERSIONS = 10  # each turn leaves the slot's slope in P (a few per cent) of the last


def _terms(params: RigParameters, keys: tuple[tuple[str, str], ...]
           ) -> tuple[tuple[float, float], ...]:
    """A channel's slot terms that act: (code, coefficient)."""
    return tuple((params.number(code), params.number(coeff)) for code, coeff in keys
                 if params.number(coeff) != 0.0)


def _slot(terms: tuple[tuple[float, float], ...], signal: int, values: Value,
          time_s: float | np.ndarray) -> Value:
    """A channel's slot Σ c_k φ_k at its quantity ``values`` (the basis ``signal``) and the
    time since the run's first sample (0.0: no term)."""
    if not terms:
        none: Any = 0.0  # a float for arrays too: adds nothing, not even to a NaN's place
        return none
    quantity = np.atleast_1d(np.asarray(values, dtype=float))
    signals = np.zeros((quantity.size, basis.N_SIGNALS))
    signals[:, signal] = quantity
    signals[:, basis.RUN_TIME] = np.broadcast_to(time_s, quantity.shape)
    total = sum(coeff * basis.term_values(round(code), signals) for code, coeff in terms)
    added: Any = total if np.ndim(values) else float(total[0])
    return added


RUNOUT_KEYS = (K.SENSORS_WHEEL_RUNOUT_1, K.SENSORS_WHEEL_RUNOUT_1_PHASE_RAD,
               K.SENSORS_WHEEL_RUNOUT_2, K.SENSORS_WHEEL_RUNOUT_2_PHASE_RAD)


def late(times_s: np.ndarray, values: np.ndarray, delay_s: float) -> np.ndarray:
    """``values`` (at the increasing ``times_s``) as a channel ``delay_s`` late reads them:
    each sample's value ``delay_s`` before it, linearly interpolated (the first sample's
    before the start); ``values`` itself when in step. Element k needs only the samples from
    ``times_s[k] − delay_s`` on: a block passes its recent history."""
    if delay_s <= 0.0:
        return values
    return np.interp(times_s - delay_s, times_s, values)


def wheel_angle_rad(times_s: np.ndarray, speed_rad_s: np.ndarray) -> np.ndarray:
    """The wheel angle since the first sample [rad]: the trapezoid integral of the sampled
    speed, summed in sample order (the plant block adds the same increments one by one)."""
    steps = 0.5 * (speed_rad_s[1:] + speed_rad_s[:-1]) * np.diff(times_s)
    return np.concatenate([[0.0], np.cumsum(steps)])


def _noisy(value: Value, std: float, rng: np.random.Generator | None) -> Value:
    """``value`` plus N(0, std²) noise of its shape (a new array; a float stays a float)."""
    if rng is None or std <= 0.0:
        return value + 0.0
    size = None if np.ndim(value) == 0 else np.shape(value)
    noise: Any = rng.normal(0.0, std, size)  # a float when size is None
    return value + noise
