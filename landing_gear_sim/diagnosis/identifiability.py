"""What a campaign can tell: which candidates its runs can identify, before anything is
fitted.

A candidate is fitted on the runs that carry its signature and checked on others. Some
runs are indispensable: the valve's map and A(s) are calibrated on the actuator-only
runs, and without them an actuator effect fitted on the braking runs' pressure absorbs the
uncalibrated valve (a 13.7 ms "delay" on a rig that had none, issue 13); without braking
runs nothing about the wheel can be told. Such candidates are skipped with a reason, and
the verdict cannot be ``none`` while they are untested.
"""

from __future__ import annotations

from collections.abc import Sequence

from landing_gear_sim.calibration.runs import ClassifiedRun, RunKind, Selector, Setup, select
from landing_gear_sim.diagnosis.catalogue import Candidate

Need = tuple[Selector, str, str]
"""A run kind (or family) a candidate cannot be identified without, named, and why."""

REQUIRED: dict[str, Need] = {
    "actuator_delay": (RunKind.ACTUATOR_DYNAMIC, "actuator step/sweep run",
                       "without it the valve's A(s) is not calibrated and a delay would "
                       "absorb its error"),
    "actuator_dynamics": (RunKind.ACTUATOR_DYNAMIC, "actuator step/sweep run",
                          "the pressure's response to fast current changes"),
    "pressure_sensor_offset": (RunKind.ACTUATOR_RAMP, "quasi-static actuator ramp",
                               "the valve map is re-fitted with the offset; without it the "
                               "offset trades with the uncalibrated map"),
}
"""Causes that need a run kind beyond their family."""
BRAKING_NEED: Need = (Setup.BRAKE, "braking run", "the wheel's signals")
ACTUATOR_NEED: Need = (Setup.ACTUATOR, "actuator-only run", "the valve alone")


def required_runs(candidate: Candidate) -> Need:
    """The runs ``candidate`` cannot be identified without."""
    if candidate.cause in REQUIRED:
        return REQUIRED[candidate.cause]
    return ACTUATOR_NEED if Setup.ACTUATOR in candidate.runs else BRAKING_NEED


def untestable(candidate: Candidate, runs: Sequence[ClassifiedRun]) -> str:
    """Why ``runs`` cannot identify ``candidate`` ('' when they can)."""
    needed, what, why = required_runs(candidate)
    return "" if select(runs, [needed]) else f"not identifiable: no {what} in the campaign ({why})"


def actuator_calibrated(runs: Sequence[ClassifiedRun]) -> bool:
    """Whether the valve's map and A(s) were calibrated (so the pressure residual means
    something about the rig, not about the datasheet)."""
    return bool(select(runs, [RunKind.ACTUATOR_RAMP]) and select(runs, [RunKind.ACTUATOR_DYNAMIC]))
