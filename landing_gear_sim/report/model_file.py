"""The extended model as the params file ``diagnose -o`` writes (issue 41): it opens with the
verdict in a brake engineer's words and the law of each equation whose generic slot it
fills, in engineering units, and says beside each filled place what its code names. A
file of codes alone (``wheel.term_1_code: 37.0``) kept the law on the terminal."""

from __future__ import annotations

from pathlib import Path

from landing_gear_sim.diagnosis.diagnose import Diagnosis
from landing_gear_sim.diagnosis.equations.registry import held_laws
from landing_gear_sim.diagnosis.terms import slot_notes
from landing_gear_sim.report.words import headline


def write_extended_model(result: Diagnosis, path: Path) -> None:
    """``result``'s extended model as a params file at ``path``, with what made it."""
    result.extended.to_yaml(path, header=model_header(result),
                            notes=slot_notes(result.extended))


def model_header(result: Diagnosis) -> list[str]:
    """The comment lines above the extended model's values."""
    lines = ["The model `landing-gear-sim diagnose` calibrated and extended on a campaign: a ROS 2",
             "params file (`--config` here, `--params-file` to a node).", ""]
    # a line per clause: a law wrapped at a width had its term cut in two ('[P' / '> 0.5 bar]')
    clauses = headline(result).split("; ")
    lines += [c + ";" for c in clauses[:-1]] + clauses[-1:]
    if laws := held_laws(result.extended):
        lines += ["", "The laws it extends, with the terms its generic slots hold:"]
        lines += [f"  {law}" for law in laws]
    return lines
