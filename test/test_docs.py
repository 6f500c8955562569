"""The command lines the README and the docs show still parse (issue 32)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from landing_gear_sim.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"```(?:sh|bash|console)?\n(.*?)```", re.DOTALL)


def _command_lines(text: str) -> list[str]:
    """Each `landing-gear-sim ...` line of the document's code blocks, continuations joined
    and comments dropped."""
    lines = []
    for block in FENCE.findall(text):
        for line in block.replace("\\\n", " ").splitlines():
            line = line.split(" #")[0].strip()
            if line.startswith("landing-gear-sim "):
                lines.append(line)
    return lines


def _as_argv(synopsis: str) -> list[str]:
    """A synopsis as a user would type it: optional parts taken, `a|b` as its first choice,
    `X...` as one X, `X[,X...]` as X."""
    text = re.sub(r"\[,[^\]]*\]", "", synopsis)
    text = text.replace("[", " ").replace("]", " ").replace("...", "")
    return [word.split("|")[0] for word in shlex.split(text)[1:]]


COMMANDS = [(path.relative_to(ROOT).as_posix(), line) for path in DOCUMENTS
            for line in _command_lines(path.read_text())]


def test_the_documents_show_command_lines():
    assert len(COMMANDS) >= 20, COMMANDS


@pytest.mark.parametrize(("document", "line"), COMMANDS)
def test_every_documented_command_line_parses(document, line):
    try:
        build_parser().parse_args(_as_argv(line))
    except SystemExit as exc:
        pytest.fail(f"{document}: `{line}` no longer parses (exit {exc.code})")


YAML_FENCE = re.compile(r"```yaml\n(.*?)```", re.DOTALL)
MAPPINGS = [(path.relative_to(ROOT).as_posix(), block) for path in DOCUMENTS
            for block in YAML_FENCE.findall(path.read_text())
            if "{column:" in block or "{topic:" in block]


def test_the_documents_show_column_mappings():
    assert len(MAPPINGS) >= 3, MAPPINGS


@pytest.mark.parametrize(("document", "block"), MAPPINGS)
def test_every_documented_column_mapping_reads(document, block, tmp_path):
    """The data contract once showed `field: velocity[wheel]` unquoted: not valid YAML."""
    from msg_tools.errors import RunFormatError
    from msg_tools.mapping import read_mapping

    path = tmp_path / "mapping.yaml"
    path.write_text(block)
    try:
        read_mapping(path)
    except RunFormatError as exc:
        pytest.fail(f"{document}: the mapping it shows does not read: {exc}")
