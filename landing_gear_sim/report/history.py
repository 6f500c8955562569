"""Plots of a rig's history: one figure per parameter, its value and 1-σ per campaign."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt

from landing_gear_sim.campaigns.history import Change, table_columns
from landing_gear_sim.report.figures import save_figure


def plot_history(rows: Sequence[dict[str, Any]], found: Sequence[Change], folder: Path
                 ) -> list[Path]:
    """``folder/<key>.png`` for every parameter of ``rows`` (campaigns in time order): value
    ± 1σ per campaign, a found trend or step named in the title and marked."""
    columns = table_columns(rows)
    names = columns["campaign"]
    by_key = {c.key: c for c in found}
    written = []
    for key in (k for k in columns if k.endswith(".std")):
        key = key.removesuffix(".std")
        fig, ax = plt.subplots(figsize=(max(6.0, 0.5 * len(names)), 3.5))
        ax.errorbar(range(len(names)), columns[key], yerr=columns[f"{key}.std"], fmt="o",
                    capsize=3)
        change = by_key.get(key)
        if change is not None and change.kind == "step":
            ax.axvline(names.index(change.at) - 0.5, color="tab:red", linestyle="--")
        ax.set_title(change.describe() if change else f"{key}: no trend, no step")
        ax.set_xticks(range(len(names)), names, rotation=45, ha="right", fontsize=8)
        ax.set_ylabel(key.split(".")[-1])
        ax.grid(alpha=0.3)
        fig.tight_layout()
        written.append(save_figure(fig, folder / f"{key}.png"))
    return written
