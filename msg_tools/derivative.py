"""Speed from an encoder's angle, for logs that carry positions only (JointState.position).

The angle is unwrapped (encoders that count modulo one turn), differentiated by central
differences on its own, possibly uneven, stamps (``numpy.gradient``, second order), then
smoothed by a Savitzky-Golay filter (2nd order, 11 samples): it keeps a ramp or a parabola
exactly and attenuates the quantisation noise of the differences; its -3 dB point is at
about a tenth of the sample rate (99 Hz at 1 kHz), above the wheel dynamics of interest.
"""

from __future__ import annotations

import numpy as np

WINDOW_SAMPLES = 11
ORDER = 2


def speed_from_angle(time_s: np.ndarray, angle_rad: np.ndarray) -> np.ndarray:
    """Angular speed [rad/s], shape (n,), of the angles ``angle_rad`` [rad] at ``time_s``."""
    unwrapped = np.unwrap(angle_rad)
    speed = np.gradient(unwrapped, time_s)
    if speed.size <= WINDOW_SAMPLES:
        return speed
    # imported here: scipy.signal costs ~1.6 s to import, paid by every ROS node that reads
    # or writes bags (through msg_tools.io) and never meets an angle-only log
    import scipy.signal

    return scipy.signal.savgol_filter(speed, WINDOW_SAMPLES, ORDER)
