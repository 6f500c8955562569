"""A diagnosis in a brake engineer's words: what each cause is, physically, and the one
sentence the page and the terminal open with (the log-likelihood figures stay in the
tables, for whoever checks the rule)."""

from __future__ import annotations

import re
from collections.abc import Sequence

from landing_gear_sim.calibration.measured import channel_words
from landing_gear_sim.diagnosis.alike import Alike, name_of
from landing_gear_sim.diagnosis.diagnose import INCONCLUSIVE, Diagnosis
from landing_gear_sim.diagnosis.families import REGISTRY
from landing_gear_sim.diagnosis.findings import Finding
from msg_tools.units import DISPLAY_UNITS, display

CAUSE_WORDS: dict[str, str] = {
    "actuator_delay": "the valve answers later than the model's",
    "pressure_sensor_offset": "the pressure transducer reads off its zero",
    "actuator_dynamics": "the valve follows its current at another speed than the model's",
    "tire_relaxation": "the tyre builds its force over a rolled length",
    "gear_walk": "the landing gear walks fore and aft",
    "brake_fade": "the brake loses torque as it absorbs energy",
    "drag": "the flywheel's air drag is not the model's",
    "load_dependent_radius": "the tyre's rolling radius changes with its load",
    "friction_curve": "the tyre's friction curve is not the model's",
    "unexplained": "the model misses something it has no law for",
    "inconsistent": "the measured channels contradict one another",
}
"""Each catalogued cause, physically (a cause missing here reads as its name)."""

FAMILY_WORDS: dict[str, str] = {name: text for family in REGISTRY
                                 for name, text in family.words.items()}
"""Each family a ``discovered`` finding may name, physically, as its module says it
(``Family.words``); an equation's own family reads 'the <equation>'s law lacks a term the
runs show'."""


EVIDENCE_CLASSES: tuple[tuple[float, str], ...] = (
    (-10.0, "decisive"), (-6.0, "strong"), (-2.0, "positive"), (0.0, "weak"))
"""ΔBIC upper bounds and their evidence class for the extension (Kass & Raftery 1995: 2, 6
and 10 units; the scoring accepts only a decisive one)."""


def evidence_class(delta_bic: float | None) -> str:
    """'decisive (-78.5)': the evidence ``delta_bic`` gives for the extension, its number
    beside it, to the tenth every table writes ('-': not scored)."""
    if delta_bic is None:
        return "-"
    name = next((n for bound, n in EVIDENCE_CLASSES if delta_bic <= bound), "against")
    return f"{name} ({delta_bic:+.1f})"


def gain_text(held_out: float | None) -> str:
    """A held-out log-likelihood change as the improvement it is (positive: better), to
    the tenth the JSON's reader checks, as every table and the terminal write it (the
    terminal's +78 had been the page's +79); '-' where none was scored."""
    return "-" if held_out is None else f"{-held_out:+.1f}"


def fits_words(values: dict[str, float]) -> str:
    """'brake pressure 97.75 %, wheel speed 99.70 %': fit % per channel, in words."""
    return ", ".join(f"{channel_words(c)} {v:.2f} %" for c, v in values.items())


def title_words(finding: Finding | None, verdict: str) -> str:
    """The page's title: what the verdict found, physically ('Diagnosis: actuator_delay'
    had been its title)."""
    if finding is None:
        return {"none": "nothing is missing from the model",
                INCONCLUSIVE: "inconclusive"}.get(verdict, verdict.replace("_", " "))
    return cause_words(finding)


def cause_words(finding: Finding) -> str:
    """What ``finding`` is, physically, in a few words."""
    if finding.cause == "discovered":
        family = finding.family or ""
        return FAMILY_WORDS.get(family, f"the {family}'s law lacks a term the runs show")
    words = CAUSE_WORDS.get(finding.cause, finding.cause.replace("_", " "))
    return f"{words} in the {finding.equation}" if finding.equation else words


def held_out_words(finding: Finding) -> str:
    """What ``finding`` gains on the runs it was not fitted on, as fit % per channel ('' when
    it gains nothing there)."""
    if finding.held_out is None or finding.held_out >= 0:
        return ""
    both = [c for c in finding.fit_after if c in finding.fit_before]
    # a channel it leaves as it was is not its gain (99.8 → 99.8 % beside 95.0 → 97.5 %)
    moved = [c for c in both if f"{finding.fit_before[c]:.1f}" != f"{finding.fit_after[c]:.1f}"]
    gains = [f"{'the ' + channel_words(c) + ' fits' if i == 0 else channel_words(c)} "
             f"{finding.fit_before[c]:.1f} → {finding.fit_after[c]:.1f} %{_rmse(finding, c)}"
             for i, c in enumerate(moved or both)]
    return "on the runs it was not fitted on " + ", ".join(gains) if gains else ""


def _rmse(finding: Finding, channel: str) -> str:
    """' (RMSE 1.23 → 0.98 rad/s)' in the unit the figures show the channel in ('': not
    measured)."""
    if channel not in finding.rmse_after or channel not in finding.rmse_before:
        return ""
    factor, unit = DISPLAY_UNITS.get(channel, (1.0, ""))
    before, after = (finding.rmse_before[channel] * factor, finding.rmse_after[channel] * factor)
    return f" (RMSE {before:.3g} → {after:.3g} {unit})"


def parameters_text(finding: Finding) -> str:
    """``finding``'s parameters, each ``name = value ± σ`` in engineering units."""
    return ", ".join(parameter_text(k, v, finding.std.get(k), finding.units.get(k))
                     for k, v in finding.parameters.items())


def law_values(finding: Finding) -> str:
    """Beside a law written out with its values in engineering units: a named parameter as
    it reads, a term's coefficient by its 1-σ relative to it ('P·ΔP ± 1.2 %'; its SI value,
    'P·ΔP = 5.853e-07 ± 7e-09', had stood beside the law's '0.0585 1/bar·P·ΔP')."""
    said = []
    for key, value in finding.parameters.items():
        std = finding.std.get(key)
        if re.fullmatch(r"[a-z0-9_.]+", key):  # a contract name: its unit in its words
            said.append(parameter_text(key, value, std, finding.units.get(key)))
        elif std is not None and value:
            said.append(f"{key} ± {100 * std / abs(value):.2g} %")
    return ", ".join(said)


def candidate_values(candidate: Finding, findings: Sequence[Finding]) -> str:
    """A candidate's parameters as the verdict states them: the final values of the finding
    it became (re-calibrated after its round), and its round's own only where they differ,
    labelled (the candidates' table had shown delay_s = 0.005994 beside a verdict of
    6.003 ms)."""
    final = next((f for f in findings if f.cause == candidate.cause
                  and f.family == candidate.family
                  and set(f.parameters) == set(candidate.parameters)), None)
    shown = parameters_text(final or candidate)
    if final is None or final.parameters == candidate.parameters:
        return shown
    first = ", ".join(parameter_text(k, v, None, candidate.units.get(k))
                      for k, v in candidate.parameters.items())
    return f"{shown} (first round {first})"


def finding_sentence(finding: Finding, verdict: str, gain: bool = True) -> str:
    """One finding: its name, what it is physically, its law or values, and (``gain``) its
    held-out gain."""
    values = parameters_text(finding)
    if finding.term:
        # an unexplained finding in its equation follows, saying where the law misses
        law = f"approximately {finding.term}" if finding.approximate else finding.term
        values = law_values(finding)
        said = f"{cause_words(finding)}, {law}" + (f" ({values})" if values else "")
    else:
        said = cause_words(finding) + (f", {values}" if values else "")
    gained = held_out_words(finding) if gain else ""
    return f"{verdict}: {said}" + (f"; {gained}" if gained else "")


def headline(result: Diagnosis) -> str:
    """The verdict in one sentence: the cause, physically, its law or parameters in
    engineering units, and its fit on the runs it was not fitted on; then the others."""
    if not result.findings:
        return {"none": "The calibrated model explains every run: nothing is missing.",
                INCONCLUSIVE: "Inconclusive: the runs cannot test every candidate (see the "
                "notes)."}.get(result.verdict, f"{result.verdict}.")
    best, *others = result.findings
    also = "; ".join(finding_sentence(f, f.cause, gain=False) for f in others)  # both at once
    return (finding_sentence(best, verdict_text(result)) + "."
            + (f" Also {also}." if also else ""))


def alike_sentence(group: Alike) -> str:
    """A group of alike explanations: each with its law or values and its held-out gain
    (its ΔBIC and held-out log-likelihood gain beside), that the campaign cannot tell them
    apart, and the run that would."""
    each = " or ".join(
        finding_sentence(f, name_of(f)) + f" (evidence {evidence_class(f.delta_bic)}, "
        f"held-out gain {-(f.held_out or 0.0):+.1f})" for f in group.members)
    settle = f"; {group.next_run.sentence()}" if group.next_run is not None else ""
    return f"{each}: this campaign cannot tell them apart{settle}."


def open_sentence(result: Diagnosis) -> str:
    """What the campaign leaves open, in words ('' when nothing): each group of alike
    explanations, or the run that would settle an ``inconclusive`` verdict."""
    if result.alike:
        return " ".join(alike_sentence(g) for g in result.alike)
    if result.next_run is not None:
        settle = result.next_run.sentence()
        return f"{settle[0].upper()}{settle[1:]}."
    return ""


def verdict_text(result: Diagnosis) -> str:
    """The verdict with what names it: a discovered term's family, an unexplained finding's
    equation."""
    best = result.findings[0] if result.findings else None
    if best is not None and best.family and result.verdict == "discovered":
        return f"{result.verdict} {best.family}"
    if best is not None and best.equation and result.verdict == "unexplained":
        return f"{result.verdict}, in the {best.equation}"
    return result.verdict


KEY_UNITS = {"s": "s", "pa": "Pa", "n": "N", "a": "A", "m": "m", "j": "J", "hz": "Hz",
             "fraction": "1", "run": "run"}
"""A parameter key's last word -> its SI unit (a key carries its unit, docs/parameters.md;
``x_per_n``: per newton)."""

COMPOUND_UNITS = {"n_m_per_pa": "N m/Pa", "pa_per_a": "Pa/A", "pa_per_a2": "Pa/A^2"}
"""A key's unit of several words -> its SI unit (``gain_n_m_per_pa`` had read
'gain_n_m = 153.3 1/bar')."""


def parameter_text(key: str, value: float, std: float | None, unit: str | None = None
                   ) -> str:
    """``name = value ± σ`` in the unit a brake engineer reads, e.g. 'delay = 5.99 ± 0.29 ms'
    for ``actuator_delay.delay_s`` (issue 32: 0.0059941 ± 0.00029 s), 'gain_drift = −3.475 ±
    0.0014 %/run' for ``gain_drift_per_run``; ``unit``: the SI unit of a key that carries
    none ('-': a ratio)."""
    if not re.fullmatch(r"[\w.]+", key):  # a discovered term's name ('[P > 0.5 bar]'): whole
        return f"{key} = {value:.4g}" + ("" if std is None else f" ± {std:.2g}")
    leaf = key.rsplit(".", 1)[-1]
    name, _, suffix = leaf.rpartition("_")
    compound = next((c for c in COMPOUND_UNITS if leaf.endswith(f"_{c}")), None)
    if unit is None and compound is not None:
        name, unit = leaf.removesuffix(f"_{compound}"), COMPOUND_UNITS[compound]
    elif unit is None:
        unit = KEY_UNITS.get(suffix)
    else:
        name, unit = leaf, None if unit == "-" else unit
    if unit is not None and name.endswith("_per"):
        name, unit = name.removesuffix("_per"), f"1/{unit}"
    if unit is None or unit == "1":
        name = leaf
    if unit is None:
        return f"{name} = {value:.4g}" + ("" if std is None else f" ± {std:.2g}")
    shown = display(value, unit, ".4g")
    if std is None:
        return f"{name} = {shown}"
    number, _, unit_shown = shown.partition(" ")
    return f"{name} = {number} ± {display(std, unit, '.2g').partition(' ')[0]} {unit_shown}"
