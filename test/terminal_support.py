"""What the tests that signal a command share: the command started as from a terminal."""

from __future__ import annotations

import signal


def as_from_a_terminal() -> None:
    """Ctrl-C's default, as a terminal starts a command (a ``preexec_fn``): a suite run as a
    background job of a script (`.ci/run &`) hands its children SIGINT ignored, and Python
    keeps a SIGINT it was started ignoring (as `nohup` and `&` mean it to)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
