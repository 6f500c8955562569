"""Start-up benchmark: how long a command takes from the shell to its answer (issue 61).

Run: ``python bench/startup.py [--against DIR]``. Each command runs in a fresh interpreter
(best of ``--repeat``), beside the interpreter's own start (``python -c pass``) and
``--help``; with ``--against`` the same commands of another checkout (the code before, a
``git worktree``) run in the same session, and the table prints each command's time over
that one's. The benchmark imports nothing of the project itself: what it measures is what
a command imports and does. Targets (issue 61, a machine where ``--help`` takes 0.17 s):
``params --write`` ≤ 0.5 s, ``metrics`` and ``convert`` of one 25 s run ≤ 1 s. ``identify
--partial`` of the same run, alone in a folder, has no target: a command that prints a table
and draws nothing, whose imports show in its time (matplotlib: ~0.4 s, stop 71).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
ENTRY = "import sys; from landing_gear_sim.cli import main; sys.exit(main(sys.argv[1:]))"
TARGETS = {"params --write": 0.5, "metrics": 1.0, "convert to csv": 1.0, "convert to bag": 1.0}


def _seconds(argv: Callable[[int], list[str]], checkout: Path | None, repeat: int) -> float:
    """The best wall time of the CLI command ``argv(i)`` (its i-th repetition: an output
    of its own) from ``checkout`` (None: the bare interpreter)."""
    env = dict(os.environ)
    if checkout is not None:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(checkout),
                                                          env.get("PYTHONPATH", "")]))
    best = float("inf")
    for i in range(repeat):
        command = [sys.executable, "-c", "pass"] if checkout is None else [
            sys.executable, "-c", ENTRY, *argv(i)]
        start = time.perf_counter()
        # not from a checkout: `python -c` puts its folder first on the path, ahead of
        # PYTHONPATH, and the code before would have run today's
        subprocess.run(command, env=env, check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, cwd=tempfile.gettempdir())
        best = min(best, time.perf_counter() - start)
    return best


def _commands(folder: Path, tag: str) -> dict[str, Callable[[int], list[str]]]:
    run = str(folder / "run.csv")
    return {
        "--help": lambda i: ["--help"],
        "params --write": lambda i: ["params", "--write", str(folder / f"p{tag}{i}.yaml")],
        "metrics": lambda i: ["metrics", run],
        "convert to csv": lambda i: ["convert", run, str(folder / f"copy{tag}{i}.csv")],
        "convert to bag": lambda i: ["convert", run, str(folder / f"bag{tag}{i}")],
        # a command that prints a table and draws nothing (no target: what it imports)
        "identify --partial": lambda i: ["identify", str(folder / "one"), "--partial", "-o",
                                         str(folder / f"id{tag}{i}.yaml")],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", type=Path, help="another checkout: the code before")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        subprocess.run([sys.executable, "-c", ENTRY, "simulate", "--pressure-bar", "20",
                        "--no-plot", "-o", str(folder / "run.csv")], env={
                            **os.environ, "PYTHONPATH": str(HERE)}, check=True,
                       stdout=subprocess.DEVNULL)
        (folder / "one").mkdir()  # identify reads a folder: the run alone in it
        shutil.copy(folder / "run.csv", folder / "one" / "run.csv")
        bare = _seconds(lambda i: [], None, args.repeat)
        print(f"python -c pass: {bare:.2f} s")
        print(f"{'command':18s} {'now s':>7s} {'target':>7s}" + (
            f" {'before s':>9s} {'now/before':>10s}" if args.against else ""))
        before_commands = _commands(folder, "b")
        for name, argv in _commands(folder, "n").items():
            now = _seconds(argv, HERE, args.repeat)
            target = f"{TARGETS[name]:.1f}" if name in TARGETS else "-"
            line = f"{name:18s} {now:7.2f} {target:>7s}"
            if args.against:
                before = _seconds(before_commands[name], args.against.resolve(),
                                  args.repeat)
                line += f" {before:9.2f} {now / before:10.2f}"
            print(line)


if __name__ == "__main__":
    main()
