"""The brake gain re-estimated locally, as a figure: per band of each physical variable
(calibrated and extended model side by side) and along each run. Takes the estimates
(:mod:`landing_gear_sim.diagnosis.local_gain`), never recomputes them."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib.pyplot as plt

from landing_gear_sim.diagnosis.local_gain import VARIABLES, LocalGain
from landing_gear_sim.report.figures import save_figure
from landing_gear_sim.report.pages import html_image, html_table


def plot_local_gains(before: Sequence[LocalGain], after: Sequence[LocalGain], path: Path
                     ) -> Path:
    """One panel per variable of VARIABLES (k_b over the model's, ±1σ, per band; calibrated
    and extended model), and one of the estimates along each run (calibrated model)."""
    rows = -(-(len(VARIABLES) + 1) // 2)  # two panels a row: legible at page width
    fig, grid = plt.subplots(rows, 2, figsize=(10, 3.6 * rows + 0.6), sharey=True,
                             squeeze=False, layout="constrained")
    axes = list(grid.flat)
    for ax, variable in zip(axes, VARIABLES, strict=False):
        changes = []
        for gains, label, colour, style in ((before, "calibrated", "tab:red", "o"),
                                            (after, "extended", "tab:blue", "s")):
            for g in (g for g in gains if g.variable == variable):
                # markers alone: the bands of one constant-pressure stop share a centre,
                # and lines through them had zig-zagged up and down there
                ax.errorbar(g.centres, g.ratio, yerr=g.std, fmt=style, ms=4, capsize=2,
                            color=colour, alpha=0.8, label=f"{label} model")
                changes.append(f"{label} {100 * g.change:+.1f} % ({g.z:.0f} σ)")
        ax.axhline(1.0, color="k", linewidth=0.8)
        ax.set_xlabel(f"{variable} [{VARIABLES[variable]}]")
        ax.set_title("change over the range: " + ", ".join(changes), fontsize=8)
        ax.grid(alpha=0.3)
    along = axes[len(VARIABLES)]
    for g in (g for g in before if g.variable == "time in run"):
        along.plot(g.centres, g.ratio, "o-", ms=3, label=g.run)
    along.axhline(1.0, color="k", linewidth=0.8)
    along.set_xlabel("time since braking started [s] (calibrated)")
    along.grid(alpha=0.3)
    for ax in axes[len(VARIABLES) + 1:]:
        ax.set_visible(False)
    for row in grid:
        row[0].set_ylabel("local k_b / model's k_b")
    # the keys under the panels, off the estimates (in a corner they had covered them)
    handles, labels = axes[0].get_legend_handles_labels()
    runs = along.get_legend_handles_labels()
    fig.legend([*handles, *runs[0]], [*labels, *runs[1]], loc="outside lower center",
               ncols=4, fontsize=8)
    return save_figure(fig, path)


def local_gain_section(before: Sequence[LocalGain], after: Sequence[LocalGain],
                       folder: Path) -> tuple[str, str]:
    figure = plot_local_gains(before, after, folder / "local_gains.png")
    rows = [[model, g.variable, g.run, f"{100 * g.change:+.2f} %", f"{100 * g.change_std:.2g} %",
             f"{g.z:.1f}"] for model, gains in (("calibrated", before), ("extended", after))
            for g in gains]
    table = html_table(["model", "against", "run", "change over range", "1σ", "z"], rows)
    return ("Brake gain, re-estimated locally", html_image(figure, folder) + table)
