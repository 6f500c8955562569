"""The valve: its static map P_static = map(i) and its dynamics A(s), P = A(s)·P_static.

Everything the diagnosis knows about the valve: the samples where it has settled
(:func:`settled_valve`, the static map's and the pressure's relations read them), its
relations (the same with the current rising and falling; settles on its quadratic map;
follows A(s) between its levels), and its two libraries of terms: the static map's, read
where A(s) has settled, and A(s)'s, read over the whole of an actuator run.

A(s)'s generic slot (``actuator.term_*``, :mod:`landing_gear_sim.model.actuator`) adds
Σ c_k φ_k(P, Ṗ, ΔP) to the pressure the valve is driven by, ΔP = μ P_static − P. Its error
is an output error (the measured pressure less the model's, through the pressure channel);
a term enters it as the model pressure's change per unit of its coefficient, the run
simulated with the term tried (the plant's own step), beside the sensitivities to the
parameters the calibration owns there (ω_n, ζ, the map, the delay), taken alike.

The relation "valve the same with the current rising and falling" (:func:`valve_direction`)
and the static map's library read the same samples: there the
valve's dynamics A(s) have settled, and what the model's pressure misses is its static map.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import scipy.signal

from landing_gear_sim.calibration.braking import Braking
from landing_gear_sim.calibration.runs import ClassifiedRun, RunKind
from landing_gear_sim.calibration.slots import Slot, map_signals, seen
from landing_gear_sim.calibration.statistics import (
    effective_count,
)
from landing_gear_sim.diagnosis.catalogue import ACTUATOR, STATIC_MAP
from landing_gear_sim.diagnosis.equations.equation import Declared, Equation
from landing_gear_sim.diagnosis.library import Campaign, Library
from landing_gear_sim.diagnosis.relations import (
    MIN_CHECK_S,
    MIN_SAMPLES,
    Z_VIOLATED,
    Check,
    Checking,
    Reads,
    Relation,
)
from landing_gear_sim.diagnosis.selection import (
    Rows,
    Selected,
    Term,
    basis_terms,
    ordinary_fit,
    term_columns,
    variable,
)
from landing_gear_sim.diagnosis.terms import Shaped
from landing_gear_sim.errors import ParameterError
from landing_gear_sim.model import basis
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.actuator import actuator_matrices, actuator_pressure, settled_states
from landing_gear_sim.model.parameters import INDEX, RigParameters
from landing_gear_sim.model.scenario import (
    NOISY_CURRENT_A,
    current_noise_a,
    logged_to_held,
)
from landing_gear_sim.model.sensors import SensorModel
from msg_tools.run import Run
from msg_tools.units import PA_PER_BAR, display

MAP_LAW = "P_static = {k1}·e + {k2}·e²"
"""The valve's static map, e = I − I0 (the text its declaration and its library write)."""
DYNAMICS_LAW = "P̈ = ω_n²·(μ·P_static − P{slot}) − 2·{zeta}·ω_n·Ṗ"
"""A(s), the valve's dynamics (the text its declaration and its library write)."""
PRESSURE_FLOOR_PA = 0.2 * PA_PER_BAR
SETTLED_S = 0.3  # after a current change the valve has settled
SLOW_A_S = 0.5  # slower current changes: A(s) errors leave no direction-locked residual
RATE_WINDOW_S = 0.3  # a noisy current's rate of change is its slope over this ...
RATE_NOISE_Z = 5.0  # ... and counted beyond this many σ of that average's noise
NOISE_WINDOW_S = 0.5  # a current log's noise is read in pieces this long ...
NOISE_QUANTILE = 0.2  # ... as this quantile of the pieces' estimates


@dataclass(frozen=True)
class Settled:
    """An actuator run under a model, (n,) arrays: the current the valve was fed [A], the
    model's pressure [Pa] and the measured one's excess over it as its channel reads it
    [Pa], which way the current last moved (±1, 0: not yet), and the settled samples
    (mask); the run's rate [Hz] and the time since its first sample [s]."""

    current_a: np.ndarray
    model_pa: np.ndarray
    residual_pa: np.ndarray
    direction: np.ndarray
    settled: np.ndarray
    rate_hz: float
    time_s: np.ndarray


def settled_valve(run: ClassifiedRun, params: RigParameters) -> Settled | None:
    """The run's settled samples under ``params`` (None: a run whose log cannot tell)."""
    noise = _log_noise_a(run)
    if _unreadable(run, noise):
        return None
    current = logged_to_held(run.command_a)
    model = actuator_pressure(params, current, run.rate_hz)
    residual = run.pressure_pa - SensorModel.of(params).pressure_channel(run.time_s, model)
    change = _current_rate(run, noise)
    last = np.maximum.accumulate(np.where(change != 0.0, np.arange(change.size), 0))
    window = max(1, round(SETTLED_S * run.rate_hz))
    fast = np.abs(change) > SLOW_A_S
    slow = np.convolve(fast, np.ones(window), mode="full")[:fast.size] == 0
    band = (model > 2 * PRESSURE_FLOOR_PA) & (model < 0.9 * params.number(
        K.ACTUATOR_MAX_PRESSURE_PA))
    # the samples the logger lost are a line drawn through them, not the valve
    return Settled(current, model, residual, np.sign(change[last]), slow & band & run.compared,
                   run.rate_hz, run.time_s - run.time_s[0])


def _unreadable(run: ClassifiedRun, noise_a: float) -> bool:
    """A fast actuator run whose current log is noisy: fed the log (a sweep to 100 Hz keeps
    it), a valve with play follows the noise both ways, and which way the current last
    moved means nothing (the quasi-static ramp, fed its denoised command, still tells)."""
    return run.kind is RunKind.ACTUATOR_DYNAMIC and noise_a > NOISY_CURRENT_A


def _log_noise_a(run: ClassifiedRun) -> float:
    """The current log's noise where the command is quietest [A]: a low quantile of the
    estimate over NOISE_WINDOW_S pieces (a clean log's 100 Hz sweep read as 1.2 mA of
    'noise' over the whole run, and the run went unchecked)."""
    width = max(MIN_SAMPLES, round(NOISE_WINDOW_S * run.rate_hz))
    pieces = [run.current_a[i:i + width] for i in range(0, run.current_a.size, width)]
    return float(np.quantile([current_noise_a(p) for p in pieces], NOISE_QUANTILE))


def _current_rate(run: ClassifiedRun, noise: float) -> np.ndarray:
    """How fast the valve's current changes [A/s], (n,); 0 where it holds. A noisy log's
    rate is the least-squares slope over RATE_WINDOW_S, counted only beyond RATE_NOISE_Z
    times that slope's noise (10 mA of noise made every sample a 'fast change' on its own,
    and the relation went unchecked)."""
    if noise <= NOISY_CURRENT_A:
        return np.diff(run.current_a, prepend=run.current_a[0]) * run.rate_hz
    width = 2 * round(RATE_WINDOW_S * run.rate_hz / 2) + 1
    slope = scipy.signal.savgol_filter(run.current_a, width, 1, deriv=1,
                                       delta=1.0 / run.rate_hz, mode="nearest")
    floor = RATE_NOISE_Z * noise * run.rate_hz * math.sqrt(12.0 / width ** 3)
    return np.where(np.abs(slope) > floor, slope, 0.0)


VALVE_RATE_HZ = 100.0  # a valve's samples are thinned to this: closer ones add little
START_S = 0.5  # an actuator run's first samples: the model starts settled, the rig may not
TURNED = 10.0  # a term that moves the pressure this many times its own size turned A(s) over
REFINE_STEPS = 3  # Gauss-Newton steps on the kept terms' values
HALVINGS = 8  # a term tried too large for A(s) is tried again at half, at most this often
STEP_FRACTION = 1e-4  # an owned parameter's finite-difference step, of its value
MAP_TERMS = (Shaped((basis.VALVE_CURRENT,), (basis.CUBE, basis.SIGNED_ROOT))
             + Shaped((basis.VALVE_CURRENT,), (basis.IDENTITY,))
             * Shaped((basis.VALVE_CURRENT,), (basis.SIGNED_ROOT,)))
"""The static map's library: the map's variable e = I − I0 beyond the quadratic, in the
powers a map that bends takes (flow forces, a spring's progression: e³; a flow that goes as
the root of the opening: √e, e·√e); 1, e and e² are the calibration's own (the dead-band,
k1, k2)."""


class ValveLibrary(Library[Settled]):
    """The valve's static map P = k1 e + k2 e² + Σ c_k φ_k(e), e = I − I0: a map that bends
    beyond the quadratic the calibration fits. Its error is the measured pressure's excess
    over the model's on an actuator run's settled samples
    (:func:`settled_valve`), where A(s) has settled; the terms the
    calibration owns there are the map's (k1, k2, and the dead-band's shift: a constant)."""

    equation = Equation.VALVE
    relation = Relation.VALVE_MAP
    unit = "Pa"
    phase = "actuator runs, settled"
    sign = 1.0
    slot = Slot.STATIC_MAP
    terms = basis_terms(MAP_TERMS, "Pa")

    def sources(self, campaign: Campaign, params: RigParameters) -> list[Settled]:
        return [v for r in campaign.runs if not r.braking
                and (v := settled_valve(r, params)) is not None]

    def rows(self, source: Settled, params: RigParameters,
             terms: Sequence[Term[Settled]] | None = None) -> Rows | None:
        index = np.flatnonzero(source.settled)[::max(1, round(source.rate_hz / VALVE_RATE_HZ))]
        if index.size < 20:
            return None
        gain = params.number(K.ACTUATOR_GAIN)
        excess = _excess(source, params)[index]
        owned = gain * np.column_stack([np.ones_like(excess), excess, excess * excess])
        columns = term_columns(terms or self.terms, source, params, index, map_signals(excess))
        return Rows(source.residual_pa[index], gain * columns, owned,
                    float(np.mean(source.model_pa[index])))

    def law(self, written: str, params: RigParameters) -> str:
        k1, k2 = (display(params.number(k), unit, ".3g") for k, unit in (
            (K.ACTUATOR_MAP_K1_PA_PER_A, "Pa/A"), (K.ACTUATOR_MAP_K2_PA_PER_A2, "Pa/A^2")))
        return f"{MAP_LAW.format(k1=k1, k2=k2)} {written}"


def _excess(valve: Settled, params: RigParameters) -> np.ndarray:
    """The map's variable e = I − I0 ≥ 0 [A] of the current the valve was fed."""
    return el.valve_excess(valve.current_a, params.number(K.ACTUATOR_MAX_CURRENT_A),
                           params.number(K.ACTUATOR_DEADBAND_CURRENT_A))


VALVE_TERMS = (
    Shaped((basis.VALVE_ERROR,), (basis.SIGN, basis.SIGNED_SQUARE, basis.CUBE,
                                  basis.SIGNED_ROOT))
    + Shaped((basis.PRESSURE_RATE,), (basis.SIGN, basis.SIGNED_SQUARE, basis.CUBE))
    + Shaped((basis.PRESSURE,), (basis.IDENTITY,))
    * Shaped((basis.VALVE_ERROR, basis.PRESSURE_RATE), (basis.IDENTITY,))
    + Shaped((basis.PRESSURE_RATE,), (basis.SIGN,)) * Shaped((basis.VALVE_ERROR,),
                                                               (basis.IDENTITY,)))
"""A(s)'s library: what the valve asks and how fast it moves, in the shapes a spool's
friction (sgn Ṗ: the pressure held a band off the map, the side it came from), a flow that
goes as the root of the drop or a damping that goes as the square take (not √Ṗ: its
infinite slope at rest makes the plant's step ring); the pressure's products with them (a
valve stiffer or more damped at pressure); a stiffness that differs rising and falling
(sgn Ṗ·ΔP: a release unlike the apply). ΔP and Ṗ alone are ω_n's and ζ's, the
calibration's own."""


@dataclass(frozen=True)
class ValveRun:
    """An actuator run under a model: the current the valve was fed [A], A(s)'s states as
    the model steps them ((n, 3): P [Pa], Ṗ [Pa/s], the delayed static pressure [Pa]), the
    measured pressure less the model's through its channel [Pa], the model's sensitivity to
    each parameter the calibration owns in A(s) ((n, j) [Pa per unit]), its rate [Hz], and
    what the logger's noise left in the current it was fed makes of the model's pressure
    ((n,) [Pa], one draw; zeros: none given), and the samples its error is read on
    (``ClassifiedRun.compared``: not those the logger lost)."""

    current_a: np.ndarray
    states: np.ndarray
    residual_pa: np.ndarray
    owned: np.ndarray
    matrices: np.ndarray
    rate_hz: float
    noise_pa: np.ndarray
    compared: np.ndarray


OWNED = (*ACTUATOR, K.ACTUATOR_GAIN, *STATIC_MAP[:3], K.ACTUATOR_DELAY_S)


def valve_run(run: ClassifiedRun, params: RigParameters, noise_a: float = 0.0) -> ValveRun:
    """``run`` under ``params`` (see :class:`ValveRun`), its logger's current noise
    ``noise_a`` [A] (:func:`command_noise_a`)."""
    current = logged_to_held(run.command_a)
    vector = params.vector()
    matrices = actuator_matrices(vector, 1.0 / run.rate_hz)
    states = settled_states(vector, matrices, current)
    channel = SensorModel.of(params).pressure_channel
    residual = run.pressure_pa - channel(run.time_s, states[:, 0])
    fed = run.fed_noise_a(noise_a)
    noise = np.zeros(current.size) if fed == 0.0 else settled_states(
        vector, matrices, current + fed * np.random.default_rng(0).standard_normal(
            current.size))[:, 0] - states[:, 0]
    return ValveRun(current, states, residual,
                    _sensitivities(params, current, run.rate_hz, states[:, 0]),
                    matrices, run.rate_hz, noise, run.compared)


def command_noise_a(runs: Sequence[ClassifiedRun]) -> float:
    """The logger's white noise on the current [A]: the least of the actuator runs' (one
    logger wrote them all; a clean 200 Hz sweep's own steps read as 3.5 mA of it, a
    ramp's read nothing)."""
    return min((current_noise_a(r.current_a) for r in runs if not r.braking), default=0.0)


def _owned(params: RigParameters) -> tuple[str, ...]:
    """The owned parameters of A(s) under ``params``: the delay only where it has one."""
    return tuple(k for k in OWNED if k != K.ACTUATOR_DELAY_S or params.has("actuator_delay"))


def _moved(params: RigParameters, codes: list[int], values: np.ndarray, owned: np.ndarray
           ) -> RigParameters | None:
    """``params`` with the terms ``codes`` at ``values`` in the free places of A(s)'s slot
    and the owned parameters moved by ``owned`` (None: a step out of their bounds)."""
    changes = {key: params.number(key) + shift for key, shift in zip(_owned(params), owned,
                                                                      strict=True)}
    free = [pair for pair in Slot.VALVE.keys if params.number(pair[1]) == 0.0]
    for (code_key, coeff_key), code, value in zip(free, codes, values, strict=False):
        changes[code_key], changes[coeff_key] = float(code), float(value)
    try:
        return params.replace(changes, "refined")
    except ParameterError:
        return None


def _sensitivities(params: RigParameters, current_a: np.ndarray, rate_hz: float,
                   model_pa: np.ndarray) -> np.ndarray:
    """The model pressure's change per unit of each owned parameter, (n, j)."""
    columns = []
    for key in _owned(params):
        value = params.number(key)
        step = STEP_FRACTION * max(abs(value), 1e-3 if key == K.ACTUATOR_DELAY_S else 1e-6)
        moved = params.replace({key: value + step}, "sensitivity").vector()
        pressure = settled_states(moved, actuator_matrices(moved, 1.0 / rate_hz),
                                  current_a)[:, 0]
        columns.append((pressure - model_pa) / step)
    return np.column_stack(columns)


def valve_signals(states: np.ndarray, gain: float) -> np.ndarray:
    """``model.basis``'s signals A(s)'s slot sees at ``states`` (:class:`ValveRun`'s),
    (n, N_SIGNALS)."""
    out = np.zeros((states.shape[0], basis.N_SIGNALS))
    out[:, basis.PRESSURE] = states[:, 0]
    out[:, basis.PRESSURE_RATE] = states[:, 1]
    out[:, basis.VALVE_ERROR] = gain * states[:, 2] - states[:, 0]
    return seen(Slot.VALVE, out)


def _free_place(params: RigParameters) -> int | None:
    """The first free place of A(s)'s slot (its code's index in the vector; None: full)."""
    free = [code for code, coeff in Slot.VALVE.keys if params.number(coeff) == 0.0]
    return INDEX[free[0]] if free else None


def _secant(v: ValveRun, params: RigParameters, code: int, place: int) -> np.ndarray:
    """The model pressure's change per unit of the term ``code``'s coefficient [Pa per unit],
    (n,): the run simulated with the term tried at a coefficient that takes at most the
    error's rms off A(s)'s input along the model's states (a secant over the size of what
    is to be explained: a spool's friction is no linear law), halved while that turns A(s)
    over (moves the pressure TURNED times the size). The plant's own step, so a friction
    holds the model a band off where it settles (a derivative at 0 sees nothing there);
    taken off, as a friction's is (a sign term pushing the spool on is another law, a relay
    that chatters about the map)."""
    signals = valve_signals(v.states, params.number(K.ACTUATOR_GAIN))
    largest = float(np.max(np.abs(basis.term_values(code, signals))))
    size = float(np.sqrt(np.mean(v.residual_pa ** 2)))
    vector = params.vector().copy()
    vector[place] = float(code)
    for _ in range(HALVINGS if largest > 0.0 else 0):
        vector[place + 1] = coeff = -size / largest
        change = settled_states(vector, v.matrices, v.current_a)[:, 0] - v.states[:, 0]
        if np.all(np.abs(change) < TURNED * size):
            return change / coeff
        size /= 2.0
    return np.zeros(v.states.shape[0])


class ValveDynamicsLibrary(Library[ValveRun]):
    """A(s): P̈ = ω_n² (μ P_static + Σ c_k φ_k − P) − 2 ζ ω_n Ṗ: a spool that sticks, a
    valve that stiffens with pressure, a release unlike the apply. Its error is the
    measured pressure less the model's over an actuator run (after its first
    :data:`START_S`), thinned to :data:`VALVE_RATE_HZ`; owned: ω_n, ζ, μ, the map, the
    delay."""

    equation = Equation.VALVE
    relation = Relation.VALVE_DYNAMICS
    unit = "Pa"
    phase = "actuator runs"
    sign = 1.0
    slot = Slot.VALVE
    # a quarter per cent of the mean model pressure (0.08 bar of 30): a second stage that
    # moved a sweep by 1 bar rms left 0.11 bar at 20σ once ω_n had taken the rest, and came
    # out `none` under the half per cent; the nulls' A(s) checks sit at 1-2σ, 0.6-1.7 kPa
    min_effect = 0.0025
    terms = basis_terms(VALVE_TERMS, "Pa")

    def select(self, campaign: Campaign, params: RigParameters) -> list[Selected]:
        """The kept terms, their values refined by Gauss-Newton steps with the owned
        parameters (a stiffening the calibration took into ω_n is half a term's first
        fit: the error is linearised about a model that is not the rig's); a term the
        refined fit does not find is dropped, the weakest first."""
        chosen = super().select(campaign, params)
        if any(s.term.code is None for s in chosen):
            return chosen
        runs = [r for r in campaign.runs if not r.braking]
        while chosen:
            refined = self._refined(runs, params, chosen)
            if refined is None:
                return chosen
            values, t = refined
            if len(chosen) == 1 or t.min() >= Z_VIOLATED:
                return [replace(s, value=float(v), t=float(z))
                        for s, v, z in zip(chosen, values, t, strict=True)]
            chosen = [s for i, s in enumerate(chosen) if i != int(np.argmin(t))]
        return chosen

    def _refined(self, runs: Sequence[ClassifiedRun], params: RigParameters,
                 chosen: list[Selected]) -> tuple[np.ndarray, np.ndarray] | None:
        """The ``chosen`` terms' values after REFINE_STEPS Gauss-Newton steps, and each
        value over its σ there (None: a step left the owned parameters' bounds)."""
        terms = [s.term for s in chosen]
        values, owned = np.array([s.value for s in chosen]), np.zeros(len(_owned(params)))
        t = np.full(values.size, np.inf)
        for _ in range(REFINE_STEPS):
            trial = _moved(params, [int(s.term.code or 0) for s in chosen], values, owned)
            # a step the valve may not survive runs its states off to inf: the check below
            # says so, where numpy's warnings had reached the terminal
            with np.errstate(over="ignore", invalid="ignore"):
                rows = [r for run in runs if trial is not None
                        and (r := self.rows(valve_run(run, trial), trial, terms)) is not None]
            if trial is None or not rows:
                return None
            design = np.vstack([np.hstack([r.terms, r.owned]) for r in rows])
            error = np.concatenate([r.error for r in rows])
            if not (np.isfinite(design).all() and np.isfinite(error).all()):
                return None  # a step the valve does not survive (a release fitted on one apply)
            step, z = ordinary_fit(design, error)
            values, owned = values + step[:values.size], owned + step[values.size:]
            sigma = np.abs(step[:values.size]) / np.maximum(z[:values.size], 1e-300)
            t = np.abs(values) / np.maximum(sigma, 1e-300)
        return values, t

    def sources(self, campaign: Campaign, params: RigParameters) -> list[ValveRun]:
        if not params.has("actuator_dynamics"):
            return []
        noise = command_noise_a(campaign.runs)
        return [valve_run(r, params, noise) for r in campaign.runs if not r.braking]

    def rows(self, source: ValveRun, params: RigParameters,
             terms: Sequence[Term[ValveRun]] | None = None) -> Rows | None:
        n = source.residual_pa.size
        index = np.arange(round(START_S * source.rate_hz), n,
                          max(1, round(source.rate_hz / VALVE_RATE_HZ)))
        # a step the logger lost is bridged by a line through it: an error of the whole
        # step (1.8 MPa), no term of A(s), whose structure took every term's σ
        index = index[source.compared[index]]
        if index.size < 20:
            return None
        scale = float(np.mean(np.abs(source.states[index, 0])))
        place = _free_place(params)
        if place is None:
            return None
        columns = [_secant(source, params, t.code, place)
                   if t.code is not None else variable(t, source, params)
                   for t in terms or self.terms]
        # a noisy current fed to the model is errors in the variables: its √ΔP and sgn Ṗ
        # read a null's 200 Hz log (6.7 mA) at 12.6 kPa and 7σ
        return Rows(source.residual_pa[index], np.column_stack(columns)[index],
                    source.owned[index], scale,
                    input_noise=float(np.sqrt(np.mean(source.noise_pa[index] ** 2))))

    def law(self, written: str, params: RigParameters) -> str:
        wn = display(params.number(K.ACTUATOR_NATURAL_FREQUENCY_HZ), "Hz", ".3g")
        zeta = params.number(K.ACTUATOR_DAMPING_RATIO)
        return (DYNAMICS_LAW.format(slot=f" {written}", zeta=f"{zeta:.3g}")
                + f", ω_n = 2π·{wn}")


VALVE = ValveLibrary()


VALVE_DYNAMICS = ValveDynamicsLibrary()


def valve_direction(run: ClassifiedRun, params: RigParameters) -> Check | None:
    """Measured minus model pressure where the current fell last, against where it rose
    last (on the settled samples, :func:`settled_valve`): a static map
    cannot tell the two apart, a valve with play can. Positive: more pressure on the way
    down."""
    valve = settled_valve(run, params)
    if valve is None:
        return None
    falling, rising = (valve.residual_pa[valve.settled & (valve.direction == s)]
                       for s in (-1.0, 1.0))
    if min(falling.size, rising.size) < MIN_CHECK_S * run.rate_hz:
        return None
    std = math.sqrt(sum(float(np.var(r)) / effective_count(r - r.mean())
                        for r in (falling, rising)))
    return Check(Relation.VALVE_DIRECTION, run.name, "slow current changes",
                 float(falling.mean() - rising.mean()), std, PRESSURE_FLOOR_PA, "Pa")


def output_error(run: ClassifiedRun, simulated: Run) -> np.ndarray:
    """The valve's output error: the measured pressure less the model's [Pa]."""
    return run.pressure_pa - simulated.pressure_pa


def error(run: ClassifiedRun, b: Braking, params: RigParameters, simulated: Run
          ) -> np.ndarray:
    """The valve's error in a braking run: its output error [Pa]."""
    return output_error(run, simulated)


DECLARED = Declared(f"P = A(s)·P_static, {DYNAMICS_LAW.format(slot='', zeta='ζ')}, "
                    f"{MAP_LAW.format(k1='k1', k2='k2')} (valve pressure)", "pressure_pa", (
    Checking((Relation.VALVE_DIRECTION,), Reads.ACTUATOR_RUN, valve_direction),
    Checking((Relation.VALVE_MAP,), Reads.CAMPAIGN, VALVE.check),
    Checking((Relation.VALVE_DYNAMICS,), Reads.CAMPAIGN, VALVE_DYNAMICS.check)))
