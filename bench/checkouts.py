"""A checkout's code measured in a fresh interpreter: how a bench's ``--against`` runs the
code before beside the code now."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path


def is_checkout(folder: Path) -> bool:
    """Whether ``folder`` holds a checkout of the package (a worktree made, no typo)."""
    return (folder / "landing_gear_sim" / "__init__.py").is_file()


def measured_in(checkout: Path, script: str, *args: str, bench: str) -> dict:
    """What ``script`` (a ``python -c`` program whose last line is a JSON object, its
    ``checkout`` the folder its ``landing_gear_sim`` came from) printed, run with ``args``
    by ``checkout``'s code in a fresh interpreter. Exits naming ``bench`` when the code
    that ran was another checkout's."""
    # not from a checkout's folder: `python -c` puts its folder first on the path
    done = subprocess.run([sys.executable, "-c", script, *args],
                          env=dict(os.environ, PYTHONPATH=str(checkout)), check=True,
                          capture_output=True, text=True, cwd=tempfile.gettempdir())
    measured = json.loads(done.stdout.strip().splitlines()[-1])
    if Path(measured["checkout"]) != checkout.resolve():
        # PYTHONPATH names no checkout (a worktree not made, a typo): the editable install
        # gave the main checkout's code, and "before" had measured the code now
        raise SystemExit(f"{bench}: error: {checkout} is not a checkout of the package: the "
                         f"code measured was {measured['checkout']}'s")
    return measured
