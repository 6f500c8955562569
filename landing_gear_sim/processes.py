"""Child processes that never outlive their parent (Linux), and worker-pool processes that
leave signals to their parent. Imports nothing of the project:
the graph launcher, the diagnosis' worker pool and the report's drawing all use it."""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from contextlib import AbstractContextManager, contextmanager
from typing import Any, TypeVar

Item = TypeVar("Item")
Result = TypeVar("Result")

PR_SET_PDEATHSIG = 1  # prctl option: the signal a child gets when its parent dies


def die_with_parent() -> None:
    """Ask the kernel to send this process SIGTERM when its parent dies (a killed launcher
    or a killed `diagnose` leaves no orphan running on)."""
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM)


Counter = Any  # a multiprocessing.Value("i"): its type is not importable
_THREADS = os.cpu_count() or 1
_BUSY: Counter | None = None


HELD = frozenset({signal.SIGINT, signal.SIGTERM})
"""The signals a pool's workers are forked holding (:func:`signals_held`)."""


def pool_worker(busy: Counter | None = None) -> None:
    """Initializer of a worker-pool process: dies with its parent, leaves Ctrl-C to it (the
    parent stops the pool), and ends on SIGTERM at once (without the parent's handlers,
    which a forked child inherits and which would print a traceback). ``busy``: the pool's
    count of tasks at work (:func:`working`), from which a task takes the cores the others
    leave (without it, one thread: the pool already has a process per core)."""
    global _THREADS, _BUSY
    die_with_parent()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD)  # forked under signals_held()
    _THREADS, _BUSY = 1, busy


@contextmanager
def signals_held() -> Iterator[None]:
    """Hold Ctrl-C and SIGTERM in this thread while it forks a pool's workers (whose
    initializer is :func:`pool_worker`). A worker signalled between its fork and its
    initializer ran the parent's handlers, inherited with the fork, and printed their
    exception's traceback; it inherits the hold instead, and the initializer lets the
    signal in once the worker's own handlers are in place. Here, a signal that came
    meanwhile is delivered as the block ends."""
    before = signal.pthread_sigmask(signal.SIG_BLOCK, HELD)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def busy_counter() -> Counter:
    """A count of a pool's tasks at work, shared with its (forked) workers."""
    return multiprocessing.get_context("fork").Value("i", 0)


@contextmanager
def working() -> Iterator[None]:
    """A pool task at work while inside: the last task of a pool takes every core (a
    diagnosis' longest fit had run on one core while the other idled)."""
    if _BUSY is None:
        yield
        return
    with _BUSY.get_lock():
        _BUSY.value += 1
    try:
        yield
    finally:
        with _BUSY.get_lock():
            _BUSY.value -= 1


def threads() -> int:
    """Threads a compiled simulation may use now: a core each, or in a pool's worker the
    cores its other tasks at work leave."""
    if _BUSY is None:
        return _THREADS
    return max(1, (os.cpu_count() or 1) - max(int(_BUSY.value), 1) + 1)


def map_threads(function: Callable[[Item], Result], items: Iterable[Item]) -> Sequence[Result]:
    """``function`` of each item, in order, on a thread per core: for work that releases the
    GIL (the compiled simulation). In a pool's worker, on the cores its other tasks leave
    (:func:`threads`); in a daemonic process (a Dask worker's), one thread."""
    work, cores = list(items), threads()
    if cores < 2 or len(work) < 2 or multiprocessing.current_process().daemon:
        return [function(item) for item in work]
    with ThreadPoolExecutor(min(cores, len(work))) as pool:
        return list(pool.map(function, work))


STOP_WAIT_S = 1.0  # for a pool's terminated workers to end (they take milliseconds)


def stop_pool(pool: ProcessPoolExecutor) -> None:
    """End ``pool``'s workers at once, whatever they are doing, and its manager thread with
    them. A worker terminated while it sends a result leaves half a message in the result
    pipe: the manager thread waits for the rest for ever, and the interpreter's exit joins
    it (a SIGTERM'd ``diagnose`` was found alive 25 minutes on). With this process's copy
    of the pipe's writer closed, the workers' gone with them, that read ends: the manager
    finds the pool broken and ends."""
    # the executor keeps its result pipe private (and drops it on shutdown); only its
    # workers write to it
    writer = getattr(getattr(pool, "_result_queue", None), "_writer", None)
    for child in multiprocessing.active_children():
        child.terminate()
    deadline = time.monotonic() + STOP_WAIT_S
    for child in multiprocessing.active_children():
        # a join returns as the child's sentinel closes, which can be just before the
        # kernel lets it be reaped: it had still read as running a moment after
        while child.exitcode is None and (left := deadline - time.monotonic()) > 0.0:
            child.join(timeout=left)
    pool.shutdown(wait=False, cancel_futures=True)
    if writer is not None:
        writer.close()


def fork_workers(tasks: int) -> int:
    """Worker processes for ``tasks`` independent tasks: a core each, at most one per task;
    under 2 where a pool would not pay (one core, one task) or may not be made (a daemonic
    process, a Dask worker's, may not have children)."""
    if multiprocessing.current_process().daemon:
        return 1
    return min(tasks, os.cpu_count() or 1)


@contextmanager
def forked_pool(workers: int, *initargs: Any) -> Iterator[ProcessPoolExecutor]:
    """A pool of ``workers`` forked processes, :func:`pool_worker` their initializer (with
    ``initargs``); its tasks are submitted under :func:`signals_held`, which forks them. An
    exception inside, Ctrl-C and SIGTERM included, ends the workers at once
    (:func:`stop_pool`): their tasks could run for minutes, and an executor's exit would
    wait for them. Otherwise the pool is shut down once its tasks are done."""
    pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork"),
                               initializer=pool_worker, initargs=initargs)
    try:
        yield pool
    except BaseException:
        stop_pool(pool)
        raise
    pool.shutdown()


Call = tuple[Callable[..., Result], tuple[Any, ...]]
"""A function defined at a module's top level and its arguments."""

_CALLS: Sequence[Call[Any]] = ()


def _call(index: int) -> Any:
    function, arguments = _CALLS[index]
    return function(*arguments)


def map_forked(calls: Sequence[Call[Result]]) -> list[Result]:
    """Each call's result, in order, made on a forked process per core: for work that holds
    the GIL (matplotlib's drawing). The workers inherit the calls with the fork: their
    arguments are never pickled, only the results. In this process where a pool would not
    pay or may not be made (:func:`fork_workers`)."""
    global _CALLS
    workers = fork_workers(len(calls))
    if workers < 2:
        return [function(*arguments) for function, arguments in calls]
    _CALLS = calls
    try:
        with forked_pool(workers) as pool:
            with signals_held():
                futures = [pool.submit(_call, i) for i in range(len(calls))]
            return [future.result() for future in futures]
    finally:
        _CALLS = ()


def single_threaded_blas() -> AbstractContextManager[object]:
    """BLAS on one thread while inside (the fits' matrices are small: OpenBLAS' threads
    cost more than they give, and two fitting processes each with two threads on two
    cores took twice as long: diagnose 17.7 s -> 9.8 s)."""
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas")
