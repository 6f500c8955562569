"""Measured runs in, calibrated model out: run classes, identification, validation,
and the project's own rig generator. Math only; figures and pages are in ``report``."""
