"""What the commands share: parameters, progress lines, run options, safe writes."""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
import tempfile
import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path, PosixPath
from typing import TYPE_CHECKING

from landing_gear_sim.errors import LandingGearSimError
from landing_gear_sim.model.parameters import (
    ELEMENTS,
    RigParameters,
    load_parameters,
    parse_assignment,
)
from landing_gear_sim.model.runspec import PROFILES, RunSpec
from msg_tools.units import PA_PER_BAR

if TYPE_CHECKING:
    from msg_tools.csv_io import Mapping
    from msg_tools.run import Run

PROG = "landing-gear-sim"


def progress(message: str) -> None:
    """One progress line on stderr (stdout carries the results)."""
    print(f"[{PROG}] {message}", file=sys.stderr, flush=True)


COMPILE_NOTE_AFTER_S = 1.0  # loading the compiled physics from numba's cache takes ~0.3 s


@contextmanager
def note_if_compiling() -> Iterator[None]:
    """Say so when the work inside is compiling the physics (once after an install or a
    change, ~10 s) rather than print that note on every run."""
    from landing_gear_sim.model.integrate import compiled

    def note() -> None:
        if not compiled():
            progress("compiling the physics for this machine (once after an install, ~10 s)")

    timer = threading.Timer(COMPILE_NOTE_AFTER_S, note)
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()


class InputPath(PosixPath):
    """The type of a path argument a command reads: :func:`check_inputs` finds it missing
    before the command loads anything (issue 32: the numerical stack loaded first, 1.6 s on
    a quiet machine, to say a folder was not there)."""


def check_inputs(args: argparse.Namespace) -> None:
    """Refuse the first input path of ``args`` that is not there, in one line; the others
    become plain paths (what the commands hand on, to Dask workers too)."""
    for name, value in vars(args).items():
        paths = value if isinstance(value, list) else [value]
        if not any(isinstance(path, InputPath) for path in paths):
            continue
        for path in paths:
            if not path.exists():
                raise LandingGearSimError(f"{path}: no such file or folder")
        plain = [Path(path) for path in paths]
        setattr(args, name, plain if isinstance(value, list) else plain[0])


def add_params_arguments(parser: argparse.ArgumentParser, without: bool = True) -> None:
    parser.add_argument("--config", action="append", type=InputPath, metavar="FILE",
                        help="ROS 2 params file naming what differs from the bundled "
                        "reference rig (a datasheet, or a whole calibrated set); repeat to "
                        "layer")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override one parameter, e.g. --set friction.theta1=0.8")
    if without:
        parser.add_argument("--without", action="append", default=[], choices=ELEMENTS,
                            metavar="ELEMENT",
                            help=f"switch an element off ({', '.join(ELEMENTS)})")


def add_storage_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--storage", choices=["mcap", "sqlite3"], default="mcap",
                        help="bag storage format (default mcap)")


def add_run_arguments(parser: argparse.ArgumentParser,
                      default: str | None = "constant") -> None:
    parser.add_argument("--profile", choices=[*PROFILES, "file"], default=default,
                        help=f"valve current profile (default: {default or 'none'})")
    parser.add_argument("--pressure-bar", type=float, default=30.0,
                        help="constant profile: target pressure (default 30 bar)")
    parser.add_argument("--current-a", type=float, help="constant profile: current instead")
    parser.add_argument("--file", type=Path,
                        help="--profile file: run (CSV or bag) whose current to use")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--actuator-only", action="store_true", help="wheel off the flywheel")
    where.add_argument("--rig", action="store_true", help="wheel on the flywheel")
    parser.add_argument("--duration", type=float, help="input duration [s] (actuator tests)")
    parser.add_argument("--rate", type=float, help="output rate [Hz] (default from config)")


def params_of(args: argparse.Namespace) -> RigParameters:
    """The parameter set of ``--config``, ``--set`` and ``--without``."""
    overrides = dict(parse_assignment(text) for text in args.set)
    params = load_parameters(args.config, overrides or None, over_reference=True)
    removed = getattr(args, "without", None)
    return params.without(*removed) if removed else params


def run_spec_of(args: argparse.Namespace) -> RunSpec:
    """The run of the ``--profile`` options."""
    contact = "actuator" if args.actuator_only else "rig" if args.rig else "auto"
    return RunSpec(profile=args.profile, pressure_pa=args.pressure_bar * PA_PER_BAR,
                   current_a=math.nan if args.current_a is None else args.current_a,
                   file=str(args.file or ""), contact=contact,
                   duration_s=args.duration or 0.0, rate_hz=args.rate or 0.0)


def read_one(path: Path, mapping: Mapping | None = None) -> Run:
    """The run of ``path``, saying what reading had to do to it (a cut last line)."""
    from msg_tools.io import read_run

    run = read_run(path, mapping)
    for note in run.notes:
        progress(f"note: {note}")
    return run


def mapping_of(args: argparse.Namespace) -> Mapping | None:
    from msg_tools.csv_io import read_mapping

    return read_mapping(args.mapping) if getattr(args, "mapping", None) else None


def check_outputs(files: Sequence[Path | None] = (), folders: Sequence[Path | None] = ()
                  ) -> None:
    """Fail before the work, with one error line, when an output cannot be written: its
    folder cannot be made or written to, or a file's path is a folder."""
    for path in files:
        if path is not None and path.is_dir():
            raise LandingGearSimError(f"{path}: is a folder, expected a file name")
    targets = [f.parent for f in files if f is not None] + [d for d in folders if d is not None]
    for folder in targets:
        MADE.extend(p for p in (folder, *folder.parents) if not p.exists())
        try:
            folder.mkdir(parents=True, exist_ok=True)
            with tempfile.TemporaryFile(dir=folder):
                pass
        except OSError as exc:
            raise LandingGearSimError(f"{folder}: cannot write there "
                                      f"({exc.strerror or exc}); choose a folder you can "
                                      "write to") from None


MADE: list[Path] = []
"""The folders :func:`check_outputs` made for a command's outputs."""


def remove_empty_made() -> None:
    """Remove the folders made for outputs that a command left empty (it stopped on an
    error, or was interrupted, before writing them): nothing empty is left behind."""
    for folder in sorted(set(MADE), key=lambda f: len(f.parts), reverse=True):
        with contextlib.suppress(OSError):  # not empty, or gone: kept as it is
            folder.rmdir()
    MADE.clear()


def write_atomically(path: Path, write: Callable[[Path], object]) -> None:
    """Write via a temporary file so a failure never leaves a half-written ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".part")
    write(tmp)
    tmp.replace(path)
