"""A run's clock: stamping noise told from irregular sampling, gaps found, and a run with
long gaps split into parts.

Rig loggers sample on a fixed-rate clock and stamp each row, often from a clock that is not
the sampler's (a PC's, a bag's receive time, a float with few digits): the stamps scatter
around the sampler's grid while the samples themselves are even. :func:`fixed_rate_clock`
finds that grid (each row's index on it and the grid's period and origin by least squares);
a run whose stamps leave it is sampled irregularly and gets resampled instead.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .checks import BRAKING_PRESSURE_PA, CONTACT_LOAD_N, TURNING_RAD_S
from .run import SIGNALS, Run

MAX_STAMP_NOISE = 0.3  # of a period: stamps within this of the fitted grid are on it
MAX_INTERPOLATED_GAP = 5  # missing samples bridged by interpolation ...
MAX_BRIDGED_GAP_S = 0.1  # ... or a logger's dropout up to this long; longer gaps split a run
MIN_PART_S = 1.0  # a part of a split run shorter than this carries too little to keep
PART = "__part"  # a split run's parts are named <run>__part1, <run>__part2, ...


@dataclass(frozen=True)
class Clock:
    """A fixed-rate sampling clock: row i was sampled at ``start_s + index[i] * period_s``."""

    start_s: float
    period_s: float
    index: np.ndarray
    """Integer position of each row on the grid, shape (n,), strictly increasing from 0."""

    @property
    def times_s(self) -> np.ndarray:
        """The rows' instants on the grid [s], shape (n,)."""
        return self.start_s + self.index * self.period_s

    @property
    def missing(self) -> np.ndarray:
        """Samples missing before each row, shape (n,) (0 where none)."""
        return np.concatenate([[0], np.diff(self.index) - 1])


def fixed_rate_clock(time_s: np.ndarray) -> Clock | None:
    """The fixed-rate grid the stamps ``time_s`` [s] scatter around (by less than 30 % of a
    period), or None if the samples were not taken on one."""
    steps = np.diff(time_s)
    nominal = float(np.median(steps))
    if time_s.size < 3 or nominal <= 0:
        return None
    # each step rounded on its own: a slightly wrong nominal period cannot accumulate
    index = np.concatenate([[0], np.cumsum(np.maximum(np.rint(steps / nominal), 1))])
    for _ in range(2):
        period, start = np.polyfit(index, time_s, 1)
        index = np.concatenate([[0], np.cumsum(np.maximum(np.rint(steps / period), 1))])
    period, start = np.polyfit(index, time_s, 1)
    if np.max(np.abs(time_s - start - index * period)) > MAX_STAMP_NOISE * period:
        return None
    return Clock(float(start), float(period), index.astype(np.int64))


def bridgeable(clock: Clock) -> int:
    """The most samples a gap on ``clock`` may miss to be bridged by interpolation (a
    logger's dropout of 50 ms once split every run of a campaign, and the parts that began
    mid-stop were lost)."""
    return max(MAX_INTERPOLATED_GAP, int(MAX_BRIDGED_GAP_S / clock.period_s + 1e-9))


def bridged_samples(clock: Clock) -> np.ndarray:
    """The samples of ``clock``'s grid that no row holds (mask, one per grid instant)."""
    missing = np.ones(int(clock.index[-1]) + 1, dtype=bool)
    missing[clock.index] = False
    return missing


def gap_text(time_s: np.ndarray, clock: Clock, row: int) -> str:
    """The gap before ``row`` in words: how long, after which time."""
    return (f"{clock.missing[row] * clock.period_s:.4g} s missing after "
            f"t = {time_s[row - 1]:.6g} s")


def on_clock(run: Run, clock: Clock) -> Run:
    """``run`` with its stamps replaced by the grid's instants (no sample moved)."""
    return dataclasses.replace(run, time_s=clock.times_s)


@dataclass(frozen=True)
class Split:
    """A run cut at its long gaps: the parts kept and one note per gap or part left out."""

    parts: tuple[Run, ...]
    notes: tuple[str, ...]


def split_at_gaps(run: Run) -> Split:
    """``run`` as it is, or its parts between gaps too long to bridge (:func:`bridgeable`);
    short gaps are noted (they are interpolated where a uniform grid is needed, and left
    out of every comparison with a simulation).

    A part that begins while the brake acts on the loaded wheel is left out: a simulation
    cannot start mid-stop from the measured state. So is a part shorter than MIN_PART_S.
    """
    clock = fixed_rate_clock(run.time_s)
    if clock is None:
        return Split((run,), ())
    missing, limit = clock.missing, bridgeable(clock)
    short = (missing > 0) & (missing <= limit)
    notes = [f"{run.name}: {int(np.sum(short))} short gap(s) of ≤ {limit} samples "
             f"({limit * clock.period_s:.3g} s, {int(np.sum(missing[short]))} samples in all), "
             "interpolated and left out of the comparisons"] if np.any(short) else []
    cuts = np.flatnonzero(missing > limit)
    if not cuts.size:
        return Split((run,), tuple(notes))
    notes.extend(f"{run.name}: {gap_text(run.time_s, clock, int(k))}; the run is split there"
                 for k in cuts)
    parts = []
    for number, (lo, hi) in enumerate(zip([0, *cuts], [*cuts, len(run)], strict=True), 1):
        part = _part(run, lo, hi, number)
        reason = _unusable(part)
        if reason:
            notes.append(f"{part.name}: left out ({reason})")
        else:
            parts.append(part)
    return Split(tuple(parts), tuple(notes))


def _part(run: Run, lo: int, hi: int, number: int) -> Run:
    fields = {name: getattr(run, name)[lo:hi] for name in ("time_s", *SIGNALS)}
    return dataclasses.replace(run, name=f"{run.name}{PART}{number}", **fields)


def _unusable(part: Run) -> str:
    if len(part) < 3 or part.time_s[-1] - part.time_s[0] < MIN_PART_S:
        return f"shorter than {MIN_PART_S:g} s"
    head = slice(0, 5)
    if np.median(braking(part)[head]) > 0.5:
        return "it begins mid-stop, with the brake acting on the loaded wheel"
    return ""


RATE_CHANGE = 0.1  # a log's two ends sampled this far apart (relative) changed its rate


def time_base_notes(run: Run) -> tuple[str, ...]:
    """What a run's time base will cost, in words: a gap too long to bridge while the brake
    acts on the loaded wheel (no stop is measured across it: a campaign reader splits the
    run there and leaves the part begun mid-stop out), and a rate that changes within the
    run (it is resampled at its mean rate for the model)."""
    notes = [note] if (note := rate_change_note(run)) else []
    clock = fixed_rate_clock(run.time_s)
    if clock is not None:
        acting = braking(run)
        notes.extend(f"{run.name}: {gap_text(run.time_s, clock, int(k))} while braking: no "
                     "stop is measured across it (a campaign splits the run there and leaves "
                     "the part begun mid-stop out)"
                     for k in np.flatnonzero(clock.missing > bridgeable(clock))
                     if acting[k - 1] and acting[k])
    return tuple(notes)


def braking(run: Run) -> np.ndarray:
    """Where the brake acts on the loaded wheel (mask). Without a load cell the wheel's
    contact shows as the flywheel (or, without its encoder, the wheel) turning: a NaN load
    had read 'never loaded', and a gap in such a log's stop went unsaid."""
    if "vertical_load_n" not in run.absent:
        loaded = run.vertical_load_n > CONTACT_LOAD_N
    else:
        turning = (run.wheel_speed_rad_s if "flywheel_speed_rad_s" in run.absent
                   else run.flywheel_speed_rad_s)
        loaded = np.abs(turning) > TURNING_RAD_S
    return (run.pressure_pa > BRAKING_PRESSURE_PA) & loaded


def end_rates(run: Run) -> tuple[float, float] | None:
    """The rates [Hz] at the run's start and at its end, when they differ (None: one)."""
    quarter = max(2, run.time_s.size // 4)
    first, last = (1.0 / float(np.median(np.diff(part)))
                   for part in (run.time_s[:quarter], run.time_s[-quarter:]))
    return None if abs(last / first - 1.0) <= RATE_CHANGE else (first, last)


def rate_change_note(run: Run) -> str | None:
    """A rate at the run's start unlike the one at its end, in words (None: one rate). On
    its fast clock the slow part's samples read as one-sample gaps, interpolated."""
    rates = end_rates(run)
    if rates is None:
        return None
    first, last = rates
    return (f"{run.name}: sampled at {first:.4g} Hz at its start and {last:.4g} Hz at its "
            f"end: the slower part is interpolated onto the faster part's clock or both "
            "are resampled at the mean rate for the model; its noise and detail differ "
            "from the rest")
