"""The load cell's F_z channel: F_z,read = F_z. Its relation: with no contact (an actuator
run, the wheel off the flywheel) the load cell reads no load.
"""

from __future__ import annotations

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.equations.equation import Declared
from landing_gear_sim.diagnosis.relations import Check, Checking, Reads, Relation, mean_check
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.sensors import SensorModel

FORCE_FLOOR_N = 150.0  # a load-cell offset or crosstalk smaller than this does not matter


def no_contact(run: ClassifiedRun, params: RigParameters) -> list[Check]:
    """An actuator run's F_z and F_x (the model's crosstalk taken off) over the whole run:
    with the wheel off the flywheel the load cell reads no load."""
    fx = SensorModel.of(params).true_longitudinal(run.longitudinal_force_n,
                                                  run.vertical_load_n, br.run_time_s(run))
    return [c for values, label in ((run.vertical_load_n, "F_z"), (fx, "F_x"))
            if np.any(values != 0.0)  # all 0: a channel the log never had (3 columns)
            and (c := mean_check(Relation.NO_CONTACT, run.name, f"whole run, {label}",
                                 values, FORCE_FLOOR_N, "N", run.rate_hz)) is not None]


DECLARED = Declared("F_z,read = F_z (the load cell)", "vertical_load_n", (
    Checking((Relation.NO_CONTACT,), Reads.ACTUATOR_RUN, no_contact),))
