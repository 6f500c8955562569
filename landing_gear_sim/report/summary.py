"""A diagnosis as the terminal prints it: the candidates, the verdict, its findings and the
notes. Text only: ``diagnose`` without ``--report`` draws nothing and loads no matplotlib."""

from __future__ import annotations

from landing_gear_sim.calibration.measured import channel_words
from landing_gear_sim.diagnosis.diagnose import INCONCLUSIVE, Diagnosis
from landing_gear_sim.report.pages import text_table
from landing_gear_sim.report.words import (
    evidence_class,
    gain_text,
    headline,
    open_sentence,
    verdict_text,
)


def diagnosis_summary(result: Diagnosis) -> str:
    """The terminal summary: candidates, baseline fit, verdict, findings, notes."""
    rows = [[str(f.round or "disc."), f.cause, "yes" if f.accepted else "no",
             evidence_class(f.delta_bic), gain_text(f.held_out),
             f"{_fits(f.fit_before)} -> {_fits(f.fit_after)}", f.reason]
            for f in result.candidates]
    header = ["round", "cause", "accepted", "evidence (dBIC)", "held-out gain",
              "held-out fit %", "why"]
    lines = ["candidates:", text_table(header, rows) if rows
             else "  (none: the model has them all)"]
    lines.append(f"baseline fit %: {_fits(result.baseline)}")
    lines.append(f"VERDICT: {verdict_text(result)}")
    lines.append(f"  {headline(result)}")
    if left_open := open_sentence(result):
        lines.append(f"  {left_open}")
    if result.verdict == INCONCLUSIVE:
        lines.append("  the runs given cannot test every candidate, or none is left to check one "
                     "on: see the notes")
    # the headline holds each finding's values and law, the first's held-out gain: what
    # follows is what it does not (the parameters had been printed twice, the evidence thrice)
    for i, f in enumerate(result.findings):
        lines.append(f"  {f.cause}" + (f" ({f.family})" if f.family else "") + ":")
        if f.equation:
            lines.append(f"    where: the {f.equation} (seen in the {channel_words(f.channel)})")
        if i and f.fit_after and f.fit_after != f.fit_before:
            gain = ", ".join(f"{channel_words(c)} {f.fit_before[c]:.2f} -> {f.fit_after[c]:.2f} %"
                             for c in f.fit_after)
            lines.append(f"    held-out gain: {gain}")
        lines.append(f"    evidence: {f.evidence}")
    before = [c for c in result.consistency_calibrated if c.violated]
    broken = [c for c in result.consistency if c.violated]
    noise = sum(c.within_input_noise for c in broken)
    lines.append(f"consistency: {len(result.consistency)} relations checked, "
                 f"{len(before)} violated under the calibrated model, {len(broken)} under the "
                 "extended one" + (f" ({noise} within the noise in the model's inputs)"
                                   if noise else "") + (":" if broken else ""))
    lines.extend(f"  {c.describe()}" for c in broken)
    lines.extend(f"  note: {problem}" for problem in result.problems)
    return "\n".join(lines)


def _fits(values: dict[str, float]) -> str:
    return ", ".join(f"{c.split('_')[0]} {v:.1f}" for c, v in values.items())
