"""Braking runs (paper Section IV-D): their filtered signals, the rolling radius from free
rolling, the brake gain (and fade) from the wheel's torque balance r F_x − J_w ω̇ = k_b P
(the flywheel's balance: :mod:`~landing_gear_sim.calibration.flywheel`). Signals are
low-passed (zero phase) first."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.signal
from scipy.optimize import least_squares

from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.slots import Slot, signals
from landing_gear_sim.calibration.statistics import (
    Estimate,
    covariance_std,
    linear_std,
    sample_weights,
)
from landing_gear_sim.errors import IdentificationError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.elements import (
    brake_torques,
    fade_factor,
    slip_ratio,
    wheel_extra_torque,
)
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import rim_speed_m_s, rolling_radius_at
from landing_gear_sim.model.sensors import SensorModel
from msg_tools.checks import too_short
from msg_tools.units import PA_PER_BAR

FILTER_HZ = 20.0  # zero-phase low-pass before differentiating speeds
LOADED_N = 5e3  # the wheel is on the flywheel
GAIN_UNIT = 1e-3  # the fade fit works with k_b in N m/kPa (order 1), torques in 100 N m
TORQUE_UNIT_N_M = 100.0
STEADY_RATE_RAD_S2 = 100.0  # a braked wheel decelerates at ~30 rad/s²; lock onsets far faster


@dataclass(frozen=True)
class Braking:
    """Filtered signals of one braking run, SI, on the run's clock from its first sample."""

    run: ClassifiedRun
    time_s: np.ndarray
    speed_m_s: np.ndarray
    wheel: np.ndarray
    wheel_rate: np.ndarray
    pressure: np.ndarray
    load: np.ndarray
    force: np.ndarray
    start_s: float

    @property
    def uniform_time_s(self) -> np.ndarray:
        """The nominal sample instants k/rate (for filters that need an even grid)."""
        return np.arange(self.time_s.size) / self.run.rate_hz


def lowpass(values: np.ndarray, rate_hz: float, cutoff_hz: float = FILTER_HZ) -> np.ndarray:
    sos = scipy.signal.butter(4, cutoff_hz / (rate_hz / 2), output="sos")
    return scipy.signal.sosfiltfilt(sos, values)


def prepare(run: ClassifiedRun, p: RigParameters) -> Braking:
    """The filtered signals of a braking run under the parameter set ``p``."""
    if (short := too_short(run, "a braking run's filters")) is not None:
        raise IdentificationError(short)  # the zero-phase filter's padding (a traceback once)
    rate = run.rate_hz
    wheel = lowpass(run.wheel_speed_rad_s, rate)
    sensors = SensorModel.of(p)
    return Braking(
        run=run, time_s=run.time_s - run.time_s[0],
        speed_m_s=rim_speed_m_s(p, lowpass(run.flywheel_speed_rad_s, rate)),
        wheel=wheel, wheel_rate=np.gradient(wheel, 1.0 / rate),
        pressure=lowpass(sensors.true_pressure(run.pressure_pa, run_time_s(run)), rate),
        load=lowpass(run.vertical_load_n, rate),
        force=lowpass(sensors.true_longitudinal(run.longitudinal_force_n,
                                                run.vertical_load_n, run_time_s(run)), rate),
        start_s=run.brake_start_s - float(run.time_s[0]),
    )


def in_step(b: Braking, p: RigParameters) -> Braking:
    """``b`` with its pressure taken back by the model's delay of the pressure channel (the
    pressure that made the torque at each sample; ``b`` itself when the channel is in
    step)."""
    delay = SensorModel.of(p).pressure_delay_s
    if delay <= 0.0:
        return b
    return dataclasses.replace(b, pressure=np.interp(b.time_s + delay, b.time_s, b.pressure))


def run_time_s(run: ClassifiedRun) -> np.ndarray:
    """Each sample's time since the run's first [s] (a channel that drifts counts it)."""
    return run.time_s - run.time_s[0]


def free_rolling_excess(b: Braking, params: RigParameters) -> tuple[np.ndarray, np.ndarray]:
    """The samples before the brake acts (mask), and the F_x there (the model's crosstalk
    taken off the reading) less what the wheel's balance asks of the tyre with no brake,
    (J_w ω̇ + T_extra)/r [N]: what the load cell reads beyond the physics."""
    m = free_rolling(b)
    resisted, _ = wheel_resisted(b, params)
    force = SensorModel.of(params).true_longitudinal(b.run.longitudinal_force_n[m],
                                                     b.run.vertical_load_n[m],
                                                     run_time_s(b.run)[m])
    return m, force - resisted[m] / rolling_radius_at(params, b.load[m])


def slip(b: Braking, p: RigParameters) -> np.ndarray:
    """The slip of the filtered signals (the unloaded radius), (n,)."""
    return slip_ratio(b.speed_m_s, b.wheel, p.number(K.WHEEL_UNLOADED_RADIUS_M))


def free_rolling(b: Braking) -> np.ndarray:
    """Samples after touch-down settled and before the brake acts."""
    return (b.time_s > b.start_s - 1.0) & (b.time_s < b.start_s - 0.05) & (b.load > LOADED_N)


def hub_speed(b: Braking, p: RigParameters) -> np.ndarray:
    """v_h = v_f − L θ̇, θ from the measured F_x through the gear's spring-damper (eq. 6)."""
    if not p.has("gear_walk"):
        return b.speed_m_s
    length = p.number(K.GEAR_WALK_LENGTH_M)
    system = ([length, 0.0], [p.number(K.GEAR_WALK_INERTIA_KG_M2),
                              p.number(K.GEAR_WALK_DAMPING_N_M_S_PER_RAD),
                              p.number(K.GEAR_WALK_STIFFNESS_N_M_PER_RAD)])
    # lsim's linear interpolation of the input, as a digital filter: lsim steps its state in
    # a Python loop, ~40x slower on a run of 10^5 samples
    numerator, denominator, _ = scipy.signal.cont2discrete(system, 1.0 / b.run.rate_hz,
                                                           method="foh")
    rate = scipy.signal.lfilter(np.ravel(numerator), denominator, b.force)
    return b.speed_m_s - length * rate


def fit_unloaded_radius(runs: Sequence[Braking], p: RigParameters) -> Estimate:
    """r0 from free rolling (λ = 0): r = v/ω at the load of that phase."""
    values = []
    for b in runs:
        m = free_rolling(b)
        if m.sum() > 50:
            r_eff = np.mean(b.speed_m_s[m]) / np.mean(b.wheel[m])
            values.append(r_eff + (p.number(K.WHEEL_UNLOADED_RADIUS_M)
                                   - float(np.mean(rolling_radius_at(p, b.load[m])))))
    if not values:
        raise IdentificationError("no free-rolling phase before braking")
    std = float(np.std(values) / math.sqrt(len(values))) if len(values) > 1 else float("nan")
    return Estimate(K.WHEEL_UNLOADED_RADIUS_M, float(np.mean(values)), std,
                    tuple(b.run.name for b in runs), "free rolling v/ω, a and b kept")


def torque_balance(b: Braking, p: RigParameters) -> tuple[np.ndarray, np.ndarray]:
    """The brake torque T_b the wheel's balance J_w ω̇ = r F_x − T_b − T_extra measures at
    each sample of ``b`` [N m], and the energy the brake absorbed, ∫ T_b ω dt [J]. The one
    reading of the wheel's balance from measured signals: the calibration's gain, the
    diagnosis's wheel error and library, the free rolling's F_x and the disc's run-out all
    read it."""
    pushed, resisted, energy = _wheel_torques(b, p)
    return pushed - resisted, energy


def wheel_resisted(b: Braking, p: RigParameters) -> tuple[np.ndarray, np.ndarray]:
    """What the wheel's balance takes off r F_x beside the brake, J_w ω̇ + T_extra [N m]
    (T_extra: the wheel's named slot and its generic slot of ``p``, 0 unless a diagnosis
    found a term), and the energy the brake absorbed [J]."""
    _, resisted, energy = _wheel_torques(b, p)
    return resisted, energy


def _wheel_torques(b: Braking, p: RigParameters
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The wheel's balance at each sample of ``b``: the torque the tyre pushes, r F_x, what
    it takes off beside the brake, J_w ω̇ + T_extra [N m], and the energy the brake absorbed
    [J] (a term of the generic slot may read it: taken from the torque without that slot)."""
    pushed = rolling_radius_at(p, b.load) * b.force
    resisted = p.number(K.WHEEL_INERTIA_KG_M2) * b.wheel_rate \
        + wheel_extra_torque(p.vector(), b.wheel)
    energy = _absorbed(b, pushed - resisted)
    if Slot.WHEEL.occupied(p):
        resisted = resisted + Slot.WHEEL.value_of(p, measured_signals(b, p, energy))
        energy = _absorbed(b, pushed - resisted)
    return pushed, resisted, energy


def _absorbed(b: Braking, torque: np.ndarray) -> np.ndarray:
    """The energy a brake of ``torque`` absorbed since just before it acts [J]."""
    dt = np.diff(b.time_s, prepend=b.time_s[0])
    power = np.where(b.time_s > b.start_s - 0.1, np.clip(torque, 0, None), 0.0) \
        * np.clip(b.wheel, 0, None)
    return np.cumsum(power * dt)


def measured_signals(b: Braking, p: RigParameters, energy: np.ndarray) -> np.ndarray:
    """The signals of the equations' slots (:func:`~.slots.signals`) from ``b``'s filtered
    ones and the brake's absorbed ``energy``."""
    return signals(b.time_s, b.wheel, b.speed_m_s, b.pressure, b.load, energy, p)


def model_torque(b: Braking, p: RigParameters, energy: np.ndarray, mask: np.ndarray
                 ) -> np.ndarray:
    """The brake torque the model ``p`` gives the samples ``mask`` of ``b`` [N m]: its whole
    gain law (fade at the absorbed ``energy``, slopes in speed and pressure, the run's drift),
    through the plant's own law; a disc's run-out left out (it averages out over a
    revolution; :mod:`~landing_gear_sim.calibration.wheel_angle` reads it)."""
    pressure = np.ascontiguousarray(b.pressure[mask])
    torque = brake_torques(_without_runout(p).vector(), pressure,
                           np.ascontiguousarray(energy[mask]),
                           np.ascontiguousarray(b.wheel[mask]), np.zeros_like(pressure))
    return torque * (1.0 + p.number(K.BRAKE_GAIN_DRIFT_PER_RUN) * b.run.campaign_order)


RUNOUT_AMPLITUDES = (K.BRAKE_RUNOUT_1, K.BRAKE_RUNOUT_2)


def _without_runout(p: RigParameters) -> RigParameters:
    if all(p.number(k) == 0.0 for k in RUNOUT_AMPLITUDES):
        return p
    return p.replace(dict.fromkeys(RUNOUT_AMPLITUDES, 0.0), "run-out left out")


def braking_samples(b: Braking) -> np.ndarray:
    """Samples where the torque balance measures the brake (mask (n,)): braking settled,
    pressure over 3 bar, the wheel turning and loaded."""
    return ((b.time_s > b.start_s + 0.2) & (b.pressure > 3 * PA_PER_BAR) & (b.wheel > 5.0)
            & (b.load > LOADED_N))


def steady_braking_samples(b: Braking) -> np.ndarray:
    """:func:`braking_samples` away from wheel-lock transients (|ω̇| < STEADY_RATE_RAD_S2),
    where the filtered derivative's error would dominate a local look at the gain."""
    return braking_samples(b) & (np.abs(b.wheel_rate) < STEADY_RATE_RAD_S2)


def fit_brake_gain(runs: Sequence[Braking], p: RigParameters) -> list[Estimate]:
    """k_b from the wheel torque balance r F_x − J_w ω̇ = k_b P (least squares).

    When the model has brake fade, k_b, φ, E_f and the shape s of k_b (1 − φ g(E/E_f)) P
    (:func:`~landing_gear_sim.model.elements.fade_factor`) are fitted together, E the energy
    absorbed so far (measured by the same balance).
    """
    torque, pressure, energy = [], [], []
    for b in runs:
        whole, absorbed = torque_balance(b, p)
        m = braking_samples(b)
        torque.append(whole[m])
        pressure.append(b.pressure[m])
        energy.append(absorbed[m])
    weight = sample_weights(torque)
    # a weighted row of r F_x − J_w ω̇ = k_b f(E) P: torque and pressure scaled, E as it is
    t, pr = (np.concatenate(column) * weight for column in (torque, pressure))
    e = np.concatenate(energy)
    names = tuple(b.run.name for b in runs)
    if not p.has("brake_fade"):
        gain = float(pr @ t / (pr @ pr))
        gain_std = float(linear_std(pr[:, None], t - gain * pr, 1)[0])
        return [Estimate(K.BRAKE_GAIN_N_M_PER_PA, gain, gain_std, names, "wheel torque balance")]
    keys = (K.BRAKE_GAIN_N_M_PER_PA, K.BRAKE_FADE_FRACTION, K.BRAKE_FADE_ENERGY_J,
            K.BRAKE_FADE_SHAPE)

    def residual(theta: np.ndarray) -> np.ndarray:
        gain, fraction, log_energy, shape = theta
        fade = fade_factor(fraction, e, math.exp(log_energy), shape)
        return (gain * GAIN_UNIT * fade * pr - t) / TORQUE_UNIT_N_M

    start = [p.number(keys[0]) / GAIN_UNIT, p.number(keys[1]), math.log(p.number(keys[2]))]
    bounds = ([1e-3, 0.0, math.log(1e3), 0.0], [1e2, 0.95, math.log(1e9), 1.0])
    # the shape's two ends: a fade's first slope fits either, its bend tells them apart
    fit = min((least_squares(residual, [*start, shape], bounds=bounds) for shape in (0.0, 1.0)),
              key=lambda f: f.cost)
    std = covariance_std(fit, len(keys))
    k_b, fraction, log_energy, shape = fit.x
    method = "wheel torque balance with fade"
    return [Estimate(keys[0], k_b * GAIN_UNIT, std[0] * GAIN_UNIT, names, method),
            Estimate(keys[1], fraction, std[1], names, method),
            Estimate(keys[2], math.exp(log_energy), math.exp(log_energy) * std[2], names,
                     method),
            Estimate(keys[3], shape, std[3], names, method)]
