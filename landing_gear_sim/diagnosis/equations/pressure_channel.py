"""The pressure channel: P_read = P + Σ c_k φ_k(P, t), read late by the model's delay of the
channel (the sensors' :class:`~landing_gear_sim.model.sensors.SensorModel`).

Everything the diagnosis knows about the pressure channel: its relations (zero current ⇒ zero
pressure once the valve has settled; the brake torque in step with the measured pressure;
the brake torque follows the pressure read, whenever read) and its library of terms.

A transducer that drifts (issue 41) is a term of the channel. The brake feels the true
pressure and the valve's runs read the same channel: a term of the channel shows in both, a
torque on the wheel only in the wheel's torque balance.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.calibration.slots import Slot
from landing_gear_sim.calibration.statistics import (
    linear_std,
)
from landing_gear_sim.diagnosis.equations.equation import Declared, Equation
from landing_gear_sim.diagnosis.equations.valve import PRESSURE_FLOOR_PA, SETTLED_S, settled_valve
from landing_gear_sim.diagnosis.library import BrakingLibrary, Campaign, thinned, torque_rows
from landing_gear_sim.diagnosis.relations import (
    MIN_SAMPLES,
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
    ordinary_fit,
)
from landing_gear_sim.diagnosis.terms import Shaped
from landing_gear_sim.model import basis
from landing_gear_sim.model import elements as el
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.scenario import (
    commanded,
)
from landing_gear_sim.model.sensors import SensorModel

LAW = "P_read = P"
"""The pressure channel's law, as its words and its written terms read it."""

MAX_BRAKING_SLIP = 0.15  # beyond, the torque balance's derivative error dominates
TIMING_FLOOR_S = 1e-3  # a channel out of step by less than a millisecond does not matter
PRESSURE_TERMS = (Shaped((basis.RUN_TIME,), (basis.IDENTITY, basis.SQUARE, basis.SIGNED_ROOT))
                  + Shaped((basis.PRESSURE,), (basis.IDENTITY,))
                  * Shaped((basis.RUN_TIME,), (basis.IDENTITY,)))
"""The pressure channel's library: a transducer whose zero or gain drifts with the time since
the run's start. Terms in P alone are not its: the valve's map, calibrated through the
channel, takes a bend of the reading into its own, and the wheel's torque balance cannot tell
it from the brake's (a time the valve's runs share is what tells them apart)."""


class PressureChannelLibrary(BrakingLibrary):
    """The pressure channel, P_read = P + offset + Σ c_k φ_k(P, t): a transducer that drifts.
    The brake feels the true pressure: its error is the wheel's torque balance less the
    model's torque of the pressure read, where the brake holds steadily, per k_b (a reading
    c φ too high gives the model k_b c φ too much torque). The same term must show in the
    valve's settled pressure (:func:`valve_reads`): a wheel's torque does not."""

    equation = Equation.PRESSURE_CHANNEL
    relation = Relation.PRESSURE_READING
    unit = "Pa"
    error_unit = "N m"
    slot = Slot.PRESSURE_CHANNEL
    sign = 1.0
    terms = basis_terms(PRESSURE_TERMS, "Pa")

    def rows(self, b: br.Braking, params: RigParameters,
             terms: Sequence[Term[br.Braking]] | None = None) -> Rows | None:
        index = thinned(br.steady_braking_samples(b), b.run.rate_hz)
        if index.size < 20:
            return None
        return torque_rows(b, params, index, Slot.PRESSURE_CHANNEL, terms or self.terms,
                           -params.number(K.BRAKE_GAIN_N_M_PER_PA))

    def _kept(self, campaign: Campaign, params: RigParameters, rows: list[Rows],
              fitted: Fitted | None) -> list[Selected]:
        """The kept terms, when the valve's settled pressure reads them too
        (:func:`valve_reads`)."""
        chosen = super()._kept(campaign, params, rows, fitted)
        return chosen if chosen and valve_reads(campaign, params, chosen) else []

    def check(self, campaign: Campaign, params: RigParameters) -> Check | None:
        """The relation, where a term the error needs is read by the valve too: a torque
        balance's error in time that the valve does not read is the wheel's (a bearing's
        torque through a stop), not the channel's. The rows are read and fitted once."""
        rows, fitted = self._fit(campaign, params)
        return self._check(rows, fitted) if self._kept(campaign, params, rows, fitted) \
            else None

    def law(self, written: str, params: RigParameters) -> str:
        return f"{LAW} {written}"


def valve_reads(campaign: Campaign, params: RigParameters, chosen: Sequence[Selected]
                ) -> bool:
    """Whether the actuator runs' settled pressure reads the pressure channel's ``chosen``
    terms, at their values, as the brake's torque does (at least half of their sum, the
    same way), beside the map's 1, e, e² (the map, calibrated through the channel, took the
    rest). Their sum, not each: terms alike in time (t, √t, t²) share a drift between them
    in any proportion."""
    columns, owned, errors = [], [], []
    for run in campaign.runs:
        if run.braking or (v := settled_valve(run, params)) is None:
            continue
        index = np.flatnonzero(v.settled)
        measured = np.zeros((index.size, basis.N_SIGNALS))
        measured[:, basis.PRESSURE] = run.pressure_pa[index]
        measured[:, basis.RUN_TIME] = v.time_s[index]
        excess = el.valve_excess(v.current_a[index],
                                 params.number(K.ACTUATOR_MAX_CURRENT_A),
                                 params.number(K.ACTUATOR_DEADBAND_CURRENT_A))
        columns.append(np.sum([s.value * basis.term_values(s.term.code or 0, measured)
                               for s in chosen], axis=0))
        owned.append(np.column_stack([np.ones_like(excess), excess, excess * excess]))
        errors.append(v.residual_pa[index])
    if not columns or sum(c.size for c in columns) < 20:
        return False
    coef, _ = ordinary_fit(np.column_stack([np.concatenate(columns), np.vstack(owned)]),
                           np.concatenate(errors))
    return bool(coef[0] >= 0.5)


PRESSURE_CHANNEL = PressureChannelLibrary()


def zero_current(run: ClassifiedRun, params: RigParameters) -> Check | None:
    """Pressure where the current has commanded nothing for SETTLED_S (before braking,
    between pulses): a valve that is shut holds no pressure (the model's sensor offset
    aside). 'Nothing' as the brake's start reads it: a noisy, quantised log's current is
    never exactly 0."""
    off = ~commanded(run.current_a, run.rate_hz)
    samples = max(1, round(SETTLED_S * run.rate_hz))
    settled = np.convolve(off, np.ones(samples), mode="full")[:off.size] >= samples
    pressure = SensorModel.of(params).true_pressure(run.pressure_pa[settled],
                                                    (run.time_s - run.time_s[0])[settled])
    return mean_check(Relation.ZERO_CURRENT, run.name, "current off", pressure,
                       PRESSURE_FLOOR_PA, "Pa", run.rate_hz)


def pressure_timing(runs: Sequence[br.Braking], params: RigParameters) -> list[Check]:
    """How late the pressure channel is against the brake torque it makes [s] (positive:
    the channel is late), beyond the model's own delay of that channel: the torque balance's
    T ≈ a·M + b·Ṁ, M the model's torque of the measured pressure (taken back by the model's
    delay of the channel), so T(t) ≈ a·M(t + d), d = b/a. A valve's transport delay leaves
    the measured pressure in step with the torque; a channel stamped late does not (an
    actuator delay and a wheel channel 'leading' by as much were once reported together).
    Away from lock (slip < MAX_BRAKING_SLIP), where the balance's derivative dominates."""
    rows, columns = [], []
    for b in runs:
        b = br.in_step(b, params)
        torque, energy = br.torque_balance(b, params)
        model = br.model_torque(b, params, energy, np.arange(b.time_s.size))
        slope = np.gradient(model, 1.0 / b.run.rate_hz)
        m = np.flatnonzero(br.braking_samples(b) & (br.slip(b, params) < MAX_BRAKING_SLIP))[::10]
        rows.append(torque[m])
        columns.append(np.column_stack([model[m], slope[m]]))
    t, design = np.concatenate(rows), np.vstack(columns)
    if t.size < MIN_SAMPLES or np.ptp(design[:, 1]) == 0.0:
        return []
    coef, *_ = np.linalg.lstsq(design, t, rcond=None)
    std = linear_std(design, t - design @ coef, 2)
    lag = float(coef[1] / coef[0])
    lag_std = math.hypot(std[1], lag * std[0]) / abs(float(coef[0]))
    return [Check(Relation.PRESSURE_TIMING, "campaign", f"{len(runs)} braking runs, slip < "
                  f"{MAX_BRAKING_SLIP:g}", lag, lag_std, TIMING_FLOOR_S, "s")]


DECLARED = Declared(f"{LAW} (the pressure channel)", "pressure_pa", (
    Checking((Relation.ZERO_CURRENT,), Reads.ANY_RUN, zero_current),
    Checking((Relation.PRESSURE_TIMING,), Reads.BRAKING_RUNS, pressure_timing),
    Checking((Relation.PRESSURE_READING,), Reads.CAMPAIGN, PRESSURE_CHANNEL.check)))
