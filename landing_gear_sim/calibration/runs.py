"""Measured runs and their kinds: each run classified once, from its signals, and carried.

A :class:`ClassifiedRun` is a :class:`~msg_tools.run.Run` on a uniform time base that
knows its :class:`RunKind` and its braking start; identification, validation and
diagnosis classify the runs they are given once (:func:`classified`) and pass these on.
Every filter, derivative and simulation downstream assumes one sample period, so a run
whose stamps are not evenly spaced is put on a uniform grid first: stamps that scatter
around a fixed-rate clock (a logger's stamping noise, float steps) are replaced by the
clock's instants and the samples kept; short gaps in it are interpolated (linear, the
current held); samples taken irregularly are resampled at their mean rate.
"""

from __future__ import annotations

import dataclasses
import enum
import functools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np

from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import rim_speed_m_s
from landing_gear_sim.model.scenario import (
    brake_start_index,
    current_noise_a,
    denoised_command,
    leftover_noise_a,
)
from msg_tools.errors import RunFormatError
from msg_tools.io import is_uniform, resample
from msg_tools.run import Run
from msg_tools.timebase import (
    bridgeable,
    bridged_samples,
    fixed_rate_clock,
    gap_text,
    on_clock,
)

STILL_FLYWHEEL_RAD_S = 1.0  # an actuator-only run: the flywheel stands still ...
NO_CONTACT_LOAD_N = 2e3  # ... and the wheel carries (almost) no load
RAMP_RATE_A_S = 1.0  # fastest current change of a quasi-static ramp ...
RAMP_SMOOTHING_S = 0.2  # ... measured on the current averaged over this (logging noise)
RAMP_SPAN_A = 0.5  # ... which must cover this much of the valve's range
CONSTANT_STD_A = 5e-3  # a braking run whose current varies less than this is constant ...
CONSTANT_NOISE_FACTOR = 3.0  # ... or less than this many σ of its logging noise
SETTLE_S = 0.3  # after the braking start the current has settled
UNIFORM_TOLERANCE = 1e-3  # of a period: steps closer than this count as evenly spaced
SETTLE_AFTER_GAP_S = 0.2


class Setup(enum.Enum):
    """How the rig is set up for a run: the wheel off the flywheel (an actuator-only test)
    or on it (a braking test)."""

    ACTUATOR = "actuator"
    BRAKE = "brake"

    def __str__(self) -> str:
        return self.value


class RunKind(str, enum.Enum):
    """What a run is, read from its signals. Compares equal to its value (JSON, tables)."""

    ACTUATOR_RAMP = "actuator_ramp"
    ACTUATOR_DYNAMIC = "actuator_dynamic"
    BRAKE_CONSTANT = "brake_constant"
    BRAKE_OSCILLATING = "brake_oscillating"

    def __str__(self) -> str:
        return self.value

    @property
    def setup(self) -> Setup:
        return _SETUPS[self]

    @property
    def braking(self) -> bool:
        """The wheel is on the flywheel: speeds, loads and forces carry information."""
        return self.setup is Setup.BRAKE


_SETUPS = {RunKind.ACTUATOR_RAMP: Setup.ACTUATOR, RunKind.ACTUATOR_DYNAMIC: Setup.ACTUATOR,
           RunKind.BRAKE_CONSTANT: Setup.BRAKE, RunKind.BRAKE_OSCILLATING: Setup.BRAKE}

Selector = RunKind | Setup
"""A run kind, or every kind of a setup."""


def setup_of(selector: Selector) -> Setup:
    return selector.setup if isinstance(selector, RunKind) else selector


def matches(kind: RunKind, selectors: Iterable[Selector]) -> bool:
    """Whether ``kind`` is one of ``selectors`` (kinds or setups)."""
    return any(kind is s or kind.setup is s for s in selectors)


@dataclass(frozen=True)
class ClassifiedRun(Run):
    """A run with its kind and its braking start [s, on the run's own clock] (the first
    brake command; the run's end when there is none)."""

    kind: RunKind = dataclasses.field(kw_only=True)
    brake_start_s: float = dataclasses.field(kw_only=True)
    campaign_order: float = dataclasses.field(kw_only=True, default=0.0)
    """Place among the campaign's braking runs in run order, about the middle one
    (−1, 0, 1 for three); 0 for a run classified on its own or one that does not brake."""

    bridged: np.ndarray | None = dataclasses.field(kw_only=True, default=None)
    """Samples a logger lost and the uniform grid interpolated (mask (n,)), None when none:
    a simulation of the run is not compared there (:func:`compared`)."""

    @classmethod
    def of(cls, run: Run) -> ClassifiedRun:
        """``run`` on a uniform time base, classified."""
        bridged = _bridged(run)
        run = on_uniform_grid(run)
        fields = {f.name: getattr(run, f.name) for f in dataclasses.fields(Run)}
        start = brake_start_s(run)
        return cls(**fields, kind=classify(run, start), brake_start_s=start, bridged=bridged)

    @property
    def compared(self) -> np.ndarray:
        """The samples a simulation is compared on (mask (n,)): all but those the logger lost
        and SETTLE_AFTER_GAP_S after each (a simulation fed the held current through a gap
        takes that long to follow the rig again)."""
        if self.bridged is None:
            return np.ones(len(self), dtype=bool)
        after = max(1, round(SETTLE_AFTER_GAP_S * self.rate_hz))
        lost = np.convolve(self.bridged, np.ones(after + 1), mode="full")[:len(self)] > 0
        return ~lost

    @property
    def braking(self) -> bool:
        return self.kind.braking

    @functools.cached_property
    def command_a(self) -> np.ndarray:
        """The brake command behind the logged current [A], shape (n,); computed once,
        every simulation of the run feeds it.

        The valve was driven by the command, not by the logger's noise; fed to the model,
        that noise is errors-in-variables within the valve's bandwidth, where wheel-lock
        events are sensitive to it (:func:`~landing_gear_sim.model.scenario.denoised_command`),
        and a valve with play follows it (10 mA of noise kicked the play operator back and
        forth on a quasi-static ramp). Dynamic actuator runs (sweeps up to 100 Hz, which a
        median would flatten) keep the log.
        """
        if self.kind is RunKind.ACTUATOR_DYNAMIC:
            return self.current_a
        return denoised_command(self.current_a, self.rate_hz)[0]

    def fed_noise_a(self, noise_a: float) -> float:
        """The σ [A] of a logger's white noise ``noise_a`` left in :attr:`command_a`."""
        if self.kind is RunKind.ACTUATOR_DYNAMIC:
            return noise_a
        return leftover_noise_a(noise_a, self.rate_hz)


def on_uniform_grid(run: Run) -> Run:
    """``run`` itself if its samples are evenly spaced (to 0.1 % of a period); on its
    sampling clock if it has one (gaps of a few samples interpolated); else resampled at
    its mean rate rounded to 1 Hz. A gap too long to bridge is an error (campaign readers
    split such runs, :func:`~msg_tools.timebase.split_at_gaps`)."""
    if is_uniform(run, UNIFORM_TOLERANCE):
        return run
    clock = fixed_rate_clock(run.time_s)
    if clock is None:
        return resample(run, round(run.rate_hz))
    missing = clock.missing
    if missing.max() > bridgeable(clock):
        raise RunFormatError(f"{run.name}: {gap_text(run.time_s, clock, int(np.argmax(missing)))}"
                             ", too long to interpolate; read it as part of a campaign to "
                             "have it split there")
    run = on_clock(run, clock)
    return resample(run, 1.0 / clock.period_s) if missing.max() else run


def _bridged(run: Run) -> np.ndarray | None:
    """The samples of ``run``'s uniform grid that no row holds, None when it has no gap."""
    if is_uniform(run, UNIFORM_TOLERANCE):
        return None
    clock = fixed_rate_clock(run.time_s)
    if clock is None or not clock.missing.max():
        return None
    return bridged_samples(clock)


def classified(run: Run) -> ClassifiedRun:
    """``run`` classified (a run classified already is returned as it is)."""
    return run if isinstance(run, ClassifiedRun) else ClassifiedRun.of(run)


def classify_all(runs: Iterable[Run]) -> list[ClassifiedRun]:
    """The runs of one campaign (in run order) classified, each braking run with its
    ``campaign_order``; runs classified already keep theirs (a subset must not renumber)."""
    given = list(runs)
    done = [classified(r) for r in given]
    if any(isinstance(r, ClassifiedRun) for r in given):
        return done
    braking = [i for i, r in enumerate(done) if r.braking]
    middle = (len(braking) - 1) / 2
    for rank, i in enumerate(braking):
        done[i] = dataclasses.replace(done[i], campaign_order=rank - middle)
    return done


RunT = TypeVar("RunT", bound=Run)


def fully_logged(runs: Sequence[RunT], analysis: str) -> tuple[list[RunT], list[str]]:
    """The runs that logged every channel, and a note for each left out of ``analysis``
    (a braking log without load cells or a flywheel encoder: its model needs them all)."""
    kept = [r for r in runs if not r.absent]
    return kept, [f"{r.name}: {', '.join(r.absent)} not logged: left out of {analysis}"
                  for r in runs if r.absent]


def select(runs: Sequence[ClassifiedRun], selectors: Iterable[Selector]) -> list[ClassifiedRun]:
    """The runs of one of ``selectors`` (kinds or setups), in order."""
    chosen = tuple(selectors)
    return [r for r in runs if matches(r.kind, chosen)]


def classify(run: Run, brake_start: float | None = None) -> RunKind:
    """The kind of ``run`` from its signals: actuator-only (flywheel still, no load) as a
    quasi-static ramp or dynamic; braking at constant or oscillating current
    (``brake_start``: :func:`brake_start_s` of the run, if known already)."""
    if (np.max(run.flywheel_speed_rad_s) < STILL_FLYWHEEL_RAD_S
            and np.max(np.abs(run.vertical_load_n)) < NO_CONTACT_LOAD_N):
        ramp = _fastest_change_a_s(run) < RAMP_RATE_A_S and np.ptp(run.current_a) > RAMP_SPAN_A
        return RunKind.ACTUATOR_RAMP if ramp else RunKind.ACTUATOR_DYNAMIC
    start = brake_start_s(run) if brake_start is None else brake_start
    settled = run.time_s > start + SETTLE_S
    limit = max(CONSTANT_STD_A, CONSTANT_NOISE_FACTOR * current_noise_a(run.current_a))
    if settled.sum() < 10 or np.std(run.current_a[settled]) < limit:
        return RunKind.BRAKE_CONSTANT
    return RunKind.BRAKE_OSCILLATING


def _fastest_change_a_s(run: Run) -> float:
    """Largest rate of change of the current averaged over RAMP_SMOOTHING_S [A/s]: a
    ramp's slope, not its logging noise (averaging n samples divides the noise's rate
    by about n)."""
    period = float(np.median(np.diff(run.time_s)))
    width = max(1, round(RAMP_SMOOTHING_S / period))
    if run.current_a.size <= width:
        return float(np.max(np.abs(np.diff(run.current_a)))) / period
    averaged = np.convolve(run.current_a, np.full(width, 1.0 / width), mode="valid")
    return float(np.max(np.abs(np.diff(averaged)))) / period


def brake_start_s(run: Run) -> float:
    """Time of the first brake command (or the run's end if never) [s, run clock]."""
    index = brake_start_index(run.current_a, run.rate_hz)
    return float(run.time_s[-1] if index is None else run.time_s[index])


def braking_window(run: ClassifiedRun, params: RigParameters) -> np.ndarray:
    """Samples from the brake application to where the rig is about to stop (mask (n,))."""
    speed = rim_speed_m_s(params, run.flywheel_speed_rad_s)
    return (run.time_s >= run.brake_start_s) & (
        speed > params.number(K.RIG_TEST_STOP_SPEED_M_S) + 1.0)
