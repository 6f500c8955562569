"""The load cell's F_x channel: F_x,read = F_x + c·F_z + Σ c_k φ_k(F_z, t) (the sensors'
:meth:`~landing_gear_sim.model.sensors.SensorModel.longitudinal`), t the time since the run's
first sample.

Everything the diagnosis knows about the F_x channel: its relations (in free rolling F_x is
the wheel's own inertia, J_w ω̇ / r; it reads F_x wherever F_x is known) and its library of
terms (a zero that drifts, a reading that bends with the load).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration import flywheel as fly
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.slots import Slot
from landing_gear_sim.diagnosis.equations.equation import Declared, Equation
from landing_gear_sim.diagnosis.equations.flywheel import flywheel_reads
from landing_gear_sim.diagnosis.equations.load_cell import FORCE_FLOOR_N
from landing_gear_sim.diagnosis.library import (
    Campaign,
    Library,
)
from landing_gear_sim.diagnosis.relations import (
    Check,
    Checking,
    Reads,
    Relation,
    mean_check,
)
from landing_gear_sim.diagnosis.selection import (
    Fitted,
    Rows,
    Selected,
    Term,
    basis_terms,
    term_columns,
    variable,
)
from landing_gear_sim.diagnosis.terms import Shaped
from landing_gear_sim.model import basis
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.sensors import SensorModel
from msg_tools.units import signed

LAW = "F_x,read = F_x"
"""The fx channel's law, as its words and its written terms read it."""

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

    def _kept(self, campaign: Campaign, params: RigParameters, rows: list[Rows],
              fitted: Fitted | None) -> list[Selected]:
        """The kept terms the flywheel's momentum balance carries too
        (:func:`flywheel_reads_term`): the flywheel feels the true F_x, the channel reads it
        wrong; a torque on the wheel (a bearing's, pushed by the tyre) breaks the
        free-rolling relation alike but leaves the flywheel's balance alone (U06's drift had
        been named a wheel term)."""
        return [s for s in super()._kept(campaign, params, rows, fitted)
                if flywheel_reads_term(campaign.braking, params, s.term, s.value)]

    def law(self, written: str, params: RigParameters) -> str:
        crosstalk = params.number(K.SENSORS_CROSSTALK_FX_PER_FZ)
        shown = f" {signed(crosstalk, spec='.4g')}·F_z" if crosstalk else ""
        return f"{LAW}{shown} {written}"


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


def free_rolling_force(b: br.Braking, params: RigParameters) -> Check | None:
    """The F_x the load cell reads in free rolling beyond the wheel's own inertia."""
    _, excess = br.free_rolling_excess(b, params)
    return mean_check(Relation.FREE_ROLLING, b.run.name, "before braking", excess,
                      FORCE_FLOOR_N, "N", b.run.rate_hz)


FX_CHANNEL = FxChannelLibrary()


DECLARED = Declared(f"{LAW} (the load cell's F_x channel)", "longitudinal_force_n", (
    Checking((Relation.FREE_ROLLING,), Reads.BRAKING_RUN, free_rolling_force),
    Checking((Relation.FX_CHANNEL,), Reads.CAMPAIGN, FX_CHANNEL.check)))


def flywheel_reads_term(braking: Sequence[br.Braking], params: RigParameters,
                        term: Term[Any], value: float) -> bool:
    """Whether the flywheel's balance carries ``value`` of the channel's ``term`` too (at
    least half of it, the same way): the one rule for every term of the F_x channel, a
    basis function of its generic slot or a named family's (a crosstalk's F_z, whose
    ``values`` read a run)."""
    code = term.code

    def values(b: br.Braking) -> np.ndarray:
        if code is None:
            return variable(term, b.run, params)
        measured = np.zeros((b.time_s.size, basis.N_SIGNALS))
        measured[:, basis.LOAD] = b.run.vertical_load_n
        measured[:, basis.RUN_TIME] = br.run_time_s(b.run)
        return basis.term_values(code, measured)

    return flywheel_reads(braking, params, values, value)
