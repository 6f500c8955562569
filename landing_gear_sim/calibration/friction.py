"""The Burckhardt friction curve from braking runs: a direct fit of μ = F_x/F_z against the
slip (eqs. 1, 4, 11), refined by an output-error fit of the wheel speed with a
leave-one-run-out jackknife for an honest σ."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import OptimizeResult, least_squares

from landing_gear_sim.calibration.braking import LOADED_N, Braking, hub_speed
from landing_gear_sim.calibration.differences import (
    Derivatives,
    Objective,
    side_by_side,
    stacked,
)
from landing_gear_sim.calibration.measured import simulate_run, simulate_run_with_sensitivities
from landing_gear_sim.calibration.runs import ClassifiedRun, braking_window
from landing_gear_sim.calibration.slots import Slot
from landing_gear_sim.calibration.statistics import (
    Estimate,
    covariance_std,
    negligible_gain,
    run_weights,
)
from landing_gear_sim.errors import IdentificationError
from landing_gear_sim.model import basis
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.elements import MIN_HUB_SPEED_M_S, burckhardt_mu, slip_ratio
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import friction_at, load_factor_at, rolling_radius_at
from landing_gear_sim.processes import map_threads
from msg_tools.run import Run

KEYS = (K.FRICTION_THETA1, K.FRICTION_THETA2, K.FRICTION_THETA3)
REFINE_BOUNDS = (0.2, 5.0)  # output-error refinement stays within these factors of the start
# its budget: a campaign the model fits converges in 4-6 steps; one with an effect the model
# lacks crawled along a valley for 30+ (11 s of a diagnosis' calibration, for a curve the
# diagnosis re-fits with the missing element anyway)
REFINE_ITERATIONS = 12
# below this slip a braking wheel's reading lags it (−0.13 to −0.30 seen); its noise alone
# reads down to −0.03 (a 64-count encoder at 10 bar), and those samples stay as they were
LAGGING_SLIP = -0.05


def friction_samples(runs: Sequence[Braking], p: RigParameters
                     ) -> tuple[np.ndarray, np.ndarray]:
    """(slip, μ) from eq. (1) and μ = F_x/F_z over the braking phases, decimated to 100 Hz
    (μ of the curve: the model's load sensitivity taken off)."""
    per_run = [_run_samples(b, p) for b in runs]
    return (np.concatenate([slip for slip, _ in per_run]),
            np.concatenate([mu for _, mu in per_run]))


def _run_samples(b: Braking, p: RigParameters) -> tuple[np.ndarray, np.ndarray]:
    return samples_at(b, p, friction_indices(b, p))


def samples_at(b: Braking, p: RigParameters, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(slip, μ) of ``b`` at the samples ``idx`` (μ of the curve: the load factor taken off)."""
    load = b.load[idx]
    hub = hub_speed(b, p)[idx]
    slip = slip_ratio(hub, b.wheel[idx], rolling_radius_at(p, load))
    mu = steady_force(b, p, idx, hub) / load
    if Slot.TYRE.occupied(p):  # the tyre's slot is known, like the load factor
        mu = mu - Slot.TYRE.value_of(p, tyre_signals(b, p, idx))
    return slip, mu / load_factor_at(p, load)


def steady_force(b: Braking, p: RigParameters, idx: np.ndarray, hub_m_s: np.ndarray
                 ) -> np.ndarray:
    """The tyre's steady force F_z·μ at the samples ``idx`` of ``b``: the measured force,
    or, where the model's tyre relaxes, the measured force ahead by its lag σ/v_h
    (σ/v_h·Ḟ_x = F_z·μ − F_x). With 0.69 m of it left in, an oscillating stop's μ
    scattered 0.084 about the rig's curve, 0.017 taken off, and the direct fit read
    ϑ = 0.92, 30.8, 0.24 where the steady force gives 0.96, 27.7, 0.094 (the rig's 0.97,
    27.6, 0.15)."""
    if not p.has("tire_relaxation"):
        return b.force[idx]
    lag_s = p.number(K.TYRE_RELAXATION_LENGTH_M) / np.maximum(hub_m_s, MIN_HUB_SPEED_M_S)
    return b.force[idx] + lag_s * np.gradient(b.force, b.time_s)[idx]


def tyre_signals(b: Braking, p: RigParameters, idx: np.ndarray) -> np.ndarray:
    """The tyre slot's signals at the samples ``idx`` of ``b``: its speed, load, slip (at
    the hub) and the model's curve there, as the plant gives them."""
    load = b.load[idx]
    measured = np.zeros((idx.size, basis.N_SIGNALS))
    measured[:, basis.SPEED] = b.speed_m_s[idx]
    measured[:, basis.LOAD] = load
    measured[:, basis.SLIP] = np.abs(slip_ratio(hub_speed(b, p)[idx], b.wheel[idx],
                                                rolling_radius_at(p, load)))
    measured[:, basis.CURVE] = friction_at(p, measured[:, basis.SLIP])
    return measured


def tyre_carries(b: Braking, p: RigParameters) -> np.ndarray:
    """Samples of ``b`` (mask) where the tyre carries the brake's force: braked 0.3 s,
    loaded, above the stop speed (the friction curve's samples, and a locked wheel's)."""
    stop = p.number(K.RIG_TEST_STOP_SPEED_M_S)
    return (b.time_s > b.start_s + 0.3) & (b.speed_m_s > stop + 2.0) & (b.load > LOADED_N)


def friction_indices(b: Braking, p: RigParameters) -> np.ndarray:
    """Samples of ``b`` (indices) that carry the friction curve: braking, loaded, the wheel
    turning and not read well faster than its hub, above the stop speed; at 100 Hz.

    A braking wheel read faster than its hub by more than noise is the filtered wheel speed
    lagging a wheel that spins up and down quickly near the stop, not the curve: at
    λ = −0.13 the curve μ_B(λ) is −32, and such samples (0.5 % of an oscillating run's)
    bent the direct fit to ϑ = 1.86, 10.9, 2.33 for the rig's 0.97, 27.6, 0.15, beyond what
    the refinement may move."""
    m = tyre_carries(b, p) & (b.wheel > 1.0)
    m &= slip_ratio(hub_speed(b, p), b.wheel, rolling_radius_at(p, b.load)) > LAGGING_SLIP
    return np.flatnonzero(m)[::10]


def fit_friction(runs: Sequence[Braking], p: RigParameters, fix_theta3: bool = False
                 ) -> list[Estimate]:
    """Burckhardt ϑ1, ϑ2, ϑ3 by nonlinear least squares on the (slip, μ) samples of the
    braking runs, each run weighted by :func:`run_weights` (ϑ3 optionally fixed, paper [13])."""
    keys = KEYS
    start = np.array([p.number(k) for k in keys])
    free = 2 if fix_theta3 else 3
    per_run = [_run_samples(b, p) for b in runs]
    slip, mu = (np.concatenate(column) for column in zip(*per_run, strict=True))
    weight = np.repeat(run_weights([s.size for s, _ in per_run]), [s.size for s, _ in per_run])

    def residual(theta: np.ndarray) -> np.ndarray:
        t3 = start[2] if fix_theta3 else theta[2]
        return weight * (burckhardt_mu(theta[0], theta[1], t3, slip) - mu)

    fit = least_squares(residual, start[:free], x_scale=start[:free],
                        bounds=(np.zeros(free), np.full(free, np.inf)))
    std = covariance_std(fit, free)
    method = "Burckhardt least squares on slip/μ samples" + (" (theta3 fixed)" if fix_theta3
                                                             else "")
    names = tuple(b.run.name for b in runs)
    estimates = [Estimate(k, float(v), float(s), names, method)
                 for k, v, s in zip(keys[:free], fit.x, std, strict=True)]
    if fix_theta3:
        estimates.append(Estimate(keys[2], float(start[2]), 0.0, (), "fixed"))
    return estimates


def refine_friction(runs: Sequence[ClassifiedRun], p: RigParameters, jackknife: bool = True
                    ) -> list[Estimate]:
    """Output-error refinement of ϑ1..ϑ3: simulate the braking runs with their measured
    current and fit the wheel speed over the braking phase.

    Open-loop braking rarely leaves the low-slip region, so the direct fit trades ϑ3
    against ϑ1, ϑ2; the wheel-speed response to the slip excursions pins them down.
    """
    problem = _Refinement.of(runs, p)
    start = problem.start
    residuals, derivatives = problem.residuals, problem.derivatives
    every = range(len(runs))
    fit = _least_squares(lambda thetas: residuals(thetas, every),
                         lambda theta: derivatives(theta, every), np.ones(3),
                         REFINE_ITERATIONS)
    pinned = np.isclose(fit.x, REFINE_BOUNDS[0]) | np.isclose(fit.x, REFINE_BOUNDS[1])
    if np.any(pinned):
        which = ", ".join(f"ϑ{i + 1}" for i in np.flatnonzero(pinned))
        raise IdentificationError(
            f"the output-error refinement drove {which} to a factor {REFINE_BOUNDS[0]:g} or "
            f"{REFINE_BOUNDS[1]:g} of the direct fit's {', '.join(f'{v:.4g}' for v in start)}:"
            " these braking runs do not pin the curve (constant-pressure stops stay at low "
            "slip: add oscillating runs, or keep ϑ3 with --fix-theta3)")
    std = covariance_std(fit, 3)
    if jackknife:
        std = np.maximum(std, _jackknife_std(residuals, derivatives, fit,
                                             [problem.samples(i) for i in every]))
    names = tuple(r.name for r in runs)
    method = "output error on wheel vs flywheel speed; σ: max(residual, jackknife)" + (
        f" (stopped at its budget of {REFINE_ITERATIONS} steps)" if fit.status == 0 else "")
    return [Estimate(k, float(v), float(sd), names, method)
            for k, v, sd in zip(KEYS, fit.x * start, std * start, strict=True)]


@dataclass(frozen=True)
class _Refinement:
    """The output-error refinement's problem: ϑ1..ϑ3 as factors of the direct fit's
    ``start``, the braking runs' windows and weights, and the flywheel-to-wheel radius
    ``ratio`` (not among the fitted keys: every trial's)."""

    runs: Sequence[ClassifiedRun]
    model: RigParameters
    start: np.ndarray
    windows: list[np.ndarray]
    weights: np.ndarray
    ratio: float

    @classmethod
    def of(cls, runs: Sequence[ClassifiedRun], p: RigParameters) -> _Refinement:
        windows = [braking_window(r, p) for r in runs]
        return cls(runs, p, np.array([p.number(k) for k in KEYS]), windows,
                   run_weights([int(w.sum()) for w in windows]),
                   p.number(K.FLYWHEEL_RADIUS_M) / p.number(K.WHEEL_UNLOADED_RADIUS_M))

    def trial(self, theta: np.ndarray) -> RigParameters:
        return self.model.replace(dict(zip(KEYS, theta * self.start, strict=True)),
                                  "identify")

    def slip_error(self, i: int, simulated: Run) -> np.ndarray:
        """Run i's weighted wheel-speed error less what the flywheel-speed error explains: a
        common speed offset (noisy initial speed, drag) is not the friction curve's doing."""
        run, window = self.runs[i], self.windows[i]
        wheel = simulated.wheel_speed_rad_s[window] - run.wheel_speed_rad_s[window]
        flywheel = simulated.flywheel_speed_rad_s[window] - run.flywheel_speed_rad_s[window]
        return self.weights[i] * (wheel - self.ratio * flywheel)[::5]

    def samples(self, i: int) -> int:
        """How many samples run i's error has (:meth:`slip_error`'s every fifth)."""
        return len(range(0, int(np.count_nonzero(self.windows[i])), 5))

    def residuals(self, thetas: Sequence[np.ndarray], chosen: Sequence[int]
                  ) -> list[np.ndarray]:
        """Each ϑ's error over the ``chosen`` runs, every (ϑ, run) simulated side by side
        (a Jacobian's columns share the cores)."""
        return side_by_side(lambda trial, i: self.slip_error(i, simulate_run(
            self.runs[i], trial)[0]), [self.trial(theta) for theta in thetas], chosen)

    def derivatives(self, theta: np.ndarray, chosen: Sequence[int]
                    ) -> tuple[np.ndarray, np.ndarray] | None:
        """The error at ϑ over the ``chosen`` runs and its Jacobian, from the plant's own
        derivatives (None where it gives none)."""
        params = self.trial(theta)

        def one(i: int) -> tuple[np.ndarray, np.ndarray] | None:
            found = simulate_run_with_sensitivities(self.runs[i], params, KEYS,
                                                    list(self.start))
            if found is None:
                return None
            simulated, d = found
            slope = (d["wheel_speed_rad_s"]
                     - self.ratio * d["flywheel_speed_rad_s"])[self.windows[i]]
            return self.slip_error(i, simulated), self.weights[i] * slope[::5] * self.start

        return stacked(map_threads(one, chosen))


def _least_squares(residuals: Callable[[Sequence[np.ndarray]], list[np.ndarray]],
                   derivatives: Derivatives, start: np.ndarray, iterations: int | None = None,
                   known: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
                   ) -> OptimizeResult:
    """The refinement's least squares within REFINE_BOUNDS, at most ``iterations`` steps
    (on the plant's own derivatives where differences.MODEL_DERIVATIVES is on); ``known``:
    the residual and Jacobian at ``start``, already computed."""
    objective = Objective(residuals, *REFINE_BOUNDS, known=known, derivatives=derivatives)
    return least_squares(objective.fun, start, jac=objective.jac, bounds=REFINE_BOUNDS,
                         ftol=negligible_gain(objective.fun(start)), max_nfev=iterations)


def _jackknife_std(residuals: Callable[[Sequence[np.ndarray], Sequence[int]],
                                       list[np.ndarray]],
                   derivatives: Callable[[np.ndarray, Sequence[int]],
                                         tuple[np.ndarray, np.ndarray] | None],
                   fit: OptimizeResult, samples: Sequence[int]) -> np.ndarray:
    """Leave-one-run-out spread of ``fit`` (whose runs' errors have ``samples`` each, in
    order): run-to-run variability the residuals hide. Each fit leaving a run out starts
    at ``fit``'s optimum, with ``fit``'s residual and Jacobian rows of the runs it keeps:
    a run's rows are its own simulations', so they are that fit's residual and Jacobian
    there to the bit, and its start and the start's three columns (4 of its ~14
    simulations of each run) are not simulated again."""
    n_runs = len(samples)
    if n_runs < 3:
        return np.zeros_like(fit.x)
    value, jacobian = np.split(fit.fun, np.cumsum(samples)[:-1]), np.split(
        fit.jac, np.cumsum(samples)[:-1])

    def leaving_out(i: int) -> OptimizeResult:
        chosen = [j for j in range(n_runs) if j != i]
        # in the layout the Jacobian of these runs has (Objective.jac's): the solver's
        # rounding follows it
        known = (fit.x, np.concatenate([value[j] for j in chosen]),
                 np.asfortranarray(np.concatenate([jacobian[j] for j in chosen])))
        return _least_squares(lambda thetas: residuals(thetas, chosen),
                              lambda theta: derivatives(theta, chosen), fit.x, known=known)

    fits = [leaving_out(i).x for i in range(n_runs)]
    spread = np.asarray(fits) - np.mean(fits, axis=0)
    return np.sqrt((n_runs - 1) / n_runs * np.sum(spread ** 2, axis=0))
