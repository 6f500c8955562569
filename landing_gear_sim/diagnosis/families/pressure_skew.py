"""``channel_skew`` of the pressure channel, in its measurement equation (issue 28).

The channel reads P(t − d): the brake torque the wheel's balance measures leads the
measured pressure, which a valve's transport delay cannot make (relation "brake torque in
step with the measured pressure"). Without it, a late channel reads as an actuator delay of
its size with the wheel "leading" the extended model by as much.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

from landing_gear_sim.calibration.identify import identify
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.catalogue import (
    ACTUATOR,
    ACTUATOR_RUNS,
    BRAKE_RUNS,
    PRESSURE,
    WHEEL,
    Candidate,
)
from landing_gear_sim.diagnosis.families.base import (
    Evidence,
    Family,
    Hidden,
    Proposal,
    term_candidate,
)
from landing_gear_sim.diagnosis.relations import Relation
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.units import display

KEY = K.SENSORS_PRESSURE_DELAY_S
BOUNDS = (0.0, 0.1)  # s


class PressureSkew(Family):
    name = "pressure_skew"
    reports = "channel_skew"
    words: ClassVar[dict[str, str]] = {
        "channel_skew": "a channel's samples are stamped out of time with the others"}
    equation = "pressure channel"
    keys = (KEY,)
    relations = (Relation.PRESSURE_TIMING,)
    rank = 1
    hidden = (Hidden("pressure_late", "channel_skew",
                     lambda rng, datasheet: {KEY: rng.uniform(0.004, 0.015)},
                     KEY, "pressure_delay_s", 1e-3, absolute=True),)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        """The channel late by the relation's reading, fitted with the valve's A(s) on the
        actuator runs (which pin it) and half the braking runs (whose wheel channels show
        the brake's true timing), checked on the other half; started from the model
        calibrated again through the late channel (:func:`start`)."""
        late = [c.deviation for c in evidence.violated(Relation.PRESSURE_TIMING)]
        if not late or late[0] <= 0:
            return []
        model = evidence.model
        delay = (K.ACTUATOR_DELAY_S,) if model.has("actuator_delay") else ()
        candidate = term_candidate(self, self.keys, (min(max(late[0], 1e-4), 0.09),),
                                   (BOUNDS,), (*ACTUATOR, *delay),
                                   (*ACTUATOR_RUNS, *BRAKE_RUNS), (*PRESSURE, *WHEEL))
        return [Proposal(candidate, start(evidence.runs, model, late[0]))]

    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        return f"P_read(t) = P(t − {display(params.number(KEY), 's', '.1f')})"


def start(runs: Sequence[ClassifiedRun], params: RigParameters, lag_s: float) -> RigParameters:
    """``params`` calibrated again with the channel ``lag_s`` late. Calibrated on the late
    reading, A(s) came out slow (8.2 Hz for 12) and the friction curve bent to the late brake
    it made: from there the fit stopped half-way (a 6.3 ms skew for 11.6), the true timing
    locking the wheel where the rig's did not."""
    late = params.replace({KEY: lag_s}, "the pressure channel late")
    return identify(runs, late, jackknife=False).params.replace({KEY: 0.0}, "to be fitted")


FAMILY = PressureSkew()
