"""The parameters of a graph node: declared with descriptors, checked against what the
node and the graph know, and read once, when the run is built.

``ros2 param list/get/describe`` answer (see :func:`graph_node.spin`); every parameter is
read-only, with its range where it has one (:func:`declare`), and ``ros2 param set`` on
what rclpy declares itself is refused with the reason (:func:`refuse_changes`); a name
nothing reads stops the node with the closest known one (:func:`check_overrides`).
"""

from __future__ import annotations

import difflib
import math
import sys
from typing import Any

from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    SetParametersResult,
)
from rclpy.exceptions import InvalidParameterValueException
from rclpy.node import Node
from rclpy.parameter import Parameter

from landing_gear_sim.errors import GraphError
from landing_gear_sim.model.parameters import (
    INDEX,
    SPECS,
    RigParameters,
    load_parameters,
)
from landing_gear_sim.model.runspec import RunSpec
from landing_gear_sim.model.scenario import Scenario
from landing_gear_sim.ros.graph import CLOCKS, load_scenario

INT64 = (-(2 ** 63), 2 ** 63 - 1)
FIXED_FOR_THE_RUN = ("read once, when the run starts: restart the node with -p {name}:=VALUE "
                     "(or in its params file)")


def declare(node: Node, name: str, default: Any, description: str,
            low: float | None = None, high: float | None = None) -> Any:
    """Declare one parameter and return its value: read-only (the run reads it once), any
    type a params file gives it (``1500`` for a double), within [``low``, ``high``] where
    given (``ros2 param describe`` shows it; a value outside is a one-line error)."""
    descriptor = ParameterDescriptor(description=description, dynamic_typing=True,
                                     read_only=True,
                                     additional_constraints=FIXED_FOR_THE_RUN.format(name=name))
    if low is not None or high is not None:
        _with_range(descriptor, default, low, high)
    try:
        return node.declare_parameter(name, default, descriptor).value
    except InvalidParameterValueException:
        given = _parameter_overrides(node).get(name)
        value = given.value if given is not None else default
        bounds = (f"{bound:g}" if bound is not None else sign + "inf"
                  for bound, sign in ((low, "-"), (high, "")))
        raise GraphError(f"{name} = {_as_text(value)} is out of its range "
                         f"[{', '.join(bounds)}]") from None


def _with_range(descriptor: ParameterDescriptor, default: Any, low: float | None,
                high: float | None) -> None:
    if isinstance(default, int) and not isinstance(default, bool):
        descriptor.integer_range = [IntegerRange(
            from_value=int(low if low is not None else INT64[0]),
            to_value=int(high if high is not None else INT64[1]), step=0)]
    else:
        descriptor.floating_point_range = [FloatingPointRange(
            from_value=float(low if low is not None else -sys.float_info.max),
            to_value=float(high if high is not None else sys.float_info.max), step=0.0)]


def _parameter_overrides(node: Node) -> dict[str, Parameter]:
    """What ``-p`` and the params files gave ``node`` (rclpy keeps them only here)."""
    return getattr(node, "_parameter_overrides", {})


def rig_parameters(node: Node) -> RigParameters:
    """Declare every model parameter (bundled reference rig as default) and validate the set.

    The params file of the graph (``--params-file config/reference_rig.yaml``, or the
    calibrated one) overrides the defaults; so does ``-p key:=value``.
    """
    defaults = load_parameters()
    values = {spec.key: declare(node, spec.key, defaults[spec.key],
                                f"{spec.description} [{spec.unit}]",
                                None if spec.kind != "float" or spec.signed else 0.0)
              for spec in SPECS}
    return RigParameters(values, ("node parameters",))


RUN_PARAMETERS: dict[str, tuple[Any, str, float | None]] = {
    "run.profile": ("constant", "current profile", None),
    "run.pressure_pa": (RunSpec.pressure_pa, "constant profile pressure [Pa]", 0.0),
    "run.current_a": (-1.0, "constant profile current [A]; <0: from run.pressure_pa", None),
    "run.file": ("", "file profile: run (CSV or bag)", None),
    "run.contact": ("auto", "auto | rig | actuator", None),
    "run.duration_s": (0.0, "input duration [s], 0: default", 0.0),
    "run.rate_hz": (0.0, "exchange rate [Hz], 0: from config", 0.0),
}
"""The ``run.*`` parameters (see graph.run_parameters): name -> (default, description, the
lowest value admitted)."""

GRAPH_WIDE = frozenset(INDEX) | set(RUN_PARAMETERS) | {"clock", "parameter_services", "run_id"}
"""Parameters a params file may give every node (``/**``): not an error for a node that has
no use for one (the recorder needs no friction curve)."""


def run_spec(node: Node) -> RunSpec:
    """Declare the ``run.*`` parameters and build the RunSpec."""
    value = {name: declare(node, name, default, text, low)
             for name, (default, text, low) in RUN_PARAMETERS.items()}
    current = float(value["run.current_a"])
    return RunSpec(profile=str(value["run.profile"]), pressure_pa=float(value["run.pressure_pa"]),
                   current_a=current if current >= 0 else math.nan, file=str(value["run.file"]),
                   contact=str(value["run.contact"]), duration_s=float(value["run.duration_s"]),
                   rate_hz=float(value["run.rate_hz"]))


def rig_and_run(node: Node) -> tuple[RigParameters, Scenario, bool]:
    """Declare what every graph node shares: the model, the run and the clock.

    Returns the parameter set, the run's scenario (its rate is the exchange rate) and
    whether the graph runs in lockstep.
    """
    params = rig_parameters(node)
    return params, load_scenario(run_spec(node), params), lockstep(node)


def lockstep(node: Node) -> bool:
    """Declare ``clock`` and say whether this graph runs in lockstep."""
    clock = str(declare(node, "clock", "lockstep", "lockstep | realtime"))
    if clock not in CLOCKS:
        raise GraphError(f"clock must be lockstep or realtime, got {clock!r}")
    return clock == "lockstep"


SIM_TIME_REFUSED = ("use_sim_time must stay false: the graph publishes /clock itself and its "
                    "nodes' timers are wall-clock (lockstep is driven by the data)")


def check_overrides(node: Node) -> None:
    """Refuse a parameter given to ``node`` (``-p``, a params file) that nothing reads.

    rclpy drops an override it has no declaration for; a typo (``run.profil``) would then
    silently run the default.

    Raises:
        GraphError: the first unknown name, with the closest known one.
    """
    if node.get_parameter("use_sim_time").value:
        raise GraphError(SIM_TIME_REFUSED)
    given = _parameter_overrides(node)
    for name in sorted(given):
        if not (node.has_parameter(name) or name in GRAPH_WIDE):
            known = set(node.list_parameters([], 0).names) | GRAPH_WIDE
            hint = difflib.get_close_matches(name, sorted(known), n=1)
            suggestion = f" (did you mean {hint[0]!r}?)" if hint else ""
            raise GraphError(f"unknown parameter {name!r}{suggestion}")


def refuse_changes(node: Node, changes: list[Parameter]) -> SetParametersResult:
    """``ros2 param set`` on what rclpy declared itself (``use_sim_time``; the node's own
    parameters are read-only, see :func:`declare`): refused too, with the reason, for a
    node's run is built once."""
    if not changes:
        return SetParametersResult(successful=True)
    change = changes[0]
    reason = SIM_TIME_REFUSED if change.name == "use_sim_time" and change.value else (
        f"{change.name} is read when the run starts; restart the node with "
        f"-p {change.name}:={_as_text(change.value)} (or in its params file)")
    return SetParametersResult(successful=False, reason=reason)


def _as_text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return repr(value)
    return str(list(value)) if isinstance(value, (list, tuple)) else str(value)
