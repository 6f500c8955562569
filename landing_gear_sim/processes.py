"""Child processes that never outlive their parent (Linux), and worker-pool processes that
leave signals to their parent. Imports nothing of the project:
the graph launcher and the diagnosis' worker pool both use it."""

from __future__ import annotations

import ctypes
import signal
from contextlib import AbstractContextManager

PR_SET_PDEATHSIG = 1  # prctl option: the signal a child gets when its parent dies


def die_with_parent() -> None:
    """Ask the kernel to send this process SIGTERM when its parent dies (a killed launcher
    or a killed `diagnose` leaves no orphan running on)."""
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM)


def pool_worker() -> None:
    """Initializer of a worker-pool process: dies with its parent, leaves Ctrl-C to it (the
    parent stops the pool), and ends on SIGTERM at once (without the parent's handlers,
    which a forked child inherits and which would print a traceback)."""
    die_with_parent()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def single_threaded_blas() -> AbstractContextManager[object]:
    """BLAS on one thread while inside (the fits' matrices are small: OpenBLAS' threads
    cost more than they give, and two fitting processes each with two threads on two
    cores took twice as long: diagnose 17.7 s -> 9.8 s)."""
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas")
