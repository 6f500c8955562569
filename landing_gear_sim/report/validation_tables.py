"""A calibration and its validation as text: the estimates table ``identify`` prints, and
the validation's tables and one-sentence verdict, which the terminal prints and the
validation page (:mod:`~landing_gear_sim.report.validation`) shows. No figure: a command
that prints them and draws nothing loads no matplotlib."""

from __future__ import annotations

from collections.abc import Sequence

from landing_gear_sim.calibration.measured import CHANNELS, channel_words
from landing_gear_sim.calibration.statistics import Estimate
from landing_gear_sim.calibration.validate import (
    NOISE_MULTIPLE,
    ChannelVerdict,
    RunComparison,
    Score,
)
from msg_tools.units import DISPLAY_UNITS


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


def scores_header() -> list[str]:
    return ["run", "kind", *(f"{channel_words(c)} fit %" for c in CHANNELS)]


def errors_table(comparisons: Sequence[RunComparison]) -> tuple[list[str], list[list[str]]]:
    """Header and rows: RMSE / max |error| per run and channel, in the plots' units."""
    header = ["run", *(f"{channel_words(c)} [{DISPLAY_UNITS[c][1]}]" for c in CHANNELS)]
    rows = []
    for c in comparisons:
        cells = [f"{c.scores[ch].rmse * DISPLAY_UNITS[ch][0]:.3g} / "
                 f"{c.scores[ch].max_error * DISPLAY_UNITS[ch][0]:.3g}" if ch in c.scores
                 else "" for ch in CHANNELS]
        rows.append([c.measured.name, *cells])
    return header, rows


def _shown(channel: str, value: float) -> str:
    factor, unit = DISPLAY_UNITS[channel]
    return f"{value * factor:.3g} {unit}"


def _miss(verdict: ChannelVerdict) -> str:
    """'the brake pressure on 8 of 8 runs (worst brake_osc_high: RMSE 1.9 bar, 12.7 times
    its noise of 0.15 bar)'."""
    worst = verdict.worst
    return (f"the {channel_words(verdict.channel)} on {len(verdict.failed)} of "
            f"{len(verdict.runs)} runs (worst {verdict.worst_run}: RMSE "
            f"{_shown(verdict.channel, worst.rmse)}, {worst.in_noise:.1f} times its "
            f"noise of {_shown(verdict.channel, worst.noise)})")


def _listed(words: Sequence[str]) -> str:
    """'a, b and c'."""
    return " and ".join(filter(None, [", ".join(words[:-1]), *words[-1:]]))


def validation_sentence(verdicts: Sequence[ChannelVerdict]) -> str:
    """The validation's verdict in one sentence: which channels the model matches within
    the tolerance on every run, and where it misses most."""
    if not verdicts:
        return "No channel could be scored: the runs log none of the model's channels."
    within = f"within {NOISE_MULTIPLE:g} times the logger's noise"
    kept = _listed([channel_words(v.channel) for v in verdicts if v.passed])
    failed = [v for v in verdicts if not v.passed]
    if not failed:
        return f"Pass: the model matches the rig {within} on every run, in the {kept}."
    sentence = "Fail: the model misses " + "; ".join(_miss(v) for v in failed) + "."
    return sentence + (f" It matches {within} on every run in the {kept}." if kept else "")


def verdict_table(verdicts: Sequence[ChannelVerdict]) -> tuple[list[str], list[list[str]]]:
    """Header and rows: per channel, pass or fail, the runs within the tolerance, and the
    worst run's RMSE, noise and fit % in the channel's display unit."""
    header = ["channel", "verdict", "runs within tolerance", "worst run", "RMSE",
              f"tolerance ({NOISE_MULTIPLE:g} × noise)", "fit % (worst run)"]
    rows = [[channel_words(v.channel), "pass" if v.passed else "FAIL",
             f"{len(v.runs) - len(v.failed)} of {len(v.runs)}", v.worst_run,
             _shown(v.channel, v.worst.rmse), _shown(v.channel, v.worst.tolerance),
             f"{v.worst.fit_percent:.1f}"] for v in verdicts]
    return header, rows


def noise_table(comparisons: Sequence[RunComparison]) -> tuple[list[str], list[list[str]]]:
    """Header and rows: per run and channel, the RMSE in multiples of that run's noise,
    pass or fail ('' where not scored)."""
    def cell(score: Score) -> str:
        return f"{score.in_noise:.1f} × noise {'pass' if score.passed else 'FAIL'}"

    header = ["run", *(channel_words(c) for c in CHANNELS)]
    return header, [[c.measured.name, *(cell(c.scores[ch]) if ch in c.scores else ""
                                        for ch in CHANNELS)] for c in comparisons]


TOLERANCE_DEFINITION = (
    f"<p>A channel passes a run when its RMSE is within {NOISE_MULTIPLE:g} times the "
    "logger's noise, read from the measured channel itself (the spread of its sample-to-"
    "sample differences). Fit % is shown beside it: it also punishes a run that varies "
    "little, where the logger's noise alone keeps it under 95 %.</p>")

FIT_DEFINITION = ("<p>fit % = 100·(1 − ‖y − ŷ‖ / ‖y − ȳ‖), y measured, ŷ simulated, ȳ the "
                  "measured mean: 100 is a perfect match, 0 no better than the mean, and it "
                  "can be negative. Each run is simulated with its measured input.</p>")
