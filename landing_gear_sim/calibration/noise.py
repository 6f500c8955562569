"""A logged channel's noise, read from the channel itself: what the diagnosis scales its
residuals by and what the validation's tolerance is a multiple of."""

from __future__ import annotations

import math

import numpy as np


def noise_std(values: np.ndarray) -> float:
    """Sensor-noise std of a 1 kHz channel: first differences are noise-dominated."""
    return float(np.std(np.diff(values)) / math.sqrt(2)) or 1.0


def channel_noise(values: np.ndarray) -> float:
    """A channel's white noise [its unit]: the robust spread of its second differences
    (a stop's deceleration cancels out of them), or of its first where that is less (an
    encoder's counts, mostly still between steps). First differences alone read a 200 Hz
    log's wheel channel at 3-9 times its noise, and set the tyre's floor 5.6 times higher
    than that noise does. NaN under three samples: too few to tell noise from signal."""
    if values.size < 3:
        return float("nan")
    second = np.diff(values, 2)
    robust = 1.4826 * float(np.median(np.abs(second - np.median(second)))) / np.sqrt(6.0)
    first = noise_std(values)
    return min(first, robust) if robust > 0 else first
