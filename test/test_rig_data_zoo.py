"""The rig-data zoo: one synthetic run written the ways rig loggers and recorders write it.

Every variant either reads back as the same run (within the file's resolution) or is
refused with one clear line and exit 2 — never a traceback, never a wrong run.
"""

from __future__ import annotations

import codecs
import gzip
import math
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from landing_gear_sim.cli import main
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate
from msg_tools.bag_io import TYPESTORE, write_bag
from msg_tools.contract import CSV_COLUMNS, CSV_SCALE_TO_SI, CSV_TO_FIELD
from msg_tools.csv_io import format_csv, read_mapping
from msg_tools.errors import RunFormatError
from msg_tools.io import read_campaign, read_run
from msg_tools.run import SIGNALS, Run
from msg_tools.units import PSI_PA, RPM_RAD_S


@pytest.fixture(scope="module")
def run(reference) -> Run:
    params = reference.replace({"rig_test.max_duration_s": 4.0})
    return simulate(params, sc.rig_test(params, sc.oscillating(**sc.OSC_LOW))).to_run(5)


def contract_table(run: Run) -> dict[str, np.ndarray]:
    return {c: getattr(run, CSV_TO_FIELD[c]) / CSV_SCALE_TO_SI[c] for c in CSV_COLUMNS}


def text(run: Run, separator: str = ",", decimal: str = ".", header: str | None = None,
         units: str | None = None, preamble: str = "", extra: bool = False) -> str:
    table = contract_table(run)
    names = list(table)
    lines = [preamble + (header or separator.join(names))]
    if units is not None:
        lines.append(units)
    for k in range(len(run)):
        cells = [f"{table[n][k]:.9f}" if n == "time_s" else f"{table[n][k]:.12g}" for n in names]
        if decimal == ",":
            cells = [c.replace(".", ",") for c in cells]
        if extra:
            cells.append('"ok, stable"' if k % 2 else "n/a")
        lines.append(separator.join(cells))
    return "\n".join(lines) + "\n"


HEADER = ",".join(CSV_COLUMNS)
PREAMBLE = ("Prüfstand: HIL-3, Bremse links\nOperator;Müller\nDate,2024-05-02\n"
            "Temperature [°C],21.5\n\n")


def text_variant(name: str, encode: Callable[[str], bytes], **layout: object
                 ) -> Callable[[Path, Run], Path]:
    def make(folder: Path, run: Run) -> Path:
        path = folder / name
        path.write_bytes(encode(text(run, **layout)))  # type: ignore[arg-type]
        return path
    return make


def utf8(content: str) -> bytes:
    return content.encode()


READABLE_TEXT = {
    "utf8 BOM": text_variant("bom.csv", lambda t: codecs.BOM_UTF8 + t.encode()),
    "utf16 BOM": text_variant("utf16.csv", lambda t: t.encode("utf-16")),
    "latin-1 preamble": text_variant("latin1.csv", lambda t: t.encode("latin-1"),
                                     preamble=PREAMBLE),
    "semicolon, decimal comma": text_variant("eu.csv", utf8, separator=";", decimal=",",
                                             header=HEADER.replace(",", ";")),
    "tab": text_variant("tab.tsv", utf8, separator="\t", header=HEADER.replace(",", "\t")),
    "units row": text_variant("units.csv", utf8, units="s,A,bar,rad/s,rad/s,N,N"),
    "text column": text_variant("text.csv", utf8, header=HEADER + ",comment", extra=True),
    "upper-case suffix": text_variant("RUN.CSV", utf8),
    "gzip": text_variant("run.csv.gz", lambda t: gzip.compress(t.encode())),
}


@pytest.mark.parametrize("make", READABLE_TEXT.values(), ids=READABLE_TEXT.keys())
def test_text_layouts_loggers_write_read_as_the_same_run(tmp_path, run, make):
    back = read_run(make(tmp_path, run))
    assert_same_run(back, run)


def assert_same_run(back: Run, run: Run, time_atol: float = 1e-9) -> None:
    assert len(back) == len(run)
    assert np.allclose(back.time_s, run.time_s, rtol=0, atol=time_atol)
    for name in SIGNALS:
        assert np.allclose(getattr(back, name), getattr(run, name), rtol=1e-9, atol=1e-6), name


def test_units_in_the_file_are_used_time_in_ms_included(tmp_path, run):
    table = contract_table(run)
    table["time_s"] = table["time_s"] * 1e3
    table["brake_pressure_bar"] = run.pressure_pa / PSI_PA
    table["wheel_speed_rad_s"] = run.wheel_speed_rad_s / RPM_RAD_S
    header = ",".join(f"{c} [{u}]" for c, u in zip(
        CSV_COLUMNS, ["ms", "A", "psi", "rpm", "rad/s", "N", "N"], strict=True))
    rows = "\n".join(",".join(f"{table[c][k]:.15g}" for c in CSV_COLUMNS)
                     for k in range(len(run)))
    (tmp_path / "units.csv").write_text(header + "\n" + rows + "\n")
    assert_same_run(read_run(tmp_path / "units.csv"), run)


def test_a_mapping_may_copy_header_cells_units_and_all(tmp_path, run):
    """Issue 30: a mapping naming `t [s]` as the file's header writes it was refused."""
    cells = {"time_s": "t [ms]", "current_ref_A": "I [A]", "brake_pressure_bar": "p [bar]",
             "wheel_speed_rad_s": "w [rad/s]", "flywheel_speed_rad_s": "W [rad/s]",
             "vertical_load_N": "Fz [N]", "longitudinal_force_N": "Fx [N]"}
    table = contract_table(run)
    table["time_s"] = table["time_s"] * 1e3
    rows = "\n".join(",".join(f"{table[c][k]:.15g}" for c in CSV_COLUMNS)
                     for k in range(len(run)))
    (tmp_path / "cells.csv").write_text(",".join(cells.values()) + "\n" + rows + "\n")
    (tmp_path / "map.yaml").write_text("".join(f'{c}: {{column: "{cell}"}}\n'
                                               for c, cell in cells.items()))
    assert_same_run(read_run(tmp_path / "cells.csv", read_mapping(tmp_path / "map.yaml")), run)


def test_calendar_time_column_is_read_to_the_microsecond(tmp_path, run):
    start = np.datetime64("2024-05-02T10:00:00.000000")
    stamps = start + (run.time_s * 1e6).round().astype("timedelta64[us]")
    body = text(run).splitlines()
    lines = [body[0]] + [f"{s}," + line.split(",", 1)[1]
                         for s, line in zip(stamps.astype(str), body[1:], strict=True)]
    (tmp_path / "calendar.csv").write_text("\n".join(lines) + "\n")
    back = read_run(tmp_path / "calendar.csv")
    assert np.allclose(back.time_s - back.time_s[0], run.time_s - run.time_s[0], atol=1e-6)
    assert back.time_s[0] == pytest.approx(start.astype("datetime64[us]").astype(int) * 1e-6)


GROUPED = {  # separator, decimal mark, thousands mark
    "comma thousands, decimal point": (";", ".", ","),
    "point thousands, decimal comma": (";", ",", "."),
    "apostrophe thousands (Swiss)": ("\t", ".", "'"),
    "quoted comma thousands in a comma file": (",", ".", ","),
}


@pytest.mark.parametrize("layout", GROUPED.values(), ids=GROUPED.keys())
def test_numbers_with_thousands_separators_read_as_the_same_run(tmp_path, run, layout):
    """Issue 30: loads logged as 32,412.5 N (or 32.412,5) were refused."""
    separator, decimal, thousands = layout
    table = contract_table(run)

    def cell(value: float, digits: int) -> str:
        grouped = f"{value:,.{digits}f}".replace(",", "_").replace(".", decimal)
        grouped = grouped.replace("_", thousands)
        return f'"{grouped}"' if thousands == separator else grouped

    rows = [separator.join(cell(table[c][k], 9 if c == "time_s" else 12) for c in CSV_COLUMNS)
            for k in range(len(run))]
    assert any(thousands in r for r in rows)
    (tmp_path / "grouped.csv").write_text(separator.join(CSV_COLUMNS) + "\n"
                                          + "\n".join(rows) + "\n")
    assert_same_run(read_run(tmp_path / "grouped.csv"), run)


def test_clock_time_of_day_is_read_as_seconds_across_midnight(tmp_path, run):
    """Issue 30: a time column written as HH:MM:SS.ffffff was refused; a run that passes
    midnight goes on counting."""
    start_s = 24 * 3600 - 2.0  # 23:59:58
    body = text(run).splitlines()

    def clock(seconds: float) -> str:
        seconds %= 24 * 3600
        hours, rest = divmod(seconds, 3600)
        minutes, secs = divmod(rest, 60)
        return f"{int(hours):02d}:{int(minutes):02d}:{secs:09.6f}"

    lines = [body[0]] + [f"{clock(start_s + t)}," + line.split(",", 1)[1]
                         for t, line in zip(run.time_s, body[1:], strict=True)]
    (tmp_path / "clock.csv").write_text("\n".join(lines) + "\n")
    back = read_run(tmp_path / "clock.csv")
    assert np.allclose(back.time_s - back.time_s[0], run.time_s - run.time_s[0], atol=1e-6)
    assert any("clock" in note for note in back.notes)


def test_mapping_scale_and_offset_fix_sign_and_absolute_pressure(tmp_path, run):
    table = contract_table(run)
    table["longitudinal_force_N"] = -table["longitudinal_force_N"]
    table["brake_pressure_bar"] = table["brake_pressure_bar"] + 1.01325
    rows = "\n".join(",".join(f"{table[c][k]:.15g}" for c in CSV_COLUMNS)
                     for k in range(len(run)))
    (tmp_path / "run.csv").write_text(HEADER + "\n" + rows + "\n")
    with pytest.raises(RunFormatError, match="longitudinal_force_N is negative while braking"):
        read_run(tmp_path / "run.csv")
    (tmp_path / "map.yaml").write_text("longitudinal_force_N: {scale: -1}\n"
                                       "brake_pressure_bar: {offset: -1.01325}\n")
    assert main(["convert", str(tmp_path / "run.csv"), str(tmp_path / "fixed.csv"),
                 "--mapping", str(tmp_path / "map.yaml")]) == 0
    assert_same_run(read_run(tmp_path / "fixed.csv"), run, time_atol=1e-6)


def test_an_excel_workbook_reads_as_the_same_run_from_the_sheet_holding_it(tmp_path, run):
    """Issue 30: .xlsx was not read. A test bench's export: a notes sheet first, then the
    data sheet with a title row, units in the header cells and numbers as Excel keeps
    them (floats); the run is read from the sheet that holds it, and a campaign folder
    takes the workbook as a run."""
    openpyxl = pytest.importorskip("openpyxl")
    book = openpyxl.Workbook()
    book.active.title = "Notes"
    book.active.append(["Prüfstand HIL-3, Bremse links"])
    sheet = book.create_sheet("Messung")
    sheet.append(["Run 7, 2024-05-02"])
    units = ["s", "A", "bar", "rad/s", "rad/s", "N", "N"]
    sheet.append([f"{c} [{u}]" for c, u in zip(CSV_COLUMNS, units, strict=True)])
    table = contract_table(run)
    for k in range(len(run)):
        sheet.append([float(table[c][k]) for c in CSV_COLUMNS])
    (tmp_path / "camp").mkdir()
    book.save(tmp_path / "camp" / "run7.xlsx")
    assert_same_run(read_run(tmp_path / "camp" / "run7.xlsx"), run)
    assert [r.name for r in read_campaign(tmp_path / "camp").runs] == ["run7"]


def test_a_workbook_without_the_run_lists_its_sheets_and_their_columns(tmp_path):
    openpyxl = pytest.importorskip("openpyxl")
    book = openpyxl.Workbook()
    book.active.title = "Temperatures"
    book.active.append(["t", "T_disc"])
    for k in range(50):
        book.active.append([0.1 * k, 20.0 + k])
    book.save(tmp_path / "other.xlsx")
    with pytest.raises(RunFormatError, match=r"sheet Temperatures: .*t, T_disc"):
        read_run(tmp_path / "other.xlsx")


# ---------------------------------------------------------------- binary tables


def columns(run: Run) -> dict[str, np.ndarray]:
    return {c: np.asarray(v, dtype=float) for c, v in contract_table(run).items()}


def write_mat_v5(path: Path, run: Run) -> None:
    import scipy.io

    scipy.io.savemat(path, {"log": columns(run)})  # one struct of vectors, as MATLAB users do


def write_mat_v73(path: Path, run: Run) -> None:
    h5py = pytest.importorskip("h5py")
    with h5py.File(path, "w", userblock_size=512) as file:
        for name, values in columns(run).items():
            file.create_dataset(name, data=values[np.newaxis, :])  # MATLAB stores 1×n
    with open(path, "r+b") as raw:
        raw.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Thu May  2 2024 "
                  b"HDF5 schema 1.00 .".ljust(116) + b"\x00" * 8 + b"\x00\x02IM")


def write_hdf5(path: Path, run: Run) -> None:
    h5py = pytest.importorskip("h5py")
    with h5py.File(path, "w") as file:
        group = file.create_group("rig/run")
        for name, values in columns(run).items():
            group.create_dataset(name, data=values)


def write_parquet(path: Path, run: Run) -> None:
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    pq.write_table(pa.table(columns(run)), path)


def write_mdf(path: Path, run: Run) -> None:
    asammdf = pytest.importorskip("asammdf")
    table = columns(run)
    time = table.pop("time_s")
    with asammdf.MDF(version="4.10") as mdf:
        mdf.append([asammdf.Signal(values, time, name=name) for name, values in table.items()])
        mdf.save(path, overwrite=True)


def write_tdms(path: Path, run: Run) -> None:
    nptdms = pytest.importorskip("nptdms")
    channels = [nptdms.ChannelObject("rig", name, values)
                for name, values in columns(run).items()]
    with nptdms.TdmsWriter(path) as writer:
        writer.write_segment(channels)


BINARY = {"mat v5": ("run.mat", write_mat_v5), "mat v7.3": ("run73.mat", write_mat_v73),
          "hdf5": ("run.h5", write_hdf5), "parquet": ("run.parquet", write_parquet),
          "mdf4": ("run.mf4", write_mdf), "tdms": ("run.tdms", write_tdms)}


@pytest.mark.parametrize(("name", "writer"), BINARY.values(), ids=BINARY.keys())
def test_binary_formats_read_as_the_same_run(tmp_path, run, name, writer):
    writer(tmp_path / name, run)
    assert_same_run(read_run(tmp_path / name), run)


def test_an_mdf4_of_several_rates_and_a_duplicated_name_reads_the_run_at_its_own_rate(
        tmp_path, run):
    """Issue 30: a first channel group at 10 Hz decimated the 1 kHz run to 10 Hz without a
    word, and one channel name in two groups refused the whole file. The run is read on
    the fastest group's time base, slower channels resampled onto it with a note; a
    duplicated name the run does not need does not matter."""
    asammdf = pytest.importorskip("asammdf")
    table = columns(run)
    time = table.pop("time_s")
    slow = np.arange(time[0], time[-1], 0.1)
    with asammdf.MDF(version="4.10") as mdf:
        mdf.append([asammdf.Signal(20.0 + slow, slow, name="disc_temperature", unit="degC"),
                    asammdf.Signal(np.ones_like(slow), slow, name="status")])
        mdf.append([asammdf.Signal(values, time, name=name) for name, values in table.items()])
        mdf.append([asammdf.Signal(21.0 + slow, slow, name="disc_temperature", unit="degC")])
        mdf.save(tmp_path / "rates.mf4", overwrite=True)
    back = read_run(tmp_path / "rates.mf4")
    assert_same_run(back, run)
    assert any("10 Hz" in note and "resampled" in note for note in back.notes), back.notes


# ---------------------------------------------------------------- bags


def rewrite_bag(source: Path, target: Path, topic: Callable[[str], str | None],
                message: Callable[[str, object], object] = lambda _t, m: m) -> None:
    """Copy a bag with renamed topics (None drops one) and changed messages."""
    from rosbags.highlevel import AnyReader
    from rosbags.rosbag2 import Writer

    with AnyReader([source], default_typestore=TYPESTORE) as reader, \
            Writer(target, version=9) as writer:
        out = {}
        for c in reader.connections:
            if topic(c.topic) is not None:
                out[c.topic] = writer.add_connection(topic(c.topic), c.msgtype,
                                                     typestore=TYPESTORE)
        for c, log_time, raw in reader.messages():
            if c.topic in out:
                changed = message(c.topic, reader.deserialize(raw, c.msgtype))
                writer.write(out[c.topic], log_time, TYPESTORE.serialize_cdr(changed, c.msgtype))


def test_bag_under_another_namespace_is_found_by_topic_tail(tmp_path, run):
    write_bag(run, tmp_path / "bag")
    rewrite_bag(tmp_path / "bag", tmp_path / "ns", lambda t: t.replace("/rig/", "/rig2/"))
    assert_same_run(read_run(tmp_path / "ns"), run)


SEPARATOR = "=" * 80 + "\n"
SERVICE_EVENT_DEF = (  # as rosbag2 stores rcl_interfaces/srv/GetParameters_Event
    "service_msgs/ServiceEventInfo info\nGetParameters_Request[<=1] request\n"
    "GetParameters_Response[<=1] response\n" + SEPARATOR
    + "MSG: service_msgs/ServiceEventInfo\nuint8 event_type\nbuiltin_interfaces/Time stamp\n"
    "char[16] client_gid\nint64 sequence_number\n" + SEPARATOR
    + "MSG: rcl_interfaces/GetParameters_Request\nstring[] names\n" + SEPARATOR
    + "MSG: rcl_interfaces/GetParameters_Response\nParameterValue[] values\n" + SEPARATOR
    + "MSG: rcl_interfaces/ParameterValue\nuint8 type\nfloat64 double_value\n")


def test_a_bag_recorded_with_service_events_reads_its_topics(tmp_path, run):
    """Issue 30: `ros2 bag record --all-services` adds `pkg/srv/X_Event` topics, which
    rosbags cannot name; a bag holding one was refused whole ('cannot read bag
    ('rcl_interfaces/srv/GetParameters_Event')')."""
    from rosbags.rosbag2 import Writer

    from msg_tools.bag_io import BAG_VERSION, TOPIC_TYPES, contract_messages

    with Writer(tmp_path / "bag", version=BAG_VERSION) as writer:
        topics = {t: writer.add_connection(t, kind, typestore=TYPESTORE)
                  for t, kind in TOPIC_TYPES.items()}
        event = writer.add_connection(
            "/rig/plant/get_parameters/_service_event", "rcl_interfaces/srv/GetParameters_Event",
            msgdef=SERVICE_EVENT_DEF, rihs01="RIHS01_" + "0" * 64)
        writer.write(event, 1, bytes(4 + 64))
        for k in range(len(run)):
            for topic, message in contract_messages(run, k).items():
                writer.write(topics[topic], round(float(run.time_s[k]) * 1e9),
                             TYPESTORE.serialize_cdr(message, TOPIC_TYPES[topic]))
    assert_same_run(read_run(tmp_path / "bag"), run, time_atol=1e-6)


def test_bag_topics_named_otherwise_need_and_take_a_mapping(tmp_path, run):
    write_bag(run, tmp_path / "bag")
    rewrite_bag(tmp_path / "bag", tmp_path / "other",
                lambda t: "/hyd/p1" if t.endswith("pressure") else t)
    with pytest.raises(RunFormatError, match=re.escape("brake_pressure_bar: {topic: /your/topic}")
                       ) as refused:
        read_run(tmp_path / "other")
    assert "/hyd/p1 (sensor_msgs/msg/FluidPressure)" in str(refused.value)  # what it has
    (tmp_path / "map.yaml").write_text("brake_pressure_bar: {topic: /hyd/p1}\n")
    assert main(["convert", str(tmp_path / "other"), str(tmp_path / "back.csv"),
                 "--mapping", str(tmp_path / "map.yaml")]) == 0
    assert_same_run(read_run(tmp_path / "back.csv"), run, time_atol=1e-6)


def test_position_only_joint_states_are_differentiated(tmp_path, run):
    write_bag(run, tmp_path / "bag")
    angle = {"wheel": np.concatenate([[0.0], np.cumsum(
        np.diff(run.time_s) * (run.wheel_speed_rad_s[1:] + run.wheel_speed_rad_s[:-1]) / 2)])}
    stamps = {round(t * 1e9): k for k, t in enumerate(run.time_s)}

    def positions(topic: str, message: object) -> object:
        if not topic.endswith("wheel/joint_state") or "flywheel" in topic:
            return message
        k = stamps[message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec]
        message.position = np.array([math.remainder(angle["wheel"][k], 2 * math.pi)])
        message.velocity = np.empty(0)
        return message

    rewrite_bag(tmp_path / "bag", tmp_path / "pos", lambda t: t, positions)
    back = read_run(tmp_path / "pos")
    inner = slice(10, -10)  # the filter's ends
    error = back.wheel_speed_rad_s[inner] - run.wheel_speed_rad_s[inner]
    assert np.sqrt(np.mean(error ** 2)) < 0.5  # rad/s, against ~0.1 rad/s encoder noise
    assert abs(np.mean(error)) < 0.05


def test_bare_mcap_and_a_bag_folder_without_metadata_are_read(tmp_path, run):
    write_bag(run, tmp_path / "bag")
    (storage,) = (tmp_path / "bag").glob("*.mcap")
    assert_same_run(read_run(storage), run)
    (tmp_path / "bag" / "metadata.yaml").unlink()
    assert_same_run(read_run(tmp_path / "bag"), run)


def test_ros1_bag_is_read(tmp_path, run, monkeypatch):
    """Through rosbags: its messages are not CDR, and no topic of it is read by the
    contract's fixed layouts (msg_tools.contract_cdr)."""
    from rosbags.convert import convert

    from msg_tools import bag_read

    write_bag(run, tmp_path / "bag")
    convert(srcs=[tmp_path / "bag"], dst=tmp_path / "run.bag", dst_storage=None,
            dst_version=None, compress=None, compress_mode=None, default_typestore=TYPESTORE,
            typestore=None, exclude_topics=[], include_topics=[], exclude_msgtypes=[],
            include_msgtypes=[])

    def refused(sources, types):
        raise AssertionError("a ROS 1 bag's topics planned to be read as CDR rows")

    monkeypatch.setattr(bag_read, "_by_layout", refused)
    assert_same_run(read_run(tmp_path / "run.bag"), run)


# ---------------------------------------------------------------- campaigns and refusals


def test_campaign_reads_sub_folders_and_skips_junk_with_a_note(tmp_path, run):
    (tmp_path / "day1").mkdir()
    (tmp_path / "day1" / "a.CSV").write_text(format_csv(run))
    # another run than a's: a byte-identical copy is read once (issue 62)
    (tmp_path / "b.csv").write_text(format_csv(run.part(slice(0, len(run) - 1), "b")))
    (tmp_path / "._b.csv").write_bytes(b"\x00\x05\x16\x07Mac OS X        \x00\x02")
    (tmp_path / "generating-parameters.yaml").write_text("x: 1\n")
    (tmp_path / "notes.xlsx").write_bytes(b"PK\x03\x04")
    (tmp_path / "broken.mat").write_bytes(b"MATLAB 5.0 MAT-file garbage")
    campaign = read_campaign(tmp_path)
    assert [r.name for r in campaign.runs] == ["b", "day1__a"]
    assert len(campaign.problems) == 2
    assert any("notes.xlsx: cannot read the workbook" in p for p in campaign.problems)
    assert any("broken.mat" in p for p in campaign.problems)


REFUSED = {
    "time in ms as s": (lambda run: _scaled(run, "time_s", 1e3), "is the time in ms"),
    "vertical load upside down": (lambda run: _scaled(run, "vertical_load_N", -1),
                                  "vertical_load_N is negative"),
    "pressure in Pa as bar": (lambda run: _scaled(run, "brake_pressure_bar", 1e5),
                              "implausible"),
    "binary garbage": (lambda run: "\x00\x01\x02garbage\x7f\n" * 10, "no table of numbers"),
}


def _scaled(run: Run, column: str, factor: float) -> str:
    table = contract_table(run)
    table[column] = table[column] * factor
    rows = "\n".join(",".join(f"{table[c][k]:.15g}" for c in CSV_COLUMNS)
                     for k in range(len(run)))
    return HEADER + "\n" + rows + "\n"


@pytest.mark.parametrize(("content", "fragment"), REFUSED.values(), ids=REFUSED.keys())
def test_implausible_files_are_refused_with_one_line_and_exit_2(tmp_path, run, capsys,
                                                              content, fragment):
    (tmp_path / "run.csv").write_text(content(run))
    assert main(["convert", str(tmp_path / "run.csv"), str(tmp_path / "out.csv")]) == 2
    error = capsys.readouterr().err
    assert fragment in error and "Traceback" not in error
    assert len(error.strip().splitlines()) == 1
    assert not (tmp_path / "out.csv").exists()


@pytest.mark.parametrize("cut_at", [0.6, 0.95])
def test_a_csv_cut_mid_row_keeps_every_complete_row_and_says_what_was_lost(tmp_path, run,
                                                                            capsys, cut_at):
    """Issue 30: a logger killed mid-write left half a last line, and the whole file was
    refused ("no table of numbers found")."""
    whole = text(run)
    cut = whole[:round(cut_at * len(whole))]
    cut = cut[:-3] if cut.endswith("\n") else cut  # mid-row, whatever the rounding
    (tmp_path / "camp").mkdir()
    (tmp_path / "camp" / "cut.csv").write_text(cut)
    complete = cut.count("\n") - 1  # rows ended by a newline, the header aside
    campaign = read_campaign(tmp_path / "camp")
    assert len(campaign.runs[0]) == complete
    assert np.allclose(campaign.runs[0].time_s, run.time_s[:complete], rtol=0, atol=1e-9)
    assert any("last line cut short" in p and f"{complete} complete rows" in p
               for p in campaign.problems), campaign.problems
    assert main(["convert", str(tmp_path / "camp" / "cut.csv"), str(tmp_path / "back.csv")]) == 0
    assert "last line cut short" in capsys.readouterr().err
    assert len(read_run(tmp_path / "back.csv")) == complete


def test_a_csv_without_a_final_newline_is_whole(tmp_path, run):
    (tmp_path / "whole.csv").write_text(text(run).rstrip("\n"))
    read = read_run(tmp_path / "whole.csv")
    assert len(read) == len(run) and not read.notes


def test_tdms_with_labviews_empty_units_and_half_time_properties_reads(tmp_path, run):
    """Issue 30: LabVIEW's default empty unit was refused as an unknown unit, and a channel
    with wf_increment but no wf_start_offset (npTDMS's Digital_Input.tdms) raised a
    KeyError through identify."""
    nptdms = pytest.importorskip("nptdms")
    properties = {"unit_string": "", "wf_increment": 1e-3}
    with nptdms.TdmsWriter(tmp_path / "labview.tdms") as writer:
        writer.write_segment([nptdms.ChannelObject("rig", name, values, properties=properties)
                              for name, values in columns(run).items()])
    assert_same_run(read_run(tmp_path / "labview.tdms"), run)
