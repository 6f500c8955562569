"""The figure on the diagnosis page's first screen, under the verdict's sentence
(``report.words``): the measured signal, the model before and after, in the window where the
starting model misses most, the residuals below. It draws the diagnosis' own simulations
(``Diagnosis.evidence``); choosing where to look is all it works out."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from landing_gear_sim.calibration.measured import channel_words
from landing_gear_sim.diagnosis.diagnose import Diagnosis
from landing_gear_sim.diagnosis.scoring import whole_run
from landing_gear_sim.diagnosis.signatures import RunEvidence
from landing_gear_sim.report.figures import save_figure
from msg_tools.units import DISPLAY_UNITS

SMOOTHING_S = 0.2  # the residual's envelope: a noise spike is not where the model misses
MIN_HALF_WINDOW_S = 0.5  # the window shown: at least this either side of the worst place ...
RUN_SHARE = 0.05  # ... or this share of the run


@dataclass(frozen=True)
class Misfit:
    """Where to look: a run's evidence, the channel, the window [samples], and whether the
    verdict's finding was checked on that run rather than fitted on it."""

    evidence: RunEvidence
    channel: str
    window: slice
    held_out: bool = False


def misfit_channel(result: Diagnosis) -> str | None:
    """The channel the verdict is about: the one its finding helps most on held-out runs,
    or the one an unexplained finding was seen in (None: no finding names one)."""
    best = result.findings[0] if result.findings else None
    if best is None:
        return None
    gains = {c: best.fit_after[c] - best.fit_before[c] for c in best.fit_after
             if c in best.fit_before}
    if gains:
        return max(gains, key=lambda c: gains[c])
    return best.channel if best.channel in DISPLAY_UNITS else None


def held_out_runs(result: Diagnosis) -> set[str]:
    """The runs the verdict's finding was checked on, not fitted on (a run cut in time,
    'stop (2.0-9.0 s)', as its whole run)."""
    best = result.findings[0] if result.findings else None
    return {whole_run(name) for name in best.checked_on} if best else set()


def worst_misfit(result: Diagnosis) -> Misfit | None:
    """The run and window where the starting model misses the verdict's channel most (for a
    verdict naming none, the channel each run's spectrum was taken on), among the runs the
    verdict's finding was checked on where it has any: the headline's gain is theirs."""
    named = misfit_channel(result)
    held = held_out_runs(result)
    best: tuple[tuple[bool, float], Misfit] | None = None
    for item in result.evidence:
        channel = named or item.channel
        if channel not in DISPLAY_UNITS or (channel != "pressure_pa" and not item.run.braking):
            continue
        miss = getattr(item.run, channel) - getattr(item.before, channel)
        rank = (item.run.name in held, float(np.sqrt(np.mean(miss ** 2))))
        if best is None or rank > best[0]:
            best = (rank, Misfit(item, channel, _window(item.run.time_s, miss), rank[0]))
    return None if best is None else best[1]


def _window(time_s: np.ndarray, miss: np.ndarray) -> slice:
    rate = (time_s.size - 1) / float(time_s[-1] - time_s[0])
    width = max(1, round(SMOOTHING_S * rate))
    envelope = np.convolve(np.abs(miss), np.ones(width) / width, mode="same")
    centre = int(np.argmax(envelope))
    half = round(max(MIN_HALF_WINDOW_S, RUN_SHARE * float(time_s[-1] - time_s[0])) * rate)
    return slice(max(0, centre - half), min(time_s.size, centre + half + 1))


def plot_misfit(misfit: Misfit, path: Path) -> Path:
    """The measured channel (thin black, drawn last: on top) over the starting model (blue)
    and the extended one (red, both wide and pale) in the window, the residuals of both
    below; the legend under the axes, off the data."""
    item, channel, span = misfit.evidence, misfit.channel, misfit.window
    factor, unit = DISPLAY_UNITS[channel]
    t = item.run.time_s[span] - item.run.time_s[0]
    measured = getattr(item.run, channel)[span]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 5.2), sharex=True, layout="constrained",
                                      gridspec_kw={"height_ratios": (2, 1)})
    for model, colour, label in ((item.before, "tab:blue", "starting model"),
                                 (item.after, "tab:red", "extended model")):
        simulated = getattr(model, channel)[span]
        top.plot(t, simulated * factor, color=colour, lw=2.4, alpha=0.55, label=label)
        bottom.plot(t, (measured - simulated) * factor, color=colour, lw=0.7)
    top.plot(t, measured * factor, "k", lw=0.7, label="measured", zorder=3)
    label = channel_words(channel)
    top.set_ylabel(f"{label} [{unit}]")
    bottom.set_ylabel(f"measured − model\n[{unit}]")
    bottom.axhline(0.0, color="0.5", lw=0.5)
    bottom.set_xlabel(f"time in {item.run.name} [s]")
    for axis in (top, bottom):
        axis.grid(alpha=0.3)
    role = "held out" if misfit.held_out else "a fitting run"
    fig.suptitle(f"{item.run.name}, {role}: {label} where the starting model misses most",
                 fontsize=11)
    fig.legend(loc="outside lower center", ncol=3, fontsize=8)
    return save_figure(fig, path)


def first_figure(result: Diagnosis, folder: Path) -> Path | None:
    """The first screen's figure in ``folder`` (None: no run to draw)."""
    misfit = worst_misfit(result)
    return None if misfit is None else plot_misfit(misfit, folder / "where_it_misses.png")

