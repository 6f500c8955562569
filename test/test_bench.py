"""The benchmarks measure the code they stand beside."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

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
