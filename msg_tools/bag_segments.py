"""A rosbag2 written in closed segments, so that a crash loses at most the open one.

The caller decides where a segment ends (:meth:`SegmentedBagWriter.roll`), so that
the same messages written in the same order give the same files. Each segment is a
complete storage file written by ``rosbags``; when a segment closes it is moved
into the bag folder and ``metadata.yaml`` is rewritten (atomically) to list every
closed segment. A reader (``rosbags``, ``ros2 bag info/play``, Foxglove
via the storage files) therefore always sees a valid bag: after ``SIGKILL`` it holds
everything up to the last closed segment. The open segment lives in a hidden
``.open_segment`` folder inside the bag and is never listed.

On :meth:`~SegmentedBagWriter.close` the segments are joined into one file (``join``,
default), which single-file viewers (Foxglove, PlotJuggler) prefer: the joined file is
listed in place of the segments in one atomic metadata write, then the segments go, so a
crash while joining still leaves the segmented bag. Every storage file is written in a
folder of its own final name, because mcap embeds the name (no temporary names inside).
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import yaml
from rosbags.rosbag2 import Reader, ReaderError, Writer

from .bag_io import BAG_VERSION, STORAGE, TYPESTORE
from .bag_recover import recovered
from .errors import RunFormatError

OPEN_SEGMENT = ".open_segment"
JOINING = ".joining"
META = "rosbag2_bagfile_information"


class SegmentedBagWriter:
    """Write raw CDR messages into a bag made of segments closed by :meth:`roll`.

    Args:
        path: new bag folder (must not exist).
        topics: ``{topic: message type}``, e.g.
            ``{"/rig/brake/current_ref": "std_msgs/msg/Float64"}``.
        storage: ``mcap`` or ``sqlite3``.
        join: on close, join the segments into one storage file.
    """

    def __init__(self, path: Path, topics: dict[str, str], storage: str = "mcap",
                 join: bool = True) -> None:
        if storage not in STORAGE:
            raise RunFormatError(f"unknown bag storage {storage!r}; use mcap or sqlite3")
        self.path = Path(path)
        if self.path.exists():
            raise RunFormatError(f"{self.path}: exists already, not overwriting")
        self.path.mkdir(parents=True)
        self._topics = dict(topics)
        self._storage = storage
        self._join = join
        self._closed: list[dict[str, Any]] = []
        self._writer: Writer | None = None
        self._connections: dict[str, Any] = {}
        self._count = 0

    @property
    def message_count(self) -> int:
        """Messages in closed segments (what a reader sees now)."""
        return sum(segment["message_count"] for segment in self._closed)

    def write(self, topic: str, log_time_ns: int, raw: bytes) -> None:
        """Append one serialized message to the open segment."""
        if self._writer is None:
            self._open()
        self._writer.write(self._connections[topic], log_time_ns, raw)  # type: ignore[union-attr]
        self._count += 1

    def roll(self) -> None:
        """Close the open segment (readers see it from now on); the next write opens one."""
        if self._writer is not None:
            self._close_segment()

    @property
    def joins(self) -> bool:
        """Whether :meth:`close` joins the segments (unless that close says not to)."""
        return self._join

    @property
    def segment_count(self) -> int:
        """Closed segments (storage files) the bag lists now."""
        return len(self._closed)

    def close(self, join: bool = True) -> None:
        """Close the open segment and join the segments (unless this writer or ``join``
        says not to: the segments stay, a complete bag all the same); the bag is complete.
        Safe to call twice."""
        if self._writer is not None:
            self._close_segment()
        if not self._closed:
            self._open()  # an empty run still leaves a readable bag
            self._close_segment(keep_empty=True)
        if join and self._join and self._closed[0]["relative_file_paths"][0].startswith(
                f"{self.path.name}_"):  # not joined yet (one segment too: one name always)
            self._join_segments()

    def _join_segments(self) -> None:
        files = [s["relative_file_paths"][0] for s in self._closed]
        self._closed = [_join(self.path, self.path, files, self._topics, self._storage)]

    def _open(self) -> None:
        shutil.rmtree(self.path / OPEN_SEGMENT, ignore_errors=True)
        # named as it will be in the bag (mcap embeds its file name)
        folder = self.path / OPEN_SEGMENT / f"{self.path.name}_{len(self._closed)}"
        writer = Writer(folder, version=BAG_VERSION, storage_plugin=STORAGE[self._storage])
        writer.open()
        self._connections = {topic: writer.add_connection(topic, kind, typestore=TYPESTORE)
                             for topic, kind in self._topics.items()}
        self._writer, self._count = writer, 0

    def _close_segment(self, keep_empty: bool = False) -> None:
        writer, self._writer = self._writer, None
        writer.close()  # type: ignore[union-attr]
        folder = writer.path  # type: ignore[union-attr]
        if self._count or keep_empty:
            info = yaml.safe_load((folder / "metadata.yaml").read_text())[META]
            name = info["relative_file_paths"][0]
            os.replace(folder / name, self.path / name)
            self._closed.append(info)
            self._write_metadata()
        shutil.rmtree(self.path / OPEN_SEGMENT, ignore_errors=True)

    def _write_metadata(self) -> None:
        merged = dict(self._closed[0])
        with_data = [s for s in self._closed if s["message_count"]] or self._closed
        start = min(s["starting_time"]["nanoseconds_since_epoch"] for s in with_data)
        end = max(s["starting_time"]["nanoseconds_since_epoch"] + s["duration"]["nanoseconds"]
                  for s in with_data)
        merged["starting_time"] = {"nanoseconds_since_epoch": start}
        merged["duration"] = {"nanoseconds": end - start}
        merged["message_count"] = self.message_count
        merged["relative_file_paths"] = [s["relative_file_paths"][0] for s in self._closed]
        merged["files"] = [s["files"][0] for s in self._closed]
        counts: dict[str, int] = {}
        for segment in self._closed:
            for entry in segment["topics_with_message_count"]:
                name = entry["topic_metadata"]["name"]
                counts[name] = counts.get(name, 0) + entry["message_count"]
        merged["topics_with_message_count"] = [
            {**entry, "message_count": counts[entry["topic_metadata"]["name"]]}
            for entry in self._closed[0]["topics_with_message_count"]]
        temporary = self.path / "metadata.yaml.tmp"
        temporary.write_text(yaml.safe_dump({META: merged}, sort_keys=False))
        os.replace(temporary, self.path / "metadata.yaml")


def join_bag(path: Path, say: Callable[[str], object] | None = None) -> tuple[int, int]:
    """Join an existing bag's storage files into one, as a writer's close does (a recording
    stopped by a signal keeps its segments): the joined file is listed in place of the
    segments in one atomic metadata write, then the segments go. ``say`` hears when a join
    starts (~11 µs a message: a 300 s run's 1.5 M take ~16 s). Returns the number of files
    joined (1: already one, nothing done) and of messages."""
    path = Path(path)
    with recovered([path]) as (readable, notes):
        for note in notes:  # a segment a crash cut short, read as metrics reads it
            if say is not None:
                say(f"{path}: {note}")
        try:
            info = yaml.safe_load((path / "metadata.yaml").read_text())[META]
            storage = info["storage_identifier"]
            files = info["relative_file_paths"]
            with Reader(readable[0]) as reader:
                topics = {c.topic: c.msgtype for c in reader.connections}
        except (OSError, KeyError, TypeError, yaml.YAMLError, ReaderError) as error:
            raise RunFormatError(f"{path}: not a readable rosbag2 folder ({error})"
                                 ) from error
        if storage not in STORAGE:
            raise RunFormatError(f"{path}: storage {storage!r} cannot be joined (mcap, "
                                 "sqlite3)")
        if len(files) > 1 or notes:
            if say is not None:
                say(f"joining {len(files)} segments ({info['message_count']} messages) …")
            info = _join(path, readable[0], files, topics, storage)
    return len(files), int(info["message_count"])


def _join(path: Path, source: Path, files: list[str], topics: dict[str, str],
          storage: str) -> dict[str, Any]:
    """Write the bag ``path``'s messages (read from ``source``: itself, or its recovered
    copy) into one storage file beside its segments (the storage ``files`` it lists), list
    it in their place, remove them; the joined file's metadata."""
    work = path / JOINING
    shutil.rmtree(work, ignore_errors=True)
    with Reader(source) as reader, Writer(work / path.name, version=BAG_VERSION,
                                        storage_plugin=STORAGE[storage]) as writer:
        connections = {topic: writer.add_connection(topic, kind, typestore=TYPESTORE)
                       for topic, kind in topics.items()}
        for connection, log_time_ns, raw in reader.messages():
            writer.write(connections[connection.topic], log_time_ns, raw)
    info: dict[str, Any] = yaml.safe_load((writer.path / "metadata.yaml").read_text())[META]
    name = info["relative_file_paths"][0]
    os.replace(writer.path / name, path / name)
    os.replace(writer.path / "metadata.yaml", path / "metadata.yaml")
    for segment in files:
        if segment != name:
            (path / segment).unlink()
    shutil.rmtree(work, ignore_errors=True)
    return info
