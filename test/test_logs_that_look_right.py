"""Logs that look right but are not (issue 62): each reproduction of the issue as a test,
written before its fix. A log is read as what it is, or refused with one line that names the
file, the real cause and the fix — never a traceback, never the wrong cause."""

from __future__ import annotations

import gzip
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from landing_gear_sim.cli import main
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate
from msg_tools.contract import CSV_COLUMNS, CSV_SCALE_TO_SI, CSV_TO_FIELD
from msg_tools.io import read_campaign, read_run
from msg_tools.run import Run

HEADER = ",".join(CSV_COLUMNS)


@pytest.fixture(scope="module")
def run(reference) -> Run:
    params = reference.replace({"rig_test.max_duration_s": 4.0})
    return simulate(params, sc.constant_pressure_test(params, 20e5)).to_run(5)


def _csv(run: Run, time_format: str = ".6f", **scales: float) -> str:
    table = {c: getattr(run, CSV_TO_FIELD[c]) / CSV_SCALE_TO_SI[c] * scales.get(c, 1.0)
             for c in CSV_COLUMNS}
    rows = [",".join(format(table[c][k], time_format if c == "time_s" else ".9g")
                     for c in CSV_COLUMNS) for k in range(len(run))]
    return HEADER + "\n" + "\n".join(rows) + "\n"


def _refusal(capsys, argv: list[str]) -> str:
    """The one line a refused command prints (exit 2, no traceback)."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    errors = [line for line in err.splitlines() if line.startswith("landing-gear-sim: error")]
    assert len(errors) == 1 and "Traceback" not in err, err
    return errors[0]


def test_a_pressure_of_the_wrong_sign_suggests_scale_minus_one(tmp_path, run, capsys):
    """Item 12: '-0.986 times what the valve map gives' named no fix; F_x's sign does."""
    path = tmp_path / "run.csv"
    path.write_text(_csv(run, brake_pressure_bar=-1.0))
    err = _refusal(capsys, ["metrics", str(path)])
    assert "brake_pressure_bar" in err and "sign" in err and "scale: -1" in err, err


def test_a_short_table_says_it_is_short_and_how_many_rows_an_analysis_needs(tmp_path, run,
                                                                          capsys):
    """Item 14: a 15-row file read 'no table of numbers found'; the table is fine, short."""
    path = tmp_path / "run.csv"
    path.write_text("\n".join(_csv(run).splitlines()[:16]) + "\n")
    err = _refusal(capsys, ["metrics", str(path)])
    assert "no table of numbers" not in err and "15 rows" in err and "need at least" in err, err


def test_a_time_column_with_too_few_digits_for_its_rate_says_so(tmp_path, run, capsys):
    """Item 16: time written with 2 decimals at 1 kHz read 'duplicated time 0 s at sample
    1'."""
    path = tmp_path / "run.csv"
    path.write_text(_csv(run, time_format=".2f"))
    err = _refusal(capsys, ["metrics", str(path)])
    assert "time_s" in err and "digits" in err and "duplicated" not in err, err


def test_a_gzip_compressed_csv_under_a_plain_name_is_read(tmp_path, run):
    """Item 15: a gzip-compressed file named .csv read 'no table of numbers found'."""
    path = tmp_path / "run.csv"
    path.write_bytes(gzip.compress(_csv(run).encode()))
    again = read_run(path)
    assert len(again) == len(run)
    assert np.allclose(again.pressure_pa, run.pressure_pa, rtol=1e-6, atol=1.0)
    assert main(["metrics", str(path)]) == 0


def test_nothing_is_written_beside_a_refused_log(tmp_path, run, capsys):
    path = tmp_path / "run.csv"
    path.write_text(_csv(run, time_format=".2f"))
    _refusal(capsys, ["convert", str(path), str(tmp_path / "out.csv")])
    assert sorted(p.name for p in Path(tmp_path).iterdir()) == ["run.csv"]


@pytest.mark.parametrize("padding", ["4096 NULs", "sparse to 45 MB"])
@pytest.mark.parametrize("cut_mid_line", [True, False])
def test_a_log_a_power_loss_padded_with_nul_bytes_keeps_every_complete_row(
        tmp_path, run, capsys, padding, cut_mid_line):
    """Item 1: a file cut mid-line and followed by NULs, as a power loss leaves it, raised
    '_csv.Error: field larger than field limit' (exit 1). The rows up to the cut are read,
    with a note of what was cut."""
    whole = _csv(run).encode()
    cut = whole[:len(whole) // 2]
    if not cut_mid_line:
        cut = cut[:cut.rfind(b"\n") + 1]
    elif cut.endswith(b"\n"):
        cut = cut[:-3]
    path = tmp_path / "run.csv"
    path.write_bytes(cut + (b"\0" * 4096 if padding == "4096 NULs" else b""))
    if padding != "4096 NULs":
        with path.open("r+b") as out:
            out.truncate(45 * 2 ** 20)
    complete = cut.count(b"\n") - 1
    again = read_run(path)
    assert len(again) == complete
    assert np.allclose(again.time_s, run.time_s[:complete], atol=1e-6)
    assert any("NUL" in n for n in again.notes), again.notes
    assert any("cut short" in n for n in again.notes) == cut_mid_line, again.notes
    assert main(["metrics", str(path)]) == 0
    assert "NUL" in capsys.readouterr().err


def test_a_command_that_stops_on_an_error_leaves_no_empty_report_folder(tmp_path, run,
                                                                        capsys):
    """Item 21: `validate` that stopped on an error left an empty --report folder behind
    (the check that it can be written had made it)."""
    (tmp_path / "logs").mkdir()
    (tmp_path / "logs" / "run.csv").write_text(_csv(run, time_format=".2f"))
    report = tmp_path / "out" / "report"
    _refusal(capsys, ["validate", str(tmp_path / "logs"), "--report", str(report)])
    assert not (tmp_path / "out").exists()


def test_two_columns_of_one_name_are_refused_naming_both_positions(tmp_path, run, capsys):
    """Item 2: an extra brake_pressure_bar holding 0.6 P was read silently as the first,
    and compare reported a -61 % pressure fit."""
    lines = _csv(run).splitlines()
    at = CSV_COLUMNS.index("brake_pressure_bar")
    doubled = [lines[0] + ",brake_pressure_bar"] + [
        f"{line},{0.6 * float(line.split(',')[at]):.9g}" for line in lines[1:]]
    path = tmp_path / "run.csv"
    path.write_text("\n".join(doubled) + "\n")
    err = _refusal(capsys, ["metrics", str(path)])
    assert "brake_pressure_bar" in err and "3" in err and "8" in err and "twice" in err, err


def test_a_byte_identical_copy_of_a_run_is_read_once_with_a_note(tmp_path, run):
    """Item 7: a copy under another name was counted as a ninth run and held out, with no
    note (a symlink was already caught)."""
    text = _csv(run)
    (tmp_path / "brake_const_20bar.csv").write_text(text)
    (tmp_path / "copy_of_it.csv").write_text(text)
    campaign = read_campaign(tmp_path)
    assert [r.name for r in campaign.runs] == ["brake_const_20bar"]
    assert any("copy_of_it.csv" in p and "brake_const_20bar.csv" in p and "identical" in p
               for p in campaign.skipped), campaign.skipped


def test_one_run_name_in_two_formats_is_renamed_and_said(tmp_path, run, reference):
    """Item 6: brake_const_20bar.csv and .tsv holding other data showed as two rows of one
    name in validate (the second plot overwrote the first); identify listed one and fitted
    both."""
    (tmp_path / "brake_const_20bar.csv").write_text(_csv(run))
    other = simulate(reference.replace({"rig_test.max_duration_s": 4.0}),
                     sc.constant_pressure_test(reference, 30e5)).to_run(6)
    (tmp_path / "brake_const_20bar.tsv").write_text(_csv(other).replace(",", "\t"))
    campaign = read_campaign(tmp_path)
    names = [r.name for r in campaign.runs]
    assert len(set(names)) == 2 and "brake_const_20bar" in names, names
    renamed = next(n for n in names if n != "brake_const_20bar")
    assert any(renamed in p and "brake_const_20bar.tsv" in p for p in campaign.problems), \
        campaign.problems


@pytest.mark.parametrize("channel", ["flywheel_speed_rad_s", "wheel_speed_rad_s"])
@pytest.mark.parametrize("command", ["metrics", "validate", "diagnose"])
def test_a_speed_encoder_that_reads_zero_while_the_other_turns_is_named_dead(
        tmp_path, run, capsys, command, channel):
    """Item 3: a flywheel channel at 0 throughout while the wheel turned at 190 rad/s gave
    'stop 0.0 m' in metrics, and 'simulation: time must be strictly increasing' (no file,
    the wrong cause) in validate, identify and diagnose."""
    (tmp_path / "logs").mkdir()
    path = tmp_path / "logs" / "brake_const_20bar.csv"
    path.write_text(_csv(run, **{channel: 0.0}))
    target = str(path) if command == "metrics" else str(tmp_path / "logs")
    err = _refusal(capsys, [command, target])
    assert "brake_const_20bar.csv" in err and channel in err, err
    assert "dead" in err and "time must be" not in err, err


def test_a_units_row_that_contradicts_the_columns_name_is_said(tmp_path, run, capsys):
    """Item 13: a units row saying psi under brake_pressure_bar was read silently as psi."""
    lines = _csv(run, brake_pressure_bar=14.5038).splitlines()
    units = ["s", "A", "psi", "rad/s", "rad/s", "N", "N"]
    path = tmp_path / "run.csv"
    path.write_text("\n".join([lines[0], ",".join(units), *lines[1:]]) + "\n")
    again = read_run(path)
    assert np.allclose(again.pressure_pa, run.pressure_pa, rtol=1e-4, atol=50.0)
    said = [n for n in again.notes if "brake_pressure_bar" in n]
    assert said and "psi" in said[0] and "bar" in said[0] and "units row" in said[0], \
        again.notes


def test_compare_of_two_runs_given_different_inputs_says_so(tmp_path, reference, capsys):
    """Item 9: compare of a 20 bar and a 40 bar stop printed fits of -150 % with no hint."""
    paths = []
    for bar in (20, 40):
        paths.append(tmp_path / f"stop{bar}.csv")
        assert main(["simulate", "--pressure-bar", str(bar), "--duration", "5", "--no-plot",
                     "-o", str(paths[-1])]) == 0
    capsys.readouterr()
    assert main(["compare", str(paths[0]), str(paths[1]), "--plot",
                 str(tmp_path / "c.png")]) == 0
    err = capsys.readouterr().err
    said = [line for line in err.splitlines() if "current" in line and "differ" in line]
    assert said and " A" in said[0], err
    capsys.readouterr()
    assert main(["compare", str(paths[0]), str(paths[0]), "--plot",
                 str(tmp_path / "same.png")]) == 0
    assert "differ" not in capsys.readouterr().err


def test_a_mat_file_whose_vector_is_short_names_the_length_mismatch(tmp_path, run, capsys):
    """Item 17: a .mat whose wheel vector was 100 samples short was reported as a missing
    column."""
    import scipy.io

    vectors = {c: getattr(run, CSV_TO_FIELD[c]) / CSV_SCALE_TO_SI[c] for c in CSV_COLUMNS}
    vectors["wheel_speed_rad_s"] = vectors["wheel_speed_rad_s"][:-100]
    path = tmp_path / "run.mat"
    scipy.io.savemat(path, vectors)
    err = _refusal(capsys, ["metrics", str(path)])
    assert "wheel_speed_rad_s" in err and str(len(run) - 100) in err, err
    assert str(len(run)) in err and "missing column" not in err, err


def test_metrics_of_a_log_that_changes_its_rate_are_those_of_its_signal(tmp_path, reference):
    """Item 10: a log switching from 1 kHz to 500 Hz mid-run said its slower part was
    interpolated, but metrics averaged the raw samples (efficiency 0.359 -> 0.367, mu +2.3 %):
    the slow part counted half."""
    import json

    whole = tmp_path / "whole.csv"
    assert main(["simulate", "--pressure-bar", "20", "--no-plot", "-o", str(whole)]) == 0
    lines = whole.read_text().splitlines()
    half = len(lines) // 2
    (tmp_path / "changed.csv").write_text("\n".join(lines[:half] + lines[half::2]) + "\n")
    found = {}
    for name in ("whole", "changed"):
        out = tmp_path / f"{name}.json"
        assert main(["metrics", str(tmp_path / f"{name}.csv"), "--json", str(out)]) == 0
        found[name] = json.loads(out.read_text())
    for key in ("braking_efficiency", "mean_friction", "slip_rms", "stopping_distance_m"):
        assert found["changed"][key] == pytest.approx(found["whole"][key], rel=2e-3), key


@pytest.mark.parametrize("in_kmh", [("wheel_speed_rad_s", "flywheel_speed_rad_s"),
                                    ("flywheel_speed_rad_s",)])
def test_speeds_in_km_h_are_named_on_the_channel_that_is_off(tmp_path, run, reference,
                                                             capsys, in_kmh):
    """Item 11: both speeds in km/h read 'wheel_speed_rad_s is 0.31 times ...' (0.31 is the
    wheel's radius); the flywheel alone in km/h blamed the wheel. km/h is named, with the
    scale that reads it, on the channel that is off."""
    radius = {"wheel_speed_rad_s": 0.3, "flywheel_speed_rad_s": reference.number(
        "flywheel.radius_m")}  # the wheel's rolling radius near its static load
    scales = {c: 3.6 * radius[c] for c in in_kmh}
    path = tmp_path / "run.csv"
    path.write_text(_csv(run, **scales))
    err = _refusal(capsys, ["metrics", str(path)])
    assert "km/h" in err and "scale" in err, err
    said = err.split(": ")[3].split(" look")[0]
    assert set(re.findall(r"\b(?:fly)?wheel_speed_rad_s\b", said)) == set(in_kmh), err


@pytest.mark.filterwarnings("error::RuntimeWarning")  # scipy's coherence of bands without power
def test_a_parameter_the_runs_cannot_identify_keeps_its_datasheet_value_with_a_note(
        tmp_path, reference):
    """Item 8: an actuator sweep cut to 1.5 s with no current step wrote natural_frequency_hz
    10.41 ± 1.62e7 and damping_ratio 0.458 ± 1.31e6 into the params file, with no note; and
    the note is all it says (scipy's warning of a coherence 0/0 had reached the terminal)."""
    from landing_gear_sim.calibration.campaign import generate_campaign
    from landing_gear_sim.calibration.identify import identify

    generate_campaign(tmp_path, reference, 8, ("actuator_ramp", "actuator_steps_sweep"))
    sweep = tmp_path / "actuator_steps_sweep.csv"
    lines = sweep.read_text().splitlines()
    sweep.write_text("\n".join(line for line in lines
                               if not line[0].isdigit() or float(line.split(",")[0]) < 1.5)
                     + "\n")
    result = identify(read_campaign(tmp_path).runs, reference, friction=False,
                      jackknife=False)
    assert all(abs(e.std) <= abs(e.value) for e in result.estimates), [
        (e.key, e.value, e.std) for e in result.estimates if abs(e.std) > abs(e.value)]
    for key in ("actuator.natural_frequency_hz", "actuator.damping_ratio"):
        assert result.params.number(key) == reference.number(key)
        assert any(key in p and "cannot" in p for p in result.problems), result.problems


def test_a_bag_without_the_flywheel_topic_reads_as_a_csv_without_that_column(tmp_path, run):
    """Item 18: a bag without the flywheel's topic was refused, while a CSV without that
    column is read (docs/data-contract.md: a braking log may lack it)."""
    from rosbags.rosbag2 import Reader, Writer

    from msg_tools.bag_io import BAG_VERSION, TYPESTORE, write_bag
    from msg_tools.bag_read import read_bag
    from msg_tools.contract import TOPIC_FLYWHEEL

    write_bag(run, tmp_path / "full")
    with Reader(tmp_path / "full") as reader, Writer(tmp_path / "bag",
                                                     version=BAG_VERSION) as writer:
        kept = {c.id: writer.add_connection(c.topic, c.msgtype, typestore=TYPESTORE)
                for c in reader.connections if c.topic != TOPIC_FLYWHEEL}
        for connection, stamp, raw in reader.messages():
            if connection.id in kept:
                writer.write(kept[connection.id], stamp, raw)
    again = read_bag(tmp_path / "bag")
    assert again.lacks("flywheel_speed_rad_s") == ("flywheel_speed_rad_s",)
    assert np.allclose(again.wheel_speed_rad_s, run.wheel_speed_rad_s, atol=1e-6)
    assert any("flywheel_speed_rad_s" in n and "not logged" in n for n in again.notes)


@pytest.mark.parametrize("stuck", [True, False])
def test_a_lock_the_force_does_not_confirm_is_said_unconfirmed(tmp_path, capsys, stuck):
    """Item 4: a wheel encoder stuck at 0 after 2.5 s while the flywheel turned was read as
    9.5 s locked. A locked tyre slides at the curve's mu(1); one that grips at low slip
    pulls far less: the lock is said unconfirmed, the wheel channel suspected. A real lock
    (58 bar, the wheel sliding) is not."""
    path = tmp_path / "run.csv"
    assert main(["simulate", "--pressure-bar", "20" if stuck else "58", "--no-plot", "-o",
                 str(path)]) == 0
    if stuck:
        lines = path.read_text().splitlines()
        at = CSV_COLUMNS.index("wheel_speed_rad_s")
        rows = [line.split(",") for line in lines[1:]]
        for row in rows:
            if float(row[0]) > 2.5:
                row[at] = "0"
        path.write_text("\n".join([lines[0], *(",".join(r) for r in rows)]) + "\n")
    capsys.readouterr()
    assert main(["metrics", str(path)]) == 0
    err = capsys.readouterr().err
    said = [line for line in err.splitlines() if "unconfirmed" in line]
    if stuck:
        assert said and "wheel_speed_rad_s" in said[0] and "μ" in said[0], err
    else:
        assert not said, err


def _odd_logs(run: Run) -> dict[str, Callable[[Path], Path]]:
    """The issue's classes of odd logs, each written into a folder as a user's file."""
    def text(name: str, content: str | bytes) -> Callable[[Path], Path]:
        def write(folder: Path) -> Path:
            path = folder / name
            if isinstance(content, bytes):
                path.write_bytes(content)
            else:
                path.write_text(content)
            return path
        return write

    whole = _csv(run)
    lines = whole.splitlines()
    at = CSV_COLUMNS.index("brake_pressure_bar")
    return {
        "cut and NUL-padded": text("run.csv", whole.encode()[:len(whole) // 2 - 3]
                                   + b"\0" * 4096),
        "two columns of one name": text("run.csv", "\n".join(
            [lines[0] + ",brake_pressure_bar"]
            + [f"{x},{0.6 * float(x.split(',')[at]):.6g}" for x in lines[1:]]) + "\n"),
        "dead flywheel": text("run.csv", _csv(run, flywheel_speed_rad_s=0.0)),
        "dead wheel": text("run.csv", _csv(run, wheel_speed_rad_s=0.0)),
        "pressure of the wrong sign": text("run.csv", _csv(run, brake_pressure_bar=-1.0)),
        "short": text("run.csv", "\n".join(lines[:16]) + "\n"),
        "gzip under .csv": text("run.csv", gzip.compress(whole.encode())),
        "time with 2 decimals": text("run.csv", _csv(run, time_format=".2f")),
        "speeds in km/h": text("run.csv", _csv(run, wheel_speed_rad_s=3.6 * 0.3,
                                               flywheel_speed_rad_s=3.6)),
        "binary garbage": text("run.csv", b"\x00\x01garbage\x7f\n" * 10),
        "empty": text("run.csv", ""),
    }


ODD = ("cut and NUL-padded", "two columns of one name", "dead flywheel", "dead wheel",
       "pressure of the wrong sign", "short", "gzip under .csv", "time with 2 decimals",
       "speeds in km/h", "binary garbage", "empty")


@pytest.mark.parametrize("command", ["metrics", "convert", "validate"])
@pytest.mark.parametrize("odd", ODD)
def test_an_odd_log_ends_in_a_result_or_one_line_naming_its_file(tmp_path, run, capsys,
                                                                  odd, command):
    """The issue's numbers: 0 tracebacks, and every refusal one line naming the file (each
    class's right answer is its own test above)."""
    (tmp_path / "logs").mkdir()
    path = _odd_logs(run)[odd](tmp_path / "logs")
    argv = {"metrics": [str(path)], "convert": [str(path), str(tmp_path / "out.csv")],
            "validate": [str(tmp_path / "logs"), "--report", str(tmp_path / "report")]}
    code = main([command, *argv[command]])
    err = capsys.readouterr().err
    assert code in (0, 2) and "Traceback" not in err, (code, err)
    if code == 2:
        errors = [line for line in err.splitlines() if line.startswith("landing-gear-sim: err")]
        assert len(errors) == 1 and ("run.csv" in errors[0] or "logs" in errors[0]), err
