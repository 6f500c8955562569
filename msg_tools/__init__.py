"""Run I/O for landing_gear_sim: the data contract, CSV and rosbag2 (via rosbags).

No ROS import: bags are read and written with the pure-Python ``rosbags`` library.
"""

from .errors import RunFormatError
from .run import Run

__all__ = ["Run", "RunFormatError"]
