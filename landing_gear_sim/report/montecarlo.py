"""The Monte Carlo figure: distributions per surface, from the rows the run gave."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from landing_gear_sim.report.figures import save_figure


def plot_montecarlo(rows: Sequence[dict[str, Any]], numbers: dict[str, Any], path: Path
                    ) -> Path:
    """Efficiency histogram per surface, stopping distance against entry speed (locks
    marked), and the cumulative distribution of the efficiency with its 5th percentile."""
    good = [r for r in rows if "error" not in r]
    surfaces = sorted({r["surface"] for r in good})
    fig, (hist, scatter, cdf) = plt.subplots(1, 3, figsize=(15, 4.2))
    for surface in surfaces:
        values = [r["braking_efficiency"] for r in good if r["surface"] == surface]
        hist.hist(values, bins=20, alpha=0.55, label=f"{surface} ({len(values)})")
    hist.set_xlabel("braking efficiency [-]")
    hist.set_ylabel("stops")
    hist.legend(fontsize=8)
    locked = [r for r in good if r["lock_events"] > 0]
    scatter.plot([r["entry_speed_m_s"] for r in locked],  # rings under the dots: both seen
                 [r["stopping_distance_m"] for r in locked], "o", mfc="none", ms=9,
                 color="black", zorder=1, label=f"wheel lock ({len(locked)})")
    for surface in surfaces:
        mine = [r for r in good if r["surface"] == surface]
        scatter.plot([r["entry_speed_m_s"] for r in mine],
                     [r["stopping_distance_m"] for r in mine], ".", zorder=2, label=surface)
    scatter.set_xlabel("entry speed [m/s]")
    scatter.set_ylabel("stopping distance [m]")
    scatter.legend(fontsize=8)
    efficiency = np.sort([r["braking_efficiency"] for r in good])
    cdf.plot(efficiency, np.arange(1, len(efficiency) + 1) / max(len(efficiency), 1))
    p5 = numbers.get("braking_efficiency", {}).get("p5")
    if p5 is not None:
        cdf.axvline(p5, color="tab:red", linestyle="--", label=f"p5 = {p5:.3f}")
        cdf.legend(fontsize=8)
    cdf.set_xlabel("braking efficiency [-]")
    cdf.set_ylabel("fraction of stops at or below")
    for ax in (hist, scatter, cdf):
        ax.grid(alpha=0.3)
    fig.suptitle(f"{numbers['cases']} closed-loop stops, lock rate "
                 f"{100 * numbers.get('lock_rate', 0.0):.1f} %")
    fig.tight_layout()
    return save_figure(fig, path)
