"""A user's datasheet: the values their params files give beyond the bundled reference rig
(issue 43). ``--config`` files are layered over the reference
(:func:`~.parameters.load_parameters`, ``over_reference``), so a datasheet names only what
differs; a report says which values came from it."""

from __future__ import annotations

from pathlib import Path

from landing_gear_sim.model.bundled import default_config_files
from landing_gear_sim.model.parameters import SPECS, RigParameters, Value, read_params_file

UNITS: dict[str, str] = {spec.key: spec.unit for spec in SPECS}


def datasheet_values(params: RigParameters) -> dict[str, Value]:
    """The values ``params`` took from its params files beyond the bundled reference rig's,
    by key, in the schema's order."""
    bundled = {str(p) for p in default_config_files()}
    keys = {key for source in params.sources if source not in bundled and Path(source).is_file()
            for key in read_params_file(Path(source))}
    return {spec.key: params[spec.key] for spec in SPECS if spec.key in keys}
