"""The ROS 2 graph for real: separate node processes on a private, machine-local DDS domain."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from graph_support import (
    FIELDS,
    SHORT,
    offline_run,
    product_lines,
    rig_command,
    run_command,
    wait_for,
)
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import Reader

from landing_gear_sim.model.integrate import simulate
from landing_gear_sim.model.parameters import load_parameters
from landing_gear_sim.model.runspec import RunSpec
from landing_gear_sim.ros.graph import load_scenario
from landing_gear_sim.ros.launcher import ros_environment
from msg_tools.bag_read import read_bag
from msg_tools.contract import TOPIC_CURRENT, TOPIC_PRESSURE, TOPIC_WHEEL
from msg_tools.csv_io import format_csv, write_csv
from msg_tools.run import Run

pytest.importorskip("rclpy")

def _pid_of(module: str, launcher: subprocess.Popen) -> int:
    """The node process ``module`` that this launcher started (other tests run graphs too)."""
    found = subprocess.run(["pgrep", "-P", str(launcher.pid), "-f", module],
                           capture_output=True, text=True)
    return int(found.stdout.split()[0])


def _one_by_one(*args: object) -> None:
    raise AssertionError("a message of the graph's bag was read one by one, not by its "
                         "layout: a node's frame or joint name left msg_tools.contract.FRAMES")


def _where_bags_part(first: Path, second: Path) -> str:
    """How many messages each bag holds and the first (topic, log time) where they part."""
    def messages(bag: Path) -> list[tuple[str, int, bytes]]:
        with Reader(bag) as reader:
            return [(c.topic, t, bytes(raw)) for c, t, raw in reader.messages()]

    a, b = messages(first), messages(second)
    shared = zip(a, b, strict=False)  # one may have lost messages
    at = next((i for i, (x, y) in enumerate(shared) if x != y), min(len(a), len(b)))
    return (f"{len(a)} and {len(b)} messages; first difference at message {at}: "
            f"{a[at][:2] if at < len(a) else 'none'} against "
            f"{b[at][:2] if at < len(b) else 'none'}")


def test_lockstep_graph_equals_offline_and_gives_the_same_bag_every_time(tmp_path):
    """The second run also says how far it is every 0.05 s (a long run under load once
    printed nothing for a minute), which changes nothing in its bag."""
    bags = [tmp_path / "first" / "bag", tmp_path / "second" / "bag"]
    recorded = []
    for bag, progress in zip(bags, ("0", "0.05"), strict=True):
        done = run_command(rig_command("--profile", "osc-low", "--bag", str(bag),
                                       "--progress", progress))
        assert done.returncode == 0, done.stderr[-3000:]
        recorded += [line for line in done.stderr.splitlines() if "rig.recorder" in line]
    said = [float(s) for s in re.findall(r"sim (\d+\.\d+) s of up to 1\.50 s \(\d+ %\)",
                                         done.stderr)]
    # a tick may fall on the last step (100 %) on a slow machine
    assert said and said == sorted(said) and said[-1] <= 1.5, done.stderr[-3000:]
    files = [sorted(p.relative_to(bag) for p in bag.iterdir()) for bag in bags]
    assert files[0] == files[1]
    for name in files[0]:
        # twice, in the whole suite on two busy cores, the mcap files differed (one was
        # 98,096 bytes short, 853 commands' worth: test_commands_the_recorder_had_not_...)
        assert (bags[0] / name).read_bytes() == (bags[1] / name).read_bytes(), (
            name, _where_bags_part(*bags), recorded)
    with pytest.MonkeyPatch.context() as patch:  # the nodes publish the contract's frames,
        patch.setattr(AnyReader, "deserialize", _one_by_one)  # so it reads by their layouts
        graph = read_bag(bags[0])
    offline = offline_run(SHORT)
    assert len(graph) == len(offline) == 1500
    for field in FIELDS:  # every recorded topic reads back, equal to round-off
        np.testing.assert_allclose(getattr(graph, field), getattr(offline, field),
                                   rtol=1e-9, atol=1e-6, err_msg=field)
    assert offline.pressure_pa.max() > 30e5  # the run brakes: the comparison means something


def test_sigint_to_the_graph_leaves_a_bag_with_the_run_up_to_the_stop(tmp_path, start):
    bag = tmp_path / "bag"
    long_run = {**SHORT, "rig_test.max_duration_s": 30.0}
    launcher = start(rig_command("--profile", "osc-low", "--bag", str(bag), overrides=long_run))
    wait_for(lambda: (bag / "metadata.yaml").exists())
    launcher.send_signal(signal.SIGINT)
    _, stderr = launcher.communicate(timeout=60)
    assert launcher.returncode == 130, stderr[-2000:]
    _assert_complete(bag, stderr, offline_run(long_run))


def _assert_complete(bag: Path, stderr: str, offline) -> None:
    """The bag is one closed file holding every sample the recorder got, from the first,
    equal to the offline run; no stage or open segment left behind."""
    assert "Traceback" not in stderr and "died" not in stderr, stderr[-3000:]
    closed = re.search(r"bag closed: .* \((\d+) samples", stderr)
    assert closed, stderr[-3000:]
    assert sorted(p.name for p in bag.iterdir()) == ["bag.mcap", "metadata.yaml"]
    stopped = read_bag(bag)
    assert 0 < len(stopped) == int(closed.group(1)) < len(offline)
    np.testing.assert_allclose(stopped.wheel_speed_rad_s,
                               offline.wheel_speed_rad_s[:len(stopped)], rtol=1e-9, atol=1e-6)


@pytest.mark.parametrize("moment", ["starting", "running"])
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_to_the_whole_process_group_stops_everything_cleanly(tmp_path, sig, moment):
    """A terminal's Ctrl-C reaches the launcher and every node at once: the recorder once
    crashed while closing and kept ~1 s of a 7 s run."""
    bag = tmp_path / "bag"
    long_run = {**SHORT, "rig_test.max_duration_s": 30.0}
    launcher = subprocess.Popen(rig_command("--profile", "osc-low", "--bag", str(bag),
                                            overrides=long_run),
                                env=ros_environment(), start_new_session=True, text=True,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        lines = iter(launcher.stderr.readline, "")
        cue = "starting" if moment == "starting" else "run starts"
        seen = next(line for line in lines if cue in line)
        if moment == "running":  # the first segment is closed: hundreds of samples
            wait_for(lambda: (bag / "metadata.yaml").exists())
        os.killpg(launcher.pid, sig)
        _, rest = launcher.communicate(timeout=60)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(launcher.pid, signal.SIGKILL)
    assert launcher.returncode == 130, (seen + rest)[-3000:]
    assert subprocess.run(["pgrep", "-s", str(launcher.pid)]).returncode == 1  # no orphan
    if moment == "running":
        _assert_complete(bag, rest, offline_run(long_run))
    else:
        assert "Traceback" not in rest and not bag.exists(), rest[-3000:]


def test_a_killed_recorder_fails_the_run_at_once_and_leaves_a_readable_bag(tmp_path, start):
    """A participant's death is the run's: the graph stops and `rig` exits 1 naming it (it
    once ran on to a "successful" end without its recorder)."""
    bag = tmp_path / "bag"
    run = {**SHORT, "rig_test.max_duration_s": 30.0}
    launcher = start(rig_command("--profile", "osc-low", "--bag", str(bag), overrides=run))
    wait_for(lambda: (bag / "metadata.yaml").exists() and len(list(bag.glob("bag_*"))) >= 2)
    os.kill(_pid_of("nodes.recorder", launcher), signal.SIGKILL)
    _, stderr = launcher.communicate(timeout=120)
    assert launcher.returncode == 1, stderr[-2000:]
    assert "the run failed (recorder exit code -9)" in stderr, stderr[-2000:]
    survived = read_bag(bag)  # readable as it is, no repair step
    assert survived.time_s[-1] >= 0.5
    np.testing.assert_allclose(survived.pressure_pa, offline_run(run).pressure_pa[:len(survived)],
                               rtol=1e-9, atol=1e-6)


def test_a_killed_actuator_stops_the_graph_at_once_naming_it(tmp_path, start):
    bag = tmp_path / "bag"
    run = {**SHORT, "rig_test.max_duration_s": 30.0}
    launcher = start(rig_command("--profile", "osc-low", "--bag", str(bag), overrides=run))
    wait_for(lambda: (bag / "metadata.yaml").exists())
    os.kill(_pid_of("nodes.actuator", launcher), signal.SIGKILL)
    _, stderr = launcher.communicate(timeout=120)
    assert launcher.returncode == 1, stderr[-2000:]
    assert "node actuator died (exit code -9)" in stderr, stderr[-2000:]
    assert len(read_bag(bag)) < 30000  # stopped, not run on to the end without its valve


def test_a_hung_actuator_neither_hangs_nor_crashes_the_plant(tmp_path, start):
    """A peer alive but silent (stopped, starved): after --timeout the plant holds its
    input at the safe pressure and runs on, so the recorder is still fed; at the end
    neither the plant nor the launcher waits for the lost node."""
    bag = tmp_path / "bag"
    run = {**SHORT, "rig_test.max_duration_s": 4.0}
    launcher = start(rig_command("--profile", "osc-low", "--bag", str(bag), "--timeout", "0.5",
                                 overrides=run))
    wait_for(lambda: (bag / "metadata.yaml").exists())
    os.kill(_pid_of("nodes.actuator", launcher), signal.SIGSTOP)
    _, stderr = launcher.communicate(timeout=120)
    # a participant missing is a failed run, never a success, though the bag is complete
    assert launcher.returncode == 1, stderr[-2000:]
    assert "no input from actuator" in stderr and "plant exit code 3" in stderr
    # it left once --timeout passed without the lost node's acknowledgement; it waited for
    # one until DDS dropped the stopped node, 16 s on, while the launcher waited 10 s more
    assert "not acknowledged by every reader within 0.5 s" in stderr, stderr[-2000:]
    recorded = read_bag(bag)
    assert len(recorded) == 4000  # the plant ran the whole run
    assert recorded.pressure_pa[-1] == 0.0  # the brake went to the safe pressure


# a recorder stopped longer than DDS's lease (20 s) is gone for its peers: a short run keeps
# its stop (a stopped reader slows the run to a real-time factor of ~0.3) well within it
STOPPED = {**SHORT, "rig_test.max_duration_s": 0.8}


def _lines_of(stream) -> list[str]:
    """The lines ``stream`` gives, read by a thread into the list returned, as they come."""
    lines: list[str] = []
    threading.Thread(target=lambda: lines.extend(iter(stream.readline, "")),
                     daemon=True).start()
    return lines


def test_commands_the_recorder_had_not_received_when_the_run_ended_reach_its_bag(tmp_path,
                                                                               start):
    """CI's lockstep bags once differed by 853 current commands: the profile node left at
    the run's end with commands its writer had sent but the recorder had not acknowledged,
    and DDS keeps those only in the writer. A recorder stopped (starved) from the run's
    start to a second after its end is the same, made certain."""
    bag = tmp_path / "bag"
    launcher = start(rig_command("--profile", "osc-low", "--bag", str(bag), overrides=STOPPED))
    lines = _lines_of(launcher.stderr)
    wait_for(lambda: any("run starts" in line for line in lines))
    recorder = _pid_of("nodes.recorder", launcher)
    os.kill(recorder, signal.SIGSTOP)
    try:
        wait_for(lambda: any("run ends" in line for line in lines))
        time.sleep(1.0)  # the profile node had left 0.05 s after the end
    finally:
        os.kill(recorder, signal.SIGCONT)
    assert launcher.wait(timeout=120) == 0, "".join(lines)[-3000:]
    with Reader(bag) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
    assert counts["/rig/brake/current_ref"] == 799, counts
    recorded, offline = read_bag(bag), offline_run(STOPPED)
    for field in FIELDS:
        np.testing.assert_allclose(getattr(recorded, field), getattr(offline, field),
                                   rtol=1e-9, atol=1e-6, err_msg=field)


def test_a_plant_waiting_for_a_starved_recorder_stops_at_once_on_sigint(tmp_path, start):
    """After the run the plant waits for its readers to acknowledge the last samples; rcl's
    wait does not end on a signal: SIGINT then did nothing until the recorder came back,
    and the plant died of its shut context with a traceback (exit 1)."""
    launcher = start(rig_command("--profile", "osc-low", "--bag", str(tmp_path / "bag"),
                                 overrides=STOPPED))
    lines = _lines_of(launcher.stderr)
    wait_for(lambda: any("run starts" in line for line in lines))
    recorder, plant = _pid_of("nodes.recorder", launcher), _pid_of("nodes.plant", launcher)
    os.kill(recorder, signal.SIGSTOP)
    try:
        wait_for(lambda: any("to acknowledge the run's last" in line for line in lines))
        os.kill(plant, signal.SIGINT)
        wait_for(lambda: _gone(plant), timeout_s=5.0)  # it slept in the wait until SIGCONT
    finally:
        os.kill(recorder, signal.SIGCONT)
    launcher.send_signal(signal.SIGINT)  # the rest is the recorder's (its bag lacks the end)
    launcher.wait(timeout=120)
    said = launcher.stdout.read()
    assert "node exit codes: plant 0," in said, said + "".join(lines)[-3000:]
    assert "Traceback" not in "".join(lines), "".join(lines)[-3000:]


def _gone(pid: int) -> bool:
    """Whether process ``pid`` has ended (a zombie its parent has yet to reap included)."""
    state = subprocess.run(["ps", "-o", "stat=", "-p", str(pid)], capture_output=True,
                           text=True).stdout.strip()
    return state == "" or state.startswith("Z")


def test_realtime_graph_follows_the_wall_clock_stamped_in_ros_time(tmp_path):
    bag = tmp_path / "bag"
    started, wall_started = time.monotonic(), time.time()
    done = run_command(rig_command("--profile", "osc-low", "--clock", "realtime",
                                   "--bag", str(bag)))
    assert done.returncode == 0, done.stderr[-3000:]
    recorded = read_bag(bag)
    assert len(recorded) == 1500
    assert time.monotonic() - started > 1.5
    # stamps are the ROS (system) time each sample was due, on the exact grid
    assert wall_started < recorded.time_s[0] < time.time()
    np.testing.assert_allclose(np.diff(recorded.time_s), 1e-3, atol=1e-6)  # float64 at 1.8e9 s
    # the loading device answers within the run. How soon is what the scheduler gives: a
    # few ms on a quiet machine, 0.1-0.5 s measured beside a busy suite, which is also the
    # size of the JIT delay it once had (now compiled before the handshake), so real time
    # cannot tell the two apart and the test asserts only what it can promise
    assert _load_lag_s(recorded, offline_run(SHORT)) < 1.0
    rtf = float(re.search(r"real-time factor ([0-9.]+)", done.stderr).group(1))
    assert rtf <= 1.05  # paced by the wall clock: never faster (slower only if starved)
    assert "real-time pacing: p99 period jitter" in done.stderr  # how well, said at the end


def _load_lag_s(recorded: Run, offline: Run) -> float:
    """How much later the recorded load first reaches half the offline run's final load."""
    half = 0.5 * offline.vertical_load_n[-1]
    first = [int(np.argmax(run.vertical_load_n >= half)) for run in (recorded, offline)]
    assert recorded.vertical_load_n[first[0]] >= half, "the recorded load never rose"
    return (first[0] - first[1]) * 1e-3


def test_a_recorder_waits_for_a_runs_samples_while_they_still_arrive():
    """A recorder on a busy machine had given up 5 s after the run's end with 831 of its
    1500 samples while the rest were still arriving; it waits while messages come, and
    gives up only after END_GRACE_S without one."""
    from landing_gear_sim.ros.nodes.recorder import END_GRACE_S, keeps_waiting

    assert keeps_waiting(4 * 669, quiet_s=0.01)  # 6 s after the end, still arriving
    assert not keeps_waiting(4 * 669, quiet_s=END_GRACE_S + 0.1)  # nothing more came
    assert not keeps_waiting(0, quiet_s=0.0)  # all there


def test_a_recorder_says_what_its_bag_lacks_of_the_run():
    """The bag that lacked 1402 commands came from a recorder that exited 0: a bag short of
    its run is its error now. Sensors have a message a sample; commands need only cover
    the samples (an outside controller at 100 Hz sends one for every ten)."""
    from landing_gear_sim.ros.nodes.recorder import lacks

    whole = {TOPIC_WHEEL: 1500, TOPIC_PRESSURE: 1500}
    assert lacks(1500, whole, uncovered=0) == {}
    assert lacks(None, whole, uncovered=1402) == {}  # stopped before the end was heard
    assert lacks(1500, whole, uncovered=1402) == {TOPIC_CURRENT: 1402}
    assert lacks(1500, {**whole, TOPIC_WHEEL: 1326}, uncovered=0) == {TOPIC_WHEEL: 174}


def test_replay_publishes_a_run_that_the_recorder_writes_back(tmp_path, reference):
    measured = offline_run(SHORT)
    write_csv(measured, tmp_path / "run.csv")
    bag = tmp_path / "bag"
    env = ros_environment()
    node = [sys.executable, "-m"]
    recorder = subprocess.Popen([*node, "landing_gear_sim.ros.nodes.recorder", "--ros-args", "-p",
                                 f"bag:={bag}"], env=env, stderr=subprocess.PIPE, text=True)
    try:
        replay = run_command([*node, "landing_gear_sim.ros.nodes.replay", "--ros-args", "-p",
                              f"file:={tmp_path / 'run.csv'}", "-p", "speed:=5.0",
                              "-p", "wait_for_subscribers:=1"])
        assert replay.returncode == 0, replay.stderr[-2000:]
        try:
            recorder.wait(timeout=60)
        except subprocess.TimeoutExpired:
            # once seen in the whole suite on two busy cores: what the recorder heard says why
            recorder.kill()
            pytest.fail("the recorder did not end 60 s after the replay; its log:\n"
                        + recorder.communicate()[1][-3000:])
    finally:
        recorder.kill()  # no-op once it has left; never outlive the test
        recorder.wait()
    replayed = read_bag(bag)
    assert len(replayed) == len(measured)
    for field in FIELDS:
        np.testing.assert_allclose(getattr(replayed, field), getattr(measured, field),
                                   rtol=1e-9, atol=1e-4, err_msg=field)


def _bad_files(folder: Path) -> dict[str, tuple[Path, str]]:
    good = format_csv(offline_run({"rig_test.max_duration_s": 0.05}))
    header, *rows = good.splitlines()
    cases = {
        "missing": ("", "no such file"),
        "empty": ("", "the file is empty"),
        "header_only": (header + "\n", "no data rows"),
        "no_column": (good.replace("brake_pressure_bar", "pressure"), "missing column"),
        "nan": ("\n".join([header, _with_field(rows[0], 2, "nan"), *rows[1:]]), "NaN"),
        "time_back": ("\n".join([header, rows[1], rows[0], *rows[2:]]), "not strictly increasing"),
        "garbage": ("\x00\x01binary", "no data rows"),
    }
    files = {}
    for name, (text, fragment) in cases.items():
        path = folder / f"{name}.csv"
        if name != "missing":
            path.write_text(text)
        files[name] = (path, fragment)
    return files


def _with_field(row: str, index: int, value: str) -> str:
    fields = row.split(",")
    fields[index] = value
    return ",".join(fields)


def test_replay_of_a_bad_file_is_one_error_line_and_exit_2(tmp_path):
    for name, (path, fragment) in _bad_files(tmp_path).items():
        done = run_command([sys.executable, "-m", "landing_gear_sim.ros.nodes.replay",
                            "--ros-args", "-p", f"file:={path}"], timeout=60)
        lines = product_lines(done.stderr)
        assert done.returncode == 2, (name, done.stderr)
        assert len(lines) == 1 and str(path) in lines[0] and fragment in lines[0], (name, lines)


def test_rig_replay_reruns_a_logged_test_in_the_graph_as_offline(tmp_path):
    """The measured current of a rig log drives the graph; the bag equals the offline re-run."""
    measured = offline_run(SHORT)
    write_csv(measured, tmp_path / "rig_log.csv")
    done = run_command(rig_command("--replay", str(tmp_path / "rig_log.csv"),
                                   "--bag", str(tmp_path / "bag")))
    assert done.returncode == 0, done.stderr[-3000:]
    params = load_parameters(overrides=SHORT)
    rerun = simulate(params, load_scenario(RunSpec(profile="file",
                                                   file=str(tmp_path / "rig_log.csv")),
                                           params)).to_run()
    graph = read_bag(tmp_path / "bag")
    assert len(graph) == len(rerun)
    for field in FIELDS:
        np.testing.assert_allclose(getattr(graph, field), getattr(rerun, field), rtol=1e-9,
                                   atol=1e-6, err_msg=field)
    # and the re-run reproduces the log it came from (same model: to the CSV's digits)
    np.testing.assert_allclose(graph.pressure_pa, measured.pressure_pa, atol=50.0)


@pytest.mark.parametrize("kind", ["threshold", "slip"])
def test_controller_node_in_lockstep_equals_the_offline_closed_loop(tmp_path, kind):
    from antiskid.closed_loop import closed_loop, make_controller

    done = run_command(rig_command("--controller", kind, "--bag", str(tmp_path / "bag")))
    assert done.returncode == 0, done.stderr[-3000:]
    rig = load_parameters(overrides=SHORT)
    offline = closed_loop(rig, make_controller(kind, rig, 1e-3)).to_run()
    graph = read_bag(tmp_path / "bag")
    assert len(graph) == len(offline) == 1500
    assert offline.current_a.max() > 0.3  # the controller did brake in this short run
    for field in FIELDS:
        np.testing.assert_allclose(getattr(graph, field), getattr(offline, field), rtol=1e-9,
                                   atol=1e-6, err_msg=field)


@pytest.mark.parametrize("node", ["plant", "actuator", "recorder"])
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_to_a_lone_node_ends_it_cleanly(tmp_path, start, node, sig):
    """`ros2 run landing_gear_sim plant` then Ctrl-C (or a TERM): exit 0, no traceback."""
    extra = ["-p", f"bag:={tmp_path / 'bag'}"] if node == "recorder" else []
    process = start([sys.executable, "-m", f"landing_gear_sim.ros.nodes.{node}", "--ros-args",
                     *extra])
    deadline = time.monotonic() + 60
    while "running" not in (line := process.stderr.readline()) and time.monotonic() < deadline:
        assert process.poll() is None, line
    process.send_signal(sig)
    _, errors = process.communicate(timeout=30)
    assert process.returncode == 0, errors[-2000:]
    assert "Traceback" not in errors


def test_a_node_whose_parent_is_killed_stops_cleanly_instead_of_running_on(tmp_path):
    """A supervisor's SIGTERM ends `ros2 launch` in milliseconds without its nodes: a node
    whose parent is gone takes it as a stop request (no orphan, the bag complete)."""
    bag, log = tmp_path / "bag", tmp_path / "recorder.log"
    node = f"{sys.executable} -m landing_gear_sim.ros.nodes.recorder --ros-args -p bag:={bag}"
    parent = subprocess.Popen(["sh", "-c", f"{node} 2>{log} & echo $!; wait"],
                              stdout=subprocess.PIPE, text=True)
    child = int(parent.stdout.readline())
    try:
        wait_for(lambda: log.exists() and "running" in log.read_text())
        parent.kill()
        parent.wait()
        wait_for(lambda: not _alive(child), timeout_s=30)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.kill(child, signal.SIGKILL)
    assert "Traceback" not in log.read_text()
    assert (bag / "metadata.yaml").exists()


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie has ended: its stat state is Z)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def _wait_until_running(process: subprocess.Popen) -> None:
    deadline = time.monotonic() + 60
    while "running" not in (line := process.stderr.readline()) and time.monotonic() < deadline:
        assert process.poll() is None, line


def test_a_running_node_answers_ros2_param_and_refuses_changes_with_the_reason(start):
    """`ros2 param list/get/set` on a node of the graph (it once served no services)."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from rclpy.parameter_client import AsyncParameterClient

    plant = start([sys.executable, "-m", "landing_gear_sim.ros.nodes.plant", "--ros-args",
                   "-p", "friction.theta1:=1.1"])
    _wait_until_running(plant)
    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        node = rclpy.create_node("param_probe", context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        client = AsyncParameterClient(node, "/rig/plant")
        assert client.wait_for_services(timeout_sec=30)

        def call(future):
            executor.spin_until_future_complete(future, timeout_sec=30)
            assert future.done()
            return future.result()

        names = call(client.list_parameters()).result.names
        assert {"friction.theta1", "run.profile", "clock", "timeout_s"} <= set(names)
        assert call(client.get_parameters(["friction.theta1"])).values[0].double_value == 1.1
        bad, valid = (call(client.set_parameters([Parameter("friction.theta1", value=v)]))
                      .results[0] for v in (-1.0, 1.2))
        assert not bad.successful and not valid.successful
        assert "read-only" in bad.reason and "read-only" in valid.reason
        assert call(client.get_parameters(["friction.theta1"])).values[0].double_value == 1.1
        # issue 31: the descriptors say what a value may be and that it is fixed for the run
        theta1, timeout, priority, offset = call(client.describe_parameters(
            ["friction.theta1", "timeout_s", "realtime_priority",
             "sensors.pressure_offset_pa"])).descriptors
        assert theta1.read_only and "restart the node" in theta1.additional_constraints
        assert theta1.floating_point_range[0].from_value == 0.0
        assert timeout.floating_point_range[0].from_value == 0.0
        assert (priority.integer_range[0].from_value, priority.integer_range[0].to_value) == \
            (0, 99)
        assert offset.read_only and not offset.floating_point_range  # an offset has a sign
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)
    plant.send_signal(signal.SIGINT)
    assert plant.wait(timeout=30) == 0


def test_a_misspelt_parameter_stops_the_node_with_the_closest_name(tmp_path):
    plant = run_command([sys.executable, "-m", "landing_gear_sim.ros.nodes.plant",
                         "--ros-args", "-p", "run.profil:=steps"])
    assert plant.returncode == 2
    assert plant.stderr.strip().splitlines()[-1] == (
        "plant: error: unknown parameter 'run.profil' (did you mean 'run.profile'?)")
    params = tmp_path / "params.yaml"  # the rig's keys for every node are no typo
    params.write_text("/**:\n  ros__parameters:\n    friction.theta1: 1.0\n"
                      "    run.profile: steps\n    segmentt_s: 1.0\n")
    recorder = run_command([sys.executable, "-m", "landing_gear_sim.ros.nodes.recorder",
                            "--ros-args", "--params-file", str(params),
                            "-p", f"bag:={tmp_path / 'bag'}"])
    assert recorder.returncode == 2
    assert recorder.stderr.strip().splitlines()[-1] == (
        "recorder: error: unknown parameter 'segmentt_s' (did you mean 'segment_s'?)")
    assert not (tmp_path / "bag").exists()  # refused before the bag folder is made
    plant = run_command([sys.executable, "-m", "landing_gear_sim.ros.nodes.plant",
                         "--ros-args", "-p", "friction.theta1:=-1.0"])
    assert plant.returncode == 2 and "Traceback" not in plant.stderr, plant.stderr
    assert plant.stderr.strip().splitlines()[-1].startswith(
        "plant: error: friction.theta1 = -1.0 is out of its range [0, "), plant.stderr


def test_two_rigs_share_a_domain_each_in_its_namespace(tmp_path, start):
    """`--namespace` moves every node and topic (start/stop handshake included): two rigs
    on one domain run the same profile at once and each records exactly its own run; with
    `--clock-topic` each its own clock, so a sim-time listener of one sees time go one way
    (on a shared /clock one saw 2,389 backward jumps in 7,151 messages)."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rosgraph_msgs.msg import Clock

    context = rclpy.Context()
    rclpy.init(context=context)
    heard: list[float] = []
    try:
        listener = rclpy.create_node("sim_time_listener", context=context)
        listener.create_subscription(Clock, "/rig_a/clock", lambda m: heard.append(
            m.clock.sec + 1e-9 * m.clock.nanosec), 1000)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(listener)
        rigs = {name: start(rig_command("--profile", "osc-low", "--namespace", name, "--bag",
                                        str(tmp_path / name), "--clock-topic", f"/{name}/clock"))
                for name in ("rig_a", "lab/rig_b")}
        while any(process.poll() is None for process in rigs.values()):
            executor.spin_once(timeout_sec=0.05)
    finally:
        rclpy.shutdown(context=context)
    for process in rigs.values():
        _, errors = process.communicate(timeout=180)
        assert process.returncode == 0, errors[-3000:]
    assert len(heard) > 100 and all(np.diff(heard) >= 0), (len(heard), heard[:20])
    offline = offline_run(SHORT)
    for name in rigs:
        bag = tmp_path / name
        with Reader(bag) as reader:
            assert {c.topic for c in reader.connections} == {
                f"/{name}/{topic}" for topic in ("brake/current_ref", "brake/pressure",
                                                 "wheel/joint_states", "flywheel/joint_states",
                                                 "load_cell/wrench")}
        graph = read_bag(bag)
        assert len(graph) == len(offline) == 1500  # one run each: no sample of the other
        np.testing.assert_allclose(graph.wheel_speed_rad_s, offline.wheel_speed_rad_s,
                                   rtol=1e-9, atol=1e-6)


def test_a_second_run_on_a_rig_in_use_refuses_to_start_and_leaves_the_first_alone(
        tmp_path, start):
    """A second `rig` on the namespace and domain of a running one (or of nodes left over
    from one) once took the other run's nodes as its own: their ready messages started it
    and their messages mixed in. Each session has an identity; the plant starts only with
    nodes of its own, and ends nothing of the other run."""
    first = start(rig_command("--profile", "constant", "--pressure-bar", "5", "--clock",
                              "realtime", "--bag", str(tmp_path / "first"),
                              overrides={**SHORT, "rig_test.max_duration_s": 60.0}))
    wait_for(lambda: (tmp_path / "first" / "metadata.yaml").exists(), 120)
    second = run_command(rig_command("--profile", "osc-low", "--no-bag"), timeout=180)
    assert second.returncode != 0, second.stderr[-2000:]
    assert "of another run" in second.stderr and "plant exit code 4" in second.stderr, \
        second.stderr[-2000:]
    # its actuator heard the first run's commands, stamped in wall time: it once stepped
    # towards them (~1.7e12 steps) until the stop, then died with a traceback
    assert "Traceback" not in second.stderr, second.stderr[-3000:]
    assert first.poll() is None  # still running: no run end reached it


def test_a_command_topic_remapped_on_its_source_and_the_actuator_is_found(tmp_path):
    """`-r brake/current_ref:=brake/cmd` on the profile and the actuator, as ROS users remap:
    the plant finds the command source through the graph (it once looked the literal name up
    and refused to start, exit 4)."""
    from landing_gear_sim.ros.graph import describe, options_from_arguments
    from landing_gear_sim.ros.launcher import node_command

    params_file = tmp_path / "short.yaml"
    load_parameters(overrides=SHORT).to_yaml(params_file)
    options, _ = options_from_arguments({"profile": "osc-low"})
    remap = ["-r", "brake/current_ref:=brake/cmd"]
    commands = {node.name: node_command(node, params_file)
                + (remap if node.name in ("profile", "actuator") else [])
                for node in describe(options)}
    processes = {name: subprocess.Popen(command, env=ros_environment(), text=True,
                                        stderr=subprocess.PIPE)
                 for name, command in commands.items()}
    try:
        _, plant_errors = processes["plant"].communicate(timeout=180)
        for process in processes.values():
            process.communicate(timeout=60)  # the run's end reaches every node
    finally:
        for process in processes.values():
            if process.poll() is None:
                process.kill()
    assert processes["plant"].returncode == 0, plant_errors[-2000:]
    assert "run ends after 1500 samples" in plant_errors
    assert all(p.returncode == 0 for p in processes.values())


def test_a_stop_by_a_signal_joins_the_bag_only_while_that_is_quick():
    """A 300 s run's join (1.5 M messages) outlasted launch's SIGKILL on a busy machine, and
    launch called the stopped run failed: a long bag stopped by a signal keeps its
    segments; one that ends on its own is always joined."""
    from landing_gear_sim.ros.nodes.recorder import JOIN_ON_STOP_MESSAGES, joins_on_close

    assert joins_on_close(stopped=False, messages=1_500_000)
    assert joins_on_close(stopped=True, messages=JOIN_ON_STOP_MESSAGES)
    assert not joins_on_close(stopped=True, messages=JOIN_ON_STOP_MESSAGES + 1)


def test_the_profile_node_starts_without_the_compiled_model():
    """It publishes a current profile and stamps its steps: numba and scipy's linear algebra
    are the plant's and the valve's to load (they had been 0.4 of its 0.7 s import, in
    every graph run, through the steps' clock)."""
    code = ("import sys; import landing_gear_sim.ros.nodes.profile; "
            "print(sorted({m for m in sys.modules} & {'numba', 'scipy.linalg'}))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            cwd=Path(__file__).resolve().parents[1], check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"
