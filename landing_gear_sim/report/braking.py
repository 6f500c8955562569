"""A braking run: the figure of the paper's Fig. 1 (slip, wheel vs flywheel speed, pressure)
and the metrics table."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from antiskid.metrics import BrakingMetrics, shown
from landing_gear_sim.report.figures import save_figure
from msg_tools.run import Run
from msg_tools.units import PA_PER_BAR


def plot_braking(run: Run, slip: np.ndarray, wheel_speed_m_s: np.ndarray,
                 flywheel_speed_m_s: np.ndarray, metrics: BrakingMetrics, path: Path) -> Path:
    """Slip; wheel and flywheel peripheral speeds; brake pressure. Takes results only."""
    figure, axes = plt.subplots(3, 1, sharex=True, figsize=(9, 7))
    axes[0].plot(run.time_s, slip, lw=0.8)
    axes[0].set_ylabel("slip [-]")
    axes[0].set_title(f"{run.name}: efficiency {shown(metrics.braking_efficiency, '.2f')}, stop "
                      f"{metrics.stopping_distance_m:.0f} m in {metrics.stopping_time_s:.1f} s, "
                      f"{metrics.lock_events} locks")
    axes[1].plot(run.time_s, flywheel_speed_m_s, label="flywheel (vehicle)", lw=1.0)
    axes[1].plot(run.time_s, wheel_speed_m_s, label="wheel", lw=0.8)
    axes[1].set_ylabel("speed [m/s]")
    axes[1].legend(loc="upper right")
    axes[2].plot(run.time_s, run.pressure_pa / PA_PER_BAR, lw=0.8)
    axes[2].set_ylabel("brake pressure [bar]")
    axes[2].set_xlabel("time [s]")
    for axis in axes:
        axis.grid(alpha=0.3)
    figure.tight_layout()
    return save_figure(figure, path)
