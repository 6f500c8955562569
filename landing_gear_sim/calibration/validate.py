"""Simulate measured runs with their own inputs and score the model per channel.

Fit % = 100·(1 − ‖y − ŷ‖/‖y − ȳ‖) on simulation (not one-step prediction), plus
RMSE and maximum error, per contract channel. A channel *passes* when its RMSE is within
``NOISE_MULTIPLE`` times the logger's noise read from the measured channel itself: fit %
punishes a run that varies little (a 10 bar stop read 93 % at the logger's own 0.15 bar
noise, a 64-count encoder's perfect model 45 %), the tolerance does not.
:func:`validate_campaign` also gathers what the validation report draws: the measured
friction points and the actuator's measured frequency response beside the model's.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from landing_gear_sim.calibration import braking as br
from landing_gear_sim.calibration.actuator import FrfEstimate, actuator_frf
from landing_gear_sim.calibration.friction import friction_samples
from landing_gear_sim.calibration.measured import CHANNELS, channels_of, simulate_run
from landing_gear_sim.calibration.noise import channel_noise
from landing_gear_sim.calibration.plausibility import check_units
from landing_gear_sim.calibration.runs import (
    RunKind,
    Setup,
    classified,
    classify_all,
    select,
)
from landing_gear_sim.errors import ComparisonError
from landing_gear_sim.model.integrate import SimulationResult
from landing_gear_sim.model.parameters import RigParameters
from msg_tools.io import at_times
from msg_tools.run import Run

NOISE_MULTIPLE = 3.0
"""A channel passes with its RMSE within this many times its logger's noise. Measured with
the model `identify` calibrates: its own campaigns and the shared nulls at 2 kHz, 200 Hz,
with a noisy current or a 64-count encoder read 0.8-2.6 times their noise on every
channel (but the encoder null's longitudinal force on its locking stop, 6.3: a calibration
the encoder blurred); a model missing a 6 ms valve delay 3.4-120 times on pressure and
wheel speed."""


@dataclass(frozen=True)
class Score:
    """Agreement of one channel: fit [%], RMSE and max |error|, and the measured channel's
    noise (:func:`~landing_gear_sim.calibration.noise.channel_noise`), in its SI unit."""

    fit_percent: float
    rmse: float
    max_error: float
    noise: float

    @property
    def tolerance(self) -> float:
        """The RMSE the channel passes within: ``NOISE_MULTIPLE`` × its noise."""
        return NOISE_MULTIPLE * self.noise

    @property
    def passed(self) -> bool:
        """RMSE within the tolerance (False where the noise is unknown)."""
        return self.rmse <= self.tolerance

    @property
    def in_noise(self) -> float:
        """RMSE over the noise (inf where the noise is unknown or nil)."""
        return self.rmse / self.noise if self.noise > 0 else float("inf")


@dataclass(frozen=True)
class RunComparison:
    """A measured run, its simulation with the measured input, and the scores."""

    measured: Run
    simulated: Run
    kind: RunKind
    scores: dict[str, Score]
    result: SimulationResult | None = None
    notes: tuple[str, ...] = ()
    """How the two were put on one time base, when it took more than matching samples."""


@dataclass(frozen=True)
class Validation:
    """Everything a validation report shows: the comparisons, the measured (slip, μ)
    points of the braking runs (None without braking runs), and the actuator's measured
    FRF beside the model's for each dynamic actuator run."""

    params: RigParameters
    comparisons: list[RunComparison]
    friction_points: tuple[np.ndarray, np.ndarray] | None
    frf: list[FrfEstimate]


@dataclass(frozen=True)
class ChannelVerdict:
    """One channel over a campaign: the runs it was scored on, those whose RMSE exceeds
    the tolerance, and the run it misses most, in multiples of that run's noise."""

    channel: str
    runs: tuple[str, ...]
    failed: tuple[str, ...]
    worst_run: str
    worst: Score

    @property
    def passed(self) -> bool:
        return not self.failed


def channel_verdicts(comparisons: Sequence[RunComparison]) -> list[ChannelVerdict]:
    """Each scored channel's pass or fail over ``comparisons``, in the contract's order."""
    verdicts = []
    for channel in CHANNELS:
        scored = [(c.measured.name, c.scores[channel]) for c in comparisons
                  if channel in c.scores]
        if not scored:
            continue
        worst_run, worst = max(scored, key=lambda item: item[1].in_noise)
        verdicts.append(ChannelVerdict(channel, tuple(name for name, _ in scored),
                                       tuple(name for name, s in scored if not s.passed),
                                       worst_run, worst))
    return verdicts


def fit_percent(measured: np.ndarray, simulated: np.ndarray) -> float:
    """100·(1 − ‖y − ŷ‖/‖y − ȳ‖); 100 is perfect, can be negative."""
    spread = float(np.linalg.norm(measured - measured.mean()))
    if spread == 0.0:
        return float("nan")
    return 100.0 * (1.0 - float(np.linalg.norm(measured - simulated)) / spread)


def score(measured: np.ndarray, simulated: np.ndarray) -> Score:
    error = measured - simulated
    return Score(fit_percent(measured, simulated), float(np.sqrt(np.mean(error ** 2))),
                 float(np.max(np.abs(error))), channel_noise(measured))


def compare(measured: Run, simulated: Run) -> RunComparison:
    """Score ``simulated`` against ``measured`` over the span both cover, each timed from
    its own start (a log's clock may read the epoch, a simulation's 0): the simulation at
    the measured samples (``measured`` on its uniform grid, as classified: the comparison
    keeps the samples it scored). A 100 Hz log had been matched sample by sample against a
    1 kHz simulation: the simulated trace stretched ten times."""
    run = classified(measured)
    simulated, notes = on_time_base(simulated, run)
    n = len(simulated)
    scores = {c: score(getattr(run, c)[:n], getattr(simulated, c)) for c in channels_of(run)}
    inputs = _inputs_differ(run.current_a[:n], simulated.current_a)
    return RunComparison(run, simulated, run.kind, scores,
                         notes=(*notes, *([inputs] if inputs else [])))


INPUT_SHARE = 0.02  # of the measured current's range: the two runs were given one input


def _inputs_differ(measured_a: np.ndarray, simulated_a: np.ndarray) -> str | None:
    """What says that the two runs were given different current references (their fits
    then compare two tests, not a model with its rig: a 20 bar stop against a 40 bar one
    had read −150 % with no word); None when they were given one."""
    difference = simulated_a - measured_a
    rms = float(np.sqrt(np.mean(difference ** 2)))
    span = float(np.ptp(measured_a)) or float(np.max(np.abs(measured_a))) or 1.0
    if rms <= INPUT_SHARE * span:
        return None
    return (f"the two runs' current references differ by {rms:.3g} A rms (at most "
            f"{float(np.max(np.abs(difference))):.3g} A, {100 * rms / span:.0f} % of the "
            "measured current's range): they were given different inputs, and their fits "
            "compare two tests")


SAME_RATE = 0.01  # rates closer than this (relative) are one rate


def on_time_base(simulated: Run, measured: Run) -> tuple[Run, tuple[str, ...]]:
    """``simulated`` at ``measured``'s samples over the span both cover, and what that
    took (notes); unchanged when the two share their samples."""
    elapsed = measured.time_s - measured.time_s[0]
    span = float(simulated.time_s[-1] - simulated.time_s[0])
    n = int(np.searchsorted(elapsed, span + 0.5 / measured.rate_hz, side="right"))
    if n == len(simulated) == len(measured) and np.allclose(
            simulated.time_s - simulated.time_s[0], elapsed, atol=1e-9):
        return simulated, ()
    if n < 2:
        raise ComparisonError(f"{simulated.source or simulated.name} covers {span:.3g} s: "
                              "less than two of the measured run's samples to compare on")
    notes = []
    if abs(simulated.rate_hz / measured.rate_hz - 1.0) > SAME_RATE:
        notes.append(f"the measured run is logged at {measured.rate_hz:.4g} Hz, the "
                     f"simulation at {simulated.rate_hz:.4g} Hz: the simulation is compared "
                     "at the measured samples (linear between its own)")
    if n < len(measured) or span > elapsed[-1] + 1.0 / measured.rate_hz:
        notes.append(f"compared over the first {elapsed[n - 1]:.3g} s, the span both cover "
                     f"(measured {elapsed[-1]:.3g} s, simulated {span:.3g} s)")
    at = at_times(simulated, simulated.time_s[0] + elapsed[:n])
    return replace(at, time_s=measured.time_s[:n]), tuple(notes)


def validate(runs: Sequence[Run], params: RigParameters) -> list[RunComparison]:
    """Simulate every run with its measured input and score it."""
    out = []
    for run in classify_all(runs):
        simulated, result = simulate_run(run, params)
        comparison = compare(run, simulated)
        out.append(RunComparison(run, simulated, comparison.kind, comparison.scores, result))
    return out


def validate_campaign(runs: Sequence[Run], params: RigParameters) -> Validation:
    """:func:`validate`, with the friction points and the actuator FRFs of the campaign."""
    classified_runs = classify_all(runs)
    check_units(classified_runs, params)  # a pressure in MPa had scored −600,000 %
    braking = select(classified_runs, [Setup.BRAKE])
    dynamic = select(classified_runs, [RunKind.ACTUATOR_DYNAMIC])
    points = (friction_samples([br.prepare(r, params) for r in braking], params)
              if braking else None)
    return Validation(params, validate(classified_runs, params), points,
                      [actuator_frf(r, params) for r in dynamic])

