"""Plausibility checks on a run: catch unit mix-ups and broken logs early, with a clear message."""

from __future__ import annotations

import math

import numpy as np

from .errors import RunFormatError
from .run import Run
from .units import PA_PER_BAR

PLAUSIBLE_MAX: dict[str, tuple[float, str, float]] = {
    "current_a": (20.0, "A", 1.0),
    "pressure_pa": (500 * PA_PER_BAR, "bar", PA_PER_BAR),
    "wheel_speed_rad_s": (5000.0, "rad/s", 1.0),
    "flywheel_speed_rad_s": (2000.0, "rad/s", 1.0),
    "vertical_load_n": (2e6, "N", 1.0),
    "longitudinal_force_n": (2e6, "N", 1.0),
}
"""Largest |value| a landing-gear rig can produce, per field (SI, display unit, factor)."""

SLOWEST_PERIOD_S = 0.1  # rigs log at 10 Hz or faster ...
FASTEST_PERIOD_S = 1e-6  # ... and at 1 MHz or slower
CONTACT_LOAD_N = 2e3  # the wheel is on the flywheel
TURNING_RAD_S = 1.0
BRAKING_PRESSURE_PA = 5 * PA_PER_BAR  # the brake holds torque
MIN_BRAKING_SAMPLES = 50


def check_plausible(fields: dict[str, np.ndarray], where: str) -> None:
    """Raise if a signal is out of any physical range (e.g. Pa declared as bar) or the time
    base is broken."""
    for name, (limit, unit, factor) in PLAUSIBLE_MAX.items():
        peak = float(np.max(np.abs(fields[name])))
        if peak > limit:
            raise RunFormatError(
                f"{where}: {name} reaches {peak / factor:.4g} {unit}, implausible for a rig "
                f"(max {limit / factor:g} {unit}); is the unit wrong? declare it in a "
                "column-mapping file")
    check_time(fields["time_s"], where)
    check_signs(fields, where)


def too_short(run: Run, what: str) -> str | None:
    """Why ``run`` is too short for ``what`` (a plural: 'a stop's metrics'), or None: fewer
    than MIN_BRAKING_SAMPLES rows read as a table but are no stop (a 15-row file had been
    'no table of numbers', then a traceback in a zero-phase filter)."""
    if len(run) >= MIN_BRAKING_SAMPLES:
        return None
    return (f"{run.source or run.name}: the table holds only {len(run)} rows "
            f"({run.time_s[-1] - run.time_s[0]:.3g} s): {what} need at least "
            f"{MIN_BRAKING_SAMPLES} rows while braking, from before the brake to the stop")


REPEATED_SHARE = 0.1  # of the steps zero: the time's digits, not a duplicated sample


def _check_time_digits(time_s: np.ndarray, steps: np.ndarray, where: str) -> None:
    """Raise where time never decreases but its stamps repeat in runs, each step a whole
    number of one resolution: the logger wrote the time with too few digits for its rate
    (2 decimals at 1 kHz), not a duplicated sample."""
    rising = steps[steps > 0]
    if np.any(steps < 0) or rising.size == 0 or np.mean(steps == 0) < REPEATED_SHARE:
        return
    resolution = float(np.min(rising))
    if np.max(np.abs(rising / resolution - np.round(rising / resolution))) > 1e-3:
        return
    rate = (time_s.size - 1) / float(time_s[-1] - time_s[0])
    digits = max(0, -math.floor(math.log10(resolution) + 1e-9))
    needed = max(digits + 1, math.ceil(math.log10(rate)) + 1)
    raise RunFormatError(
        f"{where}: time_s is written with too few digits for its rate: {digits} decimals "
        f"(steps of {resolution:.3g} s) for about {rate:.4g} samples a second, so stamps "
        f"repeat; log the time with {needed} decimals or more")


def check_time(time_s: np.ndarray, where: str) -> None:
    """Raise on non-increasing time, duplicated stamps or a time base in the wrong unit.

    Gaps are data, not a format error (:mod:`msg_tools.timebase` finds and splits them)."""
    steps = np.diff(time_s)
    if time_s.size < 2:
        raise RunFormatError(f"{where}: fewer than 2 samples")
    bad = np.flatnonzero(steps <= 0)
    if bad.size:
        _check_time_digits(time_s, steps, where)
        kind = "duplicated" if steps[bad[0]] == 0 else "decreasing"
        raise RunFormatError(f"{where}: time is not strictly increasing ({kind} time "
                             f"{time_s[bad[0] + 1]:.6g} s at sample {bad[0] + 1})")
    nominal = float(np.median(steps))
    if nominal > SLOWEST_PERIOD_S:
        raise RunFormatError(f"{where}: time advances {nominal:.4g} per sample, as if the rig "
                             f"logged at {1 / nominal:.3g} Hz; is the time in ms? declare its "
                             "unit (a units row, a header such as 'time [ms]', or a "
                             "column-mapping file)")
    if nominal < FASTEST_PERIOD_S:
        raise RunFormatError(f"{where}: time advances {nominal:.3g} s per sample "
                             f"({1 / nominal:.3g} Hz); is it in seconds but declared as ms or "
                             "us?")


def check_signs(fields: dict[str, np.ndarray], where: str) -> None:
    """Raise if the loads have the wrong sign for the contract: vertical load positive
    in contact, longitudinal force positive while braking."""
    contact = (np.abs(fields["vertical_load_n"]) > CONTACT_LOAD_N) & (
        np.abs(fields["flywheel_speed_rad_s"]) > TURNING_RAD_S)
    if contact.sum() < MIN_BRAKING_SAMPLES:
        return
    if np.median(fields["vertical_load_n"][contact]) < 0:
        raise RunFormatError(f"{where}: vertical_load_N is negative while the wheel is loaded; "
                             "the contract counts it positive (scale: -1 in a column mapping)")
    braking = contact & (fields["pressure_pa"] > BRAKING_PRESSURE_PA)
    if braking.sum() >= MIN_BRAKING_SAMPLES and np.median(
            fields["longitudinal_force_n"][braking]) < 0:
        raise RunFormatError(f"{where}: longitudinal_force_N is negative while braking; the "
                             "contract counts it positive when braking (scale: -1 in a "
                             "column mapping)")
