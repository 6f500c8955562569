"""Each equation's library of terms, and its error regressed on it (issue 29).

Every effect, catalogued or not, is a missing term in one of the rig's equations. For the
valve's static map, the wheel's torque balance, the flywheel's momentum balance and the
loading device's law, the error is computed from the measured signals under the model (the
other equations' terms measured) over the samples that carry it: the actuator runs' settled
ones for the valve, every braking run's thinned to the filter's bandwidth for the others.
It is regressed on the equation's library — the terms of its generic slot in the plant
(``actuator.extra_*``, ``wheel.extra_*``, ``flywheel.extra_*``, ``loading.extra_*``),
beside the terms whose coefficients the calibration owns (the map's 1, e, e²; k_b P in the
wheel's; the flywheel's mass and drag; the lift) — by a sparse solver (scikit-learn's LARS
lasso, BIC). A term the lasso keeps is significant when an ordinary fit of the kept and owned
terms finds it against the error's own noise (t over the error's effective count, above
:data:`Z_VIOLATED`) and large enough to matter (:data:`MIN_EFFECT` of the equation's scale):
the equation's relation (:class:`~.relations.Relation`) is then violated, and the equation's
family (:mod:`~.families.equation_terms`) proposes the term.
"""

from __future__ import annotations

import abc
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.equations import Equation
from landing_gear_sim.diagnosis.relations import Z_VIOLATED, Check, Relation
from landing_gear_sim.diagnosis.scoring import effective_count
from landing_gear_sim.diagnosis.settled_valve import Settled, settled_valve
from landing_gear_sim.diagnosis.sparse import sparse_coefficients
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.units import display

MIN_EFFECT = 0.005  # a term's rms effect over the equation's scale: half a per cent
EDGE_S = 0.5  # the zero-phase filter's ends are left out
SETTLE_S = 0.5  # after the touch-down ramp, before the loading device's load is its law
VALVE_RATE_HZ = 100.0  # a valve's settled samples are thinned to this: closer ones add little

S = TypeVar("S")  # what a library reads one run's rows from: a braking run's signals, ...


@dataclass(frozen=True)
class Term(Generic[S]):
    """A term of an equation's generic slot: its key (the coefficient), how it is written
    in the law (``symbol``, '' for a constant), the coefficient's SI unit and admissible
    magnitude, and its variable as the term enters the equation's error (coefficient 1),
    from what the library reads a run from and the model."""

    key: str
    symbol: str
    unit: str
    bound: float
    values: Callable[[S, RigParameters], np.ndarray]


@dataclass(frozen=True)
class Rows:
    """One run's regression rows: the equation's error, its library's terms (m, k), the
    terms the calibration owns (m, j), and the equation's scale [its unit]."""

    error: np.ndarray
    terms: np.ndarray
    owned: np.ndarray
    scale: float


@dataclass(frozen=True)
class Selected:
    """A term the equation's error needs: its fitted value, its t and its rms effect."""

    term: Term
    value: float
    t: float
    effect: float


@dataclass(frozen=True)
class Campaign:
    """What the libraries read: a campaign's runs, and its braking runs' filtered signals
    under the model (prepared once)."""

    runs: Sequence[ClassifiedRun]
    braking: Sequence[br.Braking]


class Library(abc.ABC, Generic[S]):
    """One equation's generic slot (see the module docstring): its ``terms``, the relation
    that says whether its error needs them, the unit of its error, the runs it reads
    (``phase``, in words), and the sign its terms are written with in its law (−1: they
    oppose, as a bearing's friction)."""

    equation: Equation
    relation: Relation
    terms: tuple[Term[S], ...]
    unit: str
    phase: str
    sign: float = -1.0

    @abc.abstractmethod
    def sources(self, campaign: Campaign, params: RigParameters) -> list[S]:
        """What each run that carries the equation's error gives to read it from."""

    @abc.abstractmethod
    def rows(self, source: S, params: RigParameters,
             terms: Sequence[Term[S]] | None = None) -> Rows | None:
        """The regression rows of one run on ``terms`` (default: the library's; None: the
        run has no samples to give)."""

    @abc.abstractmethod
    def law(self, written: str, params: RigParameters) -> str:
        """The equation with its slot's terms ``written`` out in it."""

    def select(self, campaign: Campaign, params: RigParameters) -> list[Selected]:
        """The library's terms the equation's error needs under ``params``."""
        rows = self._rows(campaign, params)
        return [s for s in _fit(self.terms, rows) if _significant(s, rows)] if rows else []

    def check(self, campaign: Campaign, params: RigParameters) -> Check | None:
        """The equation's relation over the campaign: its strongest term (None: no run to
        tell)."""
        rows = self._rows(campaign, params)
        fitted = _fit(self.terms, rows) if rows else []
        if not fitted:
            return None
        strongest = max(fitted, key=lambda s: s.t)
        floor = MIN_EFFECT * _scale(rows)
        return Check(self.relation, "campaign", f"{self.phase}, {strongest.term.key}",
                     strongest.effect, strongest.effect / strongest.t, floor, self.unit)

    def _rows(self, campaign: Campaign, params: RigParameters) -> list[Rows]:
        return [r for s in self.sources(campaign, params)
                if (r := self.rows(s, params)) is not None]


class BrakingLibrary(Library[br.Braking]):
    """A library read from the braking runs."""

    phase = "braking runs"

    def sources(self, campaign: Campaign, params: RigParameters) -> list[br.Braking]:
        return list(campaign.braking)


def _fit(terms: Sequence[Term[Any]], rows: Sequence[Rows]) -> list[Selected]:
    """The terms the lasso keeps among ``terms`` and the owned ones (all of ``terms`` when it
    keeps none: the relation is checked all the same), each with its ordinary fit beside the
    owned terms."""
    y = np.concatenate([r.error for r in rows])
    x, owned = np.vstack([r.terms for r in rows]), np.vstack([r.owned for r in rows])
    if y.size < 10 * (x.shape[1] + owned.shape[1]):
        return []
    lasso = sparse_coefficients(np.hstack([x, owned]), y, intercept=False)
    kept = [int(i) for i in np.flatnonzero(lasso[:len(terms)])] or list(range(len(terms)))
    coef, t = ordinary_fit(np.hstack([x[:, kept], owned]), y)
    return [Selected(terms[column], float(coef[i]), float(t[i]),
                     abs(float(coef[i])) * float(np.sqrt(np.mean(x[:, column] ** 2))))
            for i, column in enumerate(kept)]


def _significant(selected: Selected, rows: Sequence[Rows]) -> bool:
    return selected.t > Z_VIOLATED and selected.effect > MIN_EFFECT * _scale(rows)


def _scale(rows: Sequence[Rows]) -> float:
    return float(np.mean([r.scale for r in rows]))


def ordinary_fit(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """y ≈ x c by least squares: c and |c| over its standard error, the residual's
    variance taken over its effective count (an equation's error is not white)."""
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)
    residual = y - x @ coef
    variance = float(residual @ residual) / effective_count(residual)
    std = np.sqrt(np.diag(np.linalg.pinv(x.T @ x)) * variance)
    return coef, np.abs(coef) / std


def _thinned(mask: np.ndarray, rate_hz: float) -> np.ndarray:
    """The indices of ``mask`` away from the filter's ends, one per half period of its
    cut-off (the signals are low-passed there: closer samples carry no news)."""
    index = np.flatnonzero(mask)
    edge = round(EDGE_S * rate_hz)
    index = index[(index > edge) & (index < mask.size - edge)]
    return index[::max(1, round(rate_hz / (2 * br.FILTER_HZ)))]


def _about_run_mean(error: np.ndarray, terms: np.ndarray, owned: np.ndarray, scale: float
                    ) -> Rows:
    """Rows about their run's mean (each run's own constant: a static load, a speed's
    start)."""
    return Rows(error - error.mean(), terms - terms.mean(axis=0), owned - owned.mean(axis=0),
                scale)


class WheelLibrary(BrakingLibrary):
    """The wheel's torque balance J_w ω̇ = r F_x − T_b − T₀ sgn ω − T₁ ω: a bearing's
    friction, a released brake that drags, a seal. Its error is measured where the brake
    holds steadily and, with no brake at all, in the free rolling before it."""

    equation = Equation.WHEEL
    relation = Relation.WHEEL_BALANCE
    unit = "N m"
    terms = (
        Term(K.WHEEL_EXTRA_TORQUE_N_M, "", "N m", 2000.0, lambda b, _: np.sign(b.wheel)),
        Term(K.WHEEL_EXTRA_TORQUE_N_M_S_PER_RAD, "·ω", "N m s/rad", 20.0, lambda b, _: b.wheel),
    )

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        index = _thinned(br.steady_braking_samples(b) | br.free_rolling(b), b.run.rate_hz)
        if index.size < 20:
            return None
        torque, energy = br.torque_balance(b, params)
        model = br.model_torque(b, params, energy, index)
        return Rows(torque[index] - model,
                    np.column_stack([t.values(b, params)[index] for t in terms or self.terms]),
                    model[:, None], float(np.mean(np.abs(model))))

    def law(self, written: str, params: RigParameters) -> str:
        return f"J_w·ω̇ = r·F_x − T_b {written}"


class FlywheelLibrary(BrakingLibrary):
    """The flywheel's momentum balance m_f v̇ = −F_x − α_d v² − F₀ sgn v − F₁ v: its
    bearings' friction, eddy currents. Its error is measured integrated over the run,
    m_f v + ∫(F_x + α_d v²) dt about each run's mean, as the calibration measures the
    balance (the differentiated one carries m_f times the speed's noise: 2.7 kN rms)."""

    equation = Equation.FLYWHEEL
    relation = Relation.FLYWHEEL_BALANCE
    unit = "N s"
    terms = (
        Term(K.FLYWHEEL_EXTRA_FORCE_N, "", "N", 5000.0, lambda b, _: -np.sign(b.speed_m_s)),
        Term(K.FLYWHEEL_EXTRA_FORCE_N_S_PER_M, "·v", "N s/m", 100.0, lambda b, _: -b.speed_m_s),
    )

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        index = _thinned(b.speed_m_s > 1.0 + params.number(K.RIG_TEST_STOP_SPEED_M_S),
                         b.run.rate_hz)
        if index.size < 20:
            return None
        p = params.vector()
        dt = np.diff(b.time_s, prepend=b.time_s[0])
        speed = b.speed_m_s
        resisting = b.force + el.drag_forces(p, speed) + el.flywheel_extra_force(p, speed)
        impulse = np.cumsum(resisting * dt)
        columns = [np.cumsum(t.values(b, params) * dt) for t in terms or self.terms]
        owned = [speed, np.cumsum(speed * speed * dt)]
        return _about_run_mean((el.translational_mass(p) * speed + impulse)[index],
                               np.column_stack(columns)[index], np.column_stack(owned)[index],
                               float(np.std(impulse[index])))

    def law(self, written: str, params: RigParameters) -> str:
        return f"m_f·v̇ = −F_x − α_d·v² {written}"


class LoadingLibrary(BrakingLibrary):
    """The loading device's set point F_z0 − k_L v² − c v: a load that sags with speed
    beside the lift law. Its error is measured once the load has settled, about each run's
    own static load."""

    equation = Equation.LOADING
    relation = Relation.LOADING_LAW
    unit = "N"
    terms = (Term(K.LOADING_EXTRA_LOAD_N_S_PER_M, "·v", "N s/m", 500.0,
                  lambda b, _: -b.speed_m_s),)

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        loaded = b.load > br.LOADED_N
        if not loaded.any():
            return None
        touchdown = b.time_s[np.argmax(loaded)]
        settled = b.time_s > touchdown + params.number(K.LOADING_TOUCHDOWN_RAMP_S) + SETTLE_S
        index = _thinned(settled & loaded, b.run.rate_hz)
        if index.size < 20:
            return None
        speed = b.speed_m_s[index]
        columns = [t.values(b, params)[index] for t in terms or self.terms]
        return _about_run_mean(b.load[index] + el.load_lift(params.vector(), speed),
                               np.column_stack(columns),
                               (speed * speed)[:, None], float(np.mean(b.load[index])))

    def law(self, written: str, params: RigParameters) -> str:
        lift = display(params.number(K.LOADING_LIFT_COEFF_N_S2_PER_M2), "N s^2/m^2", ".3g")
        return f"F_z = F_z0 − {lift}·v² {written}"


class ValveLibrary(Library[Settled]):
    """The valve's static map P = k1 e + k2 e² + k3 e³, e = I − I0: a map that bends
    beyond the quadratic the calibration fits (flow forces, a spring's progression). Its
    error is the measured pressure's excess over the model's on an actuator run's settled
    samples (:func:`~.settled_valve.settled_valve`), where A(s) has settled; the terms the
    calibration owns there are the map's (k1, k2, and the dead-band's shift: a constant)."""

    equation = Equation.VALVE
    relation = Relation.VALVE_MAP
    unit = "Pa"
    phase = "actuator runs, settled"
    sign = 1.0
    terms = (Term(K.ACTUATOR_EXTRA_MAP_PA_PER_A3, "·e³", "Pa/A^3", 2e7,
                  lambda v, params: _excess(v, params) ** 3),)

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
        return Rows(source.residual_pa[index],
                    gain * np.column_stack([t.values(source, params)[index]
                                            for t in terms or self.terms]),
                    owned, float(np.mean(source.model_pa[index])))

    def law(self, written: str, params: RigParameters) -> str:
        k1, k2 = (display(params.number(k), unit, ".3g") for k, unit in (
            (K.ACTUATOR_MAP_K1_PA_PER_A, "Pa/A"), (K.ACTUATOR_MAP_K2_PA_PER_A2, "Pa/A^2")))
        return f"P_static = {k1}·e + {k2}·e² {written}"


def _excess(valve: Settled, params: RigParameters) -> np.ndarray:
    """The map's variable e = I − I0 ≥ 0 [A] of the current the valve was fed."""
    return el.valve_excess(valve.current_a, params.number(K.ACTUATOR_MAX_CURRENT_A),
                           params.number(K.ACTUATOR_DEADBAND_CURRENT_A))


VALVE = ValveLibrary()
WHEEL = WheelLibrary()
FLYWHEEL = FlywheelLibrary()
LOADING = LoadingLibrary()
LIBRARIES: tuple[Library[Any], ...] = (VALVE, WHEEL, FLYWHEEL, LOADING)


def equation_checks(campaign: Campaign, params: RigParameters) -> list[Check]:
    """Each library's relation over ``campaign`` under ``params``."""
    return [c for lib in LIBRARIES if (c := lib.check(campaign, params)) is not None]


def flywheel_carries(braking: Sequence[br.Braking], params: RigParameters,
                     values: Callable[[br.Braking], np.ndarray]) -> tuple[float, float]:
    """How much of ``values`` (a signal of a braking run) the measured F_x carries that the
    flywheel does not feel: its coefficient in the flywheel's balance error, and its t
    (0, 0: no run to tell). A channel's error shows wherever the channel is read; a torque
    on the wheel (a bearing's) does not reach the flywheel's balance."""
    carried = (Term[br.Braking]("", "", "", 0.0, lambda b, _: values(b)),)
    rows = [r for b in braking if (r := FLYWHEEL.rows(b, params, carried)) is not None]
    if not rows:
        return 0.0, 0.0
    coef, t = ordinary_fit(np.vstack([np.hstack([r.terms, r.owned]) for r in rows]),
                           np.concatenate([r.error for r in rows]))
    return float(coef[0]), float(t[0])
