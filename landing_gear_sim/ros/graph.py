"""The node graph, described once: which nodes, their parameters and their topics.

Both ways of bringing the graph up read this description: the ROS launch file
(``launch/rig.launch.py``) turns each :class:`NodeSpec` into a launch ``Node``, and
``landing-gear-sim rig`` (:mod:`landing_gear_sim.ros.launcher`) into a process. No ROS here.
"""

from __future__ import annotations

import math
import re
import uuid
from collections import Counter
from dataclasses import dataclass, field, replace
from pathlib import Path

from landing_gear_sim.errors import GraphError
from landing_gear_sim.model.parameters import RigParameters
from landing_gear_sim.model.runspec import RunSpec, build_scenario
from landing_gear_sim.model.scenario import Scenario
from landing_gear_sim.ros.options import (
    CLOCKS,
    GRAPH_OPTIONS,
    STORAGES,
    TOPIC_CLOCK,
    default,
    graph_settings,
)
from msg_tools.contract import (
    NAMESPACE,
    TOPIC_CURRENT,
    TOPIC_FLYWHEEL,
    TOPIC_PRESSURE,
    TOPIC_WHEEL,
    TOPIC_WRENCH,
)
from msg_tools.io import read_run
from msg_tools.units import PA_PER_BAR

PACKAGE = "landing_gear_sim"

TOPIC_HYDRAULIC = "/rig/brake/hydraulic_pressure"
"""Actuator → plant: pressure applied to the brake (sensor_msgs/FluidPressure, absolute)."""
TOPIC_LOAD = "/rig/loading/vertical_force"
"""Loading device → plant: vertical force on the gear (geometry_msgs/Vector3Stamped, z [N])."""
TOPIC_RUN_END = "/rig/run_end"
"""Plant → everyone: the run is over; data = number of samples (std_msgs/UInt64, latched)."""
TOPIC_READY = "/rig/ready"
"""Peers → plant: a node's links are matched (std_msgs/String node name, latched)."""

SENSOR_TOPICS = (TOPIC_WHEEL, TOPIC_FLYWHEEL, TOPIC_PRESSURE, TOPIC_WRENCH)
RECORDED_TOPICS = (TOPIC_CURRENT, *SENSOR_TOPICS)
FOR_THE_BAG = frozenset((*RECORDED_TOPICS, TOPIC_RUN_END))
"""The topics the recorder needs from their publishers: what it records, and the run's end.
Their publishers stay until it has them (``GraphNode.pending``), and after a run that lost a
node the launcher waits for them (:attr:`NodeSpec.publishes_for_the_bag`). Not the lockstep
inputs, which the plant took before stepping: their readers acknowledge only on DDS's next
heartbeat, and a node waiting for that made every run ~1.3 s longer."""

CONTROLLER_NODE = "antiskid_controller"
LOST_PEER_EXIT = 3
"""Exit code of a plant whose run lost a participant (held its input): never a success."""
NOT_STARTED_EXIT = 4
"""Exit code of a plant whose run could not start (a participant missing)."""
INCOMPLETE_BAG_EXIT = 5
"""Exit code of a recorder whose bag lacks part of the run: never a success."""
RECORDER = "recorder"
"""The node that writes the bag: the one with work left once the plant ends the run."""
NAMESPACE_PATTERN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(/[A-Za-z_][A-Za-z0-9_]*)*")
"""A ROS namespace without its leading '/' (what ``-r __ns:=/...`` and launch accept)."""
EXTERNAL = "external"
"""The controller of a graph whose brake commands come from the user's own node."""

ParamValue = bool | int | float | str | list[str]


@dataclass(frozen=True)
class NodeSpec:
    """One node of the graph: executable (= node name), its own parameters, its topics."""

    name: str
    parameters: dict[str, ParamValue]
    publishes: tuple[str, ...]
    subscribes: tuple[str, ...]
    namespace: str = NAMESPACE
    """Where the node and its (relative) topics live: ``rig`` → ``/rig/brake/pressure``."""
    remappings: tuple[tuple[str, str], ...] = ()
    """ROS remapping rules (``-r FROM:=TO``), e.g. the plant's ``/clock`` onto a rig's own."""

    @property
    def publishes_for_the_bag(self) -> bool:
        """Whether it publishes a topic the recorder needs (the plant, a current source)."""
        return any(topic in FOR_THE_BAG for topic in self.publishes)

    @property
    def module(self) -> str:
        """Python module whose ``main`` runs this node."""
        if self.name == CONTROLLER_NODE:
            return "antiskid.node"
        return f"{PACKAGE}.ros.nodes.{self.name}"


@dataclass(frozen=True)
class GraphOptions:
    """Everything that decides the graph of one rig session.

    Attributes:
        run: what to run (profile or ``external`` when a controller drives the brake).
        clock: ``lockstep`` (sim time, data-driven, deterministic) or ``realtime``.
        bag: rosbag2 folder to record into; None: no recorder.
        storage: ``mcap`` or ``sqlite3``.
        sensor_noise: add the ``sensors.*`` noise to the published sensor values.
        timeout_s: lockstep: how long the plant waits for a peer before holding its input.
        start_timeout_s: how long the plant waits for the run to be able to start (every
            participant linked) before giving up with an error; 0: forever.
        safe_pressure_pa: brake pressure the plant applies when the actuator is lost.
        progress_s: the plant says how far the run is every this many seconds of wall
            time; 0: never.
        controller: anti-skid controller node to run instead of the profile node, or
            ``external``: none, the commands come from a node started by the user (the
            plant waits for it, see nodes/plant.py).
        replay: the run's current comes from the ``replay`` node (``run.file``), not
            the profile node.
        parameter_services: the nodes answer ``ros2 param`` (off: the bench's comparison).
        namespace: the rig's namespace (``rig``); a second rig on the same domain takes
            another (``rig2``) and keeps to its own topics.
        clock_topic: where the plant publishes sim time (``/clock``): two lockstep rigs on
            one domain each take their own (``/rig2/clock``), so that a sim-time listener
            of one hears one clock.
        run_id: this session's identity, given to every node: the plant starts only with
            nodes of its own session (fresh for every GraphOptions).
    """
    # a controller graph is a rig test braking from rig_test.brake_start_s: run.profile
    # is "external" (see controlled_run)

    run: RunSpec = field(default_factory=RunSpec)
    clock: str = default("clock")
    bag: Path | None = None
    storage: str = default("storage")
    sensor_noise: bool = default("noise")
    timeout_s: float = default("timeout_s")  # long: a starved node is not a lost one
    start_timeout_s: float = default("start_timeout_s")
    safe_pressure_pa: float = default("safe_pressure_bar")
    progress_s: float = default("progress_s")
    controller: str | None = None
    replay: bool = False
    parameter_services: bool = default("parameter_services")
    namespace: str = default("namespace")
    clock_topic: str = default("clock_topic")
    # a letter first: launch and -p read an all-digit id (or 1e5...) as a number
    run_id: str = field(default_factory=lambda: "s" + uuid.uuid4().hex[:12], compare=False)

    def __post_init__(self) -> None:
        if not NAMESPACE_PATTERN.fullmatch(self.namespace):
            raise GraphError(f"namespace {self.namespace!r}: use letters, digits and '_' in "
                             "'/'-separated parts, none starting with a digit (rig, lab/rig2)")
        if self.clock not in CLOCKS:
            raise GraphError(f"clock must be one of {', '.join(CLOCKS)}")
        if self.storage not in STORAGES:
            raise GraphError(f"storage must be one of {', '.join(STORAGES)}")
        if not (math.isfinite(self.timeout_s) and self.timeout_s > 0):
            raise GraphError("the lockstep timeout must be > 0 s")
        if not (math.isfinite(self.start_timeout_s) and self.start_timeout_s >= 0):
            raise GraphError("the start timeout must be >= 0 s (0: wait forever)")
        if not (math.isfinite(self.progress_s) and self.progress_s >= 0):
            raise GraphError("the progress period must be >= 0 s (0: never)")
        if self.replay and self.run.profile != "file":
            raise GraphError("a replay graph needs the run file (profile 'file')")


LAUNCH_ARGUMENTS: dict[str, tuple[str, str]] = {
    "profile": ("osc-low", "current profile (simulate's --profile), or file"),
    "file": ("", "profile file: run (CSV or bag) whose current drives the graph"),
    "pressure_bar": ("30", "constant profile: brake pressure [bar]"),
    "rate_hz": ("0", "the run's rate [Hz] (0: the rig's simulation.output_rate_hz)"),
    "params_file": ("", "ROS 2 params file of the rig (default: bundled reference rig)"),
    "bag": ("", "rosbag2 folder to record into (empty: no recorder)"),
    **{o.name: (o.launch_default, o.help) for o in GRAPH_OPTIONS},
}
"""Launch-file arguments: name -> (default, description)."""


def load_scenario(spec: RunSpec, params: RigParameters) -> Scenario:
    """The scenario of ``spec``, reading its recorded run when the profile is ``file``
    (what every node of the graph and ``simulate`` run).

    Raises:
        ScenarioError, RunFormatError: the profile cannot be built or the run not read.
    """
    recorded = read_run(Path(spec.file)) if spec.replays_file else None
    return build_scenario(spec, params, recorded)


def controlled_run(run: RunSpec, controller: str | None) -> RunSpec:
    """The run of a graph: ``run``, or with a controller driving the brake, a rig test
    at the same rate whose current comes from outside (profile ``external``)."""
    return RunSpec(profile="external", rate_hz=run.rate_hz) if controller else run


def options_from_arguments(values: dict[str, str]) -> tuple[GraphOptions, Path]:
    """GraphOptions and params file from launch arguments (strings, see LAUNCH_ARGUMENTS)."""
    from landing_gear_sim.model.bundled import default_config_files

    def value(name: str) -> str:
        return values.get(name, LAUNCH_ARGUMENTS[name][0])

    def number(name: str) -> float:
        try:
            return float(value(name))
        except ValueError:
            raise GraphError(f"{name} must be a number, got {value(name)!r}") from None

    settings = graph_settings({o.name: value(o.name) for o in GRAPH_OPTIONS})
    run = controlled_run(RunSpec(profile=value("profile"), file=value("file"),
                                 pressure_pa=number("pressure_bar") * PA_PER_BAR,
                                 rate_hz=number("rate_hz")), settings["controller"])
    options = GraphOptions(run=run, bag=Path(value("bag")) if value("bag") else None,
                           **settings)
    return options, Path(value("params_file") or default_config_files()[0])


def run_parameters(run: RunSpec) -> dict[str, ParamValue]:
    """The ``run.*`` node parameters that rebuild ``run`` (see nodes.parameters.run_spec)."""
    return {"run.profile": run.profile, "run.pressure_pa": run.pressure_pa,
            "run.current_a": -1.0 if math.isnan(run.current_a) else run.current_a,
            "run.file": run.file, "run.contact": run.contact,
            "run.duration_s": run.duration_s, "run.rate_hz": run.rate_hz}


def describe(options: GraphOptions) -> list[NodeSpec]:
    """The nodes of the graph for ``options``, plant first, with their expected links."""
    run = run_parameters(options.run)
    shared: dict[str, ParamValue] = {"clock": options.clock,  # every node's
                                     "run_id": options.run_id}
    if not options.parameter_services:
        shared["parameter_services"] = False
    nodes = [
        NodeSpec("plant", {**run, **shared, "sensor_noise": options.sensor_noise,
                           "timeout_s": options.timeout_s,
                           "start_timeout_s": options.start_timeout_s,
                           "safe_pressure_pa": options.safe_pressure_pa,
                           "progress_period_s": options.progress_s},
                 (*SENSOR_TOPICS, TOPIC_CLOCK, TOPIC_RUN_END), (TOPIC_HYDRAULIC, TOPIC_LOAD)),
        NodeSpec("actuator", {**run, **shared}, (TOPIC_HYDRAULIC,), (TOPIC_CURRENT,)),
        NodeSpec("loading_device", {**run, **shared}, (TOPIC_LOAD,), (TOPIC_FLYWHEEL,)),
    ]
    if options.controller == EXTERNAL:
        pass  # the user's node: the plant finds it in the graph
    elif options.controller:
        nodes.append(NodeSpec(CONTROLLER_NODE, {**run, **shared, "type": options.controller},
                              (TOPIC_CURRENT,), (TOPIC_WHEEL, TOPIC_FLYWHEEL)))
    elif options.replay:
        nodes.append(NodeSpec("replay", {**run, **shared, "topics": "current",
                                         "file": options.run.file},
                              (TOPIC_CURRENT,), (TOPIC_WHEEL,)))
    else:
        nodes.append(NodeSpec("profile", {**run, **shared}, (TOPIC_CURRENT,), (TOPIC_WHEEL,)))
    if options.bag is not None:
        nodes.append(NodeSpec(RECORDER, {**shared, "bag": str(options.bag),
                                           "storage": options.storage},
                              (), RECORDED_TOPICS))
    clock = ((TOPIC_CLOCK, options.clock_topic),) if options.clock_topic != TOPIC_CLOCK else ()
    return [replace(node, namespace=options.namespace,
                    remappings=clock if node.name == "plant" else ())
            for node in _with_links(nodes)]


def _with_links(nodes: list[NodeSpec]) -> list[NodeSpec]:
    """Tell every node how many subscribers its outputs must have, and the plant its peers.

    Lockstep starts only when every link is matched: a message published before its
    reader is matched would be lost and the run would wait for it forever.
    """
    readers = Counter(topic for node in nodes for topic in node.subscribes)
    linked = []
    for node in nodes:
        expected = [f"{topic}={readers[topic]}" for topic in node.publishes if readers[topic]]
        # an empty list has no type in a ROS parameter (launch_ros refuses it): leave the
        # node's default, which expects no reader, instead
        extra: dict[str, ParamValue] = {"expected_subscribers": expected} if expected else {}
        if node.name == "plant":
            extra["participants"] = [n.name for n in nodes if n.name != "plant"]
        linked.append(NodeSpec(node.name, {**node.parameters, **extra}, node.publishes,
                               node.subscribes))
    return linked
