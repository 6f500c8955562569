"""The validation report: measured and simulated runs overlaid (paper Figs. 13, 14), the
friction curve (Fig. 12), the actuator's frequency response, fit per run and channel.

Functions take computed comparisons and estimates; they never simulate or fit.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from landing_gear_sim.calibration.actuator import MIN_COHERENCE, FrfEstimate
from landing_gear_sim.calibration.measured import CHANNELS, channel_words
from landing_gear_sim.calibration.statistics import Estimate
from landing_gear_sim.calibration.validate import (
    NOISE_MULTIPLE,
    ChannelVerdict,
    RunComparison,
    Score,
    Validation,
    channel_verdicts,
)
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import friction_at, friction_coefficients
from landing_gear_sim.processes import Call, map_forked
from landing_gear_sim.report.figures import DISPLAY_UNITS, fixed_margins, save_figure
from landing_gear_sim.report.pages import html_image, html_table, write_report


def plot_overlay(comparison: RunComparison, path: Path) -> Path:
    """Measured (black) and simulated (red) channels of one run (paper Figs. 13, 14), each
    with its residual below it: where the two traces overlap too closely to tell apart, the
    residual shows the difference (issue 32)."""
    channels = list(comparison.scores)
    fig, axes = plt.subplots(2 * len(channels), 1, figsize=(9, 3.0 * len(channels) + 0.8),
                             sharex=True, squeeze=False,
                             gridspec_kw={"height_ratios": [2, 1] * len(channels)})
    m, s = comparison.measured, comparison.simulated
    n = min(len(m), len(s))
    t = m.time_s[:n] - m.time_s[0]
    for i, channel in enumerate(channels):
        factor, unit = DISPLAY_UNITS[channel]
        top, bottom = axes[2 * i, 0], axes[2 * i + 1, 0]
        measured, simulated = getattr(m, channel)[:n] * factor, getattr(s, channel)[:n] * factor
        top.plot(t, measured, "k", lw=0.7, label="measured")
        top.plot(t, simulated, "r", lw=0.9, label="simulated")
        top.set_ylabel(f"{channel_words(channel)}\n[{unit}]")
        score = comparison.scores[channel]
        top.set_title(f"fit {score.fit_percent:.1f} %, RMSE {score.rmse * factor:.3g} {unit}",
                      fontsize=8, loc="right")
        bottom.plot(t, measured - simulated, "b", lw=0.5)
        bottom.set_ylabel(f"residual\n[{unit}]")
        for axis in (top, bottom):
            axis.grid(alpha=0.3)
    fig.legend(*axes[0, 0].get_legend_handles_labels(), loc="outside lower center", ncols=2,
               fontsize=8, frameon=False)
    axes[-1, 0].set_xlabel(f"time in {m.name} [s]")
    fig.suptitle(f"{m.name} ({comparison.kind}): measured and simulated", fontsize=11)
    fixed_margins(fig, top_in=0.65, gap_in=0.35)  # room for each channel's fit above its axes
    return save_figure(fig, path)


def plot_friction(slip: np.ndarray, mu: np.ndarray, params: RigParameters, path: Path) -> Path:
    """Measured (slip, μ) points and the identified Burckhardt curve (paper Fig. 12)."""
    t1, t2, t3 = friction_coefficients(params)
    grid = np.linspace(0.0, 1.0, 400)
    fig, axis = plt.subplots(figsize=(7, 4.5))
    axis.plot(slip, mu, ".", ms=2, color="grey", alpha=0.5, label="measured F_x/F_z")
    axis.plot(grid, friction_at(params, grid), "r",
              label=f"Burckhardt θ = ({t1:.3f}, {t2:.2f}, {t3:.3f})")
    axis.set_xlabel(r"slip $\lambda$ [-]")
    axis.set_ylabel(r"$\mu$ [-]")
    axis.set_xlim(0, 1)
    axis.grid(alpha=0.3)
    axis.legend()
    fig.tight_layout()
    return save_figure(fig, path)


def plot_frf(frf: FrfEstimate, path: Path) -> Path:
    """Measured actuator FRF (H1) with its coherence, and the model's A(s) beside it. Bins
    where the coherence is low (the valve no longer follows the sweep) are drawn faint,
    and the measured phase only where it is meaningful."""
    band = (frf.frequency_hz > 0.3) & (frf.frequency_hz < 150)
    f = frf.frequency_hz[band]
    coherent = frf.coherence[band] >= MIN_COHERENCE
    gain_db = 20 * np.log10(np.abs(frf.response[band]))
    phase = np.degrees(np.unwrap(np.angle(frf.response[band])))
    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    axes[0].semilogx(f[coherent], gain_db[coherent], "k.", ms=3, label="H1 (measured)")
    axes[0].semilogx(f[~coherent], gain_db[~coherent], ".", color="0.8", ms=2,
                     label=f"H1, coherence < {MIN_COHERENCE:g}")
    axes[0].semilogx(f, 20 * np.log10(np.abs(frf.model[band])), "r", label="model A(s)")
    axes[0].set_ylabel("magnitude [dB]")
    axes[0].legend(fontsize=8)
    axes[1].semilogx(f[coherent], phase[coherent], "k.", ms=3)
    axes[1].semilogx(f, np.degrees(np.unwrap(np.angle(frf.model[band]))), "r")
    axes[1].set_ylabel("phase [deg]")
    axes[2].semilogx(f, frf.coherence[band], "b")
    axes[2].axhline(MIN_COHERENCE, color="0.6", ls="--", lw=0.8)
    axes[2].set_ylabel("coherence")
    axes[2].set_xlabel("frequency [Hz]")
    for axis in axes:
        axis.grid(alpha=0.3, which="both")
    fig.suptitle(f"{frf.run}: static-map pressure → measured pressure")
    fig.tight_layout()
    return save_figure(fig, path)


def scores_table(comparisons: Sequence[RunComparison]) -> list[list[str]]:
    """Rows: run, kind, then fit % per channel ('' where not scored)."""
    rows = []
    for c in comparisons:
        cells = [f"{c.scores[ch].fit_percent:.2f}" if ch in c.scores else "" for ch in CHANNELS]
        rows.append([c.measured.name, c.kind, *cells])
    return rows


def estimates_table(estimates: Sequence[Estimate]) -> list[list[str]]:
    def runs(names: tuple[str, ...]) -> str:
        return ", ".join(names) if len(names) <= 2 else f"{names[0]} +{len(names) - 1} more"

    return [[e.key, f"{e.value:.6g}", f"{e.std:.3g}", e.method, runs(e.runs)]
            for e in estimates]


def scores_header() -> list[str]:
    return ["run", "kind", *(f"{channel_words(c)} fit %" for c in CHANNELS)]


def errors_table(comparisons: Sequence[RunComparison]) -> tuple[list[str], list[list[str]]]:
    """Header and rows: RMSE / max |error| per run and channel, in the plots' units."""
    header = ["run", *(f"{channel_words(c)} [{DISPLAY_UNITS[c][1]}]" for c in CHANNELS)]
    rows = []
    for c in comparisons:
        cells = [f"{c.scores[ch].rmse * DISPLAY_UNITS[ch][0]:.3g} / "
                 f"{c.scores[ch].max_error * DISPLAY_UNITS[ch][0]:.3g}" if ch in c.scores
                 else "" for ch in CHANNELS]
        rows.append([c.measured.name, *cells])
    return header, rows


def _shown(channel: str, value: float) -> str:
    factor, unit = DISPLAY_UNITS[channel]
    return f"{value * factor:.3g} {unit}"


def _miss(verdict: ChannelVerdict) -> str:
    """'the brake pressure on 8 of 8 runs (worst brake_osc_high: RMSE 1.9 bar, 12.7 times
    its noise of 0.15 bar)'."""
    worst = verdict.worst
    return (f"the {channel_words(verdict.channel)} on {len(verdict.failed)} of "
            f"{len(verdict.runs)} runs (worst {verdict.worst_run}: RMSE "
            f"{_shown(verdict.channel, worst.rmse)}, {worst.in_noise:.1f} times its "
            f"noise of {_shown(verdict.channel, worst.noise)})")


def _listed(words: Sequence[str]) -> str:
    """'a, b and c'."""
    return " and ".join(filter(None, [", ".join(words[:-1]), *words[-1:]]))


def validation_sentence(verdicts: Sequence[ChannelVerdict]) -> str:
    """The validation's verdict in one sentence: which channels the model matches within
    the tolerance on every run, and where it misses most."""
    if not verdicts:
        return "No channel could be scored: the runs log none of the model's channels."
    within = f"within {NOISE_MULTIPLE:g} times the logger's noise"
    kept = _listed([channel_words(v.channel) for v in verdicts if v.passed])
    failed = [v for v in verdicts if not v.passed]
    if not failed:
        return f"Pass: the model matches the rig {within} on every run, in the {kept}."
    sentence = "Fail: the model misses " + "; ".join(_miss(v) for v in failed) + "."
    return sentence + (f" It matches {within} on every run in the {kept}." if kept else "")


def verdict_table(verdicts: Sequence[ChannelVerdict]) -> tuple[list[str], list[list[str]]]:
    """Header and rows: per channel, pass or fail, the runs within the tolerance, and the
    worst run's RMSE, noise and fit % in the channel's display unit."""
    header = ["channel", "verdict", "runs within tolerance", "worst run", "RMSE",
              f"tolerance ({NOISE_MULTIPLE:g} × noise)", "fit % (worst run)"]
    rows = [[channel_words(v.channel), "pass" if v.passed else "FAIL",
             f"{len(v.runs) - len(v.failed)} of {len(v.runs)}", v.worst_run,
             _shown(v.channel, v.worst.rmse), _shown(v.channel, v.worst.tolerance),
             f"{v.worst.fit_percent:.1f}"] for v in verdicts]
    return header, rows


def noise_table(comparisons: Sequence[RunComparison]) -> tuple[list[str], list[list[str]]]:
    """Header and rows: per run and channel, the RMSE in multiples of that run's noise,
    pass or fail ('' where not scored)."""
    def cell(score: Score) -> str:
        return f"{score.in_noise:.1f} × noise {'pass' if score.passed else 'FAIL'}"

    header = ["run", *(channel_words(c) for c in CHANNELS)]
    return header, [[c.measured.name, *(cell(c.scores[ch]) if ch in c.scores else ""
                                        for ch in CHANNELS)] for c in comparisons]


TOLERANCE_DEFINITION = (
    f"<p>A channel passes a run when its RMSE is within {NOISE_MULTIPLE:g} times the "
    "logger's noise, read from the measured channel itself (the spread of its sample-to-"
    "sample differences). Fit % is shown beside it: it also punishes a run that varies "
    "little, where the logger's noise alone keeps it under 95 %.</p>")

FIT_DEFINITION = ("<p>fit % = 100·(1 − ‖y − ŷ‖ / ‖y − ȳ‖), y measured, ŷ simulated, ȳ the "
                  "measured mean: 100 is a perfect match, 0 no better than the mean, and it "
                  "can be negative. Each run is simulated with its measured input.</p>")


def write_validation_report(validation: Validation, folder: Path, title: str) -> Path:
    """The validation page ``folder/index.html`` with its figures, all or nothing
    (:func:`~landing_gear_sim.report.pages.write_report`); returns the page."""
    return write_report(folder, title, lambda stage: _validation_sections(validation, stage),
                        first_screen=3)


def _validation_sections(validation: Validation, folder: Path) -> list[tuple[str, str]]:
    """The validation page's sections; its figures are drawn into ``folder``."""
    sources = ", ".join(validation.params.sources)
    verdicts = channel_verdicts(validation.comparisons)
    sections = [("Verdict", f"<p><b>{html.escape(validation_sentence(verdicts))}</b></p>"
                 + TOLERANCE_DEFINITION + html_table(*verdict_table(verdicts))),
                ("Model", html_table(["parameters from"], [[sources]])),
                ("Within the logger's noise, per run and channel",
                 html_table(*noise_table(validation.comparisons))),
                ("Fit per run and channel", FIT_DEFINITION
                 + html_table(scores_header(), scores_table(validation.comparisons))),
                ("RMSE / max |error| per run and channel",
                 html_table(*errors_table(validation.comparisons)))]
    figures: list[tuple[str, Call[Path]]] = []
    if validation.friction_points is not None:
        figures.append(("Friction curve", (plot_friction, (
            *validation.friction_points, validation.params, folder / "friction.png"))))
    figures += [(f"Actuator frequency response ({frf.run})",
                 (plot_frf, (frf, folder / f"{frf.run}_frf.png"))) for frf in validation.frf]
    figures += [(f"{c.measured.name} ({c.kind})",
                 (plot_overlay, (c, folder / f"{c.measured.name}.png")))
                for c in validation.comparisons]
    # drawn side by side: `validate --report` of campaign_v1 (10 figures) took 7.9 s, 5.7 now
    drawn = map_forked([call for _, call in figures])
    return sections + [(name, html_image(figure, folder))
                       for (name, _), figure in zip(figures, drawn, strict=True)]
