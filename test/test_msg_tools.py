"""Contract CSV and rosbag2 I/O."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from rosbags.rosbag2 import Reader, Writer

from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate
from msg_tools.bag_io import BAG_VERSION, TYPESTORE, write_bag
from msg_tools.bag_read import read_bag
from msg_tools.contract import CSV_COLUMNS, LEGACY_CURRENT_TYPE, TOPIC_CURRENT
from msg_tools.csv_io import read_csv, write_csv
from msg_tools.errors import RunFormatError
from msg_tools.run import SIGNALS


@pytest.fixture(scope="module")
def run(reference):
    noisy = reference.replace({"sensors.pressure_noise_pa": 2e4, "sensors.force_noise_n": 50.0,
                               "rig_test.max_duration_s": 4.0})
    scenario = sc.rig_test(noisy, sc.oscillating(**sc.OSC_LOW))
    result = simulate(noisy, scenario)
    return result.to_run(noise=7)


def test_csv_round_trip_is_exact(tmp_path, run):
    """Values keep 12 significant digits; the text reads and writes back identically."""
    write_csv(run, tmp_path / "run.csv")
    back = read_csv(tmp_path / "run.csv")
    for name in ("time_s", *SIGNALS):
        assert np.allclose(getattr(back, name), getattr(run, name), rtol=1e-11, atol=1e-9), name
    write_csv(back, tmp_path / "again.csv")
    text = (tmp_path / "run.csv").read_text()
    assert (tmp_path / "again.csv").read_text() == text
    assert text.splitlines()[0] == ",".join(CSV_COLUMNS)


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_bag_round_trip_keeps_every_topic(tmp_path, run, storage):
    write_bag(run, tmp_path / "bag", storage)
    back = read_bag(tmp_path / "bag")
    assert np.allclose(back.time_s, run.time_s, rtol=0, atol=1e-9)  # stamps are integer ns
    assert np.array_equal(back.current_a, run.current_a)
    assert np.array_equal(back.wheel_speed_rad_s, run.wheel_speed_rad_s)
    assert np.array_equal(back.longitudinal_force_n, run.longitudinal_force_n)
    # through FluidPressure's absolute pressure: gauge + 1 atm and back
    assert np.allclose(back.pressure_pa, run.pressure_pa, rtol=0, atol=1e-8)


def test_a_runs_messages_serialised_at_once_are_rosbags_own_to_the_bit(run):
    """The fixed layouts of a bag's fast path against rosbags' ``serialize_cdr`` of the
    messages ``contract_messages`` builds, every topic and every sample: times with odd
    nanoseconds and before the epoch, forces of both signs, loads, a current of 0."""
    from msg_tools.bag_io import contract_messages
    from msg_tools.contract import TOPIC_TYPES
    from msg_tools.contract_cdr import contract_rows
    from msg_tools.stamps import ns_of_time

    rng = np.random.default_rng(5)
    n = 300
    odd = dataclasses.replace(
        run.part(slice(0, n), "odd"), time_s=np.sort(rng.uniform(-3.0, 2e3, n)),
        current_a=np.where(rng.random(n) < 0.2, 0.0, rng.normal(0.5, 0.3, n)),
        pressure_pa=rng.uniform(-1e4, 2e7, n), wheel_speed_rad_s=rng.normal(0, 100, n),
        flywheel_speed_rad_s=rng.normal(0, 50, n), vertical_load_n=rng.normal(2e4, 1e4, n),
        longitudinal_force_n=rng.normal(0, 5e3, n))
    for case in (run, odd):
        log_ns, rows = contract_rows(case)
        assert log_ns.tolist() == [ns_of_time(float(t)) for t in case.time_s]
        for k in range(len(case)):
            for topic, message in contract_messages(case, k).items():
                expected = bytes(TYPESTORE.serialize_cdr(message, TOPIC_TYPES[topic]))
                assert rows[topic][k].tobytes() == expected, (topic, k)


def test_a_bag_whose_messages_leave_the_contract_layout_midway_reads_as_message_by_message(
        tmp_path, run, monkeypatch):
    """The reader takes a topic's messages by their layout while they hold its constants:
    where a frame is renamed (same length, then longer), a stamp is left 0 (the log time
    stands in) or a joint logs its angle in place of its speed, those messages go through
    rosbags, in order, and the run is the one reading every message through rosbags gives,
    to the bit. A message of the layout's length with other constants is not the layout's."""
    from msg_tools import bag_read
    from msg_tools.bag_io import contract_messages
    from msg_tools.contract import TOPIC_FLYWHEEL, TOPIC_PRESSURE, TOPIC_TYPES, TOPIC_WHEEL
    from msg_tools.contract_cdr import LAYOUTS

    def altered(k: int) -> dict:
        messages = contract_messages(run, k)
        if 100 <= k < 130:
            messages[TOPIC_WHEEL].header.frame_id = "wheeL"  # same length, other bytes
        if 200 <= k < 210:
            messages[TOPIC_WHEEL].header.frame_id = "wheel_left"
        if k % 7 == 0:
            messages[TOPIC_PRESSURE].header.stamp.sec = 0
            messages[TOPIC_PRESSURE].header.stamp.nanosec = 0
        if k >= len(run) - 50:  # its angle logged in place of its speed
            joint = messages[TOPIC_FLYWHEEL]
            joint.position, joint.velocity = joint.velocity, joint.position
        return messages

    with Writer(tmp_path / "bag", version=BAG_VERSION) as writer:
        connections = {topic: writer.add_connection(topic, kind, typestore=TYPESTORE)
                       for topic, kind in TOPIC_TYPES.items()}
        for k in range(len(run)):
            for topic, message in altered(k).items():
                writer.write(connections[topic], round(float(run.time_s[k]) * 1e9) + 3,
                             TYPESTORE.serialize_cdr(message, TOPIC_TYPES[topic]))
    monkeypatch.setattr(bag_read, "CHUNK", 64)  # chunks that end inside the changes and past
    by_layout = read_bag(tmp_path / "bag")
    monkeypatch.setattr(bag_read, "_by_layout", lambda sources, types: {})
    by_message = read_bag(tmp_path / "bag")
    for name in ("time_s", *SIGNALS):
        assert np.array_equal(getattr(by_layout, name), getattr(by_message, name)), name
    assert by_layout.notes == by_message.notes
    renamed = bytes(TYPESTORE.serialize_cdr(altered(100)[TOPIC_WHEEL], TOPIC_TYPES[TOPIC_WHEEL]))
    assert len(renamed) == LAYOUTS[TOPIC_WHEEL].dtype.itemsize
    assert LAYOUTS[TOPIC_WHEEL].read(renamed) is None
    assert LAYOUTS[TOPIC_WHEEL].read(renamed.replace(b"wheeL", b"wheel")) is not None


def test_existing_bag_is_not_overwritten(tmp_path, run):
    (tmp_path / "bag").mkdir()
    with pytest.raises(RunFormatError, match="exists already"):
        write_bag(run, tmp_path / "bag")


def test_sensor_noise_follows_the_configured_std(reference):
    noisy = reference.replace({"sensors.pressure_noise_pa": 2e4})
    result = simulate(noisy, sc.actuator_test(noisy, sc.constant(0.5), 5.0))
    clean, measured = result.pressure_pa, result.to_run(noise=1).pressure_pa
    assert np.std(measured - clean) == pytest.approx(2e4, rel=0.05)
    assert np.array_equal(result.to_run(1).pressure_pa, measured)  # seeded: reproducible


@pytest.mark.parametrize(("mutate", "fragment"), [
    (lambda lines: [lines[0].replace("brake_pressure_bar", "pressure"), *lines[1:]],
     "missing column"),
    (lambda lines: [lines[0], ",".join([*lines[1].split(",")[:2], "nan",
                                        *lines[1].split(",")[3:]]), *lines[2:]], "NaN"),
    (lambda lines: [lines[0], lines[2], lines[1], *lines[3:]], "not strictly increasing"),
    (lambda lines: [lines[0], "a,b,c,d,e,f,g", *lines[2:]], "has the unit 'a'"),
    (lambda lines: [*lines[:9], "a,b,c,d,e,f,g", *lines[10:]], "unreadable value 'b' at line 10"),
])
def test_bad_csv_gives_one_message_naming_the_file(tmp_path, run, mutate, fragment):
    good = tmp_path / "good.csv"
    write_csv(run, good)
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join(mutate(good.read_text().splitlines())) + "\n")
    with pytest.raises(RunFormatError, match=fragment) as error:
        read_csv(bad)
    assert str(bad) in str(error.value)


def test_wall_clock_time_keeps_microseconds_through_bag_and_csv(tmp_path, run):
    """Real recordings are stamped with epoch time (~1.7e9 s): 12 significant digits kept
    only 10 ms of it (three rows at the same time); every writer keeps 1 µs."""
    stamped = dataclasses.replace(run, time_s=1_700_000_000.0 + run.time_s)
    write_bag(stamped, tmp_path / "bag")
    write_csv(read_bag(tmp_path / "bag"), tmp_path / "from_bag.csv")
    back = read_csv(tmp_path / "from_bag.csv")
    assert np.all(np.diff(back.time_s) > 0)
    assert np.max(np.abs(back.time_s - stamped.time_s)) < 1e-6
    write_bag(back, tmp_path / "again")
    assert np.max(np.abs(read_bag(tmp_path / "again").time_s - stamped.time_s)) < 1e-6


def _renamed(source, target, prefix: str = "", legacy: bool = False) -> None:
    """Copy a bag with its topics as an older graph (0.1: ``joint_state``, the current a
    ``std_msgs/Float64`` at its log time) or another rig (``/rig2/...``) named them."""
    def name(topic: str) -> str:
        topic = topic.removesuffix("s") if legacy and topic.endswith("joint_states") else topic
        return prefix + topic.removeprefix("/rig") if prefix else topic

    def kind(connection) -> str:
        return LEGACY_CURRENT_TYPE if legacy and connection.topic == TOPIC_CURRENT else (
            connection.msgtype)

    with Reader(source) as reader, Writer(target, version=BAG_VERSION) as writer:
        out = {c.topic: writer.add_connection(name(c.topic), kind(c), typestore=TYPESTORE)
               for c in reader.connections}
        for connection, log_time, raw in reader.messages():
            if kind(connection) != connection.msgtype:
                command = TYPESTORE.deserialize_cdr(raw, connection.msgtype)
                raw = TYPESTORE.serialize_cdr(TYPESTORE.types[LEGACY_CURRENT_TYPE](
                    data=float(command.effort[0])), LEGACY_CURRENT_TYPE)
            writer.write(out[connection.topic], log_time, raw)


@pytest.mark.parametrize(("prefix", "legacy"), [("", True), ("/lab/rig2", False)],
                         ids=["joint_state of 0.1", "second rig"])
def test_bags_with_other_names_for_the_contract_topics_read_the_same(tmp_path, run, prefix,
                                                                      legacy):
    write_bag(run, tmp_path / "bag")
    _renamed(tmp_path / "bag", tmp_path / "other", prefix, legacy)
    with Reader(tmp_path / "other") as reader:
        topics = {c.topic: c.msgtype for c in reader.connections}
    assert ("/rig/wheel/joint_state" in topics) == legacy
    assert (LEGACY_CURRENT_TYPE in topics.values()) == legacy
    assert (f"{prefix}/brake/pressure" in topics) == bool(prefix)
    back, again = read_bag(tmp_path / "bag"), read_bag(tmp_path / "other")
    for name in ("time_s", *SIGNALS):
        assert np.array_equal(getattr(back, name), getattr(again, name)), name
