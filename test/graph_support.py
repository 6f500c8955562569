"""What the graph tests share: short rig runs as a user starts them, and their offline twin."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import time

import pytest

from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.parameters import load_parameters
from landing_gear_sim.model.runspec import RunSpec, build_scenario
from landing_gear_sim.ros.launcher import ros_environment

# braking starts early and the run is short, so a graph run takes seconds
SHORT = {"rig_test.brake_start_s": 0.3, "rig_test.max_duration_s": 1.5}
FIELDS = ("current_a", "pressure_pa", "wheel_speed_rad_s", "flywheel_speed_rad_s",
          "vertical_load_n", "longitudinal_force_n")


# Fast DDS logs this when its shared-memory port lock is not free within 2 s, as under the
# suite's load (eProsima/Fast-DDS#6117), then carries on over UDP: the middleware's line,
# not the product's, and nothing the product can stop it printing
_SHM_PORT_NOTE = re.compile(r"^\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d+ "
                            r"\[RTPS_TRANSPORT_SHM Error\] Failed init_port ")
_COLOUR = re.compile(r"\x1b\[[0-9;]*m")


def product_lines(stderr: str) -> list[str]:
    """A process's error lines, without Fast DDS's note that a shared-memory port was busy."""
    return [line for line in stderr.strip().splitlines()
            if not _SHM_PORT_NOTE.match(_COLOUR.sub("", line))]


def sets(values: dict[str, float]) -> list[str]:
    return [arg for key, value in values.items() for arg in ("--set", f"{key}={value}")]


def rig_command(*args: str, overrides: dict[str, float] = SHORT) -> list[str]:
    return [sys.executable, "-m", "landing_gear_sim", "rig", *args, *sets(overrides)]


def run_command(command: list[str], timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout,
                          env=ros_environment())


@pytest.fixture
def start():
    """Start a launcher in the background; whatever a failed test leaves running is stopped."""
    started: list[subprocess.Popen] = []

    def launch(command: list[str]) -> subprocess.Popen:
        process = subprocess.Popen(command, env=ros_environment(), stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True)
        started.append(process)
        return process

    yield launch
    for process in started:
        if process.poll() is None:
            process.send_signal(signal.SIGINT)  # the launcher stops its nodes
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                process.kill()


def offline_run(overrides: dict[str, float], profile: str = "osc-low"):
    params = load_parameters(overrides=overrides)
    return simulate(params, build_scenario(RunSpec(profile=profile), params)).to_run()


def wait_for(predicate, timeout_s: float = 60.0) -> None:
    deadline = time.monotonic() + timeout_s
    while not predicate():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.05)


