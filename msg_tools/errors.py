"""Errors of msg_tools."""

from __future__ import annotations


class RunFormatError(Exception):
    """A run file is missing, unreadable or breaks the data contract; the message names it."""
