"""What an equation of the rig is: its name (:class:`Equation`) and what it declares
(:class:`Declared`): its law in words, the measured channel its error shows in and the
relations that check it. Each equation's module declares its own.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.calibration.braking import Braking
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.relations import Checking, Relation
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.run import Run


class Equation(str, enum.Enum):
    """An equation of the rig's model, or a channel's measurement (compares equal to its
    name); what each declares is in its module's ``DECLARED``, gathered by
    :data:`~.registry.DECLARED`."""

    VALVE = "valve"
    WHEEL = "wheel"
    TYRE = "tyre"
    FLYWHEEL = "flywheel"
    LOADING = "loading device"
    FX_CHANNEL = "F_x channel"
    PRESSURE_CHANNEL = "pressure channel"
    WHEEL_CHANNEL = "wheel channel"
    LOAD_CELL = "load cell"

    def __str__(self) -> str:
        return self.value


ErrorOf = Callable[[ClassifiedRun, Braking, RigParameters, Run], np.ndarray]
"""An equation's error at every sample of a braking run under a model, from the run, its
filtered signals, the model and the run simulated with it, (n,) in its unit."""


@dataclass(frozen=True)
class Declared:
    """What an equation declares: its law in words, the measured channel its error shows in,
    and the relations the rig measures twice that check it, each with its check."""

    law: str
    channel: str
    checks: tuple[Checking, ...]

    @property
    def relations(self) -> tuple[Relation, ...]:
        """The relations its checks check."""
        return tuple(r for c in self.checks for r in c.relations)
