"""Consistency of what the rig measures twice (issue 14, part 1).

The rig measures more than the model needs. Relations that hold whatever the model's
parameters are checked on each run and phase, against their noise; a violation is evidence
on its own, even where the calibrated model fits well (a calibration can bend the friction
curve, the brake gain or the drag to swallow an effect the relations still show):

* free rolling (no brake): the load cell's F_x is the wheel's own inertia, J_w ω̇ / r;
* zero current ⇒ zero pressure (once the valve has settled);
* no contact (actuator-only runs) ⇒ zero loads;
* the valve's pressure against the model's, where the current changes slowly, does not
  depend on whether the current last rose or fell (play, hysteresis: ``input_history``);
* in free rolling the wheel channel is smooth in the wheel's angle: no ripple once or twice
  per revolution beyond the model's (run-out, an out-of-round code wheel: ``wheel_angle``);
  and so is the brake torque while it brakes (a disc's run-out: ``wheel_angle`` too);
* at the same slip, μ = F_x/F_z does not depend on the load, where runs at two static
  loads share slips (a tyre's load sensitivity beyond the radius law: ``load``);
* the brake gain of the wheel's torque balance r F_x − J_w ω̇ = k_b P does not depend on
  the speed or on the pressure level (a local k_b, fitted with a linear trend), nor on the
  run (k_b of each run, in the campaign's run order: wear, a brake that beds in).

Each check is a deviation with its 1-σ from the residual's own noise (autocorrelation
counted) and a physical floor below which nothing matters; violated when it exceeds both
Z_VIOLATED σ and the floor. Each relation is a value that checks itself, declared by its
equation (:class:`~.relations.Checking` in :mod:`~landing_gear_sim.diagnosis.equations`);
this module reads them all over a campaign, and says what they leave unchecked or
unresolved. No plotting here
(:mod:`landing_gear_sim.report.diagnosis`).
"""


from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.plausibility import counted_wheel_step
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.equations.registry import (
    DECLARED,
    campaign_checks,
    declaring,
    run_checks,
)
from landing_gear_sim.diagnosis.equations.wheel import LOAD_SPREAD
from landing_gear_sim.diagnosis.equations.wheel_channel import RUNOUT_FLOOR
from landing_gear_sim.diagnosis.findings import Finding
from landing_gear_sim.diagnosis.library import Campaign
from landing_gear_sim.diagnosis.relations import Z_VIOLATED, Check, Relation, violations
from landing_gear_sim.model.parameters import RigParameters


def check_campaign(runs: Sequence[ClassifiedRun], params: RigParameters) -> list[Check]:
    """Every check the runs allow, under ``params`` (radius law, wheel inertia, sensor
    offset of the calibrated model), as each equation declares its relations' checks: each
    run's, then the campaign's."""
    prepared = [br.prepare(r, params) if r.braking else None for r in runs]
    checks = [c for run, b in zip(runs, prepared, strict=True)
              for c in run_checks(run, b, params)]
    braking = [b for b in prepared if b is not None]
    return checks + campaign_checks(Campaign(runs, braking), params)


def unchecked_relations(runs: Sequence[ClassifiedRun], checks: Sequence[Check]) -> list[str]:
    """The relations a campaign with braking runs left unchecked, each with what would
    check it (for ``problems``: a relation not checked is not a relation that holds)."""
    relation = Relation.FRICTION_IN_LOAD
    if not any(r.braking for r in runs) or any(c.relation == relation for c in checks):
        return []
    return [f"{relation}: not checked, no two constant-pressure stops at each of two "
            f"static loads ≥ {LOAD_SPREAD:.0%} apart that share slips; stops at a second static "
            "load (e.g. 70 % at 70 % of the pressures: `campaign --light-runs`) show a tyre's "
            "friction changing with the load"]

def coarse_channels(runs: Sequence[ClassifiedRun], checks: Sequence[Check]) -> list[str]:
    """What a counted wheel channel cannot resolve (for ``problems``: a ``none`` through a
    coarse encoder is no proof of a smooth wheel): the smallest ripple with the wheel's angle
    a run's free-rolling check would call violated, Z_VIOLATED of its σ (median over runs)."""
    if counted_wheel_step(runs) is None:
        return []
    stds = [c.std for c in checks if c.relation == Relation.WHEEL_ANGLE]
    if not stds:
        return []
    bound = max(Z_VIOLATED * float(np.median(stds)), RUNOUT_FLOOR)
    return [f"{Relation.WHEEL_ANGLE}: through the counted wheel channel a ripple below "
            f"{100 * bound:.1f} % of ω does not show ({Z_VIOLATED:g}σ of the free-rolling "
            f"checks, median over {len(stds)})"]

def under_floor(checks: Sequence[Check]) -> list[str]:
    """The deviations beyond Z_VIOLATED σ that lie under their floor, or within what the
    noise in the model's inputs can make (for ``problems``): the data show them, the
    diagnosis does not report them as structure, and ``none`` does not rule out an effect
    of their size (a tyre's μ_B·v² law logged at 200 Hz read 0.027 at 11σ under the 0.046
    its slip noise then allowed, and was said nowhere)."""
    under = [f"{c.reading()} lies under its floor {c.floor:.4g} {c.unit} (the least that "
             "matters, or what the log's noise makes of it): an effect of this size is not "
             "told from that here"
             for c in sorted(checks, key=lambda c: -c.z)
             if c.z > Z_VIOLATED and not c.violated]
    within = [f"{c.reading()} lies within the {c.input_noise:.4g} {c.unit} the noise in "
              "the model's inputs can make of it (a noisy logged current fed to the valve): "
              "an effect of this size is not told from that here"
              for c in violations(checks) if c.within_input_noise]
    return under + within

def inconsistent(broken: Sequence[Check]) -> Finding:
    """Violated relations as an ``unexplained`` finding (nothing in the model explains
    them): the strongest one's deviation, every one in the evidence, and the equation (or
    the channel's measurement) its relation checks."""
    best = broken[0]
    equation = declaring(best.relation)
    channel = DECLARED[equation].channel
    return Finding(cause="unexplained", parameters={"deviation": best.deviation},
                   std={"deviation": best.std}, units={"deviation": best.unit},
                   evidence=f"measured relations the model cannot break are violated, in the "
                   f"{equation}: " + "; ".join(c.describe() for c in broken[:4])
                   + (f"; and {len(broken) - 4} more" if len(broken) > 4 else ""),
                   fit_before={}, fit_after={}, delta_bic=None, held_out=None, accepted=False,
                   fitted_on=tuple(sorted({c.run for c in broken})), equation=str(equation),
                   channel=channel)
