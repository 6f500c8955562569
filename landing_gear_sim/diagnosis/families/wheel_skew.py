"""``channel_skew`` of the wheel channel, in its measurement equation (issue 16's logger).

The wheel channel reads ω(t − d): a wheel-speed residual that lags the simulation
consistently over the runs (a residual signature; 20 ms once gave 'none').
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

from landing_gear_sim.diagnosis.catalogue import BRAKE_RUNS, FRICTION, WHEEL, Candidate
from landing_gear_sim.diagnosis.families.base import (
    Evidence,
    Family,
    Hidden,
    Proposal,
    term_candidate,
)
from landing_gear_sim.diagnosis.findings import Signature, SignatureKind
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.units import display

KEY = K.SENSORS_WHEEL_SPEED_DELAY_S
BOUNDS = (0.0, 0.2)  # s


def wheel_lags(signatures: Sequence[Signature]) -> list[float]:
    """The wheel channel's consistent lags behind the model (later: positive)."""
    return [s.value for s in signatures if s.kind is SignatureKind.LAG
            and s.channel == "wheel_speed_rad_s" and s.value > 0]


class WheelSkew(Family):
    name = "wheel_skew"
    reports = "channel_skew"
    words: ClassVar[dict[str, str]] = {
        "channel_skew": "a channel's samples are stamped out of time with the others"}
    equation = "wheel channel"
    keys = (KEY,)
    relations = ()
    rank = 4
    hidden = (Hidden("channel_skew", "channel_skew",
                     lambda rng, datasheet: {KEY: rng.uniform(0.005, 0.03)},
                     KEY, "wheel_speed_delay_s", 1e-3, absolute=True),)

    def propose(self, evidence: Evidence) -> list[Proposal]:
        """Started at the measured lag, fitted with the friction curve (slip read from a
        late wheel bent it)."""
        lags = wheel_lags(evidence.signatures)
        if not lags:
            return []
        return [Proposal(term_candidate(self, self.keys, (lags[0],), (BOUNDS,), FRICTION,
                                        BRAKE_RUNS, WHEEL))]

    def formula(self, candidate: Candidate, params: RigParameters) -> str:
        return f"ω_read(t) = ω(t − {display(params.number(KEY), 's', '.1f')})"

    def reason(self, evidence: Evidence) -> str:
        return "the wheel channel lags the model's consistently (residual signature)"


FAMILY = WheelSkew()
