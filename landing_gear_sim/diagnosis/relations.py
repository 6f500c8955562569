"""The relations the rig measures twice, as values: which relation (:class:`Relation`), the
relation as a value that checks itself (:class:`Checking`: what it reads and its check), and
one check's result on a run (or the campaign) against its noise and its physical floor
(:class:`Check`). Each equation's module (:mod:`~landing_gear_sim.diagnosis.equations`)
declares its relations with their checks; :mod:`~.consistency` reads them all."""

from __future__ import annotations

import enum
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from landing_gear_sim.calibration.statistics import effective_count

if TYPE_CHECKING:
    from landing_gear_sim.calibration.braking import Braking
    from landing_gear_sim.calibration.runs import ClassifiedRun
    from landing_gear_sim.diagnosis.library import Campaign
    from landing_gear_sim.model.parameters import RigParameters

Z_VIOLATED = 6.0  # σ: with a dozen checks per campaign, no false alarm from noise
MIN_SAMPLES = 200  # a check on fewer samples is not made ...
MIN_CHECK_S = 0.2  # ... or, where a log's rate matters, on less than this much of it (200
# samples of 1 kHz; a 200 Hz log's one second of free rolling was too few samples to check)


class Relation(str, enum.Enum):
    """A relation the rig measures twice, by its display text (compares equal to it); the
    equation that declares it (``diagnosis.equations.registry.DECLARED``) is the one it
    checks."""

    FREE_ROLLING = "free rolling ⇒ F_x = J_w ω̇ / r"
    ZERO_CURRENT = "zero current ⇒ zero pressure"
    NO_CONTACT = "no contact ⇒ no load"
    GAIN_IN_SPEED = "brake gain constant in speed"
    GAIN_IN_PRESSURE = "brake gain linear in pressure"
    RUN_DRIFT = "brake gain constant from run to run"
    VALVE_DIRECTION = "valve the same with the current rising and falling"
    FRICTION_IN_LOAD = "friction the same at every load"
    WHEEL_ANGLE = "wheel channel smooth in the wheel's angle"
    PRESSURE_TIMING = "brake torque in step with the measured pressure"
    BRAKE_ANGLE = "brake torque smooth in the wheel's angle"
    WHEEL_BALANCE = "wheel turned by the tyre and the brake alone"
    FLYWHEEL_BALANCE = "flywheel slowed by F_x and the drag alone"
    LOADING_LAW = "vertical load follows F_z0 − k_L v²"
    VALVE_MAP = "valve settles on its quadratic static map"
    TYRE_LAW = "tyre follows its friction curve"
    LOCKED_SLIDING = "a locked wheel slides at the curve's μ(λ = 1) at every speed"
    FX_CHANNEL = "F_x channel reads F_x where it is known"
    VALVE_DYNAMICS = "valve follows A(s) between its levels"
    PRESSURE_READING = "brake torque follows the pressure read, whenever read"

    def __str__(self) -> str:
        return self.value


@dataclass(frozen=True)
class Check:
    """One relation on one run (or the campaign) and phase: the deviation found, its 1-σ
    and the floor below which it does not matter, in ``unit``; and what the noise in the
    model's inputs can make of it (a violation within that calls for a term, which the
    scoring may accept, but is no structure to report unexplained)."""

    relation: Relation
    run: str
    phase: str
    deviation: float
    std: float
    floor: float
    unit: str
    input_noise: float = 0.0

    @property
    def z(self) -> float:
        """The deviation over its σ (0 ± 0, a channel that never moved, is none: it had read
        as infinite σ)."""
        if self.std > 0:
            return abs(self.deviation) / self.std
        return 0.0 if self.deviation == 0.0 else math.inf

    @property
    def violated(self) -> bool:
        return self.z > Z_VIOLATED and abs(self.deviation) > self.floor

    @property
    def within_input_noise(self) -> bool:
        """Violated, but no further out than the noise in the model's inputs can move it."""
        return self.violated and abs(self.deviation) <= self.input_noise

    def describe(self) -> str:
        return self.reading() + self.mark()

    def reading(self) -> str:
        """The relation, where it was checked and what it read, without a judgement."""
        return (f"{self.relation} ({self.run}, {self.phase}): {self.deviation:+.4g} {self.unit} "
                f"± {self.std:.2g} ({self.z:.0f}σ)")

    def mark(self) -> str:
        """How the check reads beside a verdict: violated, violated within the noise the
        model's inputs carry (no structure), or nothing."""
        if self.within_input_noise:
            return (f"  violated within the inputs' noise ({self.input_noise:.2g} {self.unit}):"
                    " no structure")
        return "  VIOLATED" if self.violated else ""

    def to_json(self) -> dict[str, object]:
        return {"relation": self.relation, "run": self.run, "phase": self.phase,
                "deviation": self.deviation, "std": self.std, "floor": self.floor,
                "unit": self.unit, "violated": self.violated,
                "input_noise": self.input_noise}


def mean_check(relation: Relation, run: str, phase: str, values: np.ndarray, floor: float,
               unit: str, rate_hz: float) -> Check | None:
    """A relation that says ``values`` are 0 on average, read as their mean with its 1-σ
    (autocorrelation counted); None on less than MIN_CHECK_S of samples."""
    if values.size < MIN_CHECK_S * rate_hz:
        return None
    mean = float(np.mean(values))
    std = float(np.std(values)) / math.sqrt(effective_count(values - mean))
    return Check(relation, run, phase, mean, std, floor, unit)


def structural(checks: Sequence[Check]) -> list[Check]:
    """The violated checks beyond what the noise in the model's inputs can make."""
    return [c for c in violations(checks) if not c.within_input_noise]


def violations(checks: Sequence[Check]) -> list[Check]:
    """The violated checks, strongest first."""
    return sorted((c for c in checks if c.violated), key=lambda c: -c.z)


class Reads(str, enum.Enum):
    """What a relation's check reads, and so how it is called: a run (``check(run,
    params)``), a braking run's filtered signals (``check(braking, params)``), the braking
    runs together (``check(brakings, params)``) or the campaign (``check(campaign,
    params)``, an equation's library)."""

    ANY_RUN = "each run"
    ACTUATOR_RUN = "each run off the flywheel"
    BRAKING_RUN = "each braking run"
    BRAKING_RUNS = "the braking runs together"
    CAMPAIGN = "the campaign"


Checked = Check | Sequence[Check] | None


@dataclass(frozen=True)
class Checking:
    """A relation as a value that checks itself (or several relations one reading checks
    at once, as the brake gain's trends): what it reads (:class:`Reads`) and its check."""

    relations: tuple[Relation, ...]
    reads: Reads
    check: Callable[..., Checked]

    def on_run(self, run: ClassifiedRun, braking: Braking | None, params: RigParameters
               ) -> list[Check]:
        """Its checks of one run (``braking``: the run's filtered signals, a braking run's)."""
        args: tuple[Any, ...] | None = {
            Reads.ANY_RUN: (run,),
            Reads.ACTUATOR_RUN: (run,) if braking is None else None,
            Reads.BRAKING_RUN: (braking,) if braking is not None else None,
        }.get(self.reads)
        return [] if args is None else _listed(self.check(*args, params))

    def on_campaign(self, campaign: Campaign, params: RigParameters) -> list[Check]:
        """Its checks of the campaign as a whole."""
        if self.reads is Reads.CAMPAIGN:
            return _listed(self.check(campaign, params))
        if self.reads is Reads.BRAKING_RUNS and campaign.braking:
            return _listed(self.check(campaign.braking, params))
        return []


def _listed(checked: Checked) -> list[Check]:
    if checked is None:
        return []
    return [checked] if isinstance(checked, Check) else [c for c in checked if c is not None]
