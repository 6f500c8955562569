"""Identification of the rig model from a campaign (paper Sections IV-C, IV-D).

Each step uses the runs that carry its information and returns estimates with a
1-σ uncertainty and the runs they came from:

* runs are classified from their signals (actuator-only ramp or dynamic; braking
  at constant or oscillating current);
* valve static map (dead-band, k1, k2, saturation) from the quasi-static ramp;
* A(s) from steps + sweep: H1 frequency response with coherence (Welch), a
  2nd-order fit to it, refined by an output-error fit in the time domain;
* unloaded rolling radius from free rolling before braking (a, b kept: one load);
* flywheel inertia and drag from the flywheel's momentum balance;
* brake gain from the wheel's torque balance r F_x − J_w ω̇ = k_b P;
* Burckhardt ϑ1..ϑ3 from slip (eq. 1) and μ = F_x/F_z (eq. 4), optionally ϑ3 fixed.

No plotting here (see :mod:`landing_gear_sim.report.validation`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.signal
from numba import njit
from scipy.optimize import least_squares

from landing_gear_sim.errors import ParameterError
from landing_gear_sim.model import elements as el
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.plant import (
    actuator_matrices,
    actuator_state,
    actuator_step,
    rolling_radius_at,
)
from landing_gear_sim.model.scenario import logged_to_held
from msg_tools.run import Run

FILTER_HZ = 20.0  # zero-phase low-pass before differentiating speeds
REFINE_BOUNDS = (0.2, 5.0)  # output-error refinement stays within these factors of the start
Progress = Callable[[str], None]


@dataclass(frozen=True)
class Estimate:
    """One identified parameter: value and 1-σ uncertainty in SI, where it came from."""

    key: str
    value: float
    std: float
    runs: tuple[str, ...]
    method: str


@dataclass(frozen=True)
class FrfEstimate:
    """Empirical actuator frequency response (static-map pressure → measured pressure)."""

    frequency_hz: np.ndarray
    response: np.ndarray  # complex H1
    coherence: np.ndarray
    fitted: np.ndarray  # the fitted 2nd-order model at the same frequencies


@dataclass(frozen=True)
class Identification:
    """Result of :func:`identify`: the calibrated set and the evidence behind it."""

    params: RigParameters
    estimates: tuple[Estimate, ...]
    classes: dict[str, str]
    problems: tuple[str, ...] = ()
    frf: FrfEstimate | None = None
    friction_points: tuple[np.ndarray, np.ndarray] | None = None  # slip, μ samples


# --- classification --------------------------------------------------------------------

def classify(run: Run) -> str:
    """``actuator_ramp``, ``actuator_dynamic``, ``brake_constant`` or ``brake_oscillating``."""
    if np.max(run.flywheel_speed_rad_s) < 1.0 and np.max(np.abs(run.vertical_load_n)) < 2e3:
        slow = np.max(np.abs(np.diff(run.current_a))) < 2e-3
        return "actuator_ramp" if slow and np.ptp(run.current_a) > 0.5 else "actuator_dynamic"
    start = brake_start_s(run)
    settled = run.time_s > start + 0.3
    if settled.sum() < 10:
        return "brake_constant"
    return "brake_constant" if np.std(run.current_a[settled]) < 5e-3 else "brake_oscillating"


def brake_start_s(run: Run) -> float:
    """First instant the valve current is commanded (or the run's end if never)."""
    on = np.flatnonzero(run.current_a > 0.01)
    return float(run.time_s[on[0]]) if on.size else float(run.time_s[-1])


def _lowpass(values: np.ndarray, rate_hz: float, cutoff_hz: float = FILTER_HZ) -> np.ndarray:
    sos = scipy.signal.butter(4, cutoff_hz / (rate_hz / 2), output="sos")
    return scipy.signal.sosfiltfilt(sos, values)


def _correlation_inflation(residual: np.ndarray) -> float:
    """Variance factor (1 + ρ)/(1 − ρ) for residuals with lag-1 correlation ρ (AR(1)).

    Residuals of simulations and integrated balances are smooth; counting every
    sample as independent would claim far too small an uncertainty.
    """
    centred = residual - residual.mean()
    rho = float(centred[1:] @ centred[:-1] / max(float(centred @ centred), 1e-300))
    return (1 + rho) / (1 - rho) if 0 < rho < 1 else 1.0


def covariance_std(result: object, n_params: int) -> np.ndarray:
    """1-σ from a least_squares result: σ² (JᵀJ)⁻¹, σ² from the (correlated) residuals."""
    jac, residual = result.jac, result.fun  # type: ignore[attr-defined]
    return _linear_std(jac, residual, n_params)


def _linear_std(design: np.ndarray, residual: np.ndarray, n_params: int) -> np.ndarray:
    """1-σ of a least-squares fit with regressors ``design`` and ``residual`` left over."""
    sigma2 = float(residual @ residual) / max(residual.size - n_params, 1)
    cov = np.linalg.pinv(design.T @ design) * sigma2 * _correlation_inflation(residual)
    return np.sqrt(np.clip(np.diag(cov), 0.0, None))


# --- actuator ---------------------------------------------------------------------------

def true_pressure(pressure_pa: np.ndarray, p: RigParameters) -> np.ndarray:
    """The brake pressure behind a reading: less the sensor offset when the model has one."""
    if not p.has("pressure_sensor_offset"):
        return pressure_pa
    return pressure_pa - p.number("sensors.pressure_offset_pa")


def fit_static_map(runs: Sequence[Run], p: RigParameters) -> list[Estimate]:
    """Dead-band, k1, k2, saturation from quasi-static ramps (paper Fig. 8)."""
    current = np.concatenate([r.current_a for r in runs])
    pressure = true_pressure(np.concatenate([r.pressure_pa for r in runs]), p)
    keys = ("actuator.deadband_current_a", "actuator.map_k1_pa_per_a",
            "actuator.map_k2_pa_per_a2", "actuator.max_pressure_pa")
    scale = np.array([p.number(k) or 1.0 for k in keys])
    scale[0] = max(scale[0], 0.05)

    def model(theta: np.ndarray) -> np.ndarray:
        i0, k1, k2, p_max = theta * scale
        excess = np.maximum(current - i0, 0.0)
        return np.minimum(k1 * excess + k2 * excess ** 2, p_max)

    start = np.array([p.number(k) for k in keys]) / scale
    fit = least_squares(lambda th: (model(th) - pressure) / 1e5, start, x_scale="jac")
    std = covariance_std(fit, 4) * scale
    names = tuple(r.name for r in runs)
    return [Estimate(k, float(v), float(s), names, "static-map least squares")
            for k, v, s in zip(keys, fit.x * scale, std, strict=True)]


@njit(cache=True)
def _actuator_response(p, matrices, current):
    """Pressure for a held current sequence, starting in steady state at the first current."""
    xa = actuator_state(matrices)
    xa[0] = actuator_step(p, matrices, xa, current[0])
    for _ in range(100000):  # settle on the first level (A(s) is stable)
        before = xa[0]
        actuator_step(p, matrices, xa, current[0])
        if abs(xa[0] - before) < 1e-9 and abs(xa[1]) < 1e-6:
            break
    out = np.empty(current.size)
    out[0] = xa[0]
    for k in range(current.size - 1):
        out[k + 1] = actuator_step(p, matrices, xa, current[k])
    return out


def actuator_pressure(params: RigParameters, current_a: np.ndarray, rate_hz: float
                      ) -> np.ndarray:
    """Model pressure [Pa] for a held current sequence, from steady state at the first level."""
    vector = params.vector()
    return _actuator_response(vector, actuator_matrices(vector, 1.0 / rate_hz), current_a)


def frequency_response_estimate(run: Run, params: RigParameters
                                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """H1 = P_yu/P_uu and coherence, u = static-map pressure, y = measured pressure."""
    vector = params.vector()
    u = np.array([el.valve_static_pressure(vector, i) for i in run.current_a])
    y = run.pressure_pa
    fs = run.rate_hz
    nperseg = min(4096, u.size // 4)
    f, puu = scipy.signal.welch(u - u.mean(), fs, nperseg=nperseg)
    _, pyu = scipy.signal.csd(u - u.mean(), y - y.mean(), fs, nperseg=nperseg)
    _, coherence = scipy.signal.coherence(u, y, fs, nperseg=nperseg)
    with np.errstate(divide="ignore", invalid="ignore"):
        h1 = pyu / puu  # scipy's csd(u, y) is already the cross-spectrum of H1
    return f, h1, coherence


def second_order(frequency_hz: np.ndarray, wn: float, zeta: float, gain: float) -> np.ndarray:
    """μ ω_n² / (s² + 2 ξ ω_n s + ω_n²) at s = j 2π f."""
    s = 2j * np.pi * frequency_hz
    return gain * wn * wn / (s * s + 2 * zeta * wn * s + wn * wn)


def fit_actuator_dynamics(runs: Sequence[Run], p: RigParameters
                          ) -> tuple[list[Estimate], FrfEstimate]:
    """ω_n and ξ of A(s): FRF fit for a start, then output error on the measured pressure."""
    run = max(runs, key=len)
    f, h1, coherence = frequency_response_estimate(run, p)
    band = (f >= 0.5) & (f <= 100.0) & (coherence > 0.8) & np.isfinite(h1)
    wn0 = 2 * math.pi * p.number("actuator.natural_frequency_hz")
    zeta0 = p.number("actuator.damping_ratio")

    weight = np.sqrt(coherence[band])

    def frf_residual(theta: np.ndarray) -> np.ndarray:
        diff = (second_order(f[band], theta[0] * wn0, theta[1], 1.0) - h1[band]) * weight
        return np.concatenate([diff.real, diff.imag])

    frf_fit = least_squares(frf_residual, [1.0, zeta0], bounds=([0.1, 0.05], [10.0, 3.0]))
    wn_frf, zeta_frf = frf_fit.x[0] * wn0, frf_fit.x[1]

    def time_residual(theta: np.ndarray) -> np.ndarray:
        trial = p.replace({"actuator.natural_frequency_hz": theta[0] / (2 * math.pi),
                           "actuator.damping_ratio": theta[1]})
        model = actuator_pressure(trial, logged_to_held(run.current_a), run.rate_hz)
        return (model - run.pressure_pa) / 1e5

    fit = least_squares(time_residual, [wn_frf, zeta_frf], x_scale=[wn_frf, 0.1],
                        bounds=([1.0, 0.05], [2000.0, 3.0]))
    std = covariance_std(fit, 2)
    names = (run.name,)
    estimates = [
        Estimate("actuator.natural_frequency_hz", fit.x[0] / (2 * math.pi),
                 std[0] / (2 * math.pi), names,
                 f"output error on pressure (FRF fit gave {wn_frf / (2 * math.pi):.2f} Hz)"),
        Estimate("actuator.damping_ratio", fit.x[1], std[1], names,
                 f"output error on pressure (FRF fit gave {zeta_frf:.3f})"),
    ]
    frf = FrfEstimate(f, h1, coherence, second_order(f, fit.x[0], fit.x[1], 1.0))
    return estimates, frf


# --- braking runs -----------------------------------------------------------------------

@dataclass(frozen=True)
class _Braking:
    """Filtered signals of one braking run, SI."""

    run: Run
    time_s: np.ndarray
    speed_m_s: np.ndarray
    wheel: np.ndarray
    wheel_rate: np.ndarray
    pressure: np.ndarray
    load: np.ndarray
    force: np.ndarray
    start_s: float


def _braking(run: Run, p: RigParameters) -> _Braking:
    rate = run.rate_hz
    wheel = _lowpass(run.wheel_speed_rad_s, rate)
    return _Braking(
        run=run, time_s=run.time_s - run.time_s[0],
        speed_m_s=_lowpass(run.flywheel_speed_rad_s, rate) * p.number("flywheel.radius_m"),
        wheel=wheel, wheel_rate=np.gradient(wheel, 1.0 / rate),
        pressure=_lowpass(true_pressure(run.pressure_pa, p), rate),
        load=_lowpass(run.vertical_load_n, rate),
        force=_lowpass(run.longitudinal_force_n, rate),
        start_s=brake_start_s(run) - float(run.time_s[0]),
    )


def _free_rolling(b: _Braking) -> np.ndarray:
    """Samples after touch-down settled and before the brake acts."""
    return (b.time_s > b.start_s - 1.0) & (b.time_s < b.start_s - 0.05) & (b.load > 5e3)


def _hub_speed(b: _Braking, p: RigParameters) -> np.ndarray:
    """v_h = v_f − L θ̇, θ from the measured F_x through the gear's spring-damper (eq. 6)."""
    if not p.has("gear_walk"):
        return b.speed_m_s
    length = p.number("gear_walk.length_m")
    system = scipy.signal.lti([length, 0.0], [p.number("gear_walk.inertia_kg_m2"),
                                              p.number("gear_walk.damping_n_m_s_per_rad"),
                                              p.number("gear_walk.stiffness_n_m_per_rad")])
    _, rate, _ = scipy.signal.lsim(system, b.force, b.time_s)
    return b.speed_m_s - length * rate


def fit_unloaded_radius(runs: Sequence[_Braking], p: RigParameters) -> Estimate:
    """r0 from free rolling (λ = 0): r = v/ω at the load of that phase."""
    values = []
    for b in runs:
        m = _free_rolling(b)
        if m.sum() > 50:
            r_eff = np.mean(b.speed_m_s[m]) / np.mean(b.wheel[m])
            values.append(r_eff + (p.number("wheel.unloaded_radius_m")
                                   - float(np.mean(rolling_radius_at(p, b.load[m])))))
    if not values:
        raise ValueError("no free-rolling phase before braking")
    std = float(np.std(values) / math.sqrt(len(values))) if len(values) > 1 else float("nan")
    return Estimate("wheel.unloaded_radius_m", float(np.mean(values)), std,
                    tuple(b.run.name for b in runs), "free rolling v/ω, a and b kept")


def fit_flywheel(runs: Sequence[_Braking], p: RigParameters) -> list[Estimate]:
    """J_f and α_d from the integrated balance M Δv = −∫F_x − α ∫v² (robust to noise).

    Each run gets its own intercept: anchoring a run to one noisy speed sample
    would shift all its rows and bias the drag.
    """
    blocks, targets = [], []
    for b in runs:
        idx = np.flatnonzero((b.time_s > 0.6) & (b.speed_m_s > 5.0))[::10]
        if idx.size < 20:
            continue
        dt = np.diff(b.time_s, prepend=b.time_s[0])
        blocks.append(np.column_stack([-np.cumsum(b.force * dt)[idx],
                                       -np.cumsum(b.speed_m_s ** 2 * dt)[idx]]))
        targets.append(b.speed_m_s[idx])
    if not blocks:
        raise ValueError("no braking run long enough for the flywheel balance")
    offsets = scipy.linalg.block_diag(*[np.ones((len(y), 1)) for y in targets])
    x = np.hstack([np.vstack(blocks), offsets])
    y = np.concatenate(targets)
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)
    std_inv, std_ratio = _linear_std(x, y - x @ coef, x.shape[1])[:2]
    inv_mass, alpha_over_mass = coef[:2]
    mass = 1.0 / inv_mass
    radius = p.number("flywheel.radius_m")
    names = tuple(b.run.name for b in runs)
    alpha = alpha_over_mass * mass
    std_alpha = abs(alpha) * math.hypot(std_ratio / alpha_over_mass, std_inv * mass)
    return [
        Estimate("flywheel.inertia_kg_m2", mass * radius ** 2,
                 mass ** 2 * std_inv * radius ** 2, names, "integrated momentum balance"),
        Estimate("drag.coeff_n_s2_per_m2", float(alpha), float(std_alpha), names,
                 "integrated momentum balance"),
    ]


def _torque_balance(b: _Braking, p: RigParameters) -> tuple[np.ndarray, np.ndarray]:
    """Brake torque r F_x − J_w ω̇ [N m] and the energy the brake absorbed, ∫ T_b ω dt [J]."""
    torque = rolling_radius_at(p, b.load) * b.force - p.number("wheel.inertia_kg_m2") * b.wheel_rate
    dt = np.diff(b.time_s, prepend=b.time_s[0])
    power = np.where(b.time_s > b.start_s - 0.1, np.clip(torque, 0, None), 0.0) \
        * np.clip(b.wheel, 0, None)
    return torque, np.cumsum(power * dt)


def fit_brake_gain(runs: Sequence[_Braking], p: RigParameters) -> list[Estimate]:
    """k_b from the wheel torque balance r F_x − J_w ω̇ = k_b P (least squares).

    When the model has brake fade, k_b, φ and E_f of k_b (1 − φ(1 − e^{−E/E_f})) P are
    fitted together, E the energy absorbed so far (measured by the same balance).
    """
    torque, pressure, energy = [], [], []
    for b in runs:
        whole, absorbed = _torque_balance(b, p)
        m = (b.time_s > b.start_s + 0.2) & (b.pressure > 3e5) & (b.wheel > 5.0) & (b.load > 5e3)
        torque.append(whole[m])
        pressure.append(b.pressure[m])
        energy.append(absorbed[m])
    t, pr, e = np.concatenate(torque), np.concatenate(pressure), np.concatenate(energy)
    names = tuple(b.run.name for b in runs)
    if not p.has("brake_fade"):
        gain = float(pr @ t / (pr @ pr))
        std = float(_linear_std(pr[:, None], t - gain * pr, 1)[0])
        return [Estimate("brake.gain_n_m_per_pa", gain, std, names, "wheel torque balance")]
    keys = ("brake.gain_n_m_per_pa", "brake.fade_fraction", "brake.fade_energy_j")

    def residual(theta: np.ndarray) -> np.ndarray:
        gain, fraction, log_energy = theta
        fade = 1.0 - fraction * (1.0 - np.exp(-e / math.exp(log_energy)))
        return (gain * 1e-3 * fade * pr - t) / 100.0

    start = [p.number(keys[0]) * 1e3, p.number(keys[1]), math.log(p.number(keys[2]))]
    fit = least_squares(residual, start, bounds=([1e-3, 0.0, math.log(1e3)],
                                                 [1e2, 0.95, math.log(1e9)]))
    std = covariance_std(fit, 3)
    gain, fraction, log_energy = fit.x
    method = "wheel torque balance with fade"
    return [Estimate(keys[0], gain * 1e-3, std[0] * 1e-3, names, method),
            Estimate(keys[1], fraction, std[1], names, method),
            Estimate(keys[2], math.exp(log_energy), math.exp(log_energy) * std[2], names,
                     method)]


def friction_samples(runs: Sequence[_Braking], p: RigParameters
                     ) -> tuple[np.ndarray, np.ndarray]:
    """(slip, μ) from eq. (1) and μ = F_x/F_z over the braking phases, decimated to 100 Hz."""
    slips, mus = [], []
    stop = p.number("rig_test.stop_speed_m_s")
    for b in runs:
        m = (b.time_s > b.start_s + 0.3) & (b.speed_m_s > stop + 2.0) & (b.load > 5e3) \
            & (b.wheel > 1.0)
        idx = np.flatnonzero(m)[::10]
        radius = rolling_radius_at(p, b.load[idx])
        slips.append(1.0 - b.wheel[idx] * radius / _hub_speed(b, p)[idx])
        mus.append(b.force[idx] / b.load[idx])
    return np.concatenate(slips), np.concatenate(mus)


def fit_friction(slip: np.ndarray, mu: np.ndarray, p: RigParameters, names: tuple[str, ...],
                 fix_theta3: bool = False) -> list[Estimate]:
    """Burckhardt ϑ1, ϑ2, ϑ3 by nonlinear least squares (ϑ3 optionally fixed, paper [13])."""
    keys = ["friction.theta1", "friction.theta2", "friction.theta3"]
    start = np.array([p.number(k) for k in keys])
    free = 2 if fix_theta3 else 3

    def residual(theta: np.ndarray) -> np.ndarray:
        t1, t2 = theta[0], theta[1]
        t3 = start[2] if fix_theta3 else theta[2]
        return t1 * (1 - np.exp(-t2 * slip)) - t3 * slip - mu

    fit = least_squares(residual, start[:free], x_scale=start[:free],
                        bounds=(np.zeros(free), np.full(free, np.inf)))
    std = covariance_std(fit, free)
    method = "Burckhardt least squares on slip/μ samples" + (" (theta3 fixed)" if fix_theta3
                                                             else "")
    estimates = [Estimate(k, float(v), float(s), names, method)
                 for k, v, s in zip(keys[:free], fit.x, std, strict=True)]
    if fix_theta3:
        estimates.append(Estimate(keys[2], float(start[2]), 0.0, (), "fixed"))
    return estimates


def refine_friction(runs: Sequence[Run], p: RigParameters, jackknife: bool = True
                    ) -> list[Estimate]:
    """Output-error refinement of ϑ1..ϑ3: simulate the braking runs with their measured
    current and fit the wheel speed over the braking phase.

    Open-loop braking rarely leaves the low-slip region, so the direct fit trades ϑ3
    against ϑ1, ϑ2; the wheel-speed response to the slip excursions pins them down.
    """
    from landing_gear_sim.calibration.validate import (  # validate builds on this module
        braking_window,
        simulate_run,
    )

    keys = ("friction.theta1", "friction.theta2", "friction.theta3")
    start = np.array([p.number(k) for k in keys])
    windows = [braking_window(r, p) for r in runs]

    def slip_error(run: Run, window: np.ndarray, trial: RigParameters) -> np.ndarray:
        # wheel-speed error less what the flywheel-speed error explains: a common speed
        # offset (noisy initial speed, drag) is not the friction curve's doing
        simulated = simulate_run(run, trial)[0]
        ratio = trial.number("flywheel.radius_m") / trial.number("wheel.unloaded_radius_m")
        wheel = simulated.wheel_speed_rad_s[window] - run.wheel_speed_rad_s[window]
        flywheel = simulated.flywheel_speed_rad_s[window] - run.flywheel_speed_rad_s[window]
        return (wheel - ratio * flywheel)[::5]

    def residual(theta: np.ndarray, chosen: Sequence[int]) -> np.ndarray:
        trial = p.replace(dict(zip(keys, theta * start, strict=True)), "identify")
        return np.concatenate([slip_error(runs[i], windows[i], trial) for i in chosen])

    fit = least_squares(lambda th: residual(th, range(len(runs))), np.ones(3), diff_step=1e-4,
                        bounds=REFINE_BOUNDS)
    std = covariance_std(fit, 3)
    if jackknife:
        std = np.maximum(std, _jackknife_std(residual, fit.x, len(runs)))
    names = tuple(r.name for r in runs)
    return [Estimate(k, float(v), float(sd), names,
                     "output error on wheel vs flywheel speed; σ: max(residual, jackknife)")
            for k, v, sd in zip(keys, fit.x * start, std * start, strict=True)]


def _jackknife_std(residual: Callable[[np.ndarray, Sequence[int]], np.ndarray],
                   solution: np.ndarray, n_runs: int) -> np.ndarray:
    """Leave-one-run-out spread of the fit: run-to-run variability the residuals hide."""
    if n_runs < 3:
        return np.zeros_like(solution)
    fits = [least_squares(lambda th, i=i: residual(th, [j for j in range(n_runs) if j != i]),
                          solution, diff_step=1e-4, bounds=REFINE_BOUNDS).x
            for i in range(n_runs)]
    spread = np.asarray(fits) - np.mean(fits, axis=0)
    return np.sqrt((n_runs - 1) / n_runs * np.sum(spread ** 2, axis=0))


# --- driver -----------------------------------------------------------------------------

def identify(runs: Sequence[Run], base: RigParameters, fix_theta3: bool = False,
             progress: Progress | None = None, *, friction: bool = True,
             jackknife: bool = True) -> Identification:
    """Calibrate ``base`` on ``runs``; a step without usable runs is skipped and reported.

    ``friction=False`` keeps the friction curve of ``base`` (a model without a calibrated
    curve, for the diagnosis); ``jackknife=False`` skips the leave-one-run-out spread of
    the friction estimate (its σ is then the residual-based one, and identify is ~4x
    faster).
    """
    say = progress or (lambda _msg: None)
    classes = {r.name: classify(r) for r in runs}
    by_class: dict[str, list[Run]] = {}
    for r in runs:
        by_class.setdefault(classes[r.name], []).append(r)
    estimates: list[Estimate] = []
    problems: list[str] = []
    params = base
    frf = None
    points = None

    def adopt(new: list[Estimate]) -> None:
        nonlocal params
        estimates.extend(new)
        params = params.replace({e.key: e.value for e in new}, "identify")

    def step(name: str, needs: list[Run], missing: str, action: Callable[[], None]) -> None:
        if not needs:
            problems.append(f"{name}: skipped, no {missing} run in the campaign")
            return
        say(f"identifying {name}")
        try:
            action()
        except (ValueError, np.linalg.LinAlgError, ParameterError) as exc:
            problems.append(f"{name}: failed ({exc})")

    ramps = by_class.get("actuator_ramp", [])
    dynamic = by_class.get("actuator_dynamic", [])
    braking_runs = [r for r in runs if classes[r.name].startswith("brake_")]

    def static_map() -> None:
        adopt(fit_static_map(ramps, params))

    def dynamics() -> None:
        nonlocal frf
        found, frf = fit_actuator_dynamics(dynamic, params)
        adopt(found)

    def braking() -> None:
        nonlocal points
        prepared = [_braking(r, params) for r in braking_runs]  # independent of what follows
        adopt([fit_unloaded_radius(prepared, params)])
        adopt(fit_flywheel(prepared, params))
        adopt(fit_brake_gain(prepared, params))
        points = friction_samples(prepared, params)
        if not friction:
            return
        adopt(fit_friction(*points, params, tuple(r.name for r in braking_runs), fix_theta3))
        if not fix_theta3:
            say("refining the friction curve on the braking runs (output error)")
            refined = refine_friction(braking_runs, params, jackknife)
            estimates[:] = [e for e in estimates if not e.key.startswith("friction.")]
            adopt(refined)

    step("valve static map", ramps, "quasi-static ramp", static_map)
    step("actuator dynamics A(s)", dynamic, "actuator steps/sweep", dynamics)
    step("radius, flywheel, brake gain, friction", braking_runs, "braking", braking)
    return Identification(params, tuple(estimates), classes, tuple(problems), frf, points)
