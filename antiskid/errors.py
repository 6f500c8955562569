"""Exceptions of the anti-skid package (inside the project's tree, landing_gear_sim.errors)."""

from landing_gear_sim.errors import LandingGearSimError


class ControllerError(LandingGearSimError, ValueError):
    """Controller parameters that cannot work (negative gain, set-point outside (0, 1), ...)."""
