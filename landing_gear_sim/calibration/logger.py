"""How a rig's logger writes what its sensors read: the generator's logger realities.

A real campaign is not logged as a simulation samples it: the logger runs at its own rate
(the valve current updated at that rate, no anti-alias filter), the wheel speed may come
from counting an encoder's lines per sample, the logged current carries the shunt's noise
and the ADC's steps while the valve saw the clean current, a channel may be stamped late,
and a logger may drop a few tens of milliseconds of rows. :class:`Logger` applies these to
a simulated run, so that tests and benchmarks can hide them in campaigns of the project's
own generator (``landing-gear-sim campaign --logger ...``). The defaults log as the
generator always did: at the rig's output rate, analogue channels with Gaussian noise,
nothing late or lost.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.errors import ParameterError
from landing_gear_sim.model.integrate import SimulationResult
from landing_gear_sim.model.sensors import SensorModel, wheel_angle_rad
from msg_tools.run import SIGNALS, Run

LATE_CHANNELS = tuple(s for s in SIGNALS if s != "current_a")
"""Channels that may be stamped late (the current is the time reference)."""
DROPOUT_MARGIN_S = 1.0  # a dropout lies this far from either end of a run


@dataclass(frozen=True)
class Logger:
    """The logger's realities (see the module docstring); the defaults change nothing."""

    rate_hz: float | None = None
    """The log's rate (None: the rig's ``simulation.output_rate_hz``)."""
    encoder_counts: int = 0
    """Lines per wheel revolution of a counting encoder (0: an analogue channel)."""
    current_noise_a: float = 0.0
    current_adc_bits: int = 0
    """Bits of the current's ADC over 0..``current_range_a`` (0: not quantised)."""
    current_range_a: float = 2.0
    late_channel: str = ""
    late_s: float = 0.0
    dropout_s: float = 0.0
    """One gap of this length in every run (rows missing)."""

    def __post_init__(self) -> None:
        if self.rate_hz is not None and not (math.isfinite(self.rate_hz) and self.rate_hz > 0):
            raise ParameterError(f"logger rate must be > 0 Hz, got {self.rate_hz}")
        if self.late_channel and self.late_channel not in LATE_CHANNELS:
            raise ParameterError(f"logger late channel {self.late_channel!r}: choose from "
                                 f"{', '.join(LATE_CHANNELS)}")
        negative = [f.name for f in dataclasses.fields(self)
                    if isinstance(getattr(self, f.name), int | float)
                    and not isinstance(getattr(self, f.name), bool)
                    and getattr(self, f.name) < 0]
        if negative:
            raise ParameterError(f"logger {negative[0]} must be ≥ 0")

    @property
    def realities(self) -> list[str]:
        """What differs from the default logger, in words (empty: nothing)."""
        words = []
        if self.rate_hz is not None:
            words.append(f"logged at {self.rate_hz:g} Hz")
        if self.encoder_counts:
            words.append(f"wheel speed from a {self.encoder_counts}-count encoder")
        if self.current_noise_a:
            words.append(f"{1e3 * self.current_noise_a:g} mA noise on the logged current")
        if self.current_adc_bits:
            words.append(f"current through a {self.current_adc_bits}-bit ADC over "
                         f"0–{self.current_range_a:g} A")
        if self.late_channel and self.late_s:
            words.append(f"{self.late_channel} logged {1e3 * self.late_s:g} ms late")
        if self.dropout_s:
            words.append(f"one {1e3 * self.dropout_s:g} ms dropout per run")
        return words

    @classmethod
    def parse(cls, spec: str) -> Logger:
        """A logger from ``key=value,...`` (keys: the field names; ``late`` as
        ``channel:seconds``), e.g. ``rate_hz=200,encoder_counts=64``."""
        values: dict[str, object] = {}
        names = {f.name: f.type for f in dataclasses.fields(cls)}
        for item in filter(None, (part.strip() for part in spec.split(","))):
            key, _, text = item.partition("=")
            if key == "late":
                channel, _, seconds = text.partition(":")
                values |= {"late_channel": channel, "late_s": _number(key, seconds)}
            elif key not in names or key in ("late_channel", "late_s"):
                raise ParameterError(f"logger: unknown {key!r}; choose from rate_hz, "
                                     "encoder_counts, current_noise_a, current_adc_bits, "
                                     "current_range_a, late=CHANNEL:SECONDS, dropout_s")
            else:
                number = _number(key, text)
                values[key] = int(number) if names[key] == "int" else number
        return cls(**values)  # type: ignore[arg-type]

    def write(self, result: SimulationResult, run: Run, rng: np.random.Generator) -> Run:
        """``run`` (the sensors' reading of ``result``, sampled at ``rate_hz``) as this logger
        writes it."""
        fields = {name: getattr(run, name) for name in SIGNALS}
        if self.encoder_counts:
            fields["wheel_speed_rad_s"] = self._counted(run.time_s, _encoder_channel(result))
        fields["current_a"] = self._current(run.current_a, rng)
        if self.late_channel and self.late_s:
            values = fields[self.late_channel]
            fields[self.late_channel] = np.interp(run.time_s - self.late_s, run.time_s, values)
        kept = self._kept(run.time_s, rng)
        return Run(name=run.name, source=run.source, time_s=run.time_s[kept],
                   **{name: values[kept] for name, values in fields.items()})

    def _counted(self, time_s: np.ndarray, read_rad_s: np.ndarray) -> np.ndarray:
        """Encoder lines counted in each sample interval, as a speed [rad/s] (the first
        sample repeats the second), of the angle the channel reads."""
        line = 2.0 * np.pi / self.encoder_counts
        counts = np.floor(wheel_angle_rad(time_s, read_rad_s) / line)
        speed = np.diff(counts) * line / np.diff(time_s)
        return np.concatenate([speed[:1], speed])

    def _current(self, logged_a: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        current = logged_a + (rng.normal(0.0, self.current_noise_a, logged_a.size)
                              if self.current_noise_a else 0.0)
        if self.current_adc_bits:
            step = self.current_range_a / 2 ** self.current_adc_bits
            current = np.round(np.clip(current, 0.0, self.current_range_a) / step) * step
        return current

    def _kept(self, time_s: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """The rows the logger kept: all but one ``dropout_s`` gap (mask (n,))."""
        kept = np.ones(time_s.size, dtype=bool)
        first, last = time_s[0] + DROPOUT_MARGIN_S, time_s[-1] - DROPOUT_MARGIN_S - self.dropout_s
        if self.dropout_s and last > first:
            start = rng.uniform(first, last)
            kept &= (time_s < start) | (time_s >= start + self.dropout_s)
        return kept


def _encoder_channel(result: SimulationResult) -> np.ndarray:
    """The wheel channel without its noise [rad/s]: a counting encoder has none, but it
    counts late when the channel is late, and an eccentric disc's lines where the channel
    ripples."""
    return SensorModel.of(result.params).wheel_speed(result.time_s, result.wheel_speed_rad_s)


def _number(key: str, text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise ParameterError(f"logger {key}: not a number: {text!r}") from None
