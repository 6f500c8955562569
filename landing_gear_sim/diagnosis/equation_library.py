"""Each equation of the rig with its library of terms, and its error (issues 29, 41).

Every effect, catalogued or not, is a missing term in one of the rig's equations. For the
valve's static map and A(s) (:mod:`~.valve_library`), the wheel's torque balance, the
tyre's force law, the flywheel's momentum balance, the loading device's law and the F_x
channel, the error is computed from the measured signals under the model (the other
equations' terms measured) over the samples that carry it: the actuator runs' for the valve,
every braking run's thinned to the filter's bandwidth for the others. Each equation's
library is the terms of its generic slot in the plant, basis functions composed with
:mod:`~.terms` (``actuator.map_term_*``, ``actuator.term_*``, ``wheel.term_*``,
``friction.term_*``, ``flywheel.term_*``, ``loading.term_*``, ``sensors.fx_term_*``,
``sensors.p_term_*``: :mod:`~.pressure_channel`),
beside the terms whose coefficients the calibration owns (the map's
1, e, e²; k_b P in the wheel's; the curve's ϑ; the flywheel's mass and drag; the lift).
:mod:`~.selection` picks the terms the error needs; the equation's relation
(:class:`~.relations.Relation`) is then violated, and the equation's family
(:mod:`~.families.equation_terms`) proposes them.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration import flywheel as fly
from landing_gear_sim.calibration import friction
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.slots import Slot, seen
from landing_gear_sim.diagnosis.catalogue import noise_std
from landing_gear_sim.diagnosis.equations import Equation
from landing_gear_sim.diagnosis.library import (
    BrakingLibrary,
    Campaign,
    Library,
    about_run_mean,
    thinned,
    torque_rows,
)
from landing_gear_sim.diagnosis.locked_wheel import locked_samples
from landing_gear_sim.diagnosis.pressure_channel import PRESSURE_CHANNEL
from landing_gear_sim.diagnosis.relations import Check, Relation
from landing_gear_sim.diagnosis.selection import Rows, Term, basis_terms, term_columns
from landing_gear_sim.diagnosis.terms import Shaped, Without
from landing_gear_sim.diagnosis.valve_library import VALVE, VALVE_DYNAMICS
from landing_gear_sim.model import basis
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import (
    curve_at,
    friction_coefficients,
    load_factor_at,
    load_taken_at,
)
from landing_gear_sim.model.sensors import SensorModel
from msg_tools.units import display, signed

SETTLE_S = 0.5  # after the touch-down ramp, before the loading device's load is its law


WHEEL_TERMS = (
    Shaped((basis.OMEGA,), (basis.SIGN, basis.IDENTITY, basis.SIGNED_SQUARE, basis.SIGNED_ROOT))
    + Shaped((basis.SPEED, basis.LOAD, basis.SLIP),
             (basis.IDENTITY, basis.SIGNED_SQUARE, basis.SIGNED_ROOT))
    + Shaped((basis.PRESSURE,), (basis.STEP, basis.SIGNED_SQUARE, basis.SIGNED_ROOT))
    + Shaped((basis.BRAKE_ENERGY,), (basis.STEP, basis.IDENTITY, basis.SIGNED_ROOT))
    + Shaped((basis.OMEGA,), (basis.SIGN,)) * Shaped((basis.PRESSURE,), (basis.STEP,)))
"""The wheel's library: its speeds, load and slip in the shapes a bearing, a seal, a
windage or a tyre's rolling loss take; whether the brake is applied and has been; the
pressure beyond linear (k_b P is the calibration's own)."""


class WheelLibrary(BrakingLibrary):
    """The wheel's torque balance J_w ω̇ = r F_x − T_b − Σ c_k φ_k: a bearing's friction, a
    released brake that drags, a seal, pads that drag once applied. Its error is measured
    where the brake holds steadily and, with no brake at all, in the free rolling before
    it."""

    equation = Equation.WHEEL
    relation = Relation.WHEEL_BALANCE
    unit = "N m"
    slot = Slot.WHEEL
    terms = basis_terms(WHEEL_TERMS, "N m")

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        index = thinned(br.steady_braking_samples(b) | br.free_rolling(b), b.run.rate_hz)
        if index.size < 20:
            return None
        return torque_rows(b, params, index, Slot.WHEEL, terms or self.terms)

    def law(self, written: str, params: RigParameters) -> str:
        return f"J_w·ω̇ = r·F_x − T_b {written}"


FLYWHEEL_TERMS = (Shaped((basis.SPEED,), (basis.SIGN, basis.IDENTITY, basis.CUBE))
                  + Shaped((basis.SPEED,), (basis.SIGN, basis.IDENTITY))
                  * Shaped((basis.LOAD,), (basis.IDENTITY,)))
"""The flywheel's library: its speed in the powers a bearing's friction, eddy currents or a
windage take, and the load the tyre presses on its bearings; α_d v² is the calibration's
own."""


class FlywheelLibrary(BrakingLibrary):
    """The flywheel's momentum balance m_f v̇ = −F_x − α_d v² − Σ c_k φ_k(v, F_z): its
    bearings' friction, eddy currents. Its error is measured integrated over the run,
    m_f v + ∫(F_x + α_d v²) dt about each run's mean, as the calibration measures the
    balance (the differentiated one carries m_f times the speed's noise: 2.7 kN rms)."""

    equation = Equation.FLYWHEEL
    relation = Relation.FLYWHEEL_BALANCE
    unit = "N"
    error_unit = "N s"
    slot = Slot.FLYWHEEL
    terms = basis_terms(FLYWHEEL_TERMS, "N")

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        index = thinned(b.speed_m_s > 1.0 + params.number(K.RIG_TEST_STOP_SPEED_M_S),
                         b.run.rate_hz)
        if index.size < 20:
            return None
        dt = np.diff(b.time_s, prepend=b.time_s[0])
        speed = b.speed_m_s
        balance = fly.momentum_balance(b, params)
        impulse = balance - el.translational_mass(params.vector()) * speed
        measured = seen(Slot.FLYWHEEL, br.measured_signals(b, params, np.zeros(speed.size)))
        everywhere = np.arange(speed.size)
        # a term opposes the motion: the balance's error is minus its impulse
        columns = -np.cumsum(term_columns(terms or self.terms, b, params, everywhere, measured)
                             * dt[:, None], axis=0)
        owned = [speed, np.cumsum(speed * speed * dt)]
        return about_run_mean(balance[index], columns[index],
                               np.column_stack(owned)[index], float(np.std(impulse[index])))

    def law(self, written: str, params: RigParameters) -> str:
        return f"m_f·v̇ = −F_x − α_d·v² {written}"


LOADING_TERMS = Without(
    Shaped((basis.SPEED, basis.CONTACT_TIME),
           (basis.IDENTITY, basis.SIGNED_SQUARE, basis.CUBE, basis.SIGNED_ROOT))
    + Shaped((basis.SPEED,), (basis.IDENTITY,)) * Shaped((basis.CONTACT_TIME,),
                                                          (basis.IDENTITY,)),
    frozenset({basis.factor_code(basis.SPEED, basis.SIGNED_SQUARE)}))
"""The loading device's library: the speed and the time since contact in powers (a
cylinder that leaks, a servo that sags, a lift law of another form); k_L v² is the
calibration's own."""


class LoadingLibrary(BrakingLibrary):
    """The loading device's set point F_z0 − k_L v² − Σ c_k φ_k(v, t_c): a load that sags
    with speed beside the lift law, a cylinder that leaks. Its error is measured once the
    load has settled, about each run's own static load."""

    equation = Equation.LOADING
    relation = Relation.LOADING_LAW
    unit = "N"
    slot = Slot.LOADING
    # a quarter per cent of the static load (80 N of 32 kN): a leak of 0.4 % at 54σ was
    # under the half per cent and came out `none`; the nulls' loading checks sit below 2σ,
    # a few newtons (a load cell's 100 N noise averages out over a stop)
    min_effect = 0.0025
    terms = basis_terms(LOADING_TERMS, "N")

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        loaded = b.load > br.LOADED_N
        if not loaded.any():
            return None
        touchdown = b.time_s[np.argmax(loaded)]
        settled = b.time_s > touchdown + params.number(K.LOADING_TOUCHDOWN_RAMP_S) + SETTLE_S
        index = thinned(settled & loaded, b.run.rate_hz)
        if index.size < 20:
            return None
        speed = b.speed_m_s[index]
        measured = seen(Slot.LOADING, br.measured_signals(b, params, np.zeros(b.time_s.size))
                        [index])
        taken = load_taken_at(params, b.time_s[index], speed)
        # the set point the servo was following: the load led by its lag (a set point that
        # falls with v² is followed τ late, 120 N at 60 m/s braking at 8 m/s²)
        tau = params.number(K.LOADING_SERVO_TIME_CONSTANT_S)
        setpoint = b.load + tau * np.gradient(b.load, b.time_s)
        return about_run_mean(setpoint[index] + taken,
                               -term_columns(terms or self.terms, b, params, index, measured),
                               (speed * speed)[:, None], float(np.mean(b.load[index])))

    def law(self, written: str, params: RigParameters) -> str:
        lift = display(params.number(K.LOADING_LIFT_COEFF_N_S2_PER_M2), "N s^2/m^2", ".3g")
        return f"F_z = F_z0 − {lift}·v² {written}"


TYRE_TERMS = (Shaped((basis.CURVE,), (basis.SQUARE, basis.CUBE))
              + Shaped((basis.CURVE,), (basis.IDENTITY,))
              * Shaped((basis.SPEED, basis.SLIP), (basis.IDENTITY, basis.SIGNED_ROOT)))
"""The tyre's library: the calibrated curve μ_B in the powers another curve's shape takes
(a magic formula's peak), and scaled by the speed (a friction that falls with the sliding
speed) or the slip (beyond the peak): every term bounded over the slips, 0 where the curve
is (at zero slip a rolling tyre pushes nothing: λ² once gave a locked wheel 0.8 more μ), and
of a finite slope there (the plant's step is sized by the curve's steepest slope). μ_B alone
and its ϑ are the calibration's own, the load the ``load`` family's (within a stop the load
follows the speed: terms in both read alike, and a clean campaign's slip noise filled
them)."""


class TyreLibrary(BrakingLibrary):
    """The tyre's force law F_x = F_z (μ_B(λ) g(F_z) + Σ c_k φ_k(λ, v, F_z)): a friction
    curve of another shape, a friction that changes with speed within a stop. Its error is
    μ = F_x / F_z less the model's over the braking samples the calibration fits its curve
    on; the curve's ϑ are owned (their derivatives: the curve may bend)."""

    equation = Equation.TYRE
    relation = Relation.TYRE_LAW
    unit = "-"
    slot = Slot.TYRE
    sign = 1.0
    terms = basis_terms(TYRE_TERMS, "-")

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        index = friction.friction_indices(b, params)
        if index.size < 20:
            return None
        slip, curve_mu = friction.samples_at(b, params, index)
        factor = load_factor_at(params, b.load[index])
        t1, t2, t3 = friction_coefficients(params)
        model = el.burckhardt_mu(t1, t2, t3, slip)
        measured = seen(Slot.TYRE, friction.tyre_signals(b, params, index))
        slope = t1 * t2 * np.exp(-t2 * slip) - t3
        return Rows((curve_mu - model) * factor,
                    term_columns(terms or self.terms, b, params, index, measured),
                    _curve_derivatives(params, slip, factor),
                    float(np.mean(np.abs(model * factor))),
                    float(np.sqrt(np.mean((slope * factor * _slip_noise(b, index)) ** 2))))

    def law(self, written: str, params: RigParameters) -> str:
        return f"μ = μ_B(λ)·g(F_z) {written}"


class LockedTyreLibrary(TyreLibrary):
    """The tyre's law where the wheel is locked (:mod:`~.locked_wheel`): the slip is 1
    exactly there whatever the wheel channel reads, so a term in speed shows free of the
    slip's noise that floors the curve's samples (the plan's 1561 and 1544, unexplained in
    the tyre). Its rows are about each run's mean (its relation reads a trend within the
    runs, beside each run's level). Not a check of its own: its relation is the locked
    wheel's; it says which terms a violation of it needs."""

    relation = Relation.LOCKED_SLIDING
    phase = "locked wheel"

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        index = locked_samples(b, params)
        if index.size < 20:
            return None
        _, curve_mu = friction.samples_at(b, params, index)
        factor = load_factor_at(params, b.load[index])
        slip = np.ones(index.size)
        model = curve_at(params, slip, b.speed_m_s[index])
        signals = friction.tyre_signals(b, params, index)
        signals[:, basis.SLIP], signals[:, basis.CURVE] = slip, model
        return about_run_mean((curve_mu - model) * factor,
                              term_columns(terms or self.terms, b, params, index,
                                           seen(Slot.TYRE, signals)),
                              _curve_derivatives(params, slip, factor),
                              float(np.mean(np.abs(model * factor))))


def _curve_derivatives(params: RigParameters, slip: np.ndarray, factor: np.ndarray
                       ) -> np.ndarray:
    """The curve μ_B's derivatives in ϑ1, ϑ2, ϑ3 at ``slip``, times the load ``factor``: the
    terms the calibration owns in the tyre's law (it may bend the curve)."""
    t1, t2, _ = friction_coefficients(params)
    decay = np.exp(-t2 * slip)
    return np.column_stack([1.0 - decay, t1 * slip * decay, -slip]) * factor[:, None]


FX_TERMS = (Shaped((basis.RUN_TIME,), (basis.IDENTITY, basis.SQUARE, basis.SIGNED_ROOT))
            + Shaped((basis.LOAD,), (basis.SIGNED_SQUARE,))
            + Shaped((basis.RUN_TIME,), (basis.IDENTITY,)) * Shaped((basis.LOAD,),
                                                                   (basis.IDENTITY,)))
"""The F_x channel's library: a zero that drifts with the time since the run's start (a
load cell warming), and a reading that bends with the load; F_z alone is the named
``channel_crosstalk``'s."""
KNOWN_RATE_HZ = 100.0  # samples where F_x is known, thinned to this


class FxChannelLibrary(Library[tuple[ClassifiedRun, "br.Braking | None"]]):
    """The load cell's F_x channel, F_x,read = F_x + c F_z + Σ c_k φ_k(F_z, t): its error is
    the reading less the true F_x where that is known — off the ground (0), in the free
    rolling before the brake acts (the wheel's inertia force and the model's wheel torque,
    pushed by the tyre) and, while braking, the flywheel's: its momentum balance over
    windows of BALANCE_WINDOW_S gives the force's mean there (a drift or a bend that grows
    with the load shows under the load: off the ground F_z is 0, in the free rolling t is
    short; such terms had been named a wheel term or left unexplained). The flywheel's mass
    and drag are owned: a calibration's small error in them is not a channel's."""

    equation = Equation.FX_CHANNEL
    relation = Relation.FX_CHANNEL
    unit = "N"
    phase = "where F_x is known"
    slot = Slot.FX_CHANNEL
    sign = 1.0
    terms = basis_terms(FX_TERMS, "N")

    def sources(self, campaign: Campaign, params: RigParameters
                ) -> list[tuple[ClassifiedRun, br.Braking | None]]:
        prepared = {b.run.name: b for b in campaign.braking}
        return [(r, prepared.get(r.name)) for r in campaign.runs]

    def rows(self, source: tuple[ClassifiedRun, br.Braking | None], params: RigParameters,
             terms: Sequence[Term[tuple[ClassifiedRun, br.Braking | None]]] | None = None
             ) -> Rows | None:
        run, b = source
        chosen = terms or self.terms
        time = br.run_time_s(run)
        if b is not None:
            mask, excess = br.free_rolling_excess(b, params)
            index, error = np.flatnonzero(mask), excess
        else:
            index = np.arange(len(run))
            error = np.asarray(SensorModel.of(params).true_longitudinal(
                run.longitudinal_force_n, run.vertical_load_n, time))
        step = max(1, round(run.rate_hz / KNOWN_RATE_HZ))
        index, error = index[::step], error[::step]
        columns = term_columns(chosen, source, params, index, _fx_signals(run, time, index))
        owned = np.zeros((index.size, 2))
        if b is not None and (windows := _balance_windows(b, params, chosen, source)):
            error, columns, owned = (np.concatenate([a, w]) for a, w in zip(
                (error, columns, owned), windows, strict=True))
        if error.size < 20:
            return None
        return Rows(error, columns, owned, params.number(K.LOADING_STATIC_LOAD_N))

    def law(self, written: str, params: RigParameters) -> str:
        crosstalk = params.number(K.SENSORS_CROSSTALK_FX_PER_FZ)
        shown = f" {signed(crosstalk, spec='.4g')}·F_z" if crosstalk else ""
        return f"F_x,read = F_x{shown} {written}"


BALANCE_WINDOW_S = 1.0  # the flywheel's speed noise over m_f·Δv falls with the window


def _fx_signals(run: ClassifiedRun, time: np.ndarray, index: np.ndarray) -> np.ndarray:
    """The F_x channel slot's signals at the samples ``index``: the load and the run's time."""
    measured = np.zeros((index.size, basis.N_SIGNALS))
    measured[:, basis.LOAD] = run.vertical_load_n[index]
    measured[:, basis.RUN_TIME] = time[index]
    return measured


def _balance_windows(b: br.Braking, params: RigParameters, terms: Sequence[Term[Any]],
                     source: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The F_x reading's mean excess over the flywheel's momentum balance in windows of a
    stop (m_f Δv + ∫(F_x + α_d v² + F_f) dt over the window's length), the terms' means
    there, and the owned columns (the mass's Δv and the drag's v², same means); None: no
    window. Windows start 1/KNOWN_RATE_HZ apart, on the flywheel and above the stop speed."""
    p = params.vector()
    width = round(BALANCE_WINDOW_S * b.run.rate_hz)
    on = np.flatnonzero((b.time_s > b.start_s) & (b.load > br.LOADED_N)
                        & (b.speed_m_s > 1.0 + params.number(K.RIG_TEST_STOP_SPEED_M_S)))
    if on.size <= width:
        return None
    span = np.arange(on[0], on[-1] + 1)
    dt = np.diff(b.time_s, prepend=b.time_s[0])[span]
    speed = b.speed_m_s[span]
    time = br.run_time_s(b.run)
    values = np.column_stack([
        fly.momentum_balance(b, params)[span],
        np.cumsum(term_columns(terms, source, params, span, _fx_signals(b.run, time, span))
                  * dt[:, None], axis=0),
        el.translational_mass(p) * speed, np.cumsum(speed * speed * dt)])
    starts = np.arange(0, span.size - width, max(1, round(b.run.rate_hz / KNOWN_RATE_HZ)))
    means = (values[starts + width] - values[starts]) / (b.time_s[span][starts + width]
                                                         - b.time_s[span][starts])[:, None]
    return means[:, 0], means[:, 1:1 + len(terms)], means[:, 1 + len(terms):]


def _slip_noise(b: br.Braking, index: np.ndarray) -> np.ndarray:
    """The 1-σ of the slip at the samples ``index`` that the wheel channel's noise leaves
    through the calibration's low-pass: the channel's noise (:func:`channel_noise`) over the
    share of its band the filter passes, over the speed."""
    raw = channel_noise(b.run.wheel_speed_rad_s)
    filtered = raw * np.sqrt(min(1.0, 2.0 * br.FILTER_HZ / (b.run.rate_hz / 2.0)))
    return filtered / np.maximum(b.wheel[index], 1.0)


def channel_noise(values: np.ndarray) -> float:
    """A channel's white noise [its unit]: the robust spread of its second differences
    (a stop's deceleration cancels out of them), or of its first where that is less (an
    encoder's counts, mostly still between steps). First differences alone read a 200 Hz
    log's wheel channel at 3-9 times its noise, and set the tyre's floor 5.6 times higher
    than that noise does."""
    second = np.diff(values, 2)
    robust = 1.4826 * float(np.median(np.abs(second - np.median(second)))) / np.sqrt(6.0)
    first = noise_std(values)
    return min(first, robust) if robust > 0 else first


WHEEL = WheelLibrary()
TYRE = TyreLibrary()
LOCKED_TYRE = LockedTyreLibrary()  # the tyre's slot read where the wheel locks; not a check
FLYWHEEL = FlywheelLibrary()
LOADING = LoadingLibrary()
FX_CHANNEL = FxChannelLibrary()
LIBRARIES: tuple[Library[Any], ...] = (VALVE, VALVE_DYNAMICS, WHEEL, TYRE, FLYWHEEL, LOADING,
                                       FX_CHANNEL, PRESSURE_CHANNEL)


def equation_checks(campaign: Campaign, params: RigParameters) -> list[Check]:
    """Each library's relation over ``campaign`` under ``params``."""
    return [c for lib in LIBRARIES if (c := lib.check(campaign, params)) is not None]


def held_laws(params: RigParameters) -> list[str]:
    """Each equation whose generic slot ``params`` fills, with its law written out ('the
    wheel: J_w·ω̇ = r·F_x − T_b − 148 N m·[P > 0.5 bar]')."""
    return [f"the {library.equation}: {law}" for library in LIBRARIES
            if (law := library.held_law(params)) is not None]


def held_notes(params: RigParameters) -> dict[str, str]:
    """By key, what each filled place of every generic slot of ``params`` holds."""
    return {key: note for library in LIBRARIES for key, note in library.held_notes(params).items()}
