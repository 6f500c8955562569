"""Test-session set-up: DDS stays on this machine, on a domain private to this process."""

from __future__ import annotations

import os
import zlib

# Set before anything can import rclpy: Fast DDS would otherwise multicast on the LAN,
# and parallel test processes would cross-talk on a shared domain. One domain per test
# process: the run's own base, then one step per xdist worker, so the workers of one run
# never share a domain (each process's pid modulo 100 had, 1 run in 100).
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ["ROS_DOMAIN_ID"] = str(1 + (
    zlib.crc32(os.environ.get("PYTEST_XDIST_TESTRUNUID", str(os.getpid())).encode()) % 50 * 4
    + int(os.environ.get("PYTEST_XDIST_WORKER", "gw0").removeprefix("gw"))) % 200)

import pytest
from graph_support import start  # noqa: F401  # the graph tests' launcher fixture

from landing_gear_sim.model.parameters import RigParameters, load_parameters


@pytest.fixture(scope="session")
def reference() -> RigParameters:
    """The bundled reference-rig parameter set."""
    return load_parameters()


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--slow", action="store_true",
                     help="also run the slow diagnosis sweeps (make test-slow)")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "slow: minutes-long diagnosis cases (make test-slow)")
    config.addinivalue_line("markers", "long: a test of a minute or more, started first")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    # the longest first: collected last, the README's whole list (~2 min) had run alone on
    # one core while the other had finished
    items.sort(key=lambda item: "long" not in item.keywords)
    if config.getoption("--slow"):
        return
    skip = pytest.mark.skip(reason="slow diagnosis case: run with --slow (make test-slow)")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)
