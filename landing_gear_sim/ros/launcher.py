"""Bring the graph up without a ROS install: every node of :func:`graph.describe` as a process.

``landing-gear-sim rig`` uses this: start the nodes, wait for the run to end, stop
them cleanly, leave the bag. The ROS launch file starts the same description.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from landing_gear_sim.errors import GraphError
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.processes import die_with_parent
from landing_gear_sim.ros.graph import (
    LOST_PEER_EXIT,
    NOT_STARTED_EXIT,
    RECORDER,
    GraphOptions,
    NodeSpec,
    ParamValue,
    describe,
)

LINGER_S = 10.0  # after the plant ends, how long the others may take to finish on their own
STOP_S = 5.0  # after SIGINT, how long before SIGKILL
RESEND_S = 0.5  # SIGINT repeated this often while a node still runs
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)  # both stop the graph; the bag is closed


def ros_environment(environ: dict[str, str] | None = None) -> dict[str, str]:
    """The environment for the nodes: the user's own (``environ``, default the process's).

    The domain and discovery settings are the user's: the launcher never picks them (the
    tests and ``make`` choose a private domain on this machine for themselves).
    """
    env = dict(os.environ if environ is None else environ)
    env.setdefault("PYTHONUNBUFFERED", "1")  # node logs arrive as they are written
    return env


def format_value(value: ParamValue) -> str:
    """A parameter value as ``-p name:=VALUE`` expects it (YAML, strings quoted)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, list):
        return "[" + ", ".join(format_value(v) for v in (value or [""])) + "]"
    return "'" + str(value).replace("'", "''") + "'"


def parameter_arguments(node: NodeSpec) -> list[str]:
    """``-p name:=VALUE`` for each of the node's own parameters. The launch file passes
    them so too: given as a dict, launch_ros writes them to a ``launch_params_*`` file it
    never removes (193 in /tmp after one stopping benchmark)."""
    return [arg for name, value in node.parameters.items()
            for arg in ("-p", f"{name}:={format_value(value)}")]


def node_command(node: NodeSpec, params_file: Path, python: str = sys.executable) -> list[str]:
    """The command line that runs ``node`` with the graph's params file."""
    remaps = [arg for rule in node.remappings for arg in ("-r", ":=".join(rule))]
    return [python, "-m", node.module, "--ros-args", "-r", f"__ns:=/{node.namespace}",
            *remaps, "--params-file", str(params_file), *parameter_arguments(node)]


@dataclass
class Outcome:
    """How a graph run ended: exit code per node, whether the user interrupted it, and the
    node whose death ended it."""

    exit_codes: dict[str, int]
    interrupted: bool = False
    failed: str | None = None

    @property
    def ok(self) -> bool:
        return not self.interrupted and self.failed is None and self.failing is None

    @property
    def failing(self) -> str | None:
        """The node that ended with an error, the plant first (a recorder whose bag lacks
        part of the run had exited 0 at the end: a run called complete)."""
        order = sorted(self.exit_codes, key=lambda name: name != "plant")
        return next((name for name in order if self.exit_codes[name] != 0), None)


def run_graph(options: GraphOptions, params: RigParameters,
              say: Callable[[str], None] = print) -> Outcome:
    """Start the graph of ``options``, wait for the plant to finish the run, stop the rest."""
    with tempfile.TemporaryDirectory(prefix="landing_gear_sim_") as workdir:
        params_file = Path(workdir) / "rig_params.yaml"
        params.to_yaml(params_file)
        return _run_processes(options, params_file, say)


def _run_processes(options: GraphOptions, params_file: Path,
                   say: Callable[[str], None]) -> Outcome:
    env = ros_environment()
    nodes = describe(options)
    domain = env.get("ROS_DOMAIN_ID", "unset: 0")
    discovery = env.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "unset: SUBNET")
    processes: dict[str, subprocess.Popen] = {}
    failed = None
    # SIGINT too: a shell starts a background job with SIGINT ignored, and the nodes would
    # stop on the terminal's Ctrl-C while the launcher reported a complete run. Taken before
    # the first line: a signal sent on seeing "starting" found SIGINT still ignored there
    # and the whole run went on (exit 0)
    stop = StopRequest()
    previous = {sig: signal.signal(sig, stop) for sig in STOP_SIGNALS}
    say(f"starting {', '.join(n.name for n in nodes)} (ROS_DOMAIN_ID {domain}, discovery "
        f"{discovery})")
    try:
        for node in nodes:
            if stop.requested:
                break
            processes[node.name] = subprocess.Popen(node_command(node, params_file), env=env,
                                                    preexec_fn=_node_process)
        failed = _wait_for_plant(processes, say, stop)
        if failed is None:
            for_the_bag = frozenset(n.name for n in nodes if n.publishes_for_the_bag)
            _wait_all(_finishing(processes, for_the_bag), LINGER_S, stop)
    finally:
        _stop(processes)  # a second Ctrl-C meanwhile is only noted: the bag is being closed
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return Outcome(_codes(processes), stop.requested, failed)


class StopRequest:
    """The launcher's SIGINT/SIGTERM handler: it notes the stop, the wait loops act on it.

    It once raised KeyboardInterrupt instead. A signal that came while a node was being
    forked then ran it inside an at-fork hook, where CPython prints and swallows the
    exception ("Exception ignored in _releaseLock"): the launcher missed the stop (5 of 15
    group SIGTERMs at start-up), or it came inside Popen and the forked node was never
    recorded (an orphan). Noting a flag is safe anywhere.
    """

    def __init__(self) -> None:
        self.requested = False

    def __call__(self, signum: int, frame: object) -> None:
        self.requested = True


def _node_process() -> None:
    """How a node process starts: it dies with the launcher, and with SIGINT ignored until
    its package takes it (``ros/nodes/__init__``). Python's own SIGINT handler made a
    terminal's Ctrl-C in a node's first milliseconds a KeyboardInterrupt traceback; a SIGINT
    ignored there is not lost, since :func:`_stop` repeats it. SIGTERM gets its default
    back (the process just ends): the launcher's death must still end the node."""
    die_with_parent()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _wait_for_plant(processes: dict[str, subprocess.Popen], say: Callable[[str], None],
                    stop: StopRequest) -> str | None:
    """Wait until the plant ends the run; the name of a node that died before, which
    ends it at once (a run with a participant missing is not the run that was asked)."""
    while not stop.requested and processes["plant"].poll() is None:
        for name, process in processes.items():
            code = process.poll()
            if code == 2:  # a configuration error: the run cannot start
                raise GraphError(f"node {name} refused its configuration (see above)")
            if code is not None and code != 0:
                say(f"node {name} died (exit code {code}): the run failed; stopping the graph")
                return name
        time.sleep(0.05)
    return None


def _finishing(processes: dict[str, subprocess.Popen],
               for_the_bag: frozenset[str] = frozenset()) -> dict[str, subprocess.Popen]:
    """The nodes the plant's end leaves work to finish on their own: every node after a
    complete run; after a run that lost a node, which would be waited for in vain (a stopped
    actuator: LINGER_S), only the recorder and the nodes ``for_the_bag`` (whose last
    commands it may still lack: stopped at once, they took them along); none when the run
    never started. Every node too when the plant has no exit code (a stop came first: it
    ends the wait)."""
    plant = processes.get("plant")
    code = None if plant is None else plant.returncode
    if code == NOT_STARTED_EXIT:
        return {}
    if code == LOST_PEER_EXIT:
        return {name: p for name, p in processes.items()
                if name == RECORDER or name in for_the_bag}
    return processes


def _wait_all(processes: dict[str, subprocess.Popen], timeout_s: float,
              stop: StopRequest | None = None) -> None:
    deadline = time.monotonic() + timeout_s
    while (time.monotonic() < deadline and any(p.poll() is None for p in processes.values())
           and not (stop and stop.requested)):
        time.sleep(0.05)


def _stop(processes: dict[str, subprocess.Popen]) -> None:
    """SIGINT whatever still runs (the recorder closes its bag), again every
    :data:`RESEND_S` (a node still starting may not have taken the first), SIGKILL what
    hangs after :data:`STOP_S`."""
    deadline = time.monotonic() + STOP_S
    while time.monotonic() < deadline and any(p.poll() is None for p in processes.values()):
        for process in processes.values():
            if process.poll() is None:
                process.send_signal(signal.SIGINT)
                process.send_signal(signal.SIGCONT)  # a stopped node acts on it only so
        _wait_all(processes, min(RESEND_S, deadline - time.monotonic()))
    for process in processes.values():
        if process.poll() is None:
            process.kill()
            process.wait()


def _codes(processes: dict[str, subprocess.Popen]) -> dict[str, int]:
    return {name: int(process.returncode) for name, process in processes.items()}
