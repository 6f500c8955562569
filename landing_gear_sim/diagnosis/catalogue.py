"""The diagnosis catalogue: candidate model extensions and their output-error fit.

Each candidate is a real model element (switched on with ``elements.<name>``) with
physical parameters. Fitting one means: switch it on, then fit its parameters,
together with the base parameters it trades off against, by simulating the runs
that carry its signature with their measured inputs (output error, not one-step
prediction). Residuals are scaled by each channel's sensor noise, estimated from
the measurement itself.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import OptimizeResult, least_squares

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.differences import Objective
from landing_gear_sim.calibration.noise import noise_std
from landing_gear_sim.calibration.runs import (
    ClassifiedRun,
    RunKind,
    Selector,
    Setup,
    classify_all,
    select,
)
from landing_gear_sim.calibration.statistics import (
    covariance_std,
    input_timing_std_s,
    negligible_gain,
)
from landing_gear_sim.diagnosis.equations.tyre import relaxation_read
from landing_gear_sim.diagnosis.local_gain import campaign_gain
from landing_gear_sim.diagnosis.objective import (
    Scales,
    scaled_residuals,
    scaled_residuals_and_jacobian,
)
from landing_gear_sim.errors import IdentificationError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import gear_walk_modes
from msg_tools.run import Run
from msg_tools.units import PA_PER_BAR

START_RATIO = 2.0  # multi-start: optimise only starts this close to the best initial cost
PROBE_ITERATIONS = 3  # multi-start: each start gets this many steps, then only the best goes on
MAX_ITERATIONS = 40  # the budget of one optimisation, in evaluations (each Jacobian adds n more)


@dataclass(frozen=True, kw_only=True)
class Candidate:
    """A model extension the diagnosis can propose.

    Attributes:
        cause: name in the diagnosis contract.
        element: the ``elements.<name>`` switch it turns on (None: the friction curve,
            which every model has; the candidate frees its parameters).
        keys: its own parameters, fitted.
        starts: start values tried for ``keys`` (multi-start: lags and frequencies
            have local minima); empty: start from the model's current values.
        bounds: admissible range of each key.
        free: base-model parameters re-fitted with it (they could otherwise absorb
            or mask the effect).
        runs: run kinds that carry its signature, fitted on: families or kinds
            (when the campaign has none of a kind, its family).
        channels: measured channels compared.
        held_out: run kinds that also show the effect and are kept to check it (when
            empty, the fitting runs are split in two).
        contract: key parameter names of the diagnosis contract -> parameter keys.
        reach: why a fit's values lie beyond what the runs exercise ('' when they do not),
            from the fitted values, the runs fitted on and the fitted model; None: always
            within reach.
        family: a discovered term's family (``diagnosis.families``); '' for a catalogue
            cause.
        neutral: values of ``keys`` at which the extended model is the model without it
            (a term at zero); empty: no such point within the bounds.
        settings: parameters set, not fitted, in every model it is fitted from (a generic
            slot's basis function codes: at a coefficient of zero they change nothing).
        evidence: what the runs show instead of it under the calibrated model, when they
            show no sign of it ('' when they may): it is not fitted there. None: always
            fitted.
    """

    cause: str
    element: str | None
    keys: tuple[str, ...]
    starts: tuple[tuple[float, ...], ...]
    bounds: tuple[tuple[float, float], ...]
    free: tuple[str, ...]
    runs: tuple[Selector, ...]
    channels: tuple[str, ...]
    held_out: tuple[Selector, ...]
    contract: tuple[tuple[str, str], ...]
    reach: Reach | None = None
    family: str = ""
    neutral: tuple[float, ...] = ()
    settings: tuple[tuple[str, float], ...] = ()
    evidence: Evidence | None = None


Evidence = Callable[[Sequence[ClassifiedRun], RigParameters], str]
Reach = Callable[[dict[str, float], Sequence[ClassifiedRun], RigParameters], str]
FADE_REACH = 2.0  # a fade energy beyond this many times a run's largest brake energy


def fade_reach(values: dict[str, float], runs: Sequence[ClassifiedRun],
               params: RigParameters) -> str:
    """A fade energy E_f far beyond the brake energy any run absorbs: the runs see only
    the fade's first slope φ E / E_f, a law in energy, not the catalogued fade (φ 0.8 % at
    700 MJ was once named; a stop absorbs a few MJ)."""
    energies = [float(br.torque_balance(br.prepare(r, params), params)[1][-1])
                for r in runs if r.braking]
    energy = values.get(K.BRAKE_FADE_ENERGY_J, 0.0)
    largest = max(energies, default=0.0)
    if energy <= FADE_REACH * largest:
        return ""
    return (f"its fade energy {energy / 1e6:.3g} MJ lies beyond what the runs exercise (the "
            f"most a run's brake absorbed: {largest / 1e6:.3g} MJ): they show the first slope "
            "of a law in brake energy, not a fade")


FADE_Z = 2.0  # how far the brake gain falls with the energy absorbed, in σ, to fit a fade
FADE_STD = 0.005  # how well the bands must read the fall for one they do not read to count


def fade_evidence(runs: Sequence[ClassifiedRun], params: RigParameters) -> str:
    """A fade lowers the brake's gain as the brake absorbs energy: under the calibrated
    model the gain re-estimated in bands of absorbed energy (:func:`~.local_gain.campaign_gain`)
    falls with it, by FADE_Z σ or more. Where it does not, no fade is fitted: its fit and its
    null had taken 42 % of the fits' time in 22 campaigns without a fade. Fades of 2-8 %
    read a fall of 9.8-17σ (the calibration takes half of it), I01's 15 % 10.8σ. Where the
    bands cannot read the fall to FADE_STD (another effect scatters them), it is fitted. Of
    the verdict guard's 72 other campaigns that brake, 54 read the fall to 0.5 % or better
    and 1.7σ at most: no fade is fitted there. 9 read 5.5-25σ (a pressure channel that
    drifts, a seal, a gain law) and 9 to 0.53-3.2 % only: the fade is fitted, as before."""
    gain = campaign_gain(runs, params, "brake energy")
    if gain is None or (gain.change < 0.0 and gain.z >= FADE_Z) or gain.change_std > FADE_STD:
        return ""
    return (f"the brake gain does not fall with the energy the brake absorbed "
            f"({100 * gain.change:+.1f} % over {gain.centres.min():.3g}–"
            f"{gain.centres.max():.3g} {gain.unit}, {gain.z:.1f} σ)")


RELAXATION_Z = 2.0  # how far the tyre's error reads a relaxation length (its t) to fit one
# how well the samples must read the length for a relaxation they do not read to be left out:
# where the force hardly moves (constant-pressure stops alone) a 60 cm one read 50 ± 30 cm
RELAXATION_STD_M = 0.05


def relaxation_evidence(runs: Sequence[ClassifiedRun], params: RigParameters) -> str:
    """A relaxing tyre's force lags its curve by σ/v: the tyre's error under the calibrated
    model reads a relaxation length σ > 0 (:func:`~.equations.tyre.relaxation_read`), at
    t ≥ RELAXATION_Z. Where it does not, no relaxation is fitted: its fit and its null had
    taken 27 % of the fits' time in 22 campaigns without one. The project's generator's 3 cm
    read t 2.4-3.2, 8 cm 6.7-8.5, an independent rig's 45 cm (I03) 31.8; of the verdict
    guard's 72 other campaigns that brake, 70 read σ ≤ 0 or t 1.9 at most, to 4 cm or
    better: no relaxation is fitted there. I04's gear walk reads t 28.9 and 1580 reads its
    length to 6.8 cm only: fitted, as before. Where the samples cannot read the length to
    RELAXATION_STD_M (the force hardly moves: a campaign of constant-pressure stops read a
    60 cm relaxation as 50 ± 30 cm), it is fitted."""
    found = relaxation_read(runs, params)
    if found is None:
        return ""
    length_m, t = found
    if (length_m > 0.0 and t >= RELAXATION_Z) or abs(length_m) > RELAXATION_STD_M * t:
        return ""  # read, or read no better than RELAXATION_STD_M (its σ is |length| / t)
    return (f"the tyre's force does not lag its curve as a relaxing tyre's does (it reads a "
            f"relaxation length of {100 * length_m:+.1f} cm at {t:.1f} σ)")


ACTUATOR = (K.ACTUATOR_NATURAL_FREQUENCY_HZ, K.ACTUATOR_DAMPING_RATIO)
FRICTION = (K.FRICTION_THETA1, K.FRICTION_THETA2, K.FRICTION_THETA3)
STATIC_MAP = (K.ACTUATOR_DEADBAND_CURRENT_A, K.ACTUATOR_MAP_K1_PA_PER_A,
              K.ACTUATOR_MAP_K2_PA_PER_A2, K.ACTUATOR_MAX_PRESSURE_PA)
GEAR_WALK = (K.GEAR_WALK_STIFFNESS_N_M_PER_RAD, K.GEAR_WALK_DAMPING_N_M_S_PER_RAD)
PRESSURE = ("pressure_pa",)
WHEEL = ("wheel_speed_rad_s", "longitudinal_force_n")
FADE = (K.BRAKE_FADE_FRACTION, K.BRAKE_FADE_ENERGY_J)
ACTUATOR_RUNS: tuple[Selector, ...] = (Setup.ACTUATOR,)
BRAKE_RUNS: tuple[Selector, ...] = (Setup.BRAKE,)

CATALOGUE: dict[str, Candidate] = {c.cause: c for c in (
    # an actuator effect shows in every run's pressure: fitted on the actuator runs,
    # checked on the braking runs' pressure
    Candidate(cause="actuator_delay", element="actuator_delay", keys=(K.ACTUATOR_DELAY_S,),
              starts=((0.002,), (0.006,), (0.012,), (0.025,)), bounds=((0.0, 0.06),),
              free=ACTUATOR, runs=ACTUATOR_RUNS, channels=PRESSURE, held_out=BRAKE_RUNS,
              contract=(("delay_s", K.ACTUATOR_DELAY_S),)),
    # an offset shifts the whole map while calibrating it: re-fit the map with it; the
    # stretches below the dead-band tell the two apart
    Candidate(cause="pressure_sensor_offset", element="pressure_sensor_offset",
              keys=(K.SENSORS_PRESSURE_OFFSET_PA,), starts=((0.0,),),
              bounds=((-10 * PA_PER_BAR, 10 * PA_PER_BAR),), free=STATIC_MAP,
              runs=ACTUATOR_RUNS, channels=PRESSURE, held_out=BRAKE_RUNS,
              contract=(("offset_pa", K.SENSORS_PRESSURE_OFFSET_PA),)),
    Candidate(cause="actuator_dynamics", element="actuator_dynamics", keys=ACTUATOR,
              starts=((8.0, 0.5), (15.0, 0.8)), bounds=((1.0, 60.0), (0.1, 2.0)), free=(),
              runs=ACTUATOR_RUNS, channels=PRESSURE, held_out=BRAKE_RUNS,
              contract=(("natural_frequency_hz", ACTUATOR[0]),
                        ("damping_ratio", ACTUATOR[1]))),
    # fitted on the constant-pressure stops: in the oscillating runs the wheel nears the
    # skid and the output error jumps with the exact moment (a fit there got stuck at
    # 2/3 of the true length, in a valley of width ~1 %)
    Candidate(cause="tire_relaxation", element="tire_relaxation",
              keys=(K.TYRE_RELAXATION_LENGTH_M,), starts=((0.1,), (0.4,), (1.0,)),
              bounds=((0.005, 5.0),), free=FRICTION, runs=(RunKind.BRAKE_CONSTANT,),
              channels=WHEEL, held_out=(),
              contract=(("relaxation_length_m", K.TYRE_RELAXATION_LENGTH_M),),
              evidence=relaxation_evidence),
    Candidate(cause="gear_walk", element="gear_walk", keys=GEAR_WALK,
              starts=((6.9e5, 1372.0), (3e5, 1000.0), (1.5e6, 2000.0)),
              bounds=((5e4, 2e7), (10.0, 5e4)), free=FRICTION, runs=BRAKE_RUNS,
              channels=WHEEL, held_out=(), contract=()),
    Candidate(cause="brake_fade", element="brake_fade", keys=FADE,
              # a fade of 0.1 % starts near the null: from 10 % alone a campaign without a
              # fade spent 21 evaluations (11 s) climbing back from 50 times its cost
              starts=((0.1, 2e6), (0.3, 5e5), (0.001, 2e6)), bounds=((0.0, 0.9), (1e4, 1e8)),
              # the calibration bent the friction curve to absorb the fade: free it too
              free=(K.BRAKE_GAIN_N_M_PER_PA, *FRICTION), runs=BRAKE_RUNS,
              # the measured force is the brake torque over r whatever the friction
              # curve (which the calibration distorted to absorb the fade)
              channels=("longitudinal_force_n", "flywheel_speed_rad_s"), held_out=(),
              contract=(("fade_fraction", FADE[0]), ("fade_energy_j", FADE[1]),
                        ("gain_n_m_per_pa", K.BRAKE_GAIN_N_M_PER_PA),
                        ("fade_shape", K.BRAKE_FADE_SHAPE)), reach=fade_reach,
              evidence=fade_evidence),
    Candidate(cause="drag", element="drag", keys=(K.DRAG_COEFF_N_S2_PER_M2,),
              starts=((0.2,),), bounds=((0.0, 5.0),), free=(K.FLYWHEEL_INERTIA_KG_M2,),
              runs=BRAKE_RUNS, channels=("flywheel_speed_rad_s",), held_out=(),
              contract=(("drag_coeff_n_s2_per_m2", K.DRAG_COEFF_N_S2_PER_M2),)),
    # a radius falling with the load three times the reference's: from its value alone the
    # fit stopped at its budget with b near the start (2 campaigns of 6, ΔBIC +41, +145);
    # a and b trade off at one campaign's loads: a nearly linear law (a 7.6e-13, in the
    # bottom 1 % of its range) is the element with a simpler law (neutral: see _at_bound)
    Candidate(cause="load_dependent_radius", element="load_dependent_radius",
              keys=(K.RADIUS_A_M_PER_N2, K.RADIUS_B_M_PER_N),
              starts=((4e-12, 5e-7), (4e-12, 1.5e-6)), neutral=(0.0, 0.0),
              bounds=((0.0, 1e-10), (0.0, 5e-6)),
              # without the element the calibration bent the friction curve (slip read
              # with one radius at every load): free it too
              free=(K.WHEEL_UNLOADED_RADIUS_M, K.BRAKE_GAIN_N_M_PER_PA, *FRICTION),
              runs=BRAKE_RUNS, channels=WHEEL, held_out=(),
              contract=(("radius_a_m_per_n2", K.RADIUS_A_M_PER_N2),
                        ("radius_b_m_per_n", K.RADIUS_B_M_PER_N))),
    Candidate(cause="friction_curve", element=None, keys=FRICTION, starts=(),
              bounds=((0.05, 3.0), (1.0, 300.0), (0.0, 2.0)), free=(), runs=BRAKE_RUNS,
              channels=WHEEL, held_out=(),
              contract=tuple((k.split(".")[1], k) for k in FRICTION)),
)}


@dataclass(frozen=True)
class CandidateFit:
    """A fitted candidate (or its null: the same free parameters without it): the
    parameter set, values and 1-σ of what was fitted, the scaled residual, and whether the
    fit stopped on its budget of steps rather than on its tolerance."""

    candidate: Candidate
    params: RigParameters
    values: dict[str, float]
    std: dict[str, float]
    residual: np.ndarray
    stopped: bool = False

    @property
    def cost(self) -> float:
        """Sum of squared noise-scaled residuals."""
        return float(self.residual @ self.residual)


def noise_scales(runs: Sequence[Run], channels: Sequence[str]) -> Scales:
    """Noise std of every (run, channel), estimated from the measurement itself."""
    return {(r.name, c): noise_std(getattr(r, c)) for r in runs for c in channels}


def switched_on(candidate: Candidate, params: RigParameters) -> RigParameters:
    """``params`` with the candidate's element on, its keys at their first start values."""
    if candidate.element is None:
        return params
    starts = dict(zip(candidate.keys, candidate.starts[0], strict=True)) if candidate.starts \
        else {}
    return params.replace({f"elements.{candidate.element}": True, **starts},
                          f"candidate {candidate.cause}")


def fit_candidate(candidate: Candidate, runs: Sequence[Run], base: RigParameters,
                  datasheet: RigParameters | None = None, *, null: bool = False,
                  tries: int = 2, scales: Scales | None = None,
                  ended: Mapping[str, float] | None = None) -> CandidateFit:
    """Switch ``candidate`` on in ``base`` and fit its keys plus its free base parameters
    on the runs of its kinds among ``runs``.

    ``base`` is the model calibrated without the candidate; where the missing element
    distorted that calibration, the free parameters are also started from
    ``datasheet`` (the design values), and their window spans both. Of all start
    points, the ``tries`` with the lowest initial cost that start within ``START_RATIO`` of
    the best (a start further off ended no better in any campaign tried) each take
    ``PROBE_ITERATIONS`` steps; the best of them goes on, within ``MAX_ITERATIONS`` steps
    (the evaluation budget: a fit is bounded in time). ``null=True`` fits the free
    parameters alone, element off: the fair reference for the candidate. ``ended``: the
    values its parameters ended at when it was fitted before (a round earlier, on a model
    without what was accepted since): one more start, which goes on alone when it ranks
    first.
    """
    chosen = select(classify_all(runs), candidate.runs)
    if not chosen:
        kinds = "/".join(str(k) for k in candidate.runs)
        raise IdentificationError(f"{candidate.cause}: no {kinds} run to fit on")
    references = [base] + ([datasheet] if datasheet is not None else [])
    problem = _problem(candidate, chosen, base, references, null,
                       scales or noise_scales(chosen, candidate.channels))
    if not problem.keys:
        (error,) = scaled_residuals(chosen, [problem.model], candidate.channels,
                                    problem.scales)
        return CandidateFit(candidate, problem.model, {}, {}, error)
    resumed = bool(problem.own and ended)
    points = _starts(candidate, problem, references, ended if resumed else None)
    start = _best_start(candidate, problem, points, tries, resumed)
    best = _optimise(problem.objective(start), start[0], MAX_ITERATIONS)
    return _fitted(candidate, problem, best, chosen)


@dataclass(frozen=True)
class _Problem:
    """A candidate's fit: the runs it is fitted on, the model its keys (its ``own``, then
    the free base parameters) are set in, their window, and the channels' scales."""

    chosen: Sequence[ClassifiedRun]
    model: RigParameters
    own: tuple[str, ...]
    keys: tuple[str, ...]
    window: _Window
    channels: tuple[str, ...]
    scales: Scales

    def residuals(self, points: Sequence[np.ndarray]) -> list[np.ndarray]:
        """The scaled residuals of the model at each of ``points`` (unit box)."""
        trials = [self.model.replace(dict(zip(self.keys, self.window.value(u), strict=True)),
                                     "fit") for u in points]
        return scaled_residuals(self.chosen, trials, self.channels, self.scales)

    def objective(self, known: Start) -> Objective:
        """The fit's objective, from ``known`` (a point, its residual, its Jacobian)."""
        return Objective(self.residuals, known=known, derivatives=self.derivatives)

    def derivatives(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """The scaled residual at ``u`` (unit box) and its Jacobian there, from the
        plant's own derivatives (None where the plant alone does not give them)."""
        trial = self.model.replace(dict(zip(self.keys, self.window.value(u), strict=True)),
                                   "fit")
        spans = self.window.upper - self.window.lower
        found = scaled_residuals_and_jacobian(self.chosen, trial, self.keys, spans,
                                              self.channels, self.scales)
        if found is None:
            return None
        error, jacobian = found
        return error, jacobian * self.window.slope(u)


def _problem(candidate: Candidate, chosen: Sequence[ClassifiedRun], base: RigParameters,
             references: Sequence[RigParameters], null: bool, scales: Scales) -> _Problem:
    """The fit of ``candidate`` (``null``: its free parameters alone, element off): its own
    keys within their bounds, the free ones within half and twice the ``references``'."""
    own = () if null else candidate.keys
    model = base if null else switched_on(candidate, base)
    # a free parameter at 0 in every reference has no window of 0.5-2 times it: it stays
    # (a valve's dead-band of 0 had ended a diagnosis on a nan from the window's width)
    free = [k for k in candidate.free if k not in candidate.keys
            and any(r.number(k) != 0.0 for r in references)]
    own_bounds = candidate.bounds if own else ()
    lower = np.array([b[0] for b in own_bounds]
                     + [0.5 * min(r.number(k) for r in references) for k in free])
    upper = np.array([b[1] for b in own_bounds]
                     + [2.0 * max(r.number(k) for r in references) for k in free])
    return _Problem(chosen, model, tuple(own), (*own, *free), _Window(lower, upper),
                    candidate.channels, scales)


def _starts(candidate: Candidate, problem: _Problem, references: Sequence[RigParameters],
            ended: Mapping[str, float] | None) -> list[np.ndarray]:
    """The start points (unit box): each of the candidate's starts with each reference's
    free parameters; first, where it ``ended`` when fitted before."""
    free = problem.keys[len(problem.own):]
    own_starts = candidate.starts if problem.own and candidate.starts else [()]
    points = [problem.window.unit(np.array([*(s or [r.number(k) for k in problem.own]),
                                            *(r.number(k) for k in free)]))
              for s in own_starts for r in references]
    if ended:
        # where it ended, its free parameters with its keys (a delay ended beside the ω_n
        # it moved; beside the calibrated ω_n it started worse than the catalogue's)
        points.insert(0, problem.window.unit(np.array(
            [ended.get(k, problem.model.number(k)) for k in problem.keys])))
    return points


Start = tuple[np.ndarray, np.ndarray, np.ndarray | None]


def _best_start(candidate: Candidate, problem: _Problem, points: list[np.ndarray],
                tries: int, resumed: bool) -> Start:
    """Where the fit goes on from: the best start's probe, of the ``tries`` starts of the
    lowest cost within START_RATIO of the best (``resumed``: where it ended before, alone
    when it ranks first)."""
    # a start the model does not survive (an unstable valve: inf or nan) is no start
    at_points = _once_each(problem.residuals, points)
    initial = [cost if math.isfinite(cost := float(np.sum(r ** 2))) else math.inf
               for r in at_points]
    if not math.isfinite(min(initial)):
        raise IdentificationError(f"{candidate.cause}: the model diverges from every start")
    order = [i for i in np.argsort(initial)[:tries] if initial[i] <= START_RATIO * min(initial)]
    if resumed and order[0] == 0:
        order = order[:1]  # its probes told the basins apart when it was fitted before
    if len(order) == 1:
        return points[order[0]], at_points[order[0]], None
    # successive halving: the starts' first steps tell the basins apart; running each to
    # the end cost twice the time and always ended on the same optimum. Two references
    # that agree on the free parameters give one start twice: its probe is one probe
    probes: dict[bytes, OptimizeResult] = {}
    for i in order:
        if points[i].tobytes() not in probes:
            probes[points[i].tobytes()] = _optimise(
                problem.objective((points[i], at_points[i], None)), points[i],
                PROBE_ITERATIONS)
    probe = min(probes.values(), key=lambda fit: fit.cost)
    return probe.x, probe.fun, probe.jac


def _once_each(residuals: Callable[[Sequence[np.ndarray]], list[np.ndarray]],
               points: Sequence[np.ndarray]) -> list[np.ndarray]:
    """``residuals`` at ``points``, a point given twice simulated once (a start each
    reference gives alike: a discovered term's fit had simulated a quarter of its runs
    twice)."""
    unique = list({p.tobytes(): p for p in points}.values())
    found = dict(zip((p.tobytes() for p in unique), residuals(unique), strict=True))
    return [found[p.tobytes()] for p in points]


def _fitted(candidate: Candidate, problem: _Problem, best: OptimizeResult,
            chosen: Sequence[ClassifiedRun]) -> CandidateFit:
    """The fit's values and σ (a delay's with the logger's timing) in its model."""
    keys, window = list(problem.keys), problem.window
    values = window.value(best.x)
    std = covariance_std(best, len(keys)) * window.slope(best.x)
    if K.ACTUATOR_DELAY_S in keys:
        std[keys.index(K.ACTUATOR_DELAY_S)] = math.hypot(
            std[keys.index(K.ACTUATOR_DELAY_S)], input_timing_std_s(chosen))
    fitted = problem.model.replace(dict(zip(keys, values, strict=True)),
                                   f"fit {candidate.cause}")
    return CandidateFit(candidate, fitted, dict(zip(keys, map(float, values), strict=True)),
                        dict(zip(keys, map(float, std), strict=True)), best.fun,
                        stopped=best.status == 0)  # scipy's "max_nfev reached"


def _optimise(objective: Objective, start: np.ndarray, iterations: int) -> OptimizeResult:
    """Least squares on the unit box from ``start``, at most ``iterations`` steps."""
    return least_squares(objective.fun, start, jac=objective.jac, bounds=(0.0, 1.0),
                         x_scale=0.01, ftol=negligible_gain(objective.fun(start)),
                         max_nfev=iterations)


@dataclass(frozen=True)
class _Window:
    """Maps the optimiser's unit box to parameter values: logarithmic for positive
    ranges spanning more than a decade (energies, stiffnesses), linear otherwise."""

    lower: np.ndarray
    upper: np.ndarray

    @property
    def log(self) -> np.ndarray:
        return (self.lower > 0) & (self.upper > 10 * self.lower)

    def value(self, u: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            geometric = self.lower * (self.upper / self.lower) ** u
        return np.where(self.log, geometric, self.lower + u * (self.upper - self.lower))

    def unit(self, value: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            geometric = np.log(value / self.lower) / np.log(self.upper / self.lower)
        u = np.where(self.log, geometric, (value - self.lower) / (self.upper - self.lower))
        return np.clip(u, 1e-6, 1 - 1e-6)

    def slope(self, u: np.ndarray) -> np.ndarray:
        """d value / d u (turns a σ of u into a σ of the value)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            geometric = self.value(u) * np.log(self.upper / self.lower)
        return np.where(self.log, geometric, self.upper - self.lower)


def key_parameters(candidate: Candidate, params: RigParameters) -> dict[str, float]:
    """The candidate's key parameters under their contract names, SI."""
    if candidate.cause == "gear_walk":
        return gear_walk_key_parameters(params)
    return {name: params.number(key) for name, key in candidate.contract}


def gear_walk_key_parameters(params: RigParameters) -> dict[str, float]:
    """The gear-walk finding's contract parameters (see quantities.gear_walk_modes)."""
    frequency_hz, damping_ratio = gear_walk_modes(params)
    return {"frequency_hz": frequency_hz, "damping_ratio": damping_ratio}
