"""Child processes that never outlive their parent (Linux), and worker-pool processes that
leave signals to their parent. Imports nothing of the project:
the graph launcher and the diagnosis' worker pool both use it."""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ThreadPoolExecutor
from contextlib import AbstractContextManager
from typing import TypeVar

Item = TypeVar("Item")
Result = TypeVar("Result")

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
    global _THREADS
    die_with_parent()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _THREADS = 1  # the pool already has a process per core


_THREADS = os.cpu_count() or 1


def map_threads(function: Callable[[Item], Result], items: Iterable[Item]) -> Sequence[Result]:
    """``function`` of each item, in order, on a thread per core: for work that releases the
    GIL (the compiled simulation). One thread in a pool's worker, whose pool has a process
    per core already (a Dask worker is a daemonic process)."""
    work = list(items)
    if _THREADS < 2 or len(work) < 2 or multiprocessing.current_process().daemon:
        return [function(item) for item in work]
    with ThreadPoolExecutor(min(_THREADS, len(work))) as pool:
        return list(pool.map(function, work))


def single_threaded_blas() -> AbstractContextManager[object]:
    """BLAS on one thread while inside (the fits' matrices are small: OpenBLAS' threads
    cost more than they give, and two fitting processes each with two threads on two
    cores took twice as long: diagnose 17.7 s -> 9.8 s)."""
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas")
