"""Independent tasks on Dask: an embedded ``LocalCluster`` by default, a real scheduler on
request, a journal that keeps every finished task, a progress line, retries.

Each task is a function of its arguments whose result is a JSON-able dict. Results are
appended to the journal (one JSON line per task, flushed and synced) the moment they
arrive, so a crash or a Ctrl-C keeps what finished, and a run that is started again skips
the keys already in its journal. A task whose worker dies is run again elsewhere (Dask
reschedules it; ``RETRIES`` more for an exception in the task itself).
"""

from __future__ import annotations

import json
import logging
import os
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from landing_gear_sim.errors import LandingGearSimError

if TYPE_CHECKING:
    from distributed import Client

Result = dict[str, Any]
RETRIES = 2
CONNECT_TIMEOUT_S = 10.0


class EngineError(LandingGearSimError):
    """The cluster cannot be reached or started."""


@dataclass(frozen=True)
class Task:
    """One unit of work: ``function(*args)`` -> a JSON-able dict, known by ``key``."""

    key: str
    function: Callable[..., Result]
    args: tuple[Any, ...] = ()


@dataclass
class Meter:
    """Tasks done of total, their rate and the time left, as one line."""

    total: int
    done: int = 0
    started: float = field(default_factory=time.perf_counter)
    fresh: int = 0  # done in this session (the rate ignores what the journal had)

    def tick(self) -> str:
        self.done += 1
        self.fresh += 1
        elapsed = time.perf_counter() - self.started
        rate = self.fresh / elapsed if elapsed > 0 else 0.0
        left = (self.total - self.done) / rate if rate > 0 else float("nan")
        return (f"[{self.done:{len(str(self.total))}d}/{self.total}] "
                f"{100 * self.done / self.total:3.0f} %  {60 * rate:.1f} tasks/min  "
                f"ETA {_duration(left)}")


def _duration(seconds: float) -> str:
    if seconds != seconds:  # nan
        return "?"
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min"


def read_journal(path: Path) -> dict[str, Result]:
    """Results already in ``path`` by key; a line torn by a crash is ignored."""
    done: dict[str, Result] = {}
    if not path.exists():
        return done
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            entry = json.loads(line)
            done[entry["key"]] = entry["result"]
        except (json.JSONDecodeError, KeyError, TypeError):
            continue
    return done


@contextmanager
def client(scheduler: str | None = None, workers: int | None = None) -> Iterator[Client]:
    """A Dask client: of the scheduler at ``scheduler`` (``tcp://host:8786``), or of a
    ``LocalCluster`` of ``workers`` single-threaded processes on 127.0.0.1 (default: one
    per core). Closed on exit, whatever happens."""
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            connected = Client(scheduler, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError) as exc:
            raise EngineError(f"{scheduler}: no Dask scheduler answers ({exc})") from None
        with connected:
            yield connected
        return
    cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1,
                           # a free port (8787 may be another cluster's), on 127.0.0.1
                           processes=True, host="127.0.0.1", dashboard_address=":0",
                           silence_logs=logging.ERROR)
    with cluster, Client(cluster) as local:
        yield local


def run_tasks(tasks: Sequence[Task], journal: Path, engine: Client,
              say: Callable[[str], None]) -> dict[str, Result]:
    """Run the ``tasks`` whose key is not in ``journal`` on ``engine``; every result is
    appended to ``journal`` as it arrives. Returns all results (old and new) by key."""
    from distributed import as_completed

    results = read_journal(journal)
    todo = [t for t in tasks if t.key not in results]
    if len(todo) < len(tasks):
        say(f"{len(tasks) - len(todo)} of {len(tasks)} already done ({journal}); "
            f"{len(todo)} to run")
    meter = Meter(len(tasks), len(tasks) - len(todo))
    futures = {engine.submit(t.function, *t.args, key=f"{t.key}-{os.urandom(4).hex()}",
                             pure=False, retries=RETRIES): t.key for t in todo}
    journal.parent.mkdir(parents=True, exist_ok=True)
    try:
        with journal.open("a", encoding="utf-8") as out:
            for future in as_completed(futures):
                key = futures[future]
                try:
                    results[key] = future.result()
                except Exception as exc:  # one task's bug must not end the others
                    # not journaled: a run started again tries it again
                    say(f"{meter.tick()}  {key}: FAILED ({type(exc).__name__}: {exc})")
                    continue
                out.write(json.dumps({"key": key, "result": results[key]}) + "\n")
                out.flush()
                os.fsync(out.fileno())
                say(f"{meter.tick()}  {key}")
    finally:
        engine.cancel(list(futures))
    return results
