"""Run I/O for landing_gear_sim: the data contract, CSV and rosbag2 (via rosbags).

No ROS import: bags are read and written with the pure-Python ``rosbags`` library.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .errors import RunFormatError

if TYPE_CHECKING:
    from .run import Run

__all__ = ["Run", "RunFormatError"]


def __getattr__(name: str) -> Any:
    # Run on first use (PEP 562): msg_tools.units is read by the CLI's parser, and the
    # package's import must not pay for numpy there.
    if name == "Run":
        from .run import Run

        return Run
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
