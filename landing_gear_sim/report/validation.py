"""The validation report: measured and simulated runs overlaid (paper Figs. 13, 14), the
friction curve (Fig. 12), the actuator's frequency response, fit per run and channel.

Functions take computed comparisons and estimates; they never simulate or fit.
"""

from __future__ import annotations

import html
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from landing_gear_sim.calibration.actuator import MIN_COHERENCE, FrfEstimate
from landing_gear_sim.calibration.measured import channel_words
from landing_gear_sim.calibration.validate import (
    RunComparison,
    Validation,
    channel_verdicts,
)
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.quantities import friction_at, friction_coefficients
from landing_gear_sim.processes import Call, map_forked
from landing_gear_sim.report.figures import fixed_margins, save_figure
from landing_gear_sim.report.pages import html_image, html_table, write_report
from landing_gear_sim.report.validation_tables import (
    FIT_DEFINITION,
    TOLERANCE_DEFINITION,
    errors_table,
    noise_table,
    scores_header,
    scores_table,
    validation_sentence,
    verdict_table,
)
from msg_tools.units import DISPLAY_UNITS


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
