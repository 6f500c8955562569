"""The graph, without starting it: blocks, description, launch file, command lines, bag segments."""

from __future__ import annotations

import os
import runpy
import sys
import types
from pathlib import Path

import numpy as np
import pytest
import yaml
from rosbags.rosbag2 import Reader

from landing_gear_sim.cli.common import run_spec_of
from landing_gear_sim.errors import GraphError, LandingGearSimError
from landing_gear_sim.model.blocks import ActuatorBlock, LoadingBlock, PlantBlock
from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.runspec import RunSpec, build_scenario
from landing_gear_sim.ros.graph import (
    EXTERNAL,
    INCOMPLETE_BAG_EXIT,
    LAUNCH_ARGUMENTS,
    LOST_PEER_EXIT,
    NOT_STARTED_EXIT,
    RECORDED_TOPICS,
    TOPIC_CLOCK,
    TOPIC_RUN_END,
    GraphOptions,
    controlled_run,
    describe,
    options_from_arguments,
)
from landing_gear_sim.ros.launcher import (
    Outcome,
    _finishing,
    format_value,
    node_command,
    ros_environment,
)
from landing_gear_sim.ros.options import GRAPH_OPTIONS, OPTIONS, given, graph_settings
from msg_tools.bag_io import TYPESTORE
from msg_tools.bag_read import read_bag
from msg_tools.bag_segments import OPEN_SEGMENT, SegmentedBagWriter
from msg_tools.contract import ATMOSPHERE_PA, TOPIC_TYPES

ROOT = Path(__file__).resolve().parents[1]


def test_blocks_stepped_as_the_nodes_do_reproduce_the_offline_run(reference):
    """One call per message, through the message units (absolute Pa, rad/s), as the graph."""
    scenario = build_scenario(RunSpec(profile="osc-low"), reference)
    scenario = type(scenario)(scenario.name, scenario.current_a[:3000], scenario.rate_hz, True,
                              scenario.initial_speed_m_s, scenario.stop_speed_m_s)
    offline = simulate(reference, scenario).to_run()
    plant = PlantBlock(reference, scenario)
    actuator = ActuatorBlock(reference, scenario.step_s)
    loading = LoadingBlock(reference, scenario.step_s, scenario.contact)
    rows = []
    while True:
        sample = plant.sample()
        rows.append([sample.pressure_pa, sample.wheel_speed_rad_s, sample.vertical_load_n])
        if plant.finished():
            break
        absolute = actuator.step(scenario.current_a[sample.step]) + ATMOSPHERE_PA
        load = loading.step(sample.step, sample.flywheel_speed_rad_s)
        plant.advance(absolute - ATMOSPHERE_PA, load)
    graph = np.array(rows)
    expected = np.column_stack([offline.pressure_pa, offline.wheel_speed_rad_s,
                                offline.vertical_load_n])
    assert graph.shape == expected.shape
    np.testing.assert_allclose(graph, expected, rtol=1e-12, atol=1e-6)


def test_every_subscribed_topic_has_one_publisher_in_the_graph(tmp_path):
    nodes = describe(GraphOptions(bag=tmp_path / "bag"))
    publishers = {t: [n.name for n in nodes if t in n.publishes]
                  for n in nodes for t in n.subscribes}
    assert all(len(names) == 1 for names in publishers.values()), publishers
    assert [n.name for n in nodes] == ["plant", "actuator", "loading_device", "profile", "recorder"]


def test_the_plant_waits_for_every_participant_and_each_node_for_its_readers(tmp_path):
    nodes = {n.name: n for n in describe(GraphOptions(bag=tmp_path / "bag"))}
    assert nodes["plant"].parameters["participants"] == ["actuator", "loading_device", "profile",
                                                  "recorder"]
    expected = dict(item.split("=") for item in nodes["plant"].parameters["expected_subscribers"])
    # wheel: profile + recorder; flywheel: loading device + recorder; latched/clock not awaited
    assert expected == {"/rig/wheel/joint_states": "2", "/rig/flywheel/joint_states": "2",
                        "/rig/brake/pressure": "1", "/rig/load_cell/wrench": "1"}
    assert TOPIC_CLOCK not in expected and TOPIC_RUN_END not in expected
    assert nodes["profile"].parameters["expected_subscribers"] == ["/rig/brake/current_ref=2"]
    assert set(nodes["recorder"].subscribes) == set(RECORDED_TOPICS)


def test_an_external_controller_graph_has_no_command_node_and_a_start_timeout():
    nodes = {n.name: n for n in describe(GraphOptions(
        run=controlled_run(RunSpec(), EXTERNAL), controller=EXTERNAL, start_timeout_s=5.0))}
    assert list(nodes) == ["plant", "actuator", "loading_device"]  # the user brings one
    assert nodes["plant"].parameters["participants"] == ["actuator", "loading_device"]
    assert nodes["plant"].parameters["start_timeout_s"] == 5.0
    assert nodes["actuator"].parameters["run.profile"] == "external"
    with pytest.raises(GraphError, match="start timeout"):
        GraphOptions(start_timeout_s=-1.0)


def test_a_clock_topic_of_its_own_is_a_remapping_of_the_plants_clock(tmp_path):
    """Issue 31: two namespaced lockstep rigs shared /clock; the option remaps the one
    publisher of sim time, the same way from `rig` and from the launch file."""

    options, _ = options_from_arguments({"namespace": "rig2", "clock_topic": "/rig2/clock"})
    nodes = {n.name: n for n in describe(options)}
    assert nodes["plant"].remappings == (("/clock", "/rig2/clock"),)
    assert all(not n.remappings for name, n in nodes.items() if name != "plant")
    command = node_command(nodes["plant"], tmp_path / "p.yaml")
    assert command[command.index("/clock:=/rig2/clock") - 1] == "-r"
    assert not describe(GraphOptions())[0].remappings  # /clock by default


def test_without_a_bag_there_is_no_recorder_and_nobody_waits_for_one():
    nodes = {n.name: n for n in describe(GraphOptions())}
    assert "recorder" not in nodes
    assert nodes["profile"].parameters["expected_subscribers"] == ["/rig/brake/current_ref=1"]


def test_a_replay_graph_takes_the_current_from_the_replay_node(tmp_path):
    run = RunSpec(profile="file", file=str(tmp_path / "run.csv"))
    names = [n.name for n in describe(GraphOptions(run=run, replay=True))]
    assert "replay" in names and "profile" not in names
    with pytest.raises(LandingGearSimError, match="run file"):
        GraphOptions(replay=True)


def test_all_nodes_of_a_graph_build_the_same_run(tmp_path):
    nodes = describe(GraphOptions(run=RunSpec(profile="constant", pressure_pa=20e5)))
    runs = [{k: v for k, v in n.parameters.items() if k.startswith("run.")} for n in nodes
            if n.name in ("plant", "actuator", "loading_device", "profile")]
    assert all(r == runs[0] for r in runs) and runs[0]["run.pressure_pa"] == 20e5


@pytest.mark.parametrize(("value", "text"), [
    (True, "true"), (2.0, "2.0"), ("osc-low", "'osc-low'"), ("it's", "'it''s'"),
    (["a=1", "b=2"], "['a=1', 'b=2']"), ([], "['']"),
])
def test_parameter_values_are_written_as_ros_reads_them(value, text):
    assert format_value(value) == text
    assert yaml.safe_load(text) == ([""] if value == [] else value)


def test_node_command_runs_the_module_with_the_params_file(tmp_path):
    plant = describe(GraphOptions())[0]
    command = node_command(plant, tmp_path / "p.yaml", "python")
    assert command[:4] == ["python", "-m", "landing_gear_sim.ros.nodes.plant", "--ros-args"]
    assert command[4:8] == ["-r", "__ns:=/rig", "--params-file", str(tmp_path / "p.yaml")]
    assert "clock:='lockstep'" in command


def test_a_second_rig_moves_every_node_and_topic_into_its_namespace():
    nodes = describe(GraphOptions(namespace="lab/rig2"))
    assert {node.namespace for node in nodes} == {"lab/rig2"}
    assert "__ns:=/lab/rig2" in node_command(nodes[0], Path("p.yaml"))
    for bad in ("2rig", "rig-2", "/rig", "rig//2", ""):
        with pytest.raises(LandingGearSimError, match="namespace"):
            GraphOptions(namespace=bad)


def test_the_launcher_leaves_the_users_dds_settings_alone():
    assert "ROS_DOMAIN_ID" not in ros_environment({})
    assert "ROS_AUTOMATIC_DISCOVERY_RANGE" not in ros_environment({})
    user = {"ROS_DOMAIN_ID": "173", "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"}
    assert ros_environment(user).items() >= user.items()


def test_after_the_plant_the_launcher_waits_for_the_nodes_with_work_left():
    """A lost node never ends on its own (a stopped actuator held the launcher 10 s): after
    such a run only the recorder's bag and the nodes publishing for it are waited for (the
    profile, stopped at once, took commands the recorder still lacked along), after a run
    that never started nothing; a stop that came before the plant was started once raised
    KeyError there."""
    def nodes(plant_code: int | None) -> dict:
        return {name: types.SimpleNamespace(returncode=plant_code if name == "plant" else None)
                for name in ("plant", "actuator", "profile", "recorder")}

    for_the_bag = frozenset(n.name for n in describe(GraphOptions(bag=Path("b")))
                            if n.publishes_for_the_bag)
    assert for_the_bag == {"plant", "profile"}
    assert [*_finishing(nodes(0))] == ["plant", "actuator", "profile", "recorder"]
    assert [*_finishing(nodes(LOST_PEER_EXIT), for_the_bag)] == ["plant", "profile", "recorder"]
    assert _finishing(nodes(NOT_STARTED_EXIT)) == {}
    assert [*_finishing({"actuator": nodes(None)["actuator"]})] == ["actuator"]


def test_a_run_is_complete_only_when_every_node_ended_without_an_error():
    """Only the plant's code was looked at: a recorder whose bag lacked part of the run
    (INCOMPLETE_BAG_EXIT) left a run called complete, exit 0."""
    def outcome(**codes: int) -> Outcome:
        return Outcome({"plant": 0, "actuator": 0, "recorder": 0, **codes})

    assert outcome().ok and outcome().failing is None
    assert outcome(recorder=INCOMPLETE_BAG_EXIT).failing == "recorder"
    assert not outcome(recorder=INCOMPLETE_BAG_EXIT).ok
    assert outcome(recorder=-9, plant=LOST_PEER_EXIT).failing == "plant"  # the cause first
    assert not Outcome({"plant": 0}, interrupted=True).ok


@pytest.mark.parametrize("options", [GraphOptions(), GraphOptions(bag=Path("b")),
                                     GraphOptions(run=RunSpec(profile="external"),
                                                  controller="slip", bag=Path("b"))])
def test_no_node_parameter_is_an_empty_list(options):
    """launch_ros refuses an empty list ("got '()' of type tuple"): it has no element type."""
    for node in describe(options):
        assert all(value != [] for value in node.parameters.values()), node.name


def test_launch_arguments_become_graph_options(tmp_path):
    options, params = options_from_arguments({"profile": "osc-high", "clock": "realtime",
                                              "bag": str(tmp_path / "b")})
    assert options.run.profile == "osc-high" and options.clock == "realtime"
    assert params.name == "reference_rig.yaml"
    controlled, _ = options_from_arguments({"controller": "slip"})
    assert controlled.run.profile == "external" and controlled.controller == "slip"
    with pytest.raises(LandingGearSimError, match="clock"):
        options_from_arguments({"clock": "fast"})


# a value other than the default for every option of a session, as a user types it both ways
NOT_DEFAULT = {"clock": ("realtime", "realtime"), "controller": ("slip", "slip"),
               "storage": ("sqlite3", "sqlite3"), "noise": ("--noise", "true"),
               "timeout_s": ("2.5", "2.5"), "start_timeout_s": ("0", "0"),
               "safe_pressure_bar": ("3", "3"), "progress_s": ("0", "0"),
               "namespace": ("lab/rig2", "/lab/rig2"),
               "clock_topic": ("/rig2/clock", "/rig2/clock"),
               "parameter_services": ("--no-parameter-services", "false")}


def test_rig_and_the_launch_file_offer_the_same_options_to_the_same_effect(tmp_path):
    """The launch file offered part of ``rig`` (no timeouts, noise, safe pressure, rate):
    both now come from one table, and each option set either way gives one graph."""
    from landing_gear_sim.cli import build_parser

    assert set(NOT_DEFAULT) == {o.name for o in GRAPH_OPTIONS}
    assert {o.name for o in GRAPH_OPTIONS} | {"rate_hz"} <= set(LAUNCH_ARGUMENTS)
    for name, (flag_value, launch_value) in NOT_DEFAULT.items():
        option = OPTIONS[name]
        argv = [flag_value] if flag_value.startswith("--") else [option.option, flag_value]
        args = build_parser().parse_args(["rig", "--no-bag", "--rate", "500", *argv])
        cli = GraphOptions(run=controlled_run(run_spec_of(args), args.controller),
                           **graph_settings(given(args)))
        launched, _ = options_from_arguments({"profile": "constant", "pressure_bar": "30",
                                              "rate_hz": "500", name: launch_value})
        assert cli == launched, name
        assert cli != GraphOptions(run=cli.run), name  # the option changed something


def test_a_launch_argument_of_the_wrong_type_is_one_clear_error():
    with pytest.raises(GraphError, match="noise must be true or false, got 'maybe'"):
        options_from_arguments({"noise": "maybe"})
    with pytest.raises(GraphError, match="timeout_s must be a number"):
        options_from_arguments({"timeout_s": "soon"})


def test_launch_file_starts_exactly_the_described_nodes(monkeypatch, tmp_path):
    """launch/launch_ros are not on PyPI: stand-ins record what the launch file builds."""
    made: list[dict] = []

    class Record:
        def __init__(self, *args, **kwargs):
            self.args, self.kwargs = args, kwargs

    class Node(Record):
        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            made.append(kwargs)

    class LaunchConfiguration:
        def __init__(self, name):
            self.name = name

        def perform(self, context):
            return context[self.name]

    stubs = {"launch": {"LaunchDescription": lambda items: items},
             "launch.actions": {"DeclareLaunchArgument": Record, "OpaqueFunction": Record,
                                "RegisterEventHandler": Record},
             "launch.event_handlers": {"OnProcessExit": Record},
             "launch.substitutions": {"LaunchConfiguration": LaunchConfiguration},
             "launch_ros": {}, "launch_ros.actions": {"Node": Node}}
    for name, attributes in stubs.items():
        monkeypatch.setitem(sys.modules, name, types.SimpleNamespace(**attributes))
    items = runpy.run_path(str(ROOT / "launch" / "rig.launch.py"))["generate_launch_description"]()
    declared = {item.args[0] for item in items[:-2]}
    assert declared == set(LAUNCH_ARGUMENTS)
    context = {name: default for name, (default, _) in LAUNCH_ARGUMENTS.items()}
    context["bag"] = str(tmp_path / "bag")
    items[-2].kwargs["function"](context)
    options, _ = options_from_arguments(context)
    described = describe(options)
    assert [m["executable"] for m in made] == [n.name for n in described]
    # the node's own parameters as -p arguments: a dict, launch_ros writes to a file it
    # never removes; the params file is the only file
    assert all(len(m["parameters"]) == 1 for m in made)
    given = [_overrides(m["ros_arguments"]) for m in made]
    sessions = {g.pop("run_id") for g in given}
    assert len(sessions) == 1  # one session, every node in it
    assert given == [{k: format_value(v) for k, v in n.parameters.items() if k != "run_id"}
                     for n in described]
    assert all("additional_env" not in m for m in made)  # the user's environment, untouched


def _overrides(arguments: list[str]) -> dict[str, str]:
    """``-p name:=VALUE`` arguments as name -> VALUE text."""
    assert arguments[::2] == ["-p"] * (len(arguments) // 2)
    return dict(argument.split(":=", 1) for argument in arguments[1::2])


def _float64(value: float) -> bytes:
    message = TYPESTORE.types["std_msgs/msg/Float64"](data=value)
    return bytes(TYPESTORE.serialize_cdr(message, "std_msgs/msg/Float64"))


def _values(path: Path) -> list[float]:
    with Reader(path) as reader:
        return [TYPESTORE.deserialize_cdr(raw, c.msgtype).data
                for c, _, raw in reader.messages()]


def _segmented(path: Path, storage: str = "mcap", join: bool = True) -> SegmentedBagWriter:
    writer = SegmentedBagWriter(path, {"/x": "std_msgs/msg/Float64"}, storage, join)
    for k in range(30):
        writer.write("/x", k * 1_000_000, _float64(k))
        if k % 10 == 9:
            writer.roll()
    return writer


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_a_segmented_bag_closes_as_one_file_named_after_the_bag(tmp_path, storage):
    """Single-file viewers (Foxglove, PlotJuggler) open one file; mcap embeds its name."""
    _segmented(tmp_path / "bag", storage).close()
    assert _values(tmp_path / "bag") == list(range(30))
    files = sorted(p.name for p in (tmp_path / "bag").iterdir())
    assert files == [f"bag.{'db3' if storage == 'sqlite3' else 'mcap'}", "metadata.yaml"]
    meta = yaml.safe_load((tmp_path / "bag" / "metadata.yaml").read_text())
    assert meta["rosbag2_bagfile_information"]["relative_file_paths"] == [files[0]]
    assert meta["rosbag2_bagfile_information"]["message_count"] == 30
    if storage == "mcap":  # the metadata inside the file names the file, not a stage
        data = (tmp_path / "bag" / files[0]).read_bytes()
        assert b"bag.mcap" in data and b".open_segment" not in data and b".joining" not in data


@pytest.mark.parametrize("when", ["writer", "close"])
def test_segments_are_kept_when_asked(tmp_path, when):
    """By the writer (``join_segments:=false``) or at one close (a stop that cannot wait
    for the join): the bag is complete all the same."""
    writer = _segmented(tmp_path / "bag", join=when != "writer")
    writer.close(join=when != "close")
    assert _values(tmp_path / "bag") == list(range(30))
    assert len(list((tmp_path / "bag").glob("bag_*"))) == writer.segment_count == 3
    assert not (tmp_path / "bag" / OPEN_SEGMENT).exists()


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_the_join_command_joins_the_segments_a_stopped_recording_kept(tmp_path, storage,
                                                                        capsys):
    from landing_gear_sim.cli import main

    _segmented(tmp_path / "bag", storage).close(join=False)
    assert main(["join", str(tmp_path / "bag")]) == 0
    assert "3 segments joined into one file (30 messages)" in capsys.readouterr().out
    assert _values(tmp_path / "bag") == list(range(30))
    assert sorted(p.name for p in (tmp_path / "bag").iterdir()) == [
        f"bag.{'db3' if storage == 'sqlite3' else 'mcap'}", "metadata.yaml"]
    assert main(["join", str(tmp_path / "bag")]) == 0
    assert "one storage file already (30 messages)" in capsys.readouterr().out


def test_join_recovers_a_segment_that_lost_its_footer_and_says_which(tmp_path, capsys):
    """Issue 62, item 19: join of a bag whose second segment lost its footer failed without
    naming the segment, while metrics recovered the same bag."""
    from landing_gear_sim.cli import main

    _segmented(tmp_path / "bag", "mcap").close(join=False)
    segments = sorted((tmp_path / "bag").glob("*.mcap"))
    second = segments[1]
    second.write_bytes(second.read_bytes()[:-200])  # the footer and summary gone
    assert main(["join", str(tmp_path / "bag")]) == 0
    out = capsys.readouterr()
    assert second.name in out.out + out.err and "recovered" in out.out + out.err, out
    assert _values(tmp_path / "bag") == list(range(30))


def test_the_join_command_refuses_a_folder_that_is_no_bag_in_one_line(tmp_path, capsys):
    from landing_gear_sim.cli import main

    (tmp_path / "notes").mkdir()
    assert main(["join", str(tmp_path / "notes")]) == 2
    error = capsys.readouterr().err
    assert "not a readable rosbag2 folder" in error and len(error.splitlines()) == 1


def test_a_crashed_writer_leaves_a_bag_with_every_closed_segment(tmp_path):
    writer = SegmentedBagWriter(tmp_path / "bag", {"/x": "std_msgs/msg/Float64"})
    for k in range(25):
        writer.write("/x", k * 1_000_000, _float64(k))
        if k % 10 == 9:
            writer.roll()
    # no close(): as after SIGKILL, samples 20-24 are in the open segment only
    assert _values(tmp_path / "bag") == list(range(20))
    segment = next((tmp_path / "bag").glob("bag_0.*")).read_bytes()
    assert b"bag_0.mcap" in segment and b".open_segment" not in segment


def test_a_crash_while_joining_leaves_the_segmented_bag(tmp_path, monkeypatch):
    writer = _segmented(tmp_path / "bag")
    monkeypatch.setattr("msg_tools.bag_segments.os.replace", _fail_on_the_joined_file)
    with pytest.raises(OSError):
        writer.close()
    assert _values(tmp_path / "bag") == list(range(30))


_REPLACE = os.replace


def _fail_on_the_joined_file(source, target):
    if Path(source).parent.parent.name == ".joining":
        raise OSError("disk full")
    _REPLACE(source, target)


def test_an_empty_recording_is_still_a_readable_bag(tmp_path):
    SegmentedBagWriter(tmp_path / "bag", TOPIC_TYPES).close()
    with Reader(tmp_path / "bag") as reader:
        assert reader.message_count == 0
    with pytest.raises(Exception, match="no messages"):
        read_bag(tmp_path / "bag")
