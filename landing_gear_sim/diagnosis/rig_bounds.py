"""Candidates scaled from the rig, not from the reference (issue 43): a bound or start the
catalogue writes for the reference rig is widened where the user's datasheet and data say
the rig is another.

The valve's transport delay is searched up to 60 ms on the reference (its A(s) answers in
~10 ms); a slow valve's log can lag its datasheet's A(s) by 90 ms. The lag of the measured
pressure behind the datasheet's model (no delay), on the actuator runs' transitions, starts
the search and widens its bound.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis import residuals as rs
from landing_gear_sim.diagnosis.catalogue import Candidate
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.actuator import actuator_pressure
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.scenario import logged_to_held

LAG_WINDOW_S = 0.5  # the longest lag looked for
WIDER = 3.0  # a delay's bound: this many times the lag seen, when beyond the catalogue's


def observed_lag_s(runs: Sequence[ClassifiedRun], datasheet: RigParameters) -> float:
    """How late the measured pressure follows the datasheet's valve (no delay) on the
    actuator runs [s], the median over the runs (0: no actuator run)."""
    plain = datasheet.without("actuator_delay") if datasheet.has("actuator_delay") \
        else datasheet
    lags = [rs.lag_samples(r.pressure_pa, actuator_pressure(plain, logged_to_held(r.command_a),
                                                            r.rate_hz),
                           round(LAG_WINDOW_S * r.rate_hz)) / r.rate_hz
            for r in runs if not r.braking]
    return max(float(np.median(lags)), 0.0) if lags else 0.0


def scaled_to_rig(candidates: Sequence[Candidate], runs: Sequence[ClassifiedRun],
                  datasheet: RigParameters) -> list[Candidate]:
    """``candidates`` with the delay's bound and starts widened to the lag the runs show."""
    lag = observed_lag_s(runs, datasheet)
    return [_delay_widened(c, lag) if K.ACTUATOR_DELAY_S in c.keys else c
            for c in candidates]


def _delay_widened(candidate: Candidate, lag_s: float) -> Candidate:
    index = candidate.keys.index(K.ACTUATOR_DELAY_S)
    low, high = candidate.bounds[index]
    if WIDER * lag_s <= high:
        return candidate
    bounds = tuple((low, WIDER * lag_s) if i == index else b
                   for i, b in enumerate(candidate.bounds))
    first = candidate.starts[0] if candidate.starts else (0.0,) * len(candidate.keys)
    start = tuple(lag_s if i == index else value for i, value in enumerate(first))
    return replace(candidate, bounds=bounds, starts=(*candidate.starts, start))
