"""Stopping benchmark: how fast and how cleanly the graph ends on each signal path.

Run: ``python bench/stopping.py [--trials 20] [--workspace WS] [--busy 2]``. Each path is a signal
(SIGINT, SIGTERM) sent to a lone node (``plant``, ``recorder``), to ``landing-gear-sim rig``
(its PID; its whole process group, as a terminal's Ctrl-C) and, with ``--workspace`` (a
colcon-built workspace and ``ros2`` on PATH, see ../shared/tools/rosenv-recipe.sh), to
``ros2 launch`` (its PID, its process group). Per path: the stop time (median and max,
from the signal until the last process of the run has exited), the exit codes, and the
trials that were not clean: a traceback, a node escalated to SIGTERM/SIGKILL, or a process
left running. Issue 31's target: every node down within 1 s, 20/20 clean. The reference
measured in the same run: a bare rclpy node (init, a node, spin) stopped the same way.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"  # DDS never leaves this machine
os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 100))

TARGET_S = 1.0
ORPHAN_AFTER_S = 15.0  # a process of the run still there this long after the signal
SIGNALS = {"SIGINT": signal.SIGINT, "SIGTERM": signal.SIGTERM}
BARE_NODE = ("import rclpy, sys\nfrom rclpy.executors import ExternalShutdownException\n"
             "rclpy.init(); node = rclpy.create_node('bare')\n"
             "print('running', file=sys.stderr, flush=True)\n"
             "try:\n    rclpy.spin(node)\n"
             "except (KeyboardInterrupt, ExternalShutdownException):\n    pass\n")
LONG_RUN = ["--profile", "constant", "--pressure-bar", "0", "--set",
            "rig_test.max_duration_s=600"]
ESCALATED = re.compile(r"escalating|exit codes: .*-(9|15)\b|process has died")


@dataclass(frozen=True)
class Trial:
    seconds: float
    code: int
    traceback: bool
    escalated: bool
    orphan: bool

    @property
    def clean(self) -> bool:
        return not (self.traceback or self.escalated or self.orphan)


def _session_alive(session: int) -> bool:
    """Whether a process of ``session`` still runs: a zombie has ended (nodes orphaned by a
    launcher's death wait for PID 1 to reap them, seconds in a container)."""
    states = subprocess.run(["ps", "-o", "stat=", "-s", str(session)], capture_output=True,
                            text=True).stdout.split()
    return any(not state.startswith("Z") for state in states)


def trial(command: list[str], ready: str, sig: int, group: bool) -> Trial:
    """Start ``command`` in a session of its own, wait for ``ready`` in its output, signal
    it (or its group), time the exit; whatever it left running is killed afterwards."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True, start_new_session=True)
    assert process.stdout is not None
    lines: list[str] = []
    started = threading.Event()

    def read() -> None:
        for line in process.stdout:
            lines.append(line)
            if ready in line:
                started.set()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        if not started.wait(180):
            raise RuntimeError(f"{command[:4]} never said {ready!r}: {''.join(lines)[-1500:]}")
        begun = time.monotonic()
        (os.killpg if group else os.kill)(process.pid, sig)
        code = process.wait(timeout=120)
        # until the last process of the session is gone: `ros2 launch` ends on SIGTERM
        # at once, its nodes after it
        while _session_alive(process.pid) and time.monotonic() < begun + ORPHAN_AFTER_S:
            time.sleep(0.02)
        seconds = time.monotonic() - begun
        orphan = _session_alive(process.pid)
        reader.join(10)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
    output = "".join(lines)
    result = Trial(seconds, code, "Traceback" in output, bool(ESCALATED.search(output)), orphan)
    if not result.clean:  # what made it so, for whoever reads the table
        kept = Path(tempfile.gettempdir()) / f"stopping-unclean-{process.pid}.log"
        kept.write_text(output)
        print(f"  not clean: {kept}", file=sys.stderr, flush=True)
    return result


def _row(name: str, trials: list[Trial], reference_s: float | None) -> None:
    times = [t.seconds for t in trials]
    median = statistics.median(times)
    codes = ",".join(sorted({str(t.code) for t in trials}))
    ratio = f"{median / reference_s:5.1f}x" if reference_s else "    -"
    why = ", ".join(f"{sum(getattr(t, k) for t in trials)} {k}" for k in
                    ("traceback", "escalated", "orphan") if any(getattr(t, k) for t in trials))
    print(f"{name:38s} {median:6.2f} s {max(times):6.2f} s {ratio} {TARGET_S / max(times):5.2f}x"
          f"  {sum(t.clean for t in trials):2d}/{len(trials):<2d}  codes {codes}"
          + (f"  ({why})" if why else ""), flush=True)


def paths(folder: Path, workspace: Path | None) -> dict[str, tuple[list[str], str, bool]]:
    """name → (command, what it prints when up, signal the group)."""
    python = [sys.executable, "-m"]
    bag = f"bag:={folder}/{{n}}"
    found: dict[str, tuple[list[str], str, bool]] = {
        "bare rclpy node (reference)": ([sys.executable, "-c", BARE_NODE], "running", False),
        "plant": ([*python, "landing_gear_sim.ros.nodes.plant"], "running", False),
        "recorder": ([*python, "landing_gear_sim.ros.nodes.recorder", "--ros-args", "-p", bag],
                     "running", False),
        "rig (its PID)": ([*python, "landing_gear_sim", "rig", *LONG_RUN, "--bag",
                           f"{folder}/{{n}}"], "run starts", False),
        "rig (process group)": ([*python, "landing_gear_sim", "rig", *LONG_RUN, "--bag",
                                 f"{folder}/{{n}}"], "run starts", True),
    }
    if workspace is not None:
        launch = (f"source {workspace}/install/setup.bash && exec ros2 launch landing_gear_sim "
                  f"rig.launch.py profile:=constant pressure_bar:=0 {bag}")
        for name, group in (("ros2 launch (its PID)", False),
                            ("ros2 launch (process group)", True)):
            found[name] = (["bash", "-c", launch], "run starts", group)
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=20, help="per path and signal")
    parser.add_argument("--workspace", type=Path, help="colcon workspace for ros2 launch")
    parser.add_argument("--only", default="", help="the paths whose name holds this text")
    parser.add_argument("--busy", type=int, default=0,
                        help="busy loops running beside the trials (a loaded machine)")
    args = parser.parse_args()
    print(f"stop time per signal path, {args.trials} trials each, {args.busy} busy loops "
          f"beside (ratio: median against the bare rclpy node; target: {TARGET_S:g} s / max)")
    with busy_loops(args.busy):
        _paths(args)


@contextlib.contextmanager
def busy_loops(count: int) -> Iterator[None]:
    """``count`` processes spinning on a core each while the trials run."""
    loops = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(count)]
    try:
        yield
    finally:
        for loop in loops:
            loop.kill()
            loop.wait()


def _paths(args: argparse.Namespace) -> None:
    print(f"{'path':38s} {'median':>8s} {'max':>8s} {'ratio':>5s} {'target':>6s}  clean")
    with tempfile.TemporaryDirectory() as folder:
        count = 0
        reference: dict[str, float] = {}
        for name, (command, ready, group) in paths(Path(folder), args.workspace).items():
            if args.only not in name and not name.startswith("bare"):
                continue
            for signal_name, sig in SIGNALS.items():
                trials = []
                for _ in range(args.trials):
                    count += 1
                    trials.append(trial([c.format(n=count) for c in command], ready, sig, group))
                if name.startswith("bare"):
                    reference[signal_name] = statistics.median(t.seconds for t in trials)
                _row(f"{name} {signal_name}", trials, reference.get(signal_name))


if __name__ == "__main__":
    main()
