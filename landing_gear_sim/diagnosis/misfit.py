"""The model's output error beyond the logger's noise: what keeps a verdict from `none`
while the data disagree (issue 64).

A relation may hold and no candidate be accepted, and yet the model miss a channel: the
starting model of one campaign fitted its brake pressure at 87 % where nulls fit 97–99 %,
and the verdict was a calm `none`. Each run's channel is judged against its own logger's
noise (:func:`~landing_gear_sim.calibration.noise.channel_noise`, read from the measured
channel: no fixed bar or newton floor); a model that misses one by more than
:data:`MISFIT_MULTIPLE` times it leaves an ``unexplained`` finding in the equation whose
error shows in that channel, saying where in time it misses.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from landing_gear_sim.calibration.measured import channel_unit, channel_words, channels_of
from landing_gear_sim.calibration.noise import channel_noise
from landing_gear_sim.calibration.runs import ClassifiedRun
from landing_gear_sim.diagnosis.equations.registry import DECLARED
from landing_gear_sim.diagnosis.findings import Finding
from msg_tools.run import Run
from msg_tools.units import display

MISFIT_MULTIPLE = 4.0
"""A channel's RMSE over its noise past which the model misses it on a run. The final
model of the shared nulls (2 kHz, 200 Hz, a noisy current, a 64-count encoder, another rig)
and of campaign_v2 reads at most 2.7 on any run and channel (the validation's pass is 3), an
own null at 200 Hz through a noisy ADC 4.2 on one run of six."""
ENVELOPE_S = 0.2  # the residual's running RMS: where it misses, not where a spike is


@dataclass(frozen=True)
class Misfit:
    """One run's channel: its RMSE and noise [SI], and where its residual is largest."""

    run: str
    channel: str
    rmse: float
    noise: float
    start_s: float
    end_s: float
    trend: str

    @property
    def multiple(self) -> float:
        return self.rmse / self.noise


def misfits(runs: Sequence[ClassifiedRun], simulated: Sequence[Run]) -> list[Misfit]:
    """Every (run, channel) the model misses beyond :data:`MISFIT_MULTIPLE` times its
    noise, in the channels it misses so on at least half the runs that log them, the worst
    first: a model that lacks a law misses it run after run, where one stop's lock-up seen at
    200 Hz (4.2 times, the one run of six of a null) is that run's moment."""
    found: list[Misfit] = []
    scored: dict[str, int] = {}
    for run, model in zip(runs, simulated, strict=True):
        n = min(len(run), len(model))
        for channel in channels_of(run):
            scored[channel] = scored.get(channel, 0) + 1
            measured = getattr(run, channel)[:n]
            error = measured - getattr(model, channel)[:n]
            rmse, noise = float(np.sqrt(np.mean(error ** 2))), channel_noise(measured)
            if noise > 0 and rmse > MISFIT_MULTIPLE * noise:
                found.append(_located(run, channel, error, rmse, noise))
    missed = [m for m in found
              if 2 * sum(f.channel == m.channel for f in found) >= scored[m.channel]]
    return sorted(missed, key=lambda m: -m.multiple)


def _located(run: Run, channel: str, error: np.ndarray, rmse: float, noise: float
             ) -> Misfit:
    """The stretch of ``run`` where the residual's running RMS stays above half its peak
    around the peak, and whether the brake pressure rises, falls or holds over it."""
    time_s = run.time_s[:error.size] - run.time_s[0]
    width = max(1, round(ENVELOPE_S * run.rate_hz))
    envelope = np.sqrt(np.convolve(error ** 2, np.ones(width) / width, mode="same"))
    peak = int(np.argmax(envelope))
    low = envelope < 0.5 * envelope[peak]
    before, after = np.flatnonzero(low[:peak]), np.flatnonzero(low[peak:])
    start = int(before[-1]) + 1 if before.size else 0
    end = peak + int(after[0]) if after.size else error.size
    first = float(np.mean(run.pressure_pa[start:min(start + width, end)]))
    last = float(np.mean(run.pressure_pa[max(end - width, start):end]))
    floor = 3.0 * channel_noise(run.pressure_pa)
    verb = "rises" if last - first > floor else "falls" if first - last > floor else "holds"
    levels = f"{display(first, 'Pa', '.3g')} → {display(last, 'Pa', '.3g')}"
    trend = f"the brake pressure {verb} ({levels})"
    return Misfit(run.name, channel, rmse, noise, float(time_s[start]), float(time_s[end - 1]),
                  trend)


def equation_of(channel: str) -> str:
    """The equation whose error shows in ``channel`` (the first that declares it)."""
    return next((str(e) for e, d in DECLARED.items() if d.channel == channel), channel)


def misfit_finding(found: Sequence[Misfit], baseline: dict[str, float]) -> Finding:
    """The worst misfit as an ``unexplained`` finding in its channel's equation."""
    worst = found[0]
    runs = sorted({m.run for m in found if m.channel == worst.channel})
    unit = channel_unit(worst.channel)
    evidence = (f"no candidate was accepted, yet the model misses the "
                f"{channel_words(worst.channel)} by {worst.multiple:.1f} times its logger's "
                f"noise on {worst.run} (RMSE {display(worst.rmse, unit, '.3g')}, noise "
                f"{display(worst.noise, unit, '.3g')}), most from {worst.start_s:.2f} to "
                f"{worst.end_s:.2f} s, where {worst.trend}; beyond {MISFIT_MULTIPLE:g} times "
                f"on {len(runs)} run(s): {', '.join(runs)}")
    return Finding(cause="unexplained", parameters={"rmse_over_noise": round(worst.multiple, 2)},
                   std={}, units={"rmse_over_noise": "-"}, evidence=evidence,
                   fit_before=baseline, fit_after=baseline, delta_bic=None, held_out=None,
                   accepted=False, fitted_on=tuple(runs), equation=equation_of(worst.channel),
                   channel=worst.channel)
