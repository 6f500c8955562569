"""Reading runs from other layouts and bad files: one clear message naming the file."""

from __future__ import annotations

import dataclasses
import math
import shutil
import sqlite3
from pathlib import Path

import numpy as np
import pytest

from landing_gear_sim.cli import main
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate
from msg_tools.bag_io import write_bag
from msg_tools.csv_io import format_csv, read_csv, read_mapping, write_csv
from msg_tools.errors import RunFormatError
from msg_tools.io import read_campaign, read_run, resample
from msg_tools.run import SIGNALS, Run
from msg_tools.units import RPM_RAD_S

MAPPING = """
time_s: {column: t_ms, unit: ms}
current_ref_A: {column: I_valve, unit: mA}
brake_pressure_bar: {column: p_brake, unit: psi}
wheel_speed_rad_s: {column: n_wheel, unit: rpm}
flywheel_speed_rad_s: {column: n_fly, unit: rpm}
vertical_load_N: {column: Fz, unit: kN}
longitudinal_force_N: {column: Fx, unit: kN}
"""


@pytest.fixture(scope="module")
def run(reference):
    params = reference.replace({"rig_test.max_duration_s": 3.0, "sensors.force_noise_n": 50.0})
    return simulate(params, sc.rig_test(params, sc.oscillating(**sc.OSC_LOW))).to_run(3)


@pytest.fixture()
def csv_file(tmp_path, run):
    path = tmp_path / "run.csv"
    write_csv(run, path)
    return path


def test_mapped_layout_with_other_units_reads_as_the_contract(tmp_path, run):
    rpm, psi = 2 * math.pi / 60, 6894.757293168361
    columns = {"t_ms": run.time_s * 1e3, "I_valve": run.current_a * 1e3,
               "p_brake": run.pressure_pa / psi, "n_wheel": run.wheel_speed_rad_s / rpm,
               "n_fly": run.flywheel_speed_rad_s / rpm, "Fz": run.vertical_load_n / 1e3,
               "Fx": run.longitudinal_force_n / 1e3}
    path = tmp_path / "other.csv"
    table = np.column_stack(list(columns.values()))
    np.savetxt(path, table, delimiter=",", header=",".join(columns), comments="", fmt="%.15g")
    (tmp_path / "map.yaml").write_text(MAPPING)
    back = read_csv(path, mapping=read_mapping(tmp_path / "map.yaml"))
    assert np.allclose(back.pressure_pa, run.pressure_pa, rtol=1e-12, atol=1e-6)
    assert np.allclose(back.wheel_speed_rad_s, run.wheel_speed_rad_s, rtol=1e-12, atol=1e-9)
    assert np.allclose(back.time_s, run.time_s, rtol=1e-12, atol=1e-12)


def test_mapping_with_an_unknown_unit_is_refused(tmp_path):
    (tmp_path / "map.yaml").write_text(MAPPING.replace("unit: psi", "unit: atm"))
    with pytest.raises(RunFormatError, match=r"unit 'atm' of brake_pressure_bar"):
        read_mapping(tmp_path / "map.yaml")


def test_a_bag_field_with_unquoted_brackets_is_refused_with_the_fix(tmp_path):
    """`field: velocity[wheel]` inside {…} is not YAML (the data contract once showed it)."""
    (tmp_path / "map.yaml").write_text(
        "wheel_speed_rad_s: {topic: /joint_states, field: velocity[wheel]}\n")
    with pytest.raises(RunFormatError, match=r'quote a field with brackets: field: "velocity'):
        read_mapping(tmp_path / "map.yaml")


def test_pressure_in_pa_declared_as_bar_is_caught(tmp_path, run):
    text = format_csv(run).splitlines()
    header = text[0].split(",")
    k = header.index("brake_pressure_bar")
    rows = [row.split(",") for row in text[1:]]
    for row in rows:
        row[k] = repr(float(row[k]) * 1e5)
    path = tmp_path / "pa.csv"
    path.write_text("\n".join([text[0], *(",".join(r) for r in rows)]) + "\n")
    with pytest.raises(RunFormatError, match=r"pa\.csv: pressure_pa reaches .* bar, implausible"):
        read_csv(path)


@pytest.mark.parametrize(("edit", "fragment"), [
    (lambda rows: [*rows[:10], rows[10], *rows[10:]], "duplicated time"),
])
def test_broken_time_base_is_named(tmp_path, csv_file, edit, fragment):
    lines = csv_file.read_text().splitlines()
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join([lines[0], *edit(lines[1:])]) + "\n")
    with pytest.raises(RunFormatError, match=fragment) as error:
        read_csv(bad)
    assert str(bad) in str(error.value)


def test_a_lone_run_with_a_long_gap_is_read_but_not_bridged(tmp_path, csv_file):
    """Gaps are data: converting keeps them; a tool that needs one sample period bridges a
    logger's dropout of up to 0.1 s (interpolated, and not compared with a simulation) and
    says why it cannot use a run with a longer one (a campaign reader splits it,
    test_identify)."""
    from landing_gear_sim.calibration.runs import classified

    lines = csv_file.read_text().splitlines()
    gappy = tmp_path / "gappy.csv"
    gappy.write_text("\n".join([lines[0], *lines[1:101], *lines[151:]]) + "\n")
    run = read_csv(gappy)
    assert len(run) == len(lines) - 51
    bridged = classified(run)
    assert len(bridged) == len(lines) - 1 and bridged.bridged.sum() == 50
    assert not bridged.compared[100:150].any() and bridged.compared[:100].all()
    longer = tmp_path / "longer.csv"
    longer.write_text("\n".join([lines[0], *lines[1:101], *lines[251:]]) + "\n")
    with pytest.raises(RunFormatError, match=r"longer: 0.15 s missing after t = .*too long"):
        classified(read_csv(longer))


def test_bag_missing_a_topic_is_named(tmp_path, run):
    """A topic a run cannot be read without (the load cell's may be lacking, as a CSV's
    load columns may: issue 62)."""
    from rosbags.rosbag2 import Writer

    from msg_tools.bag_io import BAG_VERSION, TYPESTORE, contract_messages
    from msg_tools.contract import TOPIC_PRESSURE, TOPIC_TYPES

    path = tmp_path / "partial"
    with Writer(path, version=BAG_VERSION) as writer:
        connections = {t: writer.add_connection(t, m, typestore=TYPESTORE)
                       for t, m in TOPIC_TYPES.items() if t != TOPIC_PRESSURE}
        for k in range(20):
            for topic, message in contract_messages(run, k).items():
                if topic in connections:
                    writer.write(connections[topic], k * 1_000_000,
                                 TYPESTORE.serialize_cdr(message, TOPIC_TYPES[topic]))
    with pytest.raises(RunFormatError, match=r"partial: bag has no messages on /rig/brake/pres"):
        read_run(path)


@pytest.mark.parametrize("damage", ["empty", "truncated"])
def test_empty_or_truncated_bag_is_an_error_not_a_traceback(tmp_path, run, damage):
    path = tmp_path / "bag"
    write_bag(run, path, "sqlite3")
    database = next(path.glob("*.db3"))
    if damage == "empty":
        database.write_bytes(b"")
    else:
        database.write_bytes(database.read_bytes()[:2048])
    with pytest.raises(RunFormatError, match="bag"):
        read_run(path)


def _killed_recorder(run, tmp_path, journal: str) -> Path:
    """A sqlite3 bag as a recorder killed mid-write leaves it: copies of its files taken
    while the writer still held the database open. ``wal``: the second half of the
    messages committed into a write-ahead log not yet checkpointed; ``rollback``: a
    transaction deleting that half under way, its pages already in the database file
    (a small page cache spills them), the hot journal beside it."""
    source, copy = tmp_path / "recording", tmp_path / "copy"
    write_bag(run, source, "sqlite3")
    database = next(source.glob("*.db3"))
    connection = sqlite3.connect(database, isolation_level=None)
    middle = "timestamp > (SELECT (MIN(timestamp) + MAX(timestamp)) / 2 FROM messages)"
    if journal == "wal":
        rows = connection.execute(f"SELECT * FROM messages WHERE {middle}").fetchall()
        connection.execute(f"DELETE FROM messages WHERE {middle}")
        connection.execute("PRAGMA journal_mode=WAL")
        connection.execute("PRAGMA wal_autocheckpoint=0")
        connection.executemany("INSERT INTO messages VALUES (?, ?, ?, ?)", rows)
    else:
        connection.execute("PRAGMA cache_size=1")
        connection.execute("BEGIN")
        connection.execute(f"DELETE FROM messages WHERE {middle}")
    shutil.copytree(source, copy)
    connection.close()
    return copy


def test_a_bag_whose_messages_sit_in_its_write_ahead_log_is_read_whole(tmp_path, run):
    """A sqlite3 bag's last messages in an un-checkpointed `-wal` were read as a run of
    half the length, exit 0 (rosbags opens the database immutable and never sees the
    log). sqlite applies the log when it opens the database; done on a copy, the user's
    files stay as they were."""
    bag = _killed_recorder(run, tmp_path, "wal")
    files = {p.name: p.read_bytes() for p in bag.iterdir()}
    recovered = read_run(bag)
    assert len(recovered) == len(run)
    assert any("write-ahead log" in note for note in recovered.notes), recovered.notes
    assert {p.name: p.read_bytes() for p in bag.iterdir()} == files


def test_a_bag_with_a_hot_journal_is_rolled_back_not_refused(tmp_path, run):
    """A recorder killed inside a transaction leaves a hot `-journal`: the database file
    read as it lies was 'malformed'. Rolled back as sqlite does, the run is what was
    committed."""
    recovered = read_run(_killed_recorder(run, tmp_path, "rollback"))
    assert len(recovered) == len(run)
    assert any("unfinished transaction" in note for note in recovered.notes), recovered.notes


def test_a_bag_that_lost_messages_says_how_many_of_those_its_metadata_counts(tmp_path, run):
    """metadata.yaml counts every message the recorder wrote; a storage file that holds
    fewer (cut, or restored from an older copy) was read as a shorter run, exit 0."""
    path = tmp_path / "bag"
    write_bag(run, path, "sqlite3")
    with sqlite3.connect(next(path.glob("*.db3"))) as connection:
        connection.execute("DELETE FROM messages WHERE timestamp > "
                           "(SELECT MIN(timestamp) + 2000000000 FROM messages)")
    recovered = read_run(path)
    assert len(recovered) < len(run)
    lost = len(run) - len(recovered)
    assert any(f"{len(recovered)} of the {len(run)} messages" in note and f"{lost} lost" in note
               for note in recovered.notes), recovered.notes


@pytest.mark.parametrize("kept", [0.6, 0.95])
def test_an_mcap_cut_short_gives_every_complete_message_and_says_what_was_lost(tmp_path, run,
                                                                              kept):
    """A recorder killed mid-write leaves an mcap without its footer: 'File end magic is
    invalid', nothing read, even at 95 % of the file. Every complete message is read (of
    the chunk cut through as well), the run is what they hold, and the note says how many
    of the messages metadata.yaml counts were lost."""
    path = tmp_path / "bag"
    write_bag(run, path, "mcap")
    storage = next(path.glob("*.mcap"))
    whole = storage.read_bytes()
    storage.write_bytes(whole[:int(kept * len(whole))])
    recovered = read_run(path)
    # the file ends with its index: a cut at 60 % keeps more than 60 % of the messages
    assert 0.9 * kept * len(run) < len(recovered) < len(run)
    np.testing.assert_allclose(recovered.time_s, run.time_s[:len(recovered)], atol=1e-9)
    assert any("cut short" in note for note in recovered.notes), recovered.notes
    assert any(f"{len(recovered)} of the {len(run)} messages" in note and "lost" in note
               for note in recovered.notes), recovered.notes
    assert storage.read_bytes() == whole[:int(kept * len(whole))]


def test_campaign_skips_a_bad_file_and_keeps_the_rest(tmp_path, csv_file):
    # another run than csv_file's: a byte-identical copy is read once (issue 62)
    lines = csv_file.read_text().splitlines(keepends=True)
    (tmp_path / "good.csv").write_text("".join(lines[:-1]))
    (tmp_path / "bad.csv").write_text("time_s\n1\n")
    campaign = read_campaign(tmp_path)
    assert [r.name for r in campaign.runs] == ["good", "run"]
    assert len(campaign.problems) == 1 and "bad.csv" in campaign.problems[0]


def test_convert_round_trip_csv_bag_csv_is_exact(tmp_path, csv_file, capsys):
    assert main(["convert", str(csv_file), str(tmp_path / "bag")]) == 0
    assert main(["convert", str(tmp_path / "bag"), str(tmp_path / "back.csv")]) == 0
    assert (tmp_path / "back.csv").read_text() == csv_file.read_text()
    assert main(["convert", str(csv_file), str(tmp_path / "back.csv")]) == 2
    assert "exists already" in capsys.readouterr().err


def test_resample_puts_a_run_on_a_uniform_base(run):
    jittered = run.__class__(**{**run.__dict__, "time_s": run.time_s + np.r_[
        0, np.full(len(run) - 2, 2e-5), 0]})
    uniform = resample(jittered, 1000.0)
    assert np.allclose(np.diff(uniform.time_s), 1e-3)
    assert np.allclose(uniform.wheel_speed_rad_s, run.wheel_speed_rad_s[:len(uniform)],
                       atol=0.05)


def test_a_long_text_run_whose_column_two_channels_read_is_read_once_per_channel(
        tmp_path, run, monkeypatch):
    """The streamed reader makes the run of its columns in place (a long file's peak
    memory): a column two channels read, each in its own unit, is converted for each."""
    import msg_tools.text_stream

    path = tmp_path / "shared.csv"
    write_csv(run, path)
    (tmp_path / "map.yaml").write_text(
        "wheel_speed_rad_s: {column: flywheel_speed_rad_s, unit: rpm}\n")
    reads = []
    for threshold in (10**12, 1):  # whole, then streamed
        monkeypatch.setattr(msg_tools.text_stream, "LARGE_BYTES", threshold)
        reads.append(read_csv(path, mapping=read_mapping(tmp_path / "map.yaml")))
    whole, streamed = reads
    for field in ("wheel_speed_rad_s", "flywheel_speed_rad_s"):
        np.testing.assert_array_equal(getattr(streamed, field), getattr(whole, field))
    np.testing.assert_array_equal(streamed.wheel_speed_rad_s,
                                  streamed.flywheel_speed_rad_s * RPM_RAD_S)


def test_compare_cli_scores_a_simulation_against_itself(tmp_path, csv_file, capsys):
    assert main(["compare", str(csv_file), str(csv_file), "--plot",
                 str(tmp_path / "c.png")]) == 0
    out = capsys.readouterr().out
    assert "wheel speed" in out and "100.00" in out


def test_compare_prints_errors_in_the_units_of_its_plot(tmp_path, csv_file, capsys):
    """Issue 32: RMSE in Pa and N on the terminal, bar and kN on the plot."""
    shifted = tmp_path / "shifted.csv"
    run = read_csv(csv_file)
    write_csv(dataclasses.replace(run, pressure_pa=run.pressure_pa + 0.5e5), shifted)
    assert main(["compare", str(shifted), str(csv_file), "--plot",
                 str(tmp_path / "c.png")]) == 0
    pressure = next(line for line in capsys.readouterr().out.splitlines()
                    if line.lstrip().startswith("brake pressure"))
    assert "0.5 bar" in pressure and "kN" not in pressure
    assert "× noise: FAIL" in pressure  # issue 63: a 0.5 bar offset is beyond the noise


LAYOUTS = {
    "the contract": lambda text: text,
    "a preamble, a units row and semicolons": lambda text: "Logger: DL-7\nRig: A2\n"
    + text.replace(",", ";").replace("\n", "\ns;A;bar;rad/s;rad/s;N;N\n", 1),
    "Windows line ends and a BOM": lambda text: "\ufeff" + text.replace("\n", "\r\n"),
    "a last line cut short": lambda text: text[:-20],
    "a decimal comma": lambda text: text.replace(",", ";").replace(".", ","),
    "a footer": lambda text: text + "end of log\n",
    "an unreadable value deep down": lambda text: text[:len(text) * 2 // 3] + "x" + text[
        len(text) * 2 // 3 + 1:],
    "blank lines among the data": lambda text: text.replace("\n", "\n\n", 40),
}


STREAMED = [LAYOUTS[k] for k in ("the contract", "a preamble, a units row and semicolons",
                                  "Windows line ends and a BOM", "blank lines among the data")]


@pytest.mark.parametrize("layout", LAYOUTS.values(), ids=LAYOUTS.keys())
def test_a_long_text_run_read_from_the_open_file_is_the_run_read_whole(tmp_path, run,
                                                                        monkeypatch, layout):
    """A long CSV is read without its text in memory (an hour at 1 kHz took ~1 GB to read,
    2.2 GB to convert): the same run, the same notes and the same error as the whole text
    gives, whatever the layout."""
    import msg_tools.text_stream

    path = tmp_path / "long.csv"
    path.write_text(layout(format_csv(run)), encoding="utf-8", newline="")
    outcomes: list[Run | str] = []
    whole_texts = []
    read_text = msg_tools.text_stream.read_text
    monkeypatch.setattr(msg_tools.text_stream, "read_text",
                        lambda p: whole_texts.append(p) or read_text(p))
    monkeypatch.setattr(msg_tools.text_stream, "CHUNK_ROWS", 7)  # chunks end anywhere
    for threshold in (10**12, 1):
        monkeypatch.setattr(msg_tools.text_stream, "LARGE_BYTES", threshold)
        try:
            outcomes.append(read_csv(path))
        except RunFormatError as exc:
            outcomes.append(str(exc))
    whole, streamed = outcomes
    # the layouts the first and last lines show are read from the file, not as text
    assert len(whole_texts) == (1 if layout in STREAMED else 2)
    if isinstance(whole, str):
        assert streamed == whole
        return
    assert isinstance(streamed, Run)
    for field in dataclasses.fields(whole):
        a, b = getattr(whole, field.name), getattr(streamed, field.name)
        if isinstance(a, np.ndarray):
            np.testing.assert_array_equal(a, b, err_msg=field.name)
        else:
            assert a == b, field.name


def test_compare_puts_a_log_at_another_rate_on_the_simulations_time_base(tmp_path, csv_file,
                                                                          capsys):
    """Issue 43: a 100 Hz log against a 1 kHz simulation was compared sample by sample (the
    simulated trace stretched ten times, fits of −65 to −117 %)."""
    slow = tmp_path / "slow.csv"
    write_csv(resample(read_csv(csv_file), 100.0), slow)
    assert main(["compare", str(slow), str(csv_file), "--plot", str(tmp_path / "c.png")]) == 0
    out = capsys.readouterr()
    wheel = next(line for line in out.out.splitlines()
                 if line.lstrip().startswith("wheel speed"))
    assert float(wheel.split()[2]) > 95.0
    assert "100 Hz" in out.err and "1000 Hz" in out.err


def test_compare_says_it_scores_only_the_span_both_runs_cover(tmp_path, csv_file, capsys):
    run = read_csv(csv_file)
    shorter = tmp_path / "shorter.csv"
    write_csv(run.part(slice(0, len(run) // 2), run.name), shorter)
    assert main(["compare", str(csv_file), str(shorter), "--plot", str(tmp_path / "c.png")]) == 0
    out = capsys.readouterr()
    assert "compared over the first 1.5 s" in out.err
    assert "100.00" in out.out


@pytest.mark.parametrize("command", ["compare", "validate"])
def test_a_pressure_logged_in_mpa_is_named_before_any_score(tmp_path, csv_file, command,
                                                             capsys):
    """Issue 43: compare and validate gave fits of −1800 % to −600,000 % on a pressure in MPa
    under a bar header with no hint (metrics named MPa on the same file)."""
    folder = tmp_path / "campaign"
    folder.mkdir()
    run = read_csv(csv_file)
    write_csv(dataclasses.replace(run, pressure_pa=run.pressure_pa / 10.0),
              folder / "brake_osc_low.csv")  # MPa numbers in the bar column
    given = [str(folder / "brake_osc_low.csv"), str(csv_file), "--plot",
             str(tmp_path / "c.png")] if command == "compare" else [
        str(folder), "--report", str(tmp_path / "report")]
    assert main([command, *given]) == 2
    err = capsys.readouterr().err
    assert "brake_pressure_bar" in err and "MPa" in err and "Traceback" not in err


def test_a_folder_linking_to_itself_is_read_once(tmp_path, csv_file):
    """Issue 43: validate recursed 82 runs deep into a symlink to the folder itself and died
    on 'File name too long' after writing 81 files."""
    folder = tmp_path / "campaign"
    folder.mkdir()
    shutil.copy(csv_file, folder / "brake_osc_low.csv")
    (folder / "again").symlink_to(folder, target_is_directory=True)
    campaign = read_campaign(folder)
    assert [r.name for r in campaign.runs] == ["brake_osc_low"]
    assert any("again" in p and "already read" in p for p in campaign.problems)


def test_validate_says_which_files_of_a_campaign_it_skipped(tmp_path, csv_file, capsys):
    """Issue 43: validate dropped three unreadable files without a word (identify lists
    them)."""
    folder = tmp_path / "campaign"
    folder.mkdir()
    shutil.copy(csv_file, folder / "brake_osc_low.csv")
    (folder / "brake_const_20bar.csv").write_text("time_s,current_ref_A\n0,1\n")
    assert main(["validate", str(folder), "--report", str(tmp_path / "report")]) == 0
    err = capsys.readouterr().err
    assert "skipped" in err and "brake_const_20bar.csv" in err


def test_a_log_that_changes_its_rate_says_so_when_read(tmp_path, csv_file):
    """Issue 43: a log switching from 1 kHz to 500 Hz was resampled at its mean rate with no
    note (slip rms +15 %)."""
    run = read_csv(csv_file)
    half = len(run) // 2
    keep = np.r_[0:half, half:len(run):2]
    write_csv(dataclasses.replace(run, time_s=run.time_s[keep],
                                  **{s: getattr(run, s)[keep] for s in SIGNALS}),
              tmp_path / "switched.csv")
    notes = read_run(tmp_path / "switched.csv").notes
    assert any("1000 Hz at its start and 500 Hz at its end" in n for n in notes), notes
    assert not read_run(csv_file).notes


def test_a_campaign_tells_a_gap_while_braking_once_with_what_it_cost(tmp_path, reference):
    """The reader's note on the gap and the split's had both told it, then the part it left
    out a third time."""
    run = simulate(reference, sc.constant_pressure_test(reference, 30e5)).to_run(3)
    on = np.flatnonzero(run.current_a > 0.5 * run.current_a.max())
    lost = slice(on[len(on) // 3], on[len(on) // 3] + round(2.0 * run.rate_hz))
    keep = np.r_[0:lost.start, lost.stop:len(run)]
    folder = tmp_path / "campaign"
    folder.mkdir()
    write_csv(dataclasses.replace(run, time_s=run.time_s[keep],
                                  **{s: getattr(run, s)[keep] for s in SIGNALS}),
              folder / "brake_const_30bar.csv")
    problems = read_campaign(folder).problems
    assert len([p for p in problems if "2 s missing" in p]) == 1, problems
    assert any("begins mid-stop" in p for p in problems), problems
