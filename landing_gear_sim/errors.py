"""The project's exception tree.

Every error a user can cause (bad file, bad parameter, bad argument, data that cannot
support a step) is a :class:`LandingGearSimError`; the CLI and the nodes print its
message on one line and exit 2. The data-shaped ones are also ``ValueError`` so that
callers used to the standard library still catch them. This module imports nothing of
the project: ``msg_tools`` and ``antiskid`` derive their errors from it too.

::

    LandingGearSimError
    ├── ParameterError          a parameter is missing, unknown, mistyped or out of range
    ├── ScenarioError           a run cannot be built (profile, level, recorded input)
    ├── IdentificationError     the runs cannot support a calibration or candidate fit
    ├── DiagnosisError          a campaign cannot be diagnosed at all
    ├── ComparisonError         two runs share too little time to be compared
    ├── GraphError              the node graph cannot be configured or started
    ├── msg_tools.RunFormatError     a run file is unreadable or breaks the data contract
    └── antiskid.ControllerError     controller settings that cannot work
"""

from __future__ import annotations


class LandingGearSimError(Exception):
    """Base class of the errors a user can cause."""


class ParameterError(LandingGearSimError, ValueError):
    """A parameter is missing, unknown, of the wrong type or out of range."""


class ScenarioError(LandingGearSimError, ValueError):
    """A scenario or input profile cannot be built (bad level, bad file, ...)."""


class IdentificationError(LandingGearSimError, ValueError):
    """The runs given cannot support a calibration step or a candidate fit."""


class DiagnosisError(LandingGearSimError, ValueError):
    """The campaign cannot be diagnosed (no usable runs, unknown element)."""


class ComparisonError(LandingGearSimError, ValueError):
    """A simulated and a measured run share too little time to be compared."""


class GraphError(LandingGearSimError):
    """The node graph cannot be configured or brought up."""
