"""Campaigns the project did not make, with their truth: what a diagnosis should answer.

``../shared/data/independent/`` holds campaigns of an independent rig simulator, each with a
``truth.json`` (catalogued effects, two at once, logger realities on nulls, drift, run-out).
:func:`expected` reads what a diagnosis should answer from it: the verdict's label, the key
parameters a finding must carry (contract name, true value, tolerance) and the elements to
start without. :func:`judge` compares a diagnosis with it. Used by ``bench/detection.py``;
the product and its tests never read these folders.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

FOLDER = Path(__file__).resolve().parents[2] / "shared" / "data" / "independent"


@dataclass(frozen=True)
class Key:
    """A key parameter a finding must carry: its cause (or family), contract name, truth,
    tolerance (relative unless ``absolute``)."""

    cause: str
    name: str
    truth: float
    tolerance: float
    absolute: bool = False

    def error(self, value: float) -> float:
        return abs(value - self.truth) if self.absolute else abs(value / self.truth - 1.0)


@dataclass(frozen=True)
class Expected:
    """What a diagnosis of one campaign should answer."""

    label: str  # a cause, 'none' or 'discovered <family>'
    keys: tuple[Key, ...]
    without: tuple[str, ...]


def campaigns(folder: Path = FOLDER) -> list[Path]:
    """The campaign folders under ``folder`` that carry a truth (none when it is absent)."""
    return sorted(p.parent for p in folder.glob("*/truth.json")) if folder.is_dir() else []


def expected(campaign: Path) -> Expected:
    return expected_of(json.loads((campaign / "truth.json").read_text(encoding="utf-8")))


def expected_of(truth: dict) -> Expected:
    """What a diagnosis should answer by ``truth`` (a ``truth.json``, or the example
    campaigns' ``generating-parameters.json``, which holds its effect alike)."""
    effect = truth["effect"]
    without = tuple(truth.get("without", ()))
    if effect["cause"] == "none":
        return Expected("none", (), without)
    if effect["cause"] == "unexplained":
        family = effect["family"]
        return Expected(f"discovered {family}", _family_keys(family, effect), without)
    keys = [_cause_key(e) for e in (effect, *effect.get("also", ()))]
    return Expected(effect["cause"], tuple(keys), without)


def _cause_key(effect: dict) -> Key:
    cause = effect["cause"]
    if cause == "actuator_delay":
        return Key(cause, "delay_s", effect["delay_s"], 1e-3, absolute=True)
    if cause == "pressure_sensor_offset":
        return Key(cause, "offset_pa", effect["offset_pa"], 0.2)
    if cause == "brake_fade":
        return Key(cause, "fade_fraction", effect["fade_fraction"], 0.2)
    if cause == "tire_relaxation":
        return Key(cause, "relaxation_length_m", effect["relaxation_length_m"], 0.2)
    if cause == "gear_walk":
        return Key(cause, "frequency_hz", effect["frequency_hz"], 0.05)
    raise ValueError(f"no key parameter known for {cause}")


def _family_keys(family: str, effect: dict) -> tuple[Key, ...]:
    if family == "run_drift":
        # k_b of each braking run, as a line about the middle one: its step per run
        gains = [g for run, g in effect["brake_gain_n_m_per_pa_by_run"].items()
                 if "brake_" in run]
        slope, mean = np.polyfit(np.arange(len(gains)), gains, 1)[0], float(np.mean(gains))
        return (Key(family, "gain_drift_per_run", float(slope / mean), 0.2),)
    if family == "wheel_angle":
        return (Key(family, "brake_runout_1", effect["runout"], 0.2),)
    return ()


@dataclass(frozen=True)
class Judgement:
    ok: bool
    label: str  # what the diagnosis answered, as Expected.label
    errors: dict[str, float]  # key parameter -> error (relative unless absolute)


def judge(result: dict, want: Expected) -> Judgement:
    """``result``: a diagnosis's JSON (Diagnosis.to_json())."""
    findings = result["findings"]
    label = result["verdict"]
    if label == "discovered" and findings:
        label = f"discovered {findings[0].get('family', '')}"
    errors: dict[str, float] = {}
    ok = label == want.label
    for key in want.keys:
        found = [f for f in findings if (f.get("family") or f["cause"]) == key.cause]
        value = found[0]["parameters"].get(key.name, math.nan) if found else math.nan
        errors[f"{key.cause}.{key.name}"] = key.error(value)
        ok = ok and key.error(value) <= key.tolerance
    return Judgement(ok, label, errors)


UNSEEN = FOLDER.parent / "unseen"
"""Effects whose laws no family or slot of the project has (``../shared/data/unseen``)."""


def unseen_equation(campaign: Path) -> str | None:
    """The equation (as a finding names it) where the unseen effect of ``campaign`` lives;
    None for a campaign that is not an effect in an equation (another rig, a datasheet)."""
    truth = json.loads((campaign / "truth.json").read_text(encoding="utf-8"))
    where = truth["effect"]["equation"]
    if where.startswith("wheel (the tyre"):
        return "tyre"
    return where if where in ("valve", "wheel", "loading device", "F_x channel") else None


def judge_unseen(result: dict, equation: str) -> tuple[bool, str]:
    """Whether a diagnosis (its JSON) found the unseen effect in ``equation`` as a
    discovered term (right), and how it ended, in words."""
    findings = result["findings"]
    first = findings[0] if findings else {}
    if result["verdict"] == "discovered" and first.get("family") == equation:
        return True, f"discovered {equation}: {first.get('term', '')}"
    if result["verdict"] == "discovered":
        return False, f"discovered {first.get('family')}: {first.get('term', '')}"
    if any(f["cause"] == "unexplained" and f.get("equation") == equation for f in findings):
        return False, f"unexplained, naming the {equation}"
    return False, result["verdict"]


def datasheet_of(campaign: Path) -> Path | None:
    """The campaign's datasheet (a params file naming what differs from the reference rig),
    None when it has none (issue 43)."""
    path = campaign / "datasheet.yaml"
    return path if path.is_file() else None


TOLERANCE = 0.1  # relative, of the datasheet-plus-truth values (issue 43)


def judge_datasheet(result: dict, natural_frequency_hz: float, damping_ratio: float,
                    campaign: Path) -> tuple[bool, str]:
    """Whether a diagnosis with the campaign's datasheet answered its truth: ``none`` for a
    null on another rig; for a slow valve, its delay, and the final model's ω_n and ζ,
    within TOLERANCE."""
    truth = json.loads((campaign / "truth.json").read_text(encoding="utf-8"))
    wanted = truth["effect"]["equation"]
    if wanted == "none":
        return result["verdict"] == "none", result["verdict"]
    cause = wanted.split()[0]
    delay = truth["effect_parameters_si"]["act_delay"]
    found = next((f["parameters"].get("delay_s") for f in result["findings"]
                  if f["cause"] == cause), None)
    rig = truth["rig_si"]
    errors = {"delay": None if found is None else found / delay - 1,
              "ω_n": natural_frequency_hz * 2 * math.pi / rig["act_wn"] - 1,
              "ζ": damping_ratio / rig["act_zeta"] - 1}
    ok = all(e is not None and abs(e) <= TOLERANCE for e in errors.values())
    shown = ", ".join(f"{k} {'-' if e is None else f'{e:+.1%}'}" for k, e in errors.items())
    return ok, f"{result['verdict']}: {shown}"
