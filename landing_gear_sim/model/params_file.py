"""ROS 2 params files as text: the nested keys a file holds, and the file a parameter set
writes, with comments a reader needs beside the values (a slot's code names a basis
function: written as ``37.0`` alone it told a brake engineer nothing). Comments are YAML's
own, so the file loads in ROS and in :func:`~.parameters.load_parameters` as before."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import yaml

INDENT = 2  # yaml.safe_dump's, per level of the tree


def params_text(tree: Mapping[str, Any], node: str = "/**", header: Sequence[str] = (),
                notes: Mapping[str, str] | None = None) -> str:
    """The params file of ``tree`` (nested sections of values) for ``node``: ``header``'s
    lines as comments above it, each of ``notes`` (by dotted key) beside its key's value."""
    text = yaml.safe_dump({node: {"ros__parameters": dict(tree)}}, sort_keys=False,
                          allow_unicode=True)
    top = "".join(f"# {line}".rstrip() + "\n" for line in header)
    return top + (_beside(text, notes) if notes else text)


def _beside(text: str, notes: Mapping[str, str]) -> str:
    """``text`` (as safe_dump writes a tree) with each note after its key's value."""
    path: list[str] = []
    lines = []
    for line in text.splitlines():
        depth = (len(line) - len(line.lstrip(" "))) // INDENT
        path[depth:] = [line.strip().split(":", 1)[0]]
        key = ".".join(path[2:])  # below the node and ros__parameters
        lines.append(f"{line}  # {notes[key]}" if key in notes else line)
    return "\n".join(lines) + "\n"


def flatten(tree: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """``tree``'s values by dotted key."""
    flat: dict[str, Any] = {}
    for key, value in tree.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            flat.update(flatten(value, name + "."))
        else:
            flat[name] = value
    return flat
