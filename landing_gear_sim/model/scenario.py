"""Test scenarios: the rig procedure of paper Section III and the open-loop current profiles.

A :class:`Scenario` is everything a run needs besides the parameters: the valve
current reference sampled at the output rate (held over each sample), whether the
wheel touches the flywheel, the initial speed and the stop rule. Profiles are
functions of the time since the profile started, returning current [A].
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from landing_gear_sim.errors import ScenarioError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.run import Run
from msg_tools.units import PA_PER_BAR


def step_time(step: int, step_s: float) -> float:
    """Time of exchange step ``step`` [s], computed as the offline run does (here, not
    beside the blocks: the profile node stamps its steps without loading the compiled
    model)."""
    return step * step_s


Profile = Callable[[np.ndarray], np.ndarray]
"""Current reference [A] as a function of time since the profile started [s], shapes (n,)."""


@dataclass(frozen=True)
class Scenario:
    """One rig test to simulate.

    Attributes:
        name: short identifier, used in file names and reports.
        current_a: valve current reference, shape (n,), sample k held over
            [k/rate, (k+1)/rate).
        rate_hz: sample (and output) rate.
        contact: wheel pressed on the flywheel (braking test); False for an
            actuator-only test (speeds and loads stay 0).
        initial_speed_m_s: flywheel rim (or aircraft) speed at t = 0.
        stop_speed_m_s: the run ends when the speed falls below this; 0 runs to
            the end of the input.
        wheel_angle_rad: the wheel's angle at each sample, shape (n,), when the run
            follows a measured one (a disc's run-out acts at the measured angle); None:
            the plant's own.
    """

    name: str
    current_a: np.ndarray
    rate_hz: float
    contact: bool
    initial_speed_m_s: float
    stop_speed_m_s: float
    description: str = field(default="")
    wheel_angle_rad: np.ndarray | None = field(default=None, kw_only=True)
    settled_start: bool = field(default=False, kw_only=True)
    """The valve starts settled on the first current (a log that starts mid-hold, a part of
    a run cut in time); by default at rest, as a rig test starts even when its first sample
    commands a step (the example campaigns' sweeps)."""

    def __post_init__(self) -> None:
        current = np.asarray(self.current_a, dtype=float)
        if current.ndim != 1 or current.size < 2:
            raise ScenarioError(f"{self.name}: the current profile needs at least 2 samples")
        if not np.all(np.isfinite(current)):
            raise ScenarioError(f"{self.name}: the current profile has NaN or infinite values")
        if not (math.isfinite(self.rate_hz) and self.rate_hz > 0):
            raise ScenarioError(f"{self.name}: rate must be > 0 Hz, got {self.rate_hz}")
        object.__setattr__(self, "current_a", current)
        if self.wheel_angle_rad is not None:
            angle = np.ascontiguousarray(self.wheel_angle_rad, dtype=float)
            if angle.shape != current.shape:
                raise ScenarioError(f"{self.name}: the wheel angle has shape {angle.shape}, "
                                    f"the current {current.shape}")
            object.__setattr__(self, "wheel_angle_rad", angle)

    @property
    def step_s(self) -> float:
        return 1.0 / self.rate_hz

    @property
    def duration_s(self) -> float:
        return self.current_a.size / self.rate_hz


def sample_times(duration_s: float, rate_hz: float) -> np.ndarray:
    """Sample instants k/rate for k = 0 .. round(duration·rate) − 1."""
    return np.arange(round(duration_s * rate_hz)) / rate_hz


# --- profiles -------------------------------------------------------------------------

def constant(level_a: float) -> Profile:
    """A constant current."""
    return lambda t: np.full_like(t, level_a, dtype=float)


def quasi_static_ramp(peak_a: float = 1.0, duration_s: float = 20.0) -> Profile:
    """Slow triangle 0 → peak → 0 over ``duration_s``, for the static map (paper Fig. 8)."""
    half = duration_s / 2.0
    return lambda t: peak_a * np.clip(1.0 - np.abs(t - half) / half, 0.0, 1.0)


def applies_and_releases(levels_a: tuple[float, ...], hold_s: float = 3.0,
                         apart_s: float = 3.0, first_s: float = 2.0) -> Profile:
    """A valve's step test on a bench: from rest, each level applied for ``hold_s`` and
    released for ``apart_s``, the first at ``first_s``."""
    period = hold_s + apart_s

    def profile(t: np.ndarray) -> np.ndarray:
        current = np.zeros_like(t)
        for k, level in enumerate(levels_a):
            start = first_s + period * k
            current[(t >= start) & (t < start + hold_s)] = level
        return current

    return profile


def steps(levels_a: tuple[float, ...] = (0.2, 0.5, 0.8, 0.35), hold_s: float = 2.0) -> Profile:
    """A staircase of current steps, each held ``hold_s`` (paper Fig. 9 left)."""
    levels = np.asarray(levels_a, dtype=float)

    def profile(t: np.ndarray) -> np.ndarray:
        return levels[np.clip((t // hold_s).astype(int), 0, levels.size - 1)]

    return profile


def sine_sweep(f0_hz: float = 0.5, f1_hz: float = 100.0, duration_s: float = 20.0,
               mean_a: float = 0.5, amplitude_a: float = 0.15) -> Profile:
    """Logarithmic sine sweep f0 → f1 around ``mean_a`` (paper Fig. 9 right)."""
    def profile(t: np.ndarray) -> np.ndarray:
        import scipy.signal  # here: the CLI's parser reads this module, and scipy costs ~1 s

        tt = np.clip(t, 0.0, duration_s)
        wave = scipy.signal.chirp(tt, f0_hz, duration_s, f1_hz, method="logarithmic", phi=-90)
        return mean_a + amplitude_a * wave

    return profile


def oscillating(high_a: float, depth_a: float, frequency_hz: float) -> Profile:
    """Current at ``high_a`` with periodic releases of ``depth_a`` (paper Fig. 14)."""
    return lambda t: high_a - depth_a * 0.5 * (1.0 - np.cos(2.0 * np.pi * frequency_hz * t))


OSC_LOW = {"high_a": 0.75, "depth_a": 0.35, "frequency_hz": 2.0}
"""Deep low-frequency releases (paper Fig. 14a)."""
OSC_HIGH = {"high_a": 0.70, "depth_a": 0.12, "frequency_hz": 6.0}
"""Shallow high-frequency releases (paper Fig. 14b)."""


def steps_then_sweep() -> Profile:
    """Actuator identification input: current steps, then the 0.5 → 100 Hz sweep."""
    stair, sweep, t_sweep = steps(), sine_sweep(), 8.0
    return lambda t: np.where(t < t_sweep, stair(t), sweep(t - t_sweep))


BRAKE_ON_CURRENT_A = 0.01
"""A valve current above this is a brake command (the dead-band is ~0.1 A; 10 mA stays
clear of logging noise and of the zero current before braking)."""


BRAKE_ON_NOISE_FACTOR = 5.0
BRAKE_ON_CEILING_A = 0.05  # half the valve's dead-band: a command below it does nothing
NOISY_CURRENT_A = 5e-4  # a logged current noisier than this is denoised ...
COMMAND_MEDIAN_S = 0.021  # ... by a running median this long (keeps a command's edges) ...
MEDIAN_GAIN = 1.2533  # ... whose σ on white noise is this / √(samples)
DEFAULT_RATE_HZ = 1000.0


def current_noise_a(current_a: np.ndarray) -> float:
    """Standard deviation of the white noise on a logged current [A], from the median
    absolute first difference (robust to the command's own steps and ramps)."""
    steps = np.diff(np.asarray(current_a, dtype=float))
    if steps.size < 2:
        return 0.0
    return float(1.4826 * np.median(np.abs(steps - np.median(steps))) / np.sqrt(2.0))


def median_samples(rate_hz: float) -> int:
    """The running median's width at ``rate_hz``: COMMAND_MEDIAN_S, an odd count of at least
    3 samples (21 samples at 200 Hz flattened a 6 Hz command and made a null campaign's
    pressure show a 'line')."""
    return max(3, 2 * round(COMMAND_MEDIAN_S * rate_hz / 2) + 1)


def denoised_command(current_a: np.ndarray, rate_hz: float = DEFAULT_RATE_HZ
                     ) -> tuple[np.ndarray, float]:
    """The command behind a logged current and the σ of the noise left in it [A].

    A log noisier than 0.5 mA gets a running median of 21 ms (:func:`median_samples` at
    the log's ``rate_hz``): brake commands are held levels, steps and releases, whose edges
    a median keeps where a low-pass would smear them. A clean log is returned as it is."""
    current = np.asarray(current_a, dtype=float)
    noise = current_noise_a(current)
    if noise <= NOISY_CURRENT_A:
        return current, noise
    import scipy.ndimage  # here, as scipy.signal above

    command = scipy.ndimage.median_filter(current, size=median_samples(rate_hz),
                                          mode="nearest")
    return command, leftover_noise_a(noise, rate_hz)


def leftover_noise_a(noise_a: float, rate_hz: float = DEFAULT_RATE_HZ) -> float:
    """The σ [A] of a log's white noise ``noise_a`` left in the command
    :func:`denoised_command` makes of it: all of it in a clean log, the running median's
    share in a noisy one."""
    if noise_a <= NOISY_CURRENT_A:
        return noise_a
    return noise_a * MEDIAN_GAIN / np.sqrt(median_samples(rate_hz))


def brake_start_index(current_a: np.ndarray, rate_hz: float = DEFAULT_RATE_HZ) -> int | None:
    """Index of the first sample whose current commands the brake, or None if none does.

    A command is a current above 10 mA, or above 5 σ of the logging noise where the log is
    noisier (on the denoised command, :func:`denoised_command`; capped at 50 mA), so that
    noise alone never starts a braking and noise does not delay the start."""
    on = np.flatnonzero(commanded(current_a, rate_hz))
    return int(on[0]) if on.size else None


def commanded(current_a: np.ndarray, rate_hz: float = DEFAULT_RATE_HZ) -> np.ndarray:
    """The samples whose current commands the brake (mask (n,)): see
    :func:`brake_start_index`."""
    current, noise = denoised_command(current_a, rate_hz)
    threshold = min(max(BRAKE_ON_CURRENT_A, BRAKE_ON_NOISE_FACTOR * noise), BRAKE_ON_CEILING_A)
    return current > threshold


def logged_to_held(current_logged_a: np.ndarray) -> np.ndarray:
    """Model input from a logged current.

    In a run log (CSV row, bag sample) the current at t_k is the command in force
    over the interval that *ends* at t_k, so the pressure sampled at t_k already
    reflects it (rig loggers and the example campaigns follow this). The model
    holds sample k over [t_k, t_{k+1}): shift by one sample.
    """
    logged = np.asarray(current_logged_a, dtype=float)
    return np.concatenate([logged[1:], logged[-1:]])


def held_to_logged(current_held_a: np.ndarray) -> np.ndarray:
    """Inverse of :func:`logged_to_held`: the current as a run log shows it."""
    held = np.asarray(current_held_a, dtype=float)
    return np.concatenate([held[:1], held[:-1]])


def from_samples(time_s: np.ndarray, current_a: np.ndarray, name: str = "file") -> Profile:
    """A recorded current, held between samples (zero-order hold), last value after the end."""
    times = np.asarray(time_s, dtype=float)
    values = np.asarray(current_a, dtype=float)
    if times.size < 2 or np.any(np.diff(times) <= 0):
        raise ScenarioError(f"{name}: time must be strictly increasing with >= 2 samples")
    if not np.all(np.isfinite(values)):
        raise ScenarioError(f"{name}: the current has NaN or infinite values")

    def profile(t: np.ndarray) -> np.ndarray:
        idx = np.searchsorted(times - times[0], t + 1e-9, side="right") - 1
        return values[np.clip(idx, 0, values.size - 1)]

    return profile


def from_run(run: Run) -> tuple[Profile, float]:
    """The recorded current of a run as a profile (held as the valve saw it), and the run's
    duration [s]."""
    profile = from_samples(run.time_s, logged_to_held(run.current_a), run.source or run.name)
    return profile, float(run.time_s[-1] - run.time_s[0]) + 1.0 / run.rate_hz


# --- scenarios ------------------------------------------------------------------------

def current_for_pressure(params: RigParameters, pressure_pa: float) -> float:
    """Valve current whose static-map pressure is ``pressure_pa`` (inverse of the map)."""
    k1, k2 = params.number(K.ACTUATOR_MAP_K1_PA_PER_A), params.number(K.ACTUATOR_MAP_K2_PA_PER_A2)
    p_max = params.number(K.ACTUATOR_MAX_PRESSURE_PA)
    if not 0.0 <= pressure_pa <= p_max:
        raise ScenarioError(f"pressure {pressure_pa / PA_PER_BAR:g} bar is outside the valve "
                            f"range 0..{p_max / PA_PER_BAR:g} bar")
    target = pressure_pa / params.number(K.ACTUATOR_GAIN)
    if params.number(K.ACTUATOR_EXTRA_MAP_PA_PER_A3) or any(
            params.number(coeff) for _, coeff in K.MAP_TERMS):
        current = _map_root(params, target)
    else:
        excess = target / k1 if k2 == 0 else (
            -k1 + math.sqrt(k1 * k1 + 4 * k2 * target)) / (2 * k2)
        current = params.number(K.ACTUATOR_DEADBAND_CURRENT_A) + excess
    if current > params.number(K.ACTUATOR_MAX_CURRENT_A):
        raise ScenarioError(f"pressure {pressure_pa / PA_PER_BAR:g} bar needs more than the "
                            f"valve's {params.number('actuator.max_current_a'):g} A")
    return current


def _map_root(params: RigParameters, target_pa: float) -> float:
    """The current [A] at which the model's own static map (its cubic term and slot
    included: no closed-form inverse) first reaches ``target_pa``, bracketed on a grid of
    the valve's range (inf: it never does)."""
    import scipy.optimize  # here, as scipy.signal in sine_sweep: 0.6 s of a command's start

    from landing_gear_sim.model import elements as el  # numba: loaded for a bent map only

    p = params.vector()

    def error(current_a: float) -> float:
        return float(el.valve_static_pressure(p, current_a)) - target_pa

    grid = np.linspace(params.number(K.ACTUATOR_DEADBAND_CURRENT_A),
                       params.number(K.ACTUATOR_MAX_CURRENT_A), 1001)
    above = np.flatnonzero(np.array([error(c) for c in grid]) >= 0.0)
    if above.size == 0:
        return math.inf
    if above[0] == 0:
        return float(grid[0])
    return float(scipy.optimize.brentq(error, grid[above[0] - 1], grid[above[0]]))


def rig_test(params: RigParameters, braking: Profile, name: str = "rig_test",
             rate_hz: float | None = None) -> Scenario:
    """The rig procedure: flywheel at v0, touch-down with load ramp, spin-up, braking.

    The current is 0 until ``rig_test.brake_start_s``, then follows ``braking``
    (time measured from the braking start), ramped in over ``rig_test.brake_ramp_s``.
    The run ends when the flywheel falls below ``rig_test.stop_speed_m_s`` or after
    ``rig_test.max_duration_s``.
    """
    rate = rate_hz or params.number(K.SIMULATION_OUTPUT_RATE_HZ)
    t = sample_times(params.number(K.RIG_TEST_MAX_DURATION_S), rate)
    since = t - params.number(K.RIG_TEST_BRAKE_START_S)
    ramp_s = params.number(K.RIG_TEST_BRAKE_RAMP_S)
    ramp = np.clip(since / ramp_s, 0.0, 1.0) if ramp_s > 0 else (since >= 0).astype(float)
    current = np.where(since >= 0, braking(np.maximum(since, 0.0)) * ramp, 0.0)
    return Scenario(name, current, rate, True, params.number(K.RIG_TEST_INITIAL_SPEED_M_S),
                    params.number(K.RIG_TEST_STOP_SPEED_M_S), "rig test, braking profile")


def actuator_test(params: RigParameters, profile: Profile, duration_s: float,
                  name: str = "actuator_test", rate_hz: float | None = None) -> Scenario:
    """Wheel off the flywheel: only the valve and brake pressure respond."""
    rate = rate_hz or params.number(K.SIMULATION_OUTPUT_RATE_HZ)
    current = profile(sample_times(duration_s, rate))
    return Scenario(name, current, rate, False, 0.0, 0.0, "actuator-only test")


def constant_pressure_test(params: RigParameters, pressure_pa: float,
                           rate_hz: float | None = None) -> Scenario:
    """Rig test braking at the current that gives ``pressure_pa`` in steady state."""
    level = current_for_pressure(params, pressure_pa)
    name = f"brake_const_{pressure_pa / PA_PER_BAR:g}bar"
    return rig_test(params, constant(level), name, rate_hz)
