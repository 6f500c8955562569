"""Exceptions of the anti-skid package."""

from landing_gear_sim.errors import LandingGearSimError


class ControllerError(LandingGearSimError):
    """Controller parameters that cannot work (negative gain, set-point outside (0, 1), ...)."""
