"""Every README "Main uses" line does what it says when pasted, in order, into a fresh folder
(issue 63, item 5): exit 0, and what it writes lands under out/mine/. The lines that run
whole calibrations, diagnoses, the ROS 2 graph or Dask run under --slow (make test-slow);
the others run in every suite."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from landing_gear_sim.cli import main

ROOT = Path(__file__).resolve().parents[1]
USES = re.search(r"## Main uses.*?```sh\n(.*?)```", (ROOT / "README.md").read_text(),
                 re.DOTALL)
LINES = [line.split(" #")[0].strip() for line in (USES.group(1) if USES else "").splitlines()
         if line.startswith("landing-gear-sim ")]
HEAVY = ("rig", "metrics", "identify", "validate", "diagnose", "join", "montecarlo",
         "history")
"""What needs a calibration, a diagnosis, the graph or Dask (or what they wrote)."""


def _run(lines: list[str], folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(folder)
    (folder / "config").symlink_to(ROOT / "config")  # as from the clone's root
    for line in lines:
        argv = shlex.split(line)[1:]
        assert main(argv) == 0, line


def _quick(line: str) -> bool:
    return shlex.split(line)[1] not in HEAVY


def test_the_readme_lists_its_main_uses():
    assert len(LINES) >= 15 and all("out/mine" in line or "MY_RIG_LOGS" in line
                                    or "out/rig_threshold" in line for line in LINES), LINES


def test_the_readmes_quick_lines_run_in_a_fresh_folder_and_write_under_out_mine(
        tmp_path, monkeypatch):
    _run([line for line in LINES if _quick(line)], tmp_path, monkeypatch)
    written = {p.relative_to(tmp_path).parts[:2] for p in (tmp_path / "out").rglob("*")}
    assert written and all(parts[:2] == ("out", "mine") for parts in written
                           if len(parts) == 2), written


@pytest.mark.slow
def test_every_readme_line_runs_in_a_fresh_folder(tmp_path, monkeypatch):
    """The whole list in order (the demo's out/rig_threshold made first, as the README's
    `make demo` makes it; another rig's logs stand in for MY_RIG_LOGS)."""
    assert main(["rig", "--controller", "threshold", "--bag", str(tmp_path / "out" /
                                                                   "rig_threshold")]) == 0
    lines = [line.replace("MY_RIG_LOGS", "out/mine/camp") for line in LINES]
    _run(lines, tmp_path, monkeypatch)
