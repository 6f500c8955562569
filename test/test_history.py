"""A rig's history over many campaigns, on Dask: the table, trends and steps, resuming,
and a real scheduler whose worker dies mid-run."""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.campaigns.history import campaign_folders, parameter_change
from landing_gear_sim.cli import main

# the five identified days are one fixture: on one worker, its tests compute them once
pytestmark = pytest.mark.xdist_group("history")

GAIN = "brake.gain_n_m_per_pa"
DROP = 0.88  # the pads replaced before the 4th test day: 12 % less torque per bar
RUNS = ("actuator_ramp", "actuator_steps_sweep", "brake_const_20bar", "brake_const_30bar",
        "brake_const_40bar", "brake_osc_low")


@pytest.fixture(scope="module")
def history(tmp_path_factory, reference) -> Path:
    """Five test days of one generated rig (seeded here, never seen by the code under
    test); the brake gain drops from day 4 on."""
    folder = tmp_path_factory.mktemp("history")
    rig = rig_like(reference, np.random.default_rng(31))
    for day in range(1, 6):
        worn = rig.replace({GAIN: DROP * rig.number(GAIN)}, "new pads") if day >= 4 else rig
        generate_campaign(folder / f"2026-03-0{day}", worn, seed=40 + day, names=RUNS)
    return folder


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open(encoding="utf-8") as table:
        return list(csv.DictReader(table))


def test_a_step_is_found_at_the_campaign_where_it_happened():
    rng = np.random.default_rng(1)
    values = np.r_[np.full(4, 1.0), np.full(4, 0.9)] + rng.normal(0, 0.005, 8)
    names = [f"day{i}" for i in range(8)]
    change = parameter_change("k", names, values, np.full(8, 0.005))
    assert change is not None and change.kind == "step" and change.at == "day4"
    assert change.size == pytest.approx(-0.1, abs=0.01)


def test_steady_wear_is_a_trend():
    rng = np.random.default_rng(2)
    values = 1.0 - 0.01 * np.arange(10) + rng.normal(0, 0.002, 10)
    change = parameter_change("k", [str(i) for i in range(10)], values, np.full(10, 0.002))
    assert change is not None and change.kind == "trend"
    assert change.size == pytest.approx(-0.01, rel=0.2)


@pytest.mark.parametrize("understated", [1.0, 3.0])
def test_scatter_alone_is_no_change_even_with_understated_sigmas(understated):
    """200 histories of pure scatter; the identification's σ stated as given or 3x too
    small (the scatter then says how large it really is)."""
    rng = np.random.default_rng(3)
    flagged = sum(parameter_change("k", [str(i) for i in range(8)],
                                   1.0 + rng.normal(0, 0.01, 8),
                                   np.full(8, 0.01 / understated)) is not None
                  for _ in range(200))
    assert flagged <= 2


def test_a_folder_of_campaigns_is_split_into_its_days(history):
    assert [f.name for f in campaign_folders([history])] == [f"2026-03-0{d}" for d in range(1, 6)]
    assert campaign_folders([history / "2026-03-02"]) == [history / "2026-03-02"]


@pytest.fixture(scope="module")
def identified_history(history, tmp_path_factory) -> tuple[Path, str, str]:
    """The five days identified by a local pool of two (``history --no-diagnose``): the
    output folder, and what the command printed and said on stderr. The cluster's run
    is compared with this table."""
    out = tmp_path_factory.mktemp("identified") / "out"
    printed, said = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(said):
        code = main(["history", str(history), "--no-diagnose", "--workers", "2", "-o",
                     str(out)])
    assert code == 0, said.getvalue()
    return out, printed.getvalue(), said.getvalue()


def test_history_finds_the_new_pads_and_resumes_without_redoing(history, identified_history,
                                                                capsys):
    out, printed, _ = identified_history
    assert f"{GAIN}: step" in printed and "from 2026-03-04 on" in printed
    changes = json.loads((out / "changes.json").read_text())["changes"]
    step = next(c for c in changes if c["key"] == GAIN)
    assert step["size"] == pytest.approx(DROP - 1, abs=0.02)
    rows = _rows(out / "history.csv")
    assert [r["campaign"] for r in rows] == [f"2026-03-0{d}" for d in range(1, 6)]
    assert (out / "history.parquet").exists() and (out / "plots" / f"{GAIN}.png").exists()

    assert main(["history", str(history), "--no-diagnose", "--workers", "1", "-o", str(out)]) == 0
    assert "5 of 5 already done" in capsys.readouterr().err
    assert _rows(out / "history.csv") == rows


def test_history_diagnoses_each_campaign_inside_the_workers(history, tmp_path, capsys,
                                                           reference):
    """Diagnosis in a Dask worker (a daemonic process: no pool of its own). One day is
    enough to show it (the step between days is the previous test's)."""
    out = tmp_path / "out"
    assert main(["history", str(history / "2026-03-04"), "--workers", "2", "-o",
                 str(out)]) == 0, capsys.readouterr().err
    [row] = _rows(out / "history.csv")
    assert row["status"] == "ok" and row["verdict"] == "none", row
    worn = DROP * rig_like(reference, np.random.default_rng(31)).number(GAIN)
    assert float(row[GAIN]) == pytest.approx(worn, rel=0.02), (row[GAIN], worn)


def _dask(*args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "distributed.cli." + args[0], *args[1:]],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)


def _wait_for(condition, timeout_s: float, what: str) -> None:
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out waiting for {what}")
        time.sleep(0.1)


def _scheduler_address(path: Path) -> str | None:
    """The address in a scheduler's file, None until it is written whole (the scheduler
    writes it in place: read as soon as it existed, it was once empty)."""
    try:
        return json.loads(path.read_text())["address"]
    except (FileNotFoundError, json.JSONDecodeError, KeyError):
        return None


@pytest.mark.long
def test_a_worker_killed_mid_run_loses_nothing(history, identified_history, tmp_path):
    """A real `dask scheduler` and two `dask worker` processes on 127.0.0.1; one worker is
    killed once the first campaign is in: the table is complete and identical to that of
    a local run."""
    local, _, _ = identified_history
    address_file = tmp_path / "scheduler.json"
    processes = [_dask("dask_scheduler", "--host", "127.0.0.1", "--port", "0",
                       "--no-dashboard", "--scheduler-file", str(address_file))]
    try:
        _wait_for(lambda: _scheduler_address(address_file), 60, "the scheduler")
        address = _scheduler_address(address_file)
        processes += [_dask("dask_worker", address, "--nthreads", "1", "--no-nanny",
                            "--no-dashboard", "--host", "127.0.0.1") for _ in range(2)]
        out = tmp_path / "cluster"
        runner = subprocess.Popen(
            [sys.executable, "-m", "landing_gear_sim", "history", str(history),
             "--no-diagnose", "--scheduler", address, "-o", str(out)],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        journal = out / "journal-identify.jsonl"
        _wait_for(lambda: journal.exists() and journal.read_text().count("\n") >= 1, 120,
                  "the first campaign")
        os.killpg(processes[1].pid, signal.SIGKILL)
        try:
            _, stderr = runner.communicate(timeout=300)
        finally:
            runner.kill()
        assert runner.returncode == 0, stderr
    finally:
        for process in processes:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGTERM)
                process.wait(timeout=30)
    assert _rows(out / "history.csv") == _rows(local / "history.csv")
