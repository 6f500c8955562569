"""The options of a rig session, in one table: ``landing-gear-sim rig`` offers each as a flag
and ``ros2 launch landing_gear_sim rig.launch.py`` as an argument (``name:=value``), with the
same default and help, so the two cannot drift apart (issue 31: the launch file had offered
part of ``rig``). Light on purpose: the CLI builds its parser from it before loading
anything heavy.
"""

from __future__ import annotations

import argparse
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from landing_gear_sim.errors import GraphError
from msg_tools.contract import NAMESPACE
from msg_tools.units import PA_PER_BAR

CLOCKS = ("lockstep", "realtime")
STORAGES = ("mcap", "sqlite3")
CONTROLLERS = ("threshold", "slip", "external")
TOPIC_CLOCK = "/clock"

Value = str | float | bool | None
TRUE, FALSE = ("true", "1", "yes", "on"), ("false", "0", "no", "off")


@dataclass(frozen=True)
class GraphOption:
    """One option: the launch argument ``name``, the ``rig`` flag (``--name`` with dashes
    unless ``flag``), GraphOptions' ``attribute`` (``name`` unless given), which holds the
    value times ``scale`` (bar → Pa)."""

    name: str
    default: Value
    help: str
    choices: tuple[str, ...] = ()
    flag: str = ""
    field: str = ""
    scale: float = 1.0

    @property
    def attribute(self) -> str:
        return self.field or self.name

    @property
    def option(self) -> str:
        return self.flag or "--" + self.name.replace("_", "-")

    @property
    def launch_default(self) -> str:
        """The default as a launch argument writes it (None: empty)."""
        if isinstance(self.default, bool):
            return str(self.default).lower()
        return "" if self.default is None else f"{self.default:g}" \
            if isinstance(self.default, float) else self.default

    def parse(self, raw: Value) -> Value:
        """``raw`` (a launch argument's text, or the CLI's typed value) as the option's
        type, checked against its choices."""
        if isinstance(raw, str) and not isinstance(self.default, str):
            raw = self._from_text(raw)
        if self.choices and raw is not None and raw not in self.choices:
            raise GraphError(f"{self.name} must be one of {', '.join(self.choices)}, "
                             f"got {raw!r}")
        return raw

    def _from_text(self, text: str) -> Value:
        if self.default is None:
            return text or None
        if isinstance(self.default, bool):
            if text.lower() not in TRUE + FALSE:
                raise GraphError(f"{self.name} must be true or false, got {text!r}")
            return text.lower() in TRUE
        try:
            return float(text)
        except ValueError:
            raise GraphError(f"{self.name} must be a number, got {text!r}") from None


GRAPH_OPTIONS = (
    GraphOption("clock", "lockstep", "lockstep: sim time, data-driven, deterministic; "
                "realtime: wall clock", CLOCKS),
    GraphOption("controller", None, "anti-skid controller in closed loop instead of the "
                "profile; external: your own node publishes the brake commands (see "
                "examples/outside_controller.py; the run waits for it)", CONTROLLERS),
    GraphOption("storage", "mcap", "bag storage format", STORAGES),
    GraphOption("noise", False, "add the sensors.* noise to the published sensor values",
                field="sensor_noise"),
    GraphOption("timeout_s", 10.0, "lockstep: seconds to wait for a silent node before "
                "holding its input", flag="--timeout"),
    GraphOption("start_timeout_s", 60.0, "seconds to wait for every participant (an external "
                "controller) before giving up with an error; 0: wait forever",
                flag="--start-timeout"),
    GraphOption("safe_pressure_bar", 0.0, "brake pressure applied once the actuator is lost",
                field="safe_pressure_pa", scale=PA_PER_BAR),
    GraphOption("progress_s", 5.0, "say how far the run is every this many seconds; 0: never",
                flag="--progress"),
    GraphOption("namespace", NAMESPACE, "namespace of the nodes and topics (a second rig: "
                "rig2)"),
    GraphOption("clock_topic", TOPIC_CLOCK, "topic the plant publishes sim time on (a second "
                "lockstep rig: /rig2/clock, so each rig's sim-time listeners hear one clock)"),
    GraphOption("parameter_services", True, "the nodes answer ros2 param (without: a little "
                "faster)", flag="--no-parameter-services"),
)
"""Every option of a session both ways of starting the graph offer."""

OPTIONS = {o.name: o for o in GRAPH_OPTIONS}


def default(name: str) -> Any:
    """GraphOptions' default of option ``name`` (in its own unit: Pa for bar); Any: of the
    type its row gives, which GraphOptions' field declares."""
    value = OPTIONS[name].default
    return value * OPTIONS[name].scale if isinstance(value, float) else value


def graph_settings(values: Mapping[str, Value]) -> dict[str, Any]:
    """GraphOptions keyword arguments from the options' ``values`` by name (the launch
    file's texts or the CLI's typed values); an option not given keeps its default.

    Raises:
        GraphError: a value of the wrong type or not among its choices.
    """
    settings: dict[str, Any] = {}
    for name, raw in values.items():
        option = OPTIONS[name]
        value = option.parse(raw)
        if name == "namespace" and isinstance(value, str):
            value = value.strip("/")
        settings[option.attribute] = value * option.scale if isinstance(value, float) \
            else value
    return settings


def add_graph_arguments(parser: argparse.ArgumentParser) -> None:
    """Every option of GRAPH_OPTIONS as a flag of ``parser`` (dest: the option's name)."""
    for o in GRAPH_OPTIONS:
        if isinstance(o.default, bool):
            parser.add_argument(o.option, dest=o.name, help=("off: " if o.default else "")
                                + o.help, action="store_false" if o.default else "store_true")
            continue
        kind = float if isinstance(o.default, float) else str
        shown = "" if o.default is None else f" (default {o.launch_default})"
        parser.add_argument(o.option, dest=o.name, type=kind, default=o.default,
                            choices=o.choices or None, help=o.help + shown,
                            metavar=None if o.choices else o.name.rsplit("_", 1)[-1].upper())


def given(args: argparse.Namespace) -> dict[str, Value]:
    """The options' values from a parser built by :func:`add_graph_arguments`."""
    return {o.name: getattr(args, o.name) for o in GRAPH_OPTIONS}
