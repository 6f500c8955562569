"""Child processes that never outlive their parent (Linux). Imports nothing of the project:
the graph launcher and the diagnosis' worker pool both use it."""

from __future__ import annotations

import ctypes
import signal

PR_SET_PDEATHSIG = 1  # prctl option: the signal a child gets when its parent dies


def die_with_parent() -> None:
    """Ask the kernel to send this process SIGTERM when its parent dies (a killed launcher
    or a killed `diagnose` leaves no orphan running on)."""
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
