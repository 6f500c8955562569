"""Every README "Main uses" line does what it says when pasted, in order, into a fresh folder
(issue 63, item 5): exit 0, and what it writes lands under out/mine/. Every line runs in
every suite, CI's included: the calibration, the three diagnoses, the ROS 2 graph and Dask
(~105 s on an idle 2-core machine); under --slow they had run only by hand."""

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


def _run(lines: list[str], folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(folder)
    (folder / "config").symlink_to(ROOT / "config")  # as from the clone's root
    for line in lines:
        argv = shlex.split(line)[1:]
        assert main(argv) == 0, line


def test_the_readme_lists_its_main_uses():
    assert len(LINES) >= 15 and all("out/mine" in line or "MY_RIG_LOGS" in line
                                    or "out/rig_threshold" in line for line in LINES), LINES


@pytest.mark.long
def test_every_readme_line_runs_in_a_fresh_folder_and_writes_under_out_mine(tmp_path,
                                                                            monkeypatch):
    """The whole list in order (the demo's out/rig_threshold made first, as the README's
    `make demo` makes it; another rig's logs stand in for MY_RIG_LOGS)."""
    demo = tmp_path / "out" / "rig_threshold"
    assert main(["rig", "--controller", "threshold", "--bag", str(demo)]) == 0
    before = set((tmp_path / "out").rglob("*"))
    lines = [line.replace("MY_RIG_LOGS", "out/mine/camp") for line in LINES]
    _run(lines, tmp_path, monkeypatch)
    written = {p.relative_to(tmp_path).parts[:2] for p in (tmp_path / "out").rglob("*")
               if p not in before and not p.is_relative_to(demo)}
    assert written and all(parts == ("out", "mine") for parts in written
                           if len(parts) == 2), written
