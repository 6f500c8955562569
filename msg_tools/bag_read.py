"""Read a run from a ROS bag: rosbag2 (folder, or bare ``.mcap``/``.db3`` files) or ROS 1.

Messages are streamed: each is reduced to its stamp and the numbers the run needs as it is
read (``array('d')``), so memory grows with the samples kept, not with the messages
decoded. A contract topic's messages that hold its fixed layout
(:mod:`msg_tools.contract_cdr`: the contract's frames and joints, as this package and the
graph write them) are read by that layout, a few thousand at once: through rosbags one by
one, a 20 s run's ~100,000 messages took ~0.8 s of its 1.15 s read. Stamped topics are
matched to the wheel encoder's stamps by linear interpolation, the current command by its
stamp (the end of the interval it holds for), or a 0.1 bag's ``Float64`` current by log
time, held as the valve sees it.
"""

from __future__ import annotations

from array import array
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.highlevel import AnyReader

from .bag_fields import CONTRACT_SOURCES, Source, resolve
from .bag_files import storage_files
from .bag_io import TYPESTORE
from .bag_recover import recovered
from .checks import check_plausible
from .contract import ATMOSPHERE_PA, CSV_TO_FIELD, MAY_LACK, TOPIC_TYPES
from .contract_cdr import COLUMNS, LAYOUTS, Layout
from .derivative import speed_from_angle
from .errors import RunFormatError
from .mapping import DEFAULT_MAPPING, Mapping
from .run import Run
from .stamps import seconds_of_fields


def bag_paths(path: Path) -> list[Path]:
    """What to open for ``path``: the bag folder, a ROS 1 ``.bag``, a storage file, or the
    storage files of a folder that lost its ``metadata.yaml``."""
    if path.is_dir() and not (path / "metadata.yaml").exists():
        files = storage_files(path)
        if not files:
            raise RunFormatError(f"{path}: not a bag (no metadata.yaml, no .mcap/.db3 file)")
        return files
    return [path]


@dataclass
class _Series:
    """Stamps and values of one contract column as they stream in (the stamps shared by
    the columns of one topic)."""

    time_s: array  # its topic's, shared
    values: array = field(default_factory=lambda: array("d"))
    positions: bool = False
    stamped: bool = False  # header stamps, not log times


def read_bag(path: Path, name: str | None = None, mapping: Mapping | None = None) -> Run:
    """The run in the bag at ``path`` (SI, checked), on the wheel encoder's time base."""
    path = Path(path)
    where = str(path)
    try:
        with recovered(bag_paths(path)) as (paths, notes), \
                _without_interfaces(AnyReader(paths, default_typestore=TYPESTORE)) as reader:
            types = {c.topic: c.msgtype for c in reader.connections}
            sources = resolve(mapping or DEFAULT_MAPPING, types, where)
            series, read = _stream(reader, sources)
            notes += _lost(reader, read)
    except RunFormatError:
        raise
    except Exception as exc:  # rosbags raises several types for damaged bags
        raise RunFormatError(f"{where}: cannot read bag ({exc})") from None
    fields = _on_wheel_base(series, sources, where)
    logged = {s.contract for s in sources}
    absent = tuple(CSV_TO_FIELD[c] for c in MAY_LACK if c not in logged)
    if absent:  # as a CSV without those columns: what needs them skips the run, and says so
        fields.update({field: np.full(fields["time_s"].shape, np.nan) for field in absent})
        notes.append(f"{', '.join(absent)} not logged (no topic): what needs "
                     f"{'them' if len(absent) > 1 else 'it'} skips this run and says so")
    check_plausible(fields, where)
    return Run(name=name or path.stem, source=where, notes=tuple(notes), absent=absent,
               **fields)


def _without_interfaces(reader: AnyReader) -> AnyReader:
    """``reader`` blind to service-event and action topics (``pkg/srv/X_Event``, what
    ``ros2 bag record --all-services`` adds): rosbags names their types ``pkg/srv/msg/X``
    and, checking their hashes, refused every bag that held one. A run never lives there."""
    reader.readers = [_Topics(sub) for sub in reader.readers]  # type: ignore[assignment]
    return reader


class _Topics:
    """A rosbags sub-reader with its message topics only (see :func:`_without_interfaces`)."""

    def __init__(self, reader: Any) -> None:
        self._reader = reader

    def __enter__(self) -> _Topics:
        self._reader.__enter__()
        return self

    def __exit__(self, *exc: object) -> None:
        self._reader.__exit__(*exc)

    @property
    def connections(self) -> list[Any]:
        return [c for c in self._reader.connections
                if not any(f"/{kind}/" in c.msgtype for kind in ("srv", "action"))]

    @property
    def topics(self) -> dict[str, Any]:
        kept = {c.topic for c in self.connections}
        return {t: info for t, info in self._reader.topics.items() if t in kept}

    def __getattr__(self, name: str) -> Any:
        return getattr(self._reader, name)


def _lost(reader: AnyReader, read: Counter[str]) -> list[str]:
    """Per topic read, the messages the bag's metadata counts that were not in it."""
    counted: Counter[str] = Counter()
    for connection in reader.connections:
        counted[connection.topic] += connection.msgcount
    short: dict[tuple[int, int], list[str]] = {}
    for topic in read:
        if read[topic] < counted[topic]:
            short.setdefault((read[topic], counted[topic]), []).append(topic)
    return [f"{', '.join(topics)}: {n} of the {total} messages the bag's metadata counts were "
            f"in it ({total - n} lost)" for (n, total), topics in short.items()]


CHUNK = 4096
"""Messages of a topic read by its layout at once: the raw bytes held stay small."""


@dataclass
class _ByLayout:
    """A contract topic whose messages are read by their fixed layout
    (:mod:`msg_tools.contract_cdr`), a chunk at a time, as long as they hold its constants."""

    layout: Layout
    msgtype: str
    columns: list[tuple[Source, str]]
    pending: list[tuple[int, bytes]] = field(default_factory=list)


def _by_layout(sources: list[Source], types: dict[str, str]) -> dict[str, _ByLayout]:
    """The bag's topics whose every source reads a contract field of its contract type."""
    plans: dict[str, _ByLayout] = {}
    refused = set()
    for source in sources:
        contract_topic, contract_field = CONTRACT_SOURCES[source.contract]
        if (source.field.text != contract_field
                or types[source.topic] != TOPIC_TYPES[contract_topic]):
            refused.add(source.topic)
            continue
        layout = LAYOUTS[contract_topic]
        plan = plans.setdefault(source.topic, _ByLayout(layout, types[source.topic], []))
        if plan.layout is not layout:
            refused.add(source.topic)
        plan.columns.append((source, COLUMNS[source.contract]))
    return {topic: plan for topic, plan in plans.items() if topic not in refused}


def _stream(reader: AnyReader, sources: list[Source]) -> tuple[dict[str, _Series],
                                                                Counter[str]]:
    """The contract columns of ``sources`` as they stream in, and the messages read per
    topic."""
    streams = _Streams(reader, sources)
    for connection, log_time, raw in reader.messages(connections=streams.wanted):
        streams.take(connection.topic, connection.msgtype, log_time, raw)
    streams.finish()
    return streams.series, streams.read


class _Streams:
    """Each source's column as the messages come: a contract topic's by its layout, a
    chunk at a time (the messages that leave it, and every other topic's, through
    rosbags one by one, in order)."""

    def __init__(self, reader: AnyReader, sources: list[Source]) -> None:
        self._reader = reader
        self._by_topic: dict[str, list[Source]] = {}
        for source in sources:
            self._by_topic.setdefault(source.topic, []).append(source)
        self._stamps = {topic: array("d") for topic in self._by_topic}
        self.series = {s.contract: _Series(self._stamps[s.topic]) for s in sources}
        self.wanted = [c for c in reader.connections if c.topic in self._by_topic]
        # a ROS 1 bag's messages are not CDR: through rosbags, all of them
        self._plans = _by_layout(sources, {c.topic: c.msgtype for c in self.wanted}
                                 ) if reader.is2 else {}
        self.read: Counter[str] = Counter()

    def take(self, topic: str, msgtype: str, log_time: int, raw: bytes) -> None:
        self.read[topic] += 1
        plan = self._plans.get(topic)
        if plan is not None and len(raw) == plan.layout.dtype.itemsize:
            plan.pending.append((log_time, bytes(raw)))
            if len(plan.pending) >= CHUNK:
                self._flush(topic, plan)
            return
        if plan is not None:
            self._flush(topic, plan)  # the messages before this one, first
        self._one(topic, msgtype, log_time, raw)

    def finish(self) -> None:
        for topic, plan in self._plans.items():
            self._flush(topic, plan)

    def _flush(self, topic: str, plan: _ByLayout) -> None:
        if not plan.pending:
            return
        rows = plan.layout.read(b"".join(raw for _, raw in plan.pending))
        if rows is None:
            for log_time, raw in plan.pending:
                self._one(topic, plan.msgtype, log_time, raw)
        else:
            _append_rows(rows, np.array([t for t, _ in plan.pending]), self._stamps[topic],
                         plan.columns, self.series)
        plan.pending.clear()

    def _one(self, topic: str, msgtype: str, log_time: int, raw: bytes) -> None:
        message = self._reader.deserialize(raw, msgtype)
        stamp, stamped = _stamp_s(message, log_time)
        self._stamps[topic].append(stamp)
        for source in self._by_topic[topic]:
            try:
                value, position = source.field.read(message)
            except (AttributeError, IndexError, TypeError) as exc:
                raise RunFormatError(f"{topic} has no field {source.field.text} "
                                     f"({type(exc).__name__}: {exc})") from None
            target = self.series[source.contract]
            target.values.append(value)
            target.positions |= position
            target.stamped |= stamped


def _append_rows(rows: np.ndarray, log_ns: np.ndarray, stamps: array,
                 columns: list[tuple[Source, str]], series: dict[str, _Series]) -> None:
    """Rows of a contract layout appended as :func:`_stamp_s` and ``FieldPath.read`` read
    each message: a header's stamp where it is set, else the log time."""
    stamped = (rows["sec"] != 0) | (rows["nanosec"] != 0)
    times = np.where(stamped, rows["sec"].astype(float) + rows["nanosec"] * 1e-9,
                     log_ns * 1e-9)
    stamps.frombytes(times.tobytes())
    for source, column in columns:
        values = rows[column].astype(float)
        if source.field.absolute:
            values = values - ATMOSPHERE_PA
        target = series[source.contract]
        target.values.frombytes(values.tobytes())
        target.stamped |= bool(stamped.any())


def _stamp_s(message: Any, log_time_ns: int) -> tuple[float, bool]:
    """(the header stamp, True), or (the log time, False) for a message without one."""
    header = getattr(message, "header", None)
    if header is not None and (header.stamp.sec or header.stamp.nanosec):
        return seconds_of_fields(header.stamp.sec, header.stamp.nanosec), True
    return log_time_ns * 1e-9, False


def _on_wheel_base(series: dict[str, _Series], sources: list[Source], where: str
                   ) -> dict[str, np.ndarray]:
    empty = [s.topic for s in sources if not series[s.contract].time_s]
    if empty:
        raise RunFormatError(f"{where}: bag has no messages on {', '.join(dict.fromkeys(empty))}")
    base = np.frombuffer(series["wheel_speed_rad_s"].time_s)
    fields = {"time_s": base}
    for source in sources:
        # each column's stream is let go once it is on the base: at the peak the streams
        # and one column, not the streams and the run (the bag's read had taken 2.2 times
        # the memory of the same run's CSV)
        fields[CSV_TO_FIELD[source.contract]] = _column(series.pop(source.contract), source,
                                                        base)
    return fields


def _command_in_force(times: np.ndarray, base: np.ndarray, stamped: bool) -> np.ndarray:
    """Index of the command in force over the interval that ends at each ``base`` time.

    A stamped command ends its interval at its stamp (the first stamp at or after t);
    a command known only by its log time (0.1's Float64) holds from then on (the last at
    or before t). The first rows take the first command, the last rows keep the last.
    """
    if stamped:
        index = np.searchsorted(times, base - 1e-6, side="left")
    else:
        index = np.searchsorted(times, base + 1e-6, side="right") - 1
    return np.clip(index, 0, times.size - 1)


def _column(series: _Series, source: Source, base: np.ndarray) -> np.ndarray:
    """The column of ``series`` on the ``base`` times, in SI (its values converted in
    place: the stream is let go after)."""
    times = np.frombuffer(series.time_s)
    channel = source.channel
    raw = np.frombuffer(series.values)
    values = channel.to_si(raw, None if channel.unit_declared else 1.0,  # messages carry SI
                           out=raw)
    if series.positions:
        values = speed_from_angle(times, values)
    if source.contract == "current_ref_A":
        return values[_command_in_force(times, base, series.stamped)]
    return np.interp(base, times, values)
