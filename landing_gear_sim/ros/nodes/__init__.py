"""Thin rclpy adapters over the physics core, one executable and process per node.

``ros2 run landing_gear_sim <name>`` or ``python -m landing_gear_sim.ros.nodes.<name>``;
the graph they form is described once in :mod:`landing_gear_sim.ros.graph`.

Importing a node takes seconds (numpy, numba, rclpy). A Ctrl-C or SIGTERM in that time
(``ros2 launch`` stopped right after it started) used to end the process with a
KeyboardInterrupt traceback and −2, or an ImportError when it hit numpy's import. So the
signals are only noted here; once rclpy has installed its own handlers,
:func:`~landing_gear_sim.ros.nodes.graph_node.run_node` stops cleanly if one came.

A node also ends when whoever started it is gone: a supervisor's SIGTERM ends ``ros2
launch`` in milliseconds and launch does not take its nodes along, which then ran on as
orphans and mixed into the next run on the same domain.
"""

import signal

from landing_gear_sim.processes import die_with_parent

_received: list[int] = []


def _note(signum: int, frame: object) -> None:
    _received.append(signum)


def stop_requested() -> bool:
    """Whether SIGINT or SIGTERM arrived (noted from this package's import on)."""
    return bool(_received)


signal.signal(signal.SIGINT, _note)
signal.signal(signal.SIGTERM, _note)
die_with_parent()  # the parent's death comes as a SIGTERM: a stop request like any other
