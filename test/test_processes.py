"""Work spread over forked processes (:func:`landing_gear_sim.processes.map_forked`): results
in order, arguments never pickled, a failure raised where it was asked for, and Ctrl-C ending
the workers at once."""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from terminal_support import as_from_a_terminal

from landing_gear_sim.processes import map_forked


def _where(lock: threading.Lock, index: int) -> tuple[int, int]:
    with lock:  # a lock cannot be pickled: the call reached the worker with the fork
        return os.getpid(), index


def _fails(index: int) -> int:
    if index == 2:
        raise ValueError(f"figure {index} cannot be drawn")
    return index


@pytest.fixture
def two_cores(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(os, "cpu_count", lambda: 2)


def test_forked_calls_answer_in_order_from_other_processes_their_arguments_unpickled(
        two_cores):
    lock = threading.Lock()
    answers = map_forked([(_where, (lock, i)) for i in range(5)])
    assert [index for _, index in answers] == list(range(5))
    assert os.getpid() not in {pid for pid, _ in answers}
    assert multiprocessing.active_children() == []


def test_a_call_that_fails_raises_its_error_here_and_leaves_no_worker(two_cores):
    with pytest.raises(ValueError, match="figure 2 cannot be drawn"):
        map_forked([(_fails, (i,)) for i in range(4)])
    assert multiprocessing.active_children() == []


def test_on_one_core_the_calls_run_in_this_process(monkeypatch):
    monkeypatch.setattr(os, "cpu_count", lambda: 1)
    lock = threading.Lock()
    assert map_forked([(_where, (lock, i)) for i in range(2)]) == [(os.getpid(), 0),
                                                                   (os.getpid(), 1)]


_INTERRUPTED = """
import multiprocessing, os, sys, time
from pathlib import Path
from landing_gear_sim.processes import map_forked

def draw(marker):
    Path(marker).touch()
    time.sleep(60)

os.cpu_count = lambda: 2
try:
    map_forked([(draw, (f"{sys.argv[1]}/{i}",)) for i in range(2)])
except KeyboardInterrupt:
    print("stopped", len(multiprocessing.active_children()))
"""


def test_ctrl_c_while_the_workers_draw_ends_them_at_once_without_a_traceback(tmp_path: Path):
    """Ctrl-C from a terminal reaches the whole process group: the workers leave it to
    their parent, which ends them rather than wait for their minute of work."""
    process = subprocess.Popen([sys.executable, "-c", _INTERRUPTED, str(tmp_path)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True, preexec_fn=as_from_a_terminal)
    deadline = time.monotonic() + 60
    while len(list(tmp_path.iterdir())) < 2 and time.monotonic() < deadline:
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGINT)
    out, err = process.communicate(timeout=30)  # far short of the workers' 60 s
    assert process.returncode == 0 and out == "stopped 0\n", (out, err)
    assert err == ""
