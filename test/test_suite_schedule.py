"""How `make test` spreads the suite over its two workers: the tests of one ``xdist_group``
(a module's shared fixture: the history's identified days, the dual kernels' compilation)
run on one worker, so what they share is computed once.

pytest 9.2 with pytest-xdist 3.8 had dropped every group without a word (pytest-xdist
issue 1386): the grouped modules ran on both workers, each computing the fixtures again,
~120 of the suite's ~2075 worker-seconds."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

GROUPED = '''
import os
from pathlib import Path

import pytest

pytestmark = pytest.mark.xdist_group("shared")


@pytest.mark.parametrize("i", range(6))
def test_where_it_ran(i):
    Path(os.environ["RAN"], str(i)).write_text(os.environ["PYTEST_XDIST_WORKER"])
'''


def test_a_groups_tests_run_on_one_worker_as_make_test_runs_them(tmp_path: Path):
    (tmp_path / "test_grouped.py").write_text(GROUPED)
    (tmp_path / "pytest.ini").write_text("[pytest]\n")
    ran = tmp_path / "ran"
    ran.mkdir()
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-n", "2", "--dist", "loadgroup",
         "-p", "no:cacheprovider", str(tmp_path)],
        cwd=tmp_path, env=os.environ | {"RAN": str(ran)}, capture_output=True, text=True,
        timeout=120, check=False)
    assert done.returncode == 0, done.stdout + done.stderr
    workers = {path.read_text() for path in ran.iterdir()}
    assert len(list(ran.iterdir())) == 6 and len(workers) == 1, workers
