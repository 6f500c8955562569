"""Exception classes of landing_gear_sim.

Every error a user can cause (bad file, bad parameter, bad argument) is a
:class:`LandingGearSimError`; the CLI prints its message on one line and exits 2.
"""

from __future__ import annotations


class LandingGearSimError(Exception):
    """Base class of the errors a user can cause."""


class ParameterError(LandingGearSimError):
    """A parameter is missing, unknown, of the wrong type or out of range."""


class ScenarioError(LandingGearSimError):
    """A scenario or input profile cannot be built (bad level, bad file, ...)."""
