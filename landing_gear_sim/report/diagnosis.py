"""The diagnosis report: verdict and candidate tables, residual signatures, and per run the
measured / starting-model / extended-model overlays with their residuals and the residual
spectrum of the starting model; and the summary printed on the terminal."""

from __future__ import annotations

import html
import math
import textwrap
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib.artist
import matplotlib.lines
import matplotlib.patches
import matplotlib.pyplot as plt
import matplotlib.ticker
import numpy as np

from landing_gear_sim.calibration.measured import channel_words
from landing_gear_sim.diagnosis.diagnose import Diagnosis
from landing_gear_sim.diagnosis.relations import Z_VIOLATED, Check, Relation
from landing_gear_sim.diagnosis.residuals import Spectrum
from landing_gear_sim.diagnosis.scoring import BIC_THRESHOLD, HELD_OUT_THRESHOLD
from landing_gear_sim.model.datasheet import UNITS, datasheet_values
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.processes import Call, map_forked
from landing_gear_sim.report.figures import fixed_margins, save_figure
from landing_gear_sim.report.first_screen import first_figure
from landing_gear_sim.report.local_gain import local_gain_section
from landing_gear_sim.report.pages import html_image, html_table, write_report
from landing_gear_sim.report.words import (
    candidate_values,
    evidence_class,
    fits_words,
    gain_text,
    headline,
    held_out_words,
    open_sentence,
    parameters_text,
    title_words,
)
from msg_tools.run import Run
from msg_tools.units import DISPLAY_UNITS, display


def plot_before_after(measured: Run, before: Run, after: Run, channels: Sequence[str],
                      path: Path) -> Path:
    """Measured (black), starting model (blue) and extended model (red), and the two
    residuals, per channel."""
    fig, axes = plt.subplots(2 * len(channels), 1, figsize=(9, 3.2 * len(channels) + 0.6),
                             sharex=True, squeeze=False)
    t = measured.time_s - measured.time_s[0]
    for i, channel in enumerate(channels):
        factor, unit = DISPLAY_UNITS[channel]
        y = getattr(measured, channel)
        label = channel_words(channel)
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
    fig.legend(*axes[0, 0].get_legend_handles_labels(), loc="outside lower center", ncols=3,
               fontsize=8)  # off the traces (it had covered brake_osc_low's pressure)
    axes[-1, 0].set_xlabel(f"time in {measured.name} [s]")
    fig.suptitle(f"{measured.name}: measured, starting and extended model")
    fixed_margins(fig)
    return save_figure(fig, path)


def plot_spectrum(spectrum: Spectrum, title: str, channel: str, path: Path) -> Path:
    """Residual PSD, its noise floor, the detection threshold and the detected lines, in the
    channel's display unit squared per Hz (bar²/Hz: the page had read Pa²/Hz)."""
    factor, unit = DISPLAY_UNITS[channel]
    f = spectrum.frequency_hz
    psd, floor = spectrum.psd * factor ** 2, spectrum.floor * factor ** 2
    band = f > 0
    fig, axis = plt.subplots(figsize=(8, 3.8))
    axis.loglog(f[band], psd[band], "k", lw=0.7, label="residual PSD")
    finite = band & np.isfinite(floor)
    axis.loglog(f[finite], floor[finite], "g", lw=0.8, label="noise floor")
    axis.loglog(f[finite], floor[finite] * spectrum.threshold, "g--", lw=0.6,
                label="detection threshold (1 % family-wise)")
    for peak in spectrum.peaks[:5]:
        i = int(np.argmin(np.abs(f - peak.frequency_hz)))
        axis.plot(f[i], psd[i], "rv", ms=8)
        axis.annotate(f"{peak.frequency_hz:.2f} Hz", (f[i], psd[i]), fontsize=8,
                      xytext=(4, 6), textcoords="offset points", color="r")
    axis.set_xlabel("frequency [Hz]")
    axis.set_ylabel(f"PSD [{psd_unit(unit)}]")
    axis.set_title(title, fontsize=10)
    axis.grid(alpha=0.3, which="both")
    axis.legend(fontsize=8)
    fixed_margins(fig, left_in=1.1, bottom_in=0.55, top_in=0.35)
    return save_figure(fig, path)


def psd_unit(unit: str) -> str:
    """The unit of a PSD of a signal in ``unit``: (rad/s)²/Hz, Pa²/Hz (it had read
    'rad/s²/Hz', an acceleration's)."""
    return f"({unit})²/Hz" if "/" in unit or " " in unit else f"{unit}²/Hz"


def write_diagnosis_report(result: Diagnosis, folder: Path) -> Path:
    """The diagnosis page ``folder/index.html`` with its figures, all or nothing
    (:func:`~landing_gear_sim.report.pages.write_report`); returns the page."""
    best = result.findings[0] if result.findings else None
    title = title_words(best, result.verdict)
    return write_report(folder, f"Diagnosis: {title[0].upper()}{title[1:]}",
                        lambda stage: diagnosis_sections(result, stage),
                        first_screen=3 if result.problems else 2)


BASELINE_DEFINITION = (
    "<p>The calibrated starting model's fit on <i>every</i> run of the campaign. A finding's "
    "“held-out fit before” is the same model's fit on the runs that finding was checked on "
    "only, not fitted on: a smaller set, hence another number.</p>")


def _structure_table(result: Diagnosis) -> str:
    """What the residuals still hold, before and after; saying so when nothing is left."""
    after = [s.describe() for s in result.signatures_after] or [
        "no structure left: no line, lag or correlation in its residuals stands above "
        "their noise"]
    return html_table(["model", "signature"],
                      [["calibrated starting model", s.describe()]
                       for s in result.signatures_before]
                      + [["extended model", text] for text in after])


def diagnosis_sections(result: Diagnosis, folder: Path) -> list[tuple[str, str]]:
    """HTML sections of the diagnosis page; figures are written into ``folder``. Draws the
    simulations and spectra the diagnosis kept (``result.evidence``), computes nothing."""
    drawn = _drawn(result, folder)
    findings = html_table(
        ["cause", "parameters ± 1σ", "evidence (ΔBIC)", "on the held-out runs",
         "held-out fit before", "after", "held-out log-likelihood gain", "evidence"],
        [[f.cause + (f" ({f.family}): {'approximately ' * f.approximate}{f.term}"
                     if f.term else "")
          + (f" — in the {f.equation} ({channel_words(f.channel)})" if f.equation else ""),
          parameters_text(f), evidence_class(f.delta_bic),
          held_out_words(f).removeprefix("on the runs it was not fitted on ") or "-",
          fits_words(f.fit_before), fits_words(f.fit_after), gain_text(f.held_out),
          f.evidence] for f in result.findings])
    candidates = html_table(
        ["round", "cause", "accepted", "why", "key parameters", "evidence (ΔBIC)",
         "held-out log-likelihood gain", "fitted on", "checked on"],
        [[str(f.round or "discovery"), f.cause, "yes" if f.accepted else "no", f.reason,
          candidate_values(f, result.findings), evidence_class(f.delta_bic),
          gain_text(f.held_out), ", ".join(f.fitted_on), ", ".join(f.checked_on)]
         for f in result.candidates])
    figure = drawn[PAGE, "first screen"]
    left_open = open_sentence(result)
    verdict = (f"<p><b>{html.escape(headline(result))}</b></p>"
               + (f"<p><b>{html.escape(left_open)}</b></p>" if left_open else "")
               + (html_image(figure, folder) if figure else "") + "<p>Starting model: "
               f"{', '.join(result.start.sources)}{html.escape(_datasheet(result.start))}. "
               "ΔBIC = BIC(with) − BIC(without) on the "
               f"fitting runs (accepted below {BIC_THRESHOLD:g}, and only if the held-out "
               f"runs improve by more than {-HELD_OUT_THRESHOLD:g} in the same "
               f"log-likelihood units). Its evidence class reads ΔBIC on Kass and Raftery's "
               "scale: weak above −2, positive to −6, strong to −10, decisive beyond.</p>")
    sections = [("Verdict", verdict + (findings if result.findings else "")),
                ("Candidates", candidates),
                ("Starting model, calibrated: fit %", BASELINE_DEFINITION + html_table(
                    ["channel", "fit %"], [[channel_words(c), f"{v:.2f}"]
                                           for c, v in result.baseline.items()])),
                ("Residual structure", _structure_table(result))]
    if result.problems:
        sections.insert(1, ("Notes", html_table(["what the diagnosis could not do"],
                                                [[p] for p in result.problems])))
    if result.consistency:
        sections.append(drawn[PAGE, "consistency"])
    if result.local_before or result.local_after:
        sections.append(drawn[PAGE, "local gains"])
    return sections + [(f"{item.run.name} ({item.run.kind})", "".join(
        html_image(drawn[figure, item.run.name], folder) for figure in (OVERLAY, SPECTRUM)
        if (figure, item.run.name) in drawn)) for item in result.evidence]


PAGE, OVERLAY, SPECTRUM = "page", "overlay", "spectrum"
"""What a drawing is (a run's figure is named by its run, the page's by its section)."""


def _drawn(result: Diagnosis, folder: Path) -> dict[tuple[str, str], Any]:
    """The page's figures (and the sections made around one), drawn side by side: a
    campaign's 19 took 6.7 s on one core, its 8 runs' overlays and spectra 5.5 of them."""
    drawings: dict[tuple[str, str], Call[Any]] = {
        (PAGE, "first screen"): (first_figure, (result, folder))}
    if result.consistency:
        drawings[PAGE, "consistency"] = (_consistency_section, (
            result.consistency_calibrated, result.consistency, folder))
    if result.local_before or result.local_after:
        drawings[PAGE, "local gains"] = (local_gain_section, (
            result.local_before, result.local_after, folder))
    for item in result.evidence:
        run = item.run
        channels = (("pressure_pa", "wheel_speed_rad_s", "longitudinal_force_n") if run.braking
                    else ("pressure_pa",))
        drawings[OVERLAY, run.name] = (plot_before_after, (
            run, item.before, item.after, channels, folder / f"{run.name}.png"))
        if item.spectrum is not None:
            drawings[SPECTRUM, run.name] = (plot_spectrum, (
                item.spectrum, f"{run.name}: {channel_words(item.channel)} residual of the "
                "calibrated starting model", item.channel, folder / f"{run.name}_spectrum.png"))
    return dict(zip(drawings, map_forked(list(drawings.values())), strict=True))


def _consistency_section(calibrated: Sequence[Check], extended: Sequence[Check],
                         folder: Path) -> tuple[str, str]:
    pairs = paired_checks(calibrated, extended)
    table = html_table(["relation", "run", "calibrated model", "extended model", "floor",
                        "inputs' noise"],
                       [[after.relation, after.run, _check_cell(before), _check_cell(after),
                         f"{after.floor:.2g} {after.unit}", _input_noise_cell(after)]
                        for before, after in pairs])
    shown = worst_per_relation(pairs)
    caption = (f"<p>A relation is violated when its deviation is beyond {Z_VIOLATED:g} σ "
               "<i>and</i> beyond its physical floor (the size below which it does not matter "
               "to the rig, last column): the chart draws each deviation over the larger of "
               "the two, so a bar past 1 (red) is a violation and no other is. The chart "
               f"shows each of the {len(shown)} relations checked once, on its "
               f"worst run; the table all {len(pairs)} checks. A violation no further out "
               "than the noise in the model's inputs can move it (a noisy logged current fed "
               "to the valve: last column) is orange: it calls for terms, which the scoring "
               "judges, but is no structure the verdict reports.</p>")
    figure = plot_consistency(shown, folder / "consistency.png") if shown else None
    image = html_image(figure, folder) if figure else ""
    return ("Consistency of what the rig measures twice", caption + image + table)


def paired_checks(calibrated: Sequence[Check], extended: Sequence[Check]
                  ) -> list[tuple[Check | None, Check]]:
    """Each check of the extended model with the check of the calibrated model that measures
    the same: the same relation, run and phase (a relation checked twice on a run, as "no
    contact ⇒ no load" on F_x and on F_z, is two checks), or, where the phase names what
    each model's fit kept (an equation's terms), the one check of that relation and run;
    None where that one was not made. (Paired by relation and run alone, F_z's −0.60 N had
    stood beside F_x's −0.28 N as if one had become the other.)"""
    exact = {(c.relation, c.run, c.phase): c for c in calibrated}
    alone: dict[tuple[Relation, str], list[Check]] = {}
    for c in calibrated:
        alone.setdefault((c.relation, c.run), []).append(c)
    after = Counter((c.relation, c.run) for c in extended)

    def before(check: Check) -> Check | None:
        key = (check.relation, check.run)
        same = alone.get(key, [])
        return exact.get((*key, check.phase)) or (
            same[0] if len(same) == 1 and after[key] == 1 else None)

    return [(before(c), c) for c in extended]


def _check_cell(check: Check | None) -> str:
    if check is None:
        return "-"
    return f"{check.deviation:+.4g} ± {check.std:.2g} {check.unit} ({check.phase})" + (
        " violated within the inputs' noise" if check.within_input_noise
        else " VIOLATED" if check.violated else "")


def _input_noise_cell(check: Check) -> str:
    return f"{check.input_noise:.2g} {check.unit}" if check.input_noise > 0 else "-"


Pair = tuple[Check | None, Check]


def worst_per_relation(pairs: Sequence[Pair]) -> list[tuple[Pair, int]]:
    """Per relation (in the order first checked), its check furthest out under either model,
    with how many checks the relation had."""
    by_relation: dict[Relation, list[Pair]] = {}
    for pair in pairs:
        by_relation.setdefault(pair[1].relation, []).append(pair)
    return [(max(group, key=lambda p: max(reach(p[0]), reach(p[1]))), len(group))
            for group in by_relation.values()]


def plot_consistency(rows: Sequence[tuple[Pair, int]], path: Path) -> Path:
    """Each relation's worst check (``rows``: see :func:`worst_per_relation`), its deviation
    over its threshold (log scale: :func:`reach`) under the calibrated model (pale) and the
    extended one; past 1 the check is violated, and red. (Drawn in σ against the 6σ line,
    a relation 13σ out but under its physical floor had read as violated beside a verdict
    that said none was.)"""
    pairs = [pair for pair, _ in rows]
    fig, ax = plt.subplots(figsize=(9, 0.2 * len(pairs) + 1.3))  # 20 relations in 600 px
    rows_at = np.arange(len(pairs))
    for offset, alpha, index in ((-0.2, 0.4, 0), (0.2, 1.0, 1)):
        checks = [pair[index] for pair in pairs]
        ax.barh(rows_at + offset, [reach(c) for c in checks], height=0.4, alpha=alpha,
                color=[_colour(c) for c in checks])
    ax.axvline(1.0, color="k", linestyle="--")
    keys: list[matplotlib.artist.Artist] = [
        matplotlib.patches.Patch(color="tab:grey", alpha=a, label=label)
        for a, label in ((0.4, "calibrated model"), (1.0, "extended model"))]
    keys.append(matplotlib.patches.Patch(color="tab:red", label="violated"))
    if any(c is not None and c.within_input_noise for pair in pairs for c in pair):
        keys.append(matplotlib.patches.Patch(color="tab:orange",
                                             label="violated within\nthe inputs' noise"))
    keys.append(matplotlib.lines.Line2D([], [], color="k", linestyle="--",
                                        label=f"threshold: {Z_VIOLATED:g} σ or\nthe floor"))
    ax.set_xscale("log")
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    # wrapped: a long relation's first letters were cut off at the figure's edge
    ax.set_yticks(rows_at, [textwrap.fill(f"{after.relation} — {after.run}"
                                          + (f" (worst of {count})" if count > 1 else ""), 44)
                            for (_, after), count in rows], fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel(f"|deviation| / max({Z_VIOLATED:g} σ, the relation's physical floor)")
    # off the data: the bars' ends were under it
    ax.legend(handles=keys, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    fig.tight_layout()
    return save_figure(fig, path)


def reach(check: Check | None) -> float:
    """How far a check's deviation goes towards its violation: |deviation| over the larger
    of Z_VIOLATED σ and the relation's physical floor (past 1: violated), clipped for a log
    axis; 0 where the check was not made."""
    if check is None:
        return 0.0
    threshold = max(Z_VIOLATED * check.std, check.floor)
    ratio = abs(check.deviation) / threshold if threshold > 0 else math.inf
    return max(min(ratio, 1e4), 1e-2)


def _colour(check: Check | None) -> str:
    if check is None or not check.violated:
        return "tab:grey"
    return "tab:orange" if check.within_input_noise else "tab:red"


def _datasheet(params: RigParameters) -> str:
    """The values the user's params files gave beyond the bundled reference rig, in words."""
    given = datasheet_values(params)
    if not given:
        return ""
    shown = ", ".join(f"{key} = {display(float(value), UNITS[key], '.4g')}"
                      if isinstance(value, float) else f"{key} = {value}"
                      for key, value in given.items())
    return f" (from the datasheet, over the reference rig: {shown})"
