"""Errors of msg_tools, inside the project's exception tree (landing_gear_sim.errors)."""

from __future__ import annotations

from landing_gear_sim.errors import LandingGearSimError


class RunFormatError(LandingGearSimError, ValueError):
    """A run file is missing, unreadable or breaks the data contract; the message names it."""
