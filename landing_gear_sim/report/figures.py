"""Figures of the model: a simulated run, the frequency responses; and what every figure
shares (the Agg backend, saving, margins). Functions take computed results; they never
simulate.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from landing_gear_sim.model.integrate import SimulationResult
from landing_gear_sim.model.linear import FrequencyResponse
from msg_tools.units import PA_PER_BAR

# every module that draws imports this one before it draws: figures go to PNG files on any
# machine, a display or none (pyplot picks its backend at the first figure, not at import)
matplotlib.use("Agg")


def save_figure(fig: plt.Figure, path: Path) -> Path:
    """Write ``fig`` as PNG (creating the folder) and close it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def fixed_margins(fig: plt.Figure, *, left_in: float = 0.95, right_in: float = 0.2,
                  top_in: float = 0.45, bottom_in: float = 0.85, gap_in: float = 0.25) -> None:
    """Margins and gaps between rows of axes, in inches: room for two-line y labels on the
    left, a title above, the x label and a one-row legend below. A layout engine measures
    every tick label in a draw of its own before the real one: a third of a diagnosis
    page's time went to it (8 runs, each with its spectrum)."""
    width, height = fig.get_size_inches()
    grid = fig.axes[0].get_gridspec()
    rows = grid.nrows if grid is not None else 1
    bottom, top = bottom_in / height, 1.0 - top_in / height
    row_in = ((top - bottom) * height - (rows - 1) * gap_in) / rows
    fig.subplots_adjust(left=left_in / width, right=1.0 - right_in / width, bottom=bottom,
                        top=top, hspace=gap_in / row_in)


def plot_simulation(result: SimulationResult, path: Path) -> Path:
    """Speeds, slip, pressure and current, forces of one run (paper Figs. 1 and 14 style)."""
    t = result.time_s
    fig, axes = plt.subplots(4, 1, figsize=(9, 10), sharex=True, layout="constrained")
    axes[0].plot(t, result.hub_speed_m_s, "k", label="hub speed $v_h$")
    axes[0].plot(t, result.wheel_speed_rad_s * result.rolling_radius_m, "r",
                 label=r"wheel speed $\omega r$")
    axes[0].set_ylabel("speed [m/s]")
    axes[1].plot(t, result.slip, "b")
    axes[1].set_ylabel(r"slip $\lambda$ [-]")
    axes[1].set_ylim(-0.05, 1.05)
    axes[2].plot(t, result.pressure_pa / PA_PER_BAR, "m", label="brake pressure")
    axes[2].set_ylabel("pressure [bar]")
    current_axis = axes[2].twinx()
    current_axis.plot(t, result.current_a, color="grey", lw=0.8, ls="--", label="valve current")
    current_axis.set_ylabel("current [A]")
    axes[2].set_zorder(current_axis.get_zorder() + 1)  # the pressure drawn over the current
    axes[2].patch.set_visible(False)
    axes[3].plot(t, result.vertical_load_n / 1e3, "g", label="vertical load $F_z$")
    axes[3].plot(t, result.longitudinal_force_n / 1e3, "c", label="tyre force $F_x$")
    axes[3].set_ylabel("force [kN]")
    axes[3].set_xlabel("time [s]")
    keyed = [axis.get_legend_handles_labels() for axis in (*axes, current_axis)]
    handles = [h for hs, _ in keyed for h in hs]
    labels = [label for _, ls in keyed for label in ls]
    # one legend under the axes: in each axis' corner it had covered the 45-50 bar pressure
    fig.legend(handles, labels, loc="outside lower center", ncols=3, fontsize=8)
    for axis in axes:
        axis.grid(alpha=0.3)
    fig.suptitle(f"{result.scenario.name}: {result.scenario.description} "
                 f"({result.stop_reason} at {t[-1]:.2f} s)")
    return save_figure(fig, path)


def plot_bode(responses: Sequence[FrequencyResponse], path: Path) -> Path:
    """G_λ and G_η magnitude and phase, with (solid red) and without (dash-dot black)
    gear walk, one line per speed (paper Fig. 7)."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    speeds = sorted({r.speed_m_s for r in responses})
    shade = {v: 0.35 + 0.65 * i / max(len(speeds) - 1, 1) for i, v in enumerate(speeds)}
    for response in responses:
        style = ({"color": "red", "ls": "-"} if response.gear_walk
                 else {"color": "black", "ls": "-."})
        label = f"{response.speed_m_s:g} m/s, {'with' if response.gear_walk else 'no'} gear walk"
        for col, values in enumerate((response.slip, response.decel)):
            axes[0, col].semilogx(response.frequency_hz, 20 * np.log10(np.abs(values)),
                                  alpha=shade[response.speed_m_s], label=label, **style)
            axes[1, col].semilogx(response.frequency_hz, np.degrees(np.unwrap(np.angle(values))),
                                  alpha=shade[response.speed_m_s], **style)
    axes[0, 0].set_title(r"$G_\lambda$: brake torque → slip")
    axes[0, 1].set_title(r"$G_\eta$: brake torque → normalised wheel deceleration")
    for axis in axes[0]:
        axis.set_ylabel("magnitude [dB re 1/(N m)]")
    for axis in axes[1]:
        axis.set_ylabel("phase [deg]")
    for axis in axes[1]:
        axis.set_xlabel("frequency [Hz]")
    for axis in axes.flat:
        axis.grid(alpha=0.3, which="both")
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    return save_figure(fig, path)
