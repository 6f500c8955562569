"""Discovery of terms the catalogue lacks (issue 14, part 3: brake torque, load-cell channels,
the wheel channel's timing and its ripple with the wheel's angle, the valve's play, the
tyre's friction in load).

When the brake-gain consistency checks are violated, the wheel's torque balance
r F_x − J_w ω̇ = k_b P (1 + Σ c_i x_i) is regressed on a library of physical terms x_i
with a sparse solver (scikit-learn's LARS lasso, its penalty chosen by BIC): the fewest terms
that explain the gain's variation are kept. When the free-rolling relation is violated, what
the F_x channel reads where the true F_x is known (before braking: the wheel's inertia force;
off the ground: 0) is regressed the same way on the other channels it may carry. Each kept
term fills the model's slot for it (the brake gain's slopes, the sensors' crosstalk), and
the extension is scored exactly like a catalogue candidate: fitted with the parameters it
distorted, ΔBIC against the same re-fit without it, and the gain on held-out runs. A term
that passes is reported as ``discovered`` with its family and its formula, never under a
catalogue name.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
import scipy.linalg

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.identify import identify
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.wheel_angle import (
    BRAKE_RUNOUT_KEYS,
    ORDERS,
    TREND,
    brake_ripple,
    ripple_design,
)
from landing_gear_sim.diagnosis.catalogue import (
    ACTUATOR,
    ACTUATOR_RUNS,
    BRAKE_RUNS,
    FRICTION,
    PRESSURE,
    STATIC_MAP,
    WHEEL,
    Candidate,
)
from landing_gear_sim.diagnosis.consistency import (
    BRAKE_RUNOUT_FLOOR,
    FORCE_FLOOR_N,
    RUNOUT_FLOOR,
    free_rolling_excess,
)
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import reference_load_n
from landing_gear_sim.model.sensors import RUNOUT_KEYS
from msg_tools.units import PA_PER_BAR

DISCOVERED = "discovered"
DECIMATE = 100  # samples: the balance's residual is smooth; BIC must not count it 100x
MIN_RELATIVE_EFFECT = 0.02  # a term changing the gain by less over its range is dropped
RUNOUT_DECIMATE = 3  # samples: keeps a twice-per-revolution ripple at 60 m/s (62 Hz) resolved


@dataclass(frozen=True)
class Term:
    """A term of a library: its family, the model slot that holds its coefficient, its
    symbol in the formula, and the coefficient's admissible magnitude."""

    family: str
    key: str
    symbol: str
    bound: float  # |coefficient| admissible [1/unit of the term]


TermT = TypeVar("TermT", bound=Term)


@dataclass(frozen=True)
class LibraryTerm(Term):
    """A physical term the brake gain may depend on."""

    values: Callable[[br.Braking], np.ndarray]


BRAKE_LIBRARY = (
    LibraryTerm("sliding_speed", "brake.gain_slope_wheel_speed_s_per_rad", "ω", 1 / 200.0,
                lambda b: b.wheel),
    LibraryTerm("pressure_level", "brake.gain_slope_pressure_per_pa", "P", 1 / 60e5,
                lambda b: b.pressure),
)


def select_brake_terms(runs: Sequence[br.Braking], params: RigParameters
                       ) -> dict[LibraryTerm, float]:
    """Terms of BRAKE_LIBRARY the torque balance of ``runs`` needs, with their coefficient
    (the sparse fit's, a start for the output-error fit)."""
    ratio, columns = [], []
    for b in runs:
        torque, _ = br.torque_balance(b, params)
        m = np.flatnonzero(br.steady_braking_samples(b))[::DECIMATE]
        ratio.append(torque[m] / (params.number("brake.gain_n_m_per_pa") * b.pressure[m]))
        columns.append(np.column_stack([t.values(b)[m] for t in BRAKE_LIBRARY]))
    y, x = np.concatenate(ratio), np.vstack(columns)
    if y.size < 4 * len(BRAKE_LIBRARY):
        return {}
    coefficients = sparse_coefficients(x, y) / np.mean(y)
    return {term: float(c) for term, c, span in zip(BRAKE_LIBRARY, coefficients, np.ptp(x, axis=0),
                                                     strict=True)
            if abs(c) * span > MIN_RELATIVE_EFFECT}


def sparse_coefficients(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """y ≈ c₀ + x c by the LARS lasso with its penalty chosen by BIC, on standardised
    columns: c in the units of x's columns (0 for a term left out), shape (k,)."""
    # imported here: scikit-learn costs ~1 s to import and most diagnoses never get here
    from sklearn.linear_model import LassoLarsIC

    spread = x.std(axis=0)
    fit = LassoLarsIC(criterion="bic").fit((x - x.mean(axis=0)) / spread, y)
    return np.asarray(fit.coef_) / spread


@dataclass(frozen=True)
class ChannelTerm(Term):
    """Another measured channel the F_x channel may carry (the coefficient: a fraction)."""

    values: Callable[[ClassifiedRun], np.ndarray]


CHANNEL_LIBRARY = (
    ChannelTerm("channel_crosstalk", "sensors.crosstalk_fx_per_fz", "F_z", 0.1,
                lambda r: r.vertical_load_n),
)


def select_channel_terms(runs: Sequence[ClassifiedRun], braking: Sequence[br.Braking],
                         params: RigParameters) -> dict[ChannelTerm, float]:
    """The channels the F_x channel carries, with their fractions, where the true F_x is
    known: before braking (``braking``: the braking runs prepared) and off the ground (the
    other ``runs``); sparse regression, BIC; kept when they move F_x by more than the
    consistency floor."""
    excess, columns = [], []
    for b in braking:
        mask, y = free_rolling_excess(b, params)
        excess.append(y[::DECIMATE])
        columns.append(_channels(b.run, mask))
    for run in runs:
        if not run.braking:
            excess.append(run.longitudinal_force_n[::DECIMATE])
            columns.append(_channels(run, np.ones(len(run), dtype=bool)))
    y, x = np.concatenate(excess), np.vstack(columns)
    if y.size < 4 * len(CHANNEL_LIBRARY):
        return {}
    fractions = sparse_coefficients(x, y)
    return {term: float(c) for term, c, top in zip(CHANNEL_LIBRARY, fractions,
                                                   np.max(np.abs(x), axis=0), strict=True)
            if abs(c) * top > FORCE_FLOOR_N}


def _channels(run: ClassifiedRun, mask: np.ndarray) -> np.ndarray:
    """The library's channels of ``run`` at ``mask``, decimated, shape (m, k)."""
    return np.column_stack([t.values(run)[mask] for t in CHANNEL_LIBRARY])[::DECIMATE]


def channel_candidate(terms: dict[ChannelTerm, float]) -> Candidate:
    """The kept channel terms as a candidate: fitted with what a crosstalk distorts in the
    calibration (the brake gain of the torque balance, the friction curve of μ = F_x/F_z,
    the flywheel inertia and drag of its momentum balance: without the drag the fraction
    came out 9 % high)."""
    return _term_candidate(terms, ("brake.gain_n_m_per_pa", "flywheel.inertia_kg_m2",
                                   "drag.coeff_n_s2_per_m2", *FRICTION),
                           (*WHEEL, "flywheel_speed_rad_s"))


SKEW_KEY = "sensors.wheel_speed_delay_s"
SKEW_BOUNDS = (0.0, 0.2)  # s


def skew_candidate(lag_s: float) -> Candidate:
    """The wheel channel out of step by ``lag_s`` (the residual's consistent lag) as a
    candidate: fitted with the friction curve (slip read from a late wheel bent it)."""
    return Candidate(DISCOVERED, None, (SKEW_KEY,), ((lag_s,),), (SKEW_BOUNDS,), FRICTION,
                     BRAKE_RUNS, WHEEL, (), (("wheel_speed_delay_s", SKEW_KEY),))


PRESSURE_SKEW_KEY = "sensors.pressure_delay_s"


def pressure_skew_candidate(lag_s: float, params: RigParameters) -> Candidate:
    """The pressure channel out of step by ``lag_s`` (the torque-timing relation's reading)
    as a candidate: fitted with the valve's dynamics (calibrated on a late reading, A(s)
    came out slow, or a transport delay stood in for it) on the actuator runs, which pin
    A(s), and half the braking runs, whose wheel channels show the brake's true timing;
    checked on the other half."""
    delay = ("actuator.delay_s",) if params.has("actuator_delay") else ()
    return Candidate(DISCOVERED, None, (PRESSURE_SKEW_KEY,), ((min(max(lag_s, 1e-4), 0.09),),),
                     ((0.0, 0.1),), (*ACTUATOR, *delay), (*ACTUATOR_RUNS, *BRAKE_RUNS),
                     (*PRESSURE, *WHEEL), (), (("pressure_delay_s", PRESSURE_SKEW_KEY),))


def pressure_skew_start(runs: Sequence[ClassifiedRun], params: RigParameters, lag_s: float
                        ) -> RigParameters:
    """Where a pressure skew's fit starts: ``params`` calibrated again with the channel
    ``lag_s`` late. Calibrated on the late reading, A(s) came out slow (8.2 Hz for 12) and the
    friction curve bent to the late brake it made: from there the fit stopped half-way (a
    6.3 ms skew for 11.6), the true timing locking the wheel where the rig's did not."""
    late = params.replace({PRESSURE_SKEW_KEY: lag_s}, "the pressure channel late")
    calibration = identify(runs, late, jackknife=False)
    return calibration.params.replace({PRESSURE_SKEW_KEY: 0.0}, "the skew to be fitted")


BACKLASH_KEY = "actuator.backlash_a"
BACKLASH_BOUNDS = (0.0, 0.2)  # A: a fifth of the valve's range


def backlash_candidate(excess_pa: float, params: RigParameters) -> Candidate:
    """A valve with play (``input_history``): it sees the current only once that has moved
    the backlash w the other way, so on the way down it holds ``excess_pa`` more than on
    the way up, ≈ k1·w. Fitted with the static map (fitted across both directions, it
    averaged the play away) on the actuator runs, checked on the braking runs' pressure."""
    start = min(max(excess_pa / params.number("actuator.map_k1_pa_per_a"), 1e-3),
                BACKLASH_BOUNDS[1])
    return Candidate(DISCOVERED, None, (BACKLASH_KEY,), ((start,),), (BACKLASH_BOUNDS,),
                     STATIC_MAP, ACTUATOR_RUNS, PRESSURE, BRAKE_RUNS,
                     (("backlash_a", BACKLASH_KEY),))


DRIFT_KEY = "brake.gain_drift_per_run"
DRIFT_BOUNDS = (-0.2, 0.2)  # per run: a fifth of k_b from one run to the next at most


def drift_candidate(change: float, braking_runs: int) -> Candidate:
    """k_b moving from one braking run to the next (``run_drift``: wear, bedding in),
    started at the consistency check's first-to-last ``change`` spread over the runs and
    fitted with k_b and the friction curve; checked on half the braking runs."""
    start = change / max(braking_runs - 1, 1)
    return Candidate(DISCOVERED, None, (DRIFT_KEY,), ((start,),), (DRIFT_BOUNDS,),
                     ("brake.gain_n_m_per_pa", *FRICTION), BRAKE_RUNS, WHEEL, (),
                     (("gain_drift_per_run", DRIFT_KEY),))


RUNOUT_BOUNDS = (0.0, 0.1)  # relative: a tenth of ω at most


def select_runout_orders(runs: Sequence[ClassifiedRun]) -> dict[str, float]:
    """The orders of the wheel channel's ripple with the wheel's angle that the free rolling
    of ``runs`` needs (sparse regression on cos(mθ), sin(mθ) of each run: a run has a phase
    of its own), with the median amplitude over the runs: ``sensors.wheel_runout_m`` ->
    relative amplitude, kept above the consistency floor."""
    fitted = [f for f in (ripple_design(r) for r in runs if r.braking) if f is not None]
    if not fitted:
        return {}
    detrended, waves = [], []
    for y, design in fitted:
        trend = design[:, :TREND]
        coef, *_ = np.linalg.lstsq(trend, y, rcond=None)
        detrended.append((y - trend @ coef)[::RUNOUT_DECIMATE])
        waves.append(design[::RUNOUT_DECIMATE, TREND:])
    coef = sparse_coefficients(scipy.linalg.block_diag(*waves), np.concatenate(detrended))
    pairs = coef.reshape(len(fitted), len(ORDERS), 2)
    amplitude = np.median(np.hypot(pairs[..., 0], pairs[..., 1]), axis=0)
    return {RUNOUT_KEYS[2 * i]: float(a) for i, a in enumerate(amplitude) if a > RUNOUT_FLOOR}


def runout_candidate(orders: dict[str, float]) -> Candidate:
    """The wheel encoder rippling once or twice per revolution (``wheel_angle``) at the kept
    orders, each run at its own phase: fitted alone on the braking runs' wheel channel (the
    ripple averages out of everything the calibration fitted)."""
    keys = tuple(orders)
    return Candidate(DISCOVERED, None, keys, (tuple(orders.values()),),
                     tuple(RUNOUT_BOUNDS for _ in keys), (), BRAKE_RUNS,
                     ("wheel_speed_rad_s",), (), tuple((k.split(".")[1], k) for k in keys))


BRAKE_RUNOUT_BOUNDS = (0.0, 0.3)  # relative: a third of the torque at most


def select_brake_runout_orders(runs: Sequence[ClassifiedRun], params: RigParameters
                               ) -> dict[str, float]:
    """The orders of the brake torque's ripple with the wheel's angle that the braking runs
    need, with the median amplitude over the runs (``brake.runout_m`` -> relative
    amplitude), kept above the consistency floor."""
    ripples = [r for r in (brake_ripple(run, params) for run in runs if run.braking)
               if r is not None]
    if not ripples:
        return {}
    amplitude = np.median([r.amplitude for r in ripples], axis=0)
    return {BRAKE_RUNOUT_KEYS[2 * i]: float(a) for i, a in enumerate(amplitude)
            if a > BRAKE_RUNOUT_FLOOR}


def brake_runout_candidate(orders: dict[str, float]) -> Candidate:
    """The brake torque rippling once or twice per wheel revolution (``wheel_angle``: a
    disc's run-out) at the kept orders, each run at its own phase: fitted alone on the
    braking runs' wheel channels."""
    keys = tuple(orders)
    return Candidate(DISCOVERED, None, keys, (tuple(orders.values()),),
                     tuple(BRAKE_RUNOUT_BOUNDS for _ in keys), (), BRAKE_RUNS, WHEEL, (),
                     tuple((f"brake_{k.split('.')[1]}", k) for k in keys))


LOAD_KEY = "friction.load_sensitivity_per_n"


def load_candidate(start_per_n: float, params: RigParameters) -> Candidate:
    """μ scaled by 1 − κ (F_z − F_ref) (``load``: a tyre's load sensitivity), started at
    ``start_per_n`` [1/N] (from the consistency check) and fitted with the friction curve
    (which the calibration bent to it) on the braking runs."""
    bound = 0.5 / params.number("loading.static_load_n")  # μ halved across F_z0 at most
    start = float(np.clip(start_per_n, -0.9 * bound, 0.9 * bound))
    return Candidate(DISCOVERED, None, (LOAD_KEY,), ((start,),), ((-bound, bound),), FRICTION,
                     BRAKE_RUNS, WHEEL, (), (("load_sensitivity_per_n", LOAD_KEY),))


def discovered_candidate(terms: dict[LibraryTerm, float]) -> Candidate:
    """The kept brake terms as a candidate, fitted with k_b and the friction curve."""
    return _term_candidate(terms, ("brake.gain_n_m_per_pa", *FRICTION), WHEEL)


def _term_candidate(terms: Mapping[TermT, float], free: tuple[str, ...],
                    channels: tuple[str, ...]) -> Candidate:
    """Kept library terms (started at their sparse fit, within ±bound) as a candidate the
    scoring treats like a catalogue entry, fitted on the braking runs."""
    chosen = list(terms)
    return Candidate(DISCOVERED, None, tuple(t.key for t in chosen),
                     (tuple(terms[t] for t in chosen),),
                     tuple((-t.bound, t.bound) for t in chosen), free, BRAKE_RUNS, channels,
                     (), tuple((t.key.split(".")[1], t.key) for t in chosen))


def families(candidate: Candidate) -> str:
    if set(candidate.keys) & {*RUNOUT_KEYS, *BRAKE_RUNOUT_KEYS}:
        return "wheel_angle"
    if {SKEW_KEY, PRESSURE_SKEW_KEY} & set(candidate.keys):
        return "channel_skew"
    if LOAD_KEY in candidate.keys:
        return "load"
    if BACKLASH_KEY in candidate.keys:
        return "input_history"
    if DRIFT_KEY in candidate.keys:
        return "run_drift"
    return "+".join(t.family for t in (*BRAKE_LIBRARY, *CHANNEL_LIBRARY)
                    if t.key in candidate.keys)


def _waves(candidate: Candidate, params: RigParameters, keys: Sequence[str]) -> str:
    """The ripple's orders among ``keys`` (amplitude, phase, ...) that ``candidate`` fits."""
    return " + ".join(f"{100 * params.number(k):.2f} %·cos({m}θ + φ{m})" for m, k in
                      zip(ORDERS, keys[::2], strict=True) if k in candidate.keys)


def term_formula(candidate: Candidate, params: RigParameters) -> str:
    """The extended law with its fitted values, e.g. ``T_b = k_b·P·(1 − 6.4e-04·ω)`` or
    ``F_x,read = F_x + 0.0123·F_z``."""
    if set(candidate.keys) & set(RUNOUT_KEYS):
        return f"ω_read = ω·(1 + {_waves(candidate, params, RUNOUT_KEYS)}), θ: wheel angle, " \
            "φ: each run's own"
    if set(candidate.keys) & set(BRAKE_RUNOUT_KEYS):
        gain = params.number("brake.gain_n_m_per_pa") * PA_PER_BAR
        return (f"T_b = {gain:.4g} N m/bar·P·(1 + {_waves(candidate, params, BRAKE_RUNOUT_KEYS)}"
                "), θ: wheel angle, φ: each run's own")
    if SKEW_KEY in candidate.keys:
        return f"ω_read(t) = ω(t − {1e3 * params.number(SKEW_KEY):.1f} ms)"
    if PRESSURE_SKEW_KEY in candidate.keys:
        return f"P_read(t) = P(t − {1e3 * params.number(PRESSURE_SKEW_KEY):.1f} ms)"
    if LOAD_KEY in candidate.keys:
        per_kn = 1e5 * params.number(LOAD_KEY)
        reference = reference_load_n(params)
        return (f"μ = μ_B(λ)·(1 {'−' if per_kn >= 0 else '+'} {abs(per_kn):.3f} %/kN·(F_z − "
                f"{reference / 1e3:.1f} kN))")
    if BACKLASH_KEY in candidate.keys:
        half = 500 * params.number(BACKLASH_KEY)
        return f"P_static = map(i_v), i_v = play(i, ±{half:.1f} mA)"
    if DRIFT_KEY in candidate.keys:
        gain = params.number("brake.gain_n_m_per_pa") * PA_PER_BAR
        return (f"k_b,i = {gain:.4g} N m/bar·(1 {100 * params.number(DRIFT_KEY):+.2f} %·"
                "(i − ī)), i: braking run in run order")
    channels = [t for t in CHANNEL_LIBRARY if t.key in candidate.keys]
    if channels:
        values = [params.number(t.key) for t in channels]
        return "F_x,read = F_x " + " ".join(f"{'+' if v >= 0 else '−'} {abs(v):.4g}·{t.symbol}"
                                             for t, v in zip(channels, values, strict=True))
    parts = []
    for t in BRAKE_LIBRARY:
        if t.key in candidate.keys:
            value = params.number(t.key) * (PA_PER_BAR if t.symbol == "P" else 1.0)
            unit = "·P[bar]" if t.symbol == "P" else "·ω[rad/s]"
            parts.append(f"{'+' if value >= 0 else '−'} {abs(value):.3g}{unit}")
    gain = params.number("brake.gain_n_m_per_pa") * PA_PER_BAR
    return f"T_b = {gain:.4g} N m/bar·P·(1 {' '.join(parts)})"
