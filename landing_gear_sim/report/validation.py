"""Validation figures (paper Figs. 12-14 style) and the HTML page that collects them.

Functions take computed comparisons and estimates; they never simulate or fit.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from landing_gear_sim.calibration.identify import Estimate, FrfEstimate
from landing_gear_sim.calibration.validate import CHANNELS, RunComparison
from landing_gear_sim.diagnosis.residuals import Spectrum
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.report.figures import save_figure
from msg_tools.run import Run

_UNITS = {"pressure_pa": (1e-5, "bar"), "wheel_speed_rad_s": (1.0, "rad/s"),
          "flywheel_speed_rad_s": (1.0, "rad/s"), "vertical_load_n": (1e-3, "kN"),
          "longitudinal_force_n": (1e-3, "kN")}


def plot_overlay(comparison: RunComparison, path: Path) -> Path:
    """Measured (black) and simulated (red) channels of one run (paper Figs. 13, 14)."""
    channels = list(comparison.scores)
    fig, axes = plt.subplots(len(channels), 1, figsize=(9, 2.2 * len(channels) + 0.6),
                             sharex=True, squeeze=False)
    m, s = comparison.measured, comparison.simulated
    n = min(len(m), len(s))
    t = m.time_s[:n] - m.time_s[0]
    for axis, channel in zip(axes[:, 0], channels, strict=True):
        factor, unit = _UNITS[channel]
        axis.plot(t, getattr(m, channel)[:n] * factor, "k", lw=0.7, label="measured")
        axis.plot(t, getattr(s, channel)[:n] * factor, "r", lw=0.9, label="simulated")
        score = comparison.scores[channel]
        axis.set_ylabel(f"{CHANNELS[channel].split(' [')[0]}\n[{unit}]")
        axis.set_title(f"fit {score.fit_percent:.1f} %", fontsize=8, loc="right")
        axis.grid(alpha=0.3)
    axes[0, 0].legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle(f"{m.name} ({comparison.kind})")
    fig.tight_layout()
    return save_figure(fig, path)


def plot_friction(slip: np.ndarray, mu: np.ndarray, params: RigParameters, path: Path) -> Path:
    """Measured (slip, μ) points and the identified Burckhardt curve (paper Fig. 12)."""
    t1, t2, t3 = (params.number(f"friction.theta{i}") for i in (1, 2, 3))
    grid = np.linspace(0.0, 1.0, 400)
    fig, axis = plt.subplots(figsize=(7, 4.5))
    axis.plot(slip, mu, ".", ms=2, color="grey", alpha=0.5, label="measured F_x/F_z")
    axis.plot(grid, t1 * (1 - np.exp(-t2 * grid)) - t3 * grid, "r",
              label=f"Burckhardt θ = ({t1:.3f}, {t2:.2f}, {t3:.3f})")
    axis.set_xlabel(r"slip $\lambda$ [-]")
    axis.set_ylabel(r"$\mu$ [-]")
    axis.set_xlim(0, 1)
    axis.grid(alpha=0.3)
    axis.legend()
    fig.tight_layout()
    return save_figure(fig, path)


def plot_frf(frf: FrfEstimate, path: Path) -> Path:
    """Empirical actuator FRF with coherence, and the fitted 2nd-order A(s)."""
    band = (frf.frequency_hz > 0.3) & (frf.frequency_hz < 150)
    f = frf.frequency_hz[band]
    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    axes[0].semilogx(f, 20 * np.log10(np.abs(frf.response[band])), "k.", ms=3, label="H1")
    axes[0].semilogx(f, 20 * np.log10(np.abs(frf.fitted[band])), "r", label="fitted A(s)")
    axes[0].set_ylabel("magnitude [dB]")
    axes[0].legend()
    axes[1].semilogx(f, np.degrees(np.unwrap(np.angle(frf.response[band]))), "k.", ms=3)
    axes[1].semilogx(f, np.degrees(np.unwrap(np.angle(frf.fitted[band]))), "r")
    axes[1].set_ylabel("phase [deg]")
    axes[2].semilogx(f, frf.coherence[band], "b")
    axes[2].set_ylabel("coherence")
    axes[2].set_xlabel("frequency [Hz]")
    for axis in axes:
        axis.grid(alpha=0.3, which="both")
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


def text_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A fixed-width table for the terminal."""
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows, strict=True)]
    lines = ["  ".join(str(h).ljust(w) for h, w in zip(header, widths, strict=True))]
    lines += ["  ".join(str(x).ljust(w) for x, w in zip(row, widths, strict=True))
              for row in rows]
    return "\n".join(lines)


def write_html(path: Path, title: str, sections: Sequence[tuple[str, str]]) -> Path:
    """One self-contained page (figures next to it); ``sections`` are (heading, html body)."""
    body = "\n".join(f"<h2>{html.escape(h)}</h2>\n{b}" for h, b in sections)
    page = (f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}"
            "</title><style>body{font-family:sans-serif;max-width:1100px;margin:auto}"
            "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px;"
            "font-size:13px}img{max-width:100%}</style></head><body>"
            f"<h1>{html.escape(title)}</h1>\n{body}</body></html>")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(page)
    return path


def html_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(x))}</td>" for x in row) + "</tr>"
                   for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def html_image(path: Path, relative_to: Path) -> str:
    return f"<img src='{html.escape(str(Path(path).relative_to(relative_to)))}'>"


def plot_before_after(measured: Run, before: Run, after: Run, channels: Sequence[str],
                      path: Path) -> Path:
    """Measured (black), starting model (blue) and extended model (red), and the two
    residuals, per channel."""
    fig, axes = plt.subplots(2 * len(channels), 1, figsize=(9, 3.2 * len(channels) + 0.6),
                             sharex=True, squeeze=False)
    t = measured.time_s - measured.time_s[0]
    for i, channel in enumerate(channels):
        factor, unit = _UNITS[channel]
        y = getattr(measured, channel)
        label = CHANNELS[channel].split(" [")[0]
        top, bottom = axes[2 * i, 0], axes[2 * i + 1, 0]
        top.plot(t, y * factor, "k", lw=0.6, label="measured")
        top.plot(t, getattr(before, channel) * factor, "b", lw=0.8, label="starting model")
        top.plot(t, getattr(after, channel) * factor, "r", lw=0.8, label="extended model")
        top.set_ylabel(f"{label}\n[{unit}]")
        bottom.plot(t, (y - getattr(before, channel)) * factor, "b", lw=0.5)
        bottom.plot(t, (y - getattr(after, channel)) * factor, "r", lw=0.5)
        bottom.set_ylabel(f"residual\n[{unit}]")
        for axis in (top, bottom):
            axis.grid(alpha=0.3)
    axes[0, 0].legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle(measured.name)
    fig.tight_layout()
    return save_figure(fig, path)


def plot_spectrum(spectrum: Spectrum, title: str, unit: str, path: Path) -> Path:
    """Residual PSD, its noise floor, the detection threshold and the detected lines."""
    f = spectrum.frequency_hz
    band = f > 0
    fig, axis = plt.subplots(figsize=(8, 3.8))
    axis.loglog(f[band], spectrum.psd[band], "k", lw=0.7, label="residual PSD")
    finite = band & np.isfinite(spectrum.floor)
    axis.loglog(f[finite], spectrum.floor[finite], "g", lw=0.8, label="noise floor")
    axis.loglog(f[finite], spectrum.floor[finite] * spectrum.threshold, "g--", lw=0.6,
                label="detection threshold (1 % family-wise)")
    for peak in spectrum.peaks[:5]:
        i = int(np.argmin(np.abs(f - peak.frequency_hz)))
        axis.plot(f[i], spectrum.psd[i], "rv", ms=8)
        axis.annotate(f"{peak.frequency_hz:.2f} Hz", (f[i], spectrum.psd[i]), fontsize=8,
                      xytext=(4, 6), textcoords="offset points", color="r")
    axis.set_xlabel("frequency [Hz]")
    axis.set_ylabel(f"PSD [{unit}²/Hz]")
    axis.set_title(title, fontsize=10)
    axis.grid(alpha=0.3, which="both")
    axis.legend(fontsize=8)
    fig.tight_layout()
    return save_figure(fig, path)
