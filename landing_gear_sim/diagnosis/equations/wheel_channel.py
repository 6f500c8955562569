"""The wheel's encoder: ω_read = ω, beside the model's own ripple with the wheel's angle
(run-out, an out-of-round code wheel: the sensors'
:class:`~landing_gear_sim.model.sensors.SensorModel`). Its relation: in free rolling the wheel
channel is smooth in the wheel's angle, once and twice per revolution.
"""

from __future__ import annotations

from landing_gear_sim.calibration.braking import Braking
from landing_gear_sim.calibration.wheel_angle import ORDERS, checked_ripple
from landing_gear_sim.diagnosis.equations.equation import Declared
from landing_gear_sim.diagnosis.relations import Check, Checking, Reads, Relation
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.sensors import SensorModel

RUNOUT_FLOOR = 1e-3  # a ripple below 0.1 % of the wheel speed is within the encoder's noise


def wheel_angle_ripple(prepared: Braking, params: RigParameters) -> Check | None:
    """The wheel channel's strongest ripple with the wheel's angle in free rolling, before
    the run brakes, beyond the model's own run-out of that order [relative to ω]."""
    run = prepared.run
    ripple = checked_ripple(run)
    if ripple is None:
        return None
    runout = SensorModel.of(params).runout
    checks = [Check(Relation.WHEEL_ANGLE, run.name, f"before braking, {m}× per revolution",
                    ripple.amplitude[i] - runout[2 * i], ripple.std[i], RUNOUT_FLOOR, "of ω")
              for i, m in enumerate(ORDERS)]
    return max(checks, key=lambda c: c.z)


DECLARED = Declared("ω_read = ω (the wheel's encoder)", "wheel_speed_rad_s", (
    Checking((Relation.WHEEL_ANGLE,), Reads.BRAKING_RUN, wheel_angle_ripple),))
