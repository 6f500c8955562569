"""The benchmarks measure the code they stand beside."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

from landing_gear_sim.calibration.campaign import GENERATING_FILE
from landing_gear_sim.model.parameters import load_parameters

ROOT = Path(__file__).resolve().parents[1]


def _guard(bench: Path, answers: Path) -> subprocess.CompletedProcess:
    """The guard's script in ``bench``, on no campaign: only what it does before one."""
    return subprocess.run([sys.executable, str(bench / "verdicts.py"), "--save", str(answers),
                           "--sets", "bench", "--campaigns", str(answers.parent),
                           "--only", "no campaign has this name"],
                          capture_output=True, text=True, timeout=120, cwd=answers.parent)


def test_the_verdict_guard_refuses_to_answer_for_another_checkouts_code(tmp_path):
    """Run from a worktree, the guard's script had imported the main checkout's diagnosis
    (its path is its bench/ folder; the editable install points at the main checkout), and
    would have compared that code's answers as the worktree's. It says so and stops."""
    elsewhere = tmp_path / "worktree" / "bench"
    shutil.copytree(ROOT / "bench", elsewhere, ignore=shutil.ignore_patterns("__pycache__"))
    refused = _guard(elsewhere, tmp_path / "answers.json")
    assert refused.returncode == 2, refused.stderr
    assert f"not this checkout's ({elsewhere.parent})" in refused.stderr
    assert f"PYTHONPATH={elsewhere.parent}" in refused.stderr
    own = _guard(ROOT / "bench", tmp_path / "answers.json")
    assert own.returncode == 0, own.stderr


def test_the_diagnosis_bench_refuses_code_before_that_is_no_checkout(tmp_path):
    """`--against` a folder that holds no checkout (a worktree not made) had measured the
    code now twice, through the editable install, and printed it as "before"."""
    done = subprocess.run([sys.executable, str(ROOT / "bench" / "diagnose.py"), "--against",
                           str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stderr
    assert f"{tmp_path} is not a checkout of the package" in done.stderr


def test_the_identification_bench_refuses_code_before_that_is_no_checkout(tmp_path):
    """As the diagnosis bench: "before" measured from no checkout would be the code now."""
    done = subprocess.run([sys.executable, str(ROOT / "bench" / "identify.py"), "--against",
                           str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stderr
    assert f"{tmp_path} is not a checkout of the package" in done.stderr


def _answer(verdict: str, family: str = "", **finding: object) -> dict:
    findings = [{"cause": verdict, "family": family, "equation": "", "term": "",
                 "parameters": {}, "uncertainty": {}, **finding}] if family else []
    return {"verdict": verdict, "findings": findings}


def test_the_verdict_guard_counts_the_answers_right_by_their_campaigns_truth(
        tmp_path, monkeypatch):
    """Two answers that differ may both be right, or the change may have cost a right one:
    the guard judges each by its campaign's truth as detection.py does (an outside effect:
    discovered in its equation with a held-out gain; another rig's null: none) and says
    which changed; a kept answer without what its judge reads is not counted."""
    monkeypatch.syspath_prepend(str(ROOT / "bench"))
    import detection
    import verdicts

    outside = next(c for c in verdicts.plan(["outside"], tmp_path)
                   if c.key.startswith("outside/wheel_drag_rising"))
    equation = detection.OUTSIDE["wheel_drag_rising"][0]
    assert outside.right is not None
    found = _answer("discovered", equation, held_out_delta=-40.0)
    assert outside.right(found)
    assert not outside.right(_answer("discovered", equation, held_out_delta=3.0))
    assert not outside.right(_answer("discovered", "tyre", held_out_delta=-40.0))
    assert outside.right(_answer("discovered", equation)) is None  # kept before held-out
    other_rig = tmp_path / "U99_null"
    other_rig.mkdir()
    (other_rig / "truth.json").write_text('{"effect": {"equation": "none"}}')
    null = verdicts.Campaign("unseen/U99_null", other_rig,
                             right=verdicts._truth(other_rig, None))
    valve = {"natural_frequency_hz": 14.0, "damping_ratio": 0.5}
    right = verdicts.Right()
    right.add(outside, found, _answer("unexplained"))
    right.add(null, {**_answer("discovered", "wheel"), "valve": valve},
              {**_answer("none"), "valve": valve})
    right.add(null, {**_answer("none"), "valve": valve}, _answer("none"))  # kept: no valve
    assert right.summary(against=True) == (
        f"right by the truth: 1/2 (kept: 1/2); {outside.key} (now right); "
        "unseen/U99_null (now wrong)")


def _named(cause: str, **parameters: float) -> dict:
    return {"verdict": cause, "findings": [{"cause": cause, "family": "", "equation": "",
                                            "parameters": parameters}]}


def test_the_verdict_guard_judges_the_bench_campaigns_by_the_effect_each_hides(
        tmp_path, monkeypatch):
    """The bench's campaigns had no truth: the guard compared their answers but counted none
    right or wrong, so a change that cost a right answer there went unseen. A generated one
    is judged by the cause its case hides, its key parameter by the rig written beside its
    runs within the sweep's tolerance; an example campaign by the effect its
    generating-parameters.json holds."""
    monkeypatch.syspath_prepend(str(ROOT / "bench"))
    import independent
    import verdicts

    campaigns = {c.key: c for c in verdicts.plan(["bench"], tmp_path)}
    assert len(campaigns) >= 6 and all(c.right is not None for c in campaigns.values())
    delay, null = campaigns["bench/actuator_delay_6_ms"], campaigns["bench/no_extra_effect"]
    for campaign, seconds in ((delay, 0.0071), (null, 0.0)):
        campaign.folder.mkdir(parents=True)
        rig = load_parameters().replace({"actuator.delay_s": seconds}, "the hidden effect")
        rig.to_yaml(campaign.folder / GENERATING_FILE)
    assert delay.right(_named("actuator_delay", delay_s=0.0065))
    assert not delay.right(_named("actuator_delay", delay_s=0.0055))  # 1.6 ms off the rig's
    assert not delay.right(_named("pressure_sensor_offset", offset_pa=1e5))
    assert null.right(_answer("none")) and not null.right(_named("actuator_delay", delay_s=0.0))
    example = independent.expected_of({"effect": {"cause": "actuator_delay", "delay_s": 0.008}})
    assert independent.judge(_named("actuator_delay", delay_s=0.0074), example).ok
    assert not independent.judge(_answer("none"), example).ok
