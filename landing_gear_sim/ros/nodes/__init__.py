"""Thin rclpy adapters over the physics core, one executable and process per node.

``ros2 run landing_gear_sim <name>`` or ``python -m landing_gear_sim.ros.nodes.<name>``;
the graph they form is described once in :mod:`landing_gear_sim.ros.graph`.

Importing a node takes seconds (numpy, numba, rclpy). A Ctrl-C or SIGTERM in that time
(``ros2 launch`` stopped right after it started) used to end the process with a
KeyboardInterrupt traceback and −2, or an ImportError when it hit numpy's import. So the
signals are only noted here; once rclpy has installed its own handlers,
:func:`~landing_gear_sim.ros.nodes.common.run_node` stops cleanly if one came.
"""

import signal

_received: list[int] = []


def _note(signum: int, frame: object) -> None:
    _received.append(signum)


def stop_requested() -> bool:
    """Whether SIGINT or SIGTERM arrived (noted from this package's import on)."""
    return bool(_received)


signal.signal(signal.SIGINT, _note)
signal.signal(signal.SIGTERM, _note)
