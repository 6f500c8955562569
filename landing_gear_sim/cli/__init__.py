"""``landing-gear-sim``: the command-line front end, thin over the layers below.

Every user error ends as one line ``landing-gear-sim: error: ...`` and exit code 2.
The commands live in :mod:`~landing_gear_sim.cli.model` (simulate, rig, bode, params,
campaign, convert) and :mod:`~landing_gear_sim.cli.analysis` (identify, validate,
compare, diagnose, metrics, antiskid) and :mod:`~landing_gear_sim.cli.fleet`
(history, on Dask) and :mod:`~landing_gear_sim.cli.montecarlo` (montecarlo, on Dask);
nothing in the package imports this one.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from collections.abc import Callable, Sequence

from landing_gear_sim import __version__
from landing_gear_sim.cli import analysis, fleet, model, montecarlo
from landing_gear_sim.cli.common import PROG, check_inputs, remove_empty_made
from landing_gear_sim.errors import LandingGearSimError


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=PROG, description="Landing-gear anti-skid rig "
                                     "digital twin: simulate, analyse, compare.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    model.register(sub)
    analysis.register(sub)
    fleet.register(sub)
    montecarlo.register(sub)
    return parser


def _check(args: argparse.Namespace, parser: argparse.ArgumentParser) -> None:
    if args.command == "simulate":
        if args.rate is not None and args.rate <= 0:
            parser.error("--rate must be > 0")
        if args.duration is not None and args.duration <= 0:
            parser.error("--duration must be > 0")
    if args.command == "bode":
        if not 0 < args.slip < 1:
            parser.error("--slip must be in (0, 1)")
        if not 0 < args.fmin < args.fmax:
            parser.error("need 0 < --fmin < --fmax")
        if any(v <= 0 for v in args.speeds):
            parser.error("--speeds must be > 0")


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived: the command stops as on Ctrl-C (workers ended, no partial output)."""


def _terminate(signum: int, frame: object) -> None:
    raise Terminated


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code (130 after Ctrl-C, 143 after SIGTERM; 130 for
    both from the graph launcher ``rig``, as ``ros2 launch``)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    _check(args, parser)
    if threading.current_thread() is not threading.main_thread():
        return _run(args)  # only the main thread may set handlers (and receives signals)
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        return _run(args)
    finally:
        signal.signal(signal.SIGTERM, previous)


def _run(args: argparse.Namespace) -> int:
    try:
        check_inputs(args)
        return int(args.func(args))
    except LandingGearSimError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # a disk full or a folder gone while writing: still one line
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"{PROG}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except Terminated:
        print(f"{PROG}: terminated", file=sys.stderr)
        return 130 if getattr(args, "launcher", False) else 143  # a launcher says 130
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    finally:
        remove_empty_made()


def _entry(command: str) -> Callable[[], int]:
    def run() -> int:
        return main([command, *sys.argv[1:]])

    return run


simulate_main = _entry("simulate")
bode_main = _entry("bode")
