"""What a bag a recorder left mid-write holds, recovered as the storage's own tools do.

rosbags opens a ``.db3`` as an immutable file, so it never sees what sqlite keeps beside a
database it is writing: a write-ahead log (``-wal``) not yet checkpointed — its messages
are silently missing, half a run read as a whole one — or the hot rollback journal
(``-journal``) of a transaction under way when the recorder died — the database file then
reads as malformed. Opened by sqlite as a database, the log is applied and the unfinished
transaction rolled back.

An ``.mcap`` cut short has no footer, and rosbags reads nothing of it. Its records are read
in order with the mcap library's stream reader, as far as they go, and every complete
message (of a chunk cut through too, when it is not compressed) is written to a new file.

Both are done on a copy: the user's files are never changed.
"""

from __future__ import annotations

import contextlib
import io
import shutil
import sqlite3
import struct
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path

from mcap.exceptions import McapError
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, Header, McapRecord, Message, Schema
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.writer import CompressionType, Writer

JOURNALS = {"-wal": "applied its write-ahead log",
            "-journal": "rolled back an unfinished transaction"}
MAGIC = b"\x89MCAP0\r\n"
# a chunk record: opcode (1 byte) and length (8), then message start and end time,
# uncompressed size, crc, the compression's name (length-prefixed), the records' length
_RECORD_HEAD = struct.Struct("<BQ")
_CHUNK_HEAD = struct.Struct("<QQQI")


def _storage(path: Path, suffix: str) -> list[Path]:
    files = sorted(path.glob(f"*{suffix}")) if path.is_dir() else [path]
    return [f for f in files if f.suffix.lower() == suffix]


def _journals(database: Path) -> list[str]:
    return [suffix for suffix in JOURNALS if Path(f"{database}{suffix}").exists()]


def _cut(mcap: Path) -> bool:
    """Whether ``mcap`` lacks the magic an mcap file ends with (cut short)."""
    with mcap.open("rb") as stream:
        if stream.read(len(MAGIC)) != MAGIC:
            return False  # not an mcap at all: the reader says so
        stream.seek(-len(MAGIC), io.SEEK_END)
        return stream.read() != MAGIC


def _damaged(path: Path) -> list[Path]:
    return [d for d in _storage(path, ".db3") if _journals(d)] \
        + [m for m in _storage(path, ".mcap") if _cut(m)]


@contextlib.contextmanager
def recovered(paths: Sequence[Path]) -> Iterator[tuple[list[Path], list[str]]]:
    """``paths`` (bag folders or storage files) as rosbags can read all they hold, and
    what was done to them in words: unchanged when none is damaged, else recovered copies
    that live as long as the context."""
    damaged = [(i, f) for i, p in enumerate(paths) for f in _damaged(p)]
    if not damaged:
        yield list(paths), []
        return
    with tempfile.TemporaryDirectory(prefix="bag-recovery-") as folder:
        copies = [_copy(p, Path(folder)) for p in paths]
        notes = []
        for i, original in damaged:
            copy = copies[i] if copies[i].is_file() else copies[i] / original.name
            recover = _recover if original.suffix.lower() == ".db3" else _recover_mcap
            notes.append(recover(original, copy))
        yield copies, notes


def _copy(path: Path, folder: Path) -> Path:
    target = folder / path.name
    if path.is_dir():
        shutil.copytree(path, target)
        return target
    for suffix in ("", *JOURNALS):
        if Path(f"{path}{suffix}").exists():
            shutil.copy2(f"{path}{suffix}", f"{target}{suffix}")
    return target


def _recover(original: Path, copy: Path) -> str:
    """Recover ``copy`` (of ``original``) in place; what it held beyond its database file."""
    journals = _journals(copy)
    alone = _messages(f"file:{original}?immutable=1")
    with contextlib.closing(sqlite3.connect(copy)) as connection:
        # the first read applies a write-ahead log or rolls a hot journal back
        count = connection.execute("SELECT COUNT(*) FROM messages").fetchone()[0]
        connection.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    what = " and ".join(JOURNALS[j] for j in journals)
    alone_text = "unreadable" if alone is None else f"{alone} messages"
    return (f"{original.name}: {what} as sqlite does (on a copy): {count} messages; the "
            f"database file alone: {alone_text}")


def _messages(uri: str) -> int | None:
    """Messages in the database at ``uri``; None when it cannot be read."""
    try:
        with contextlib.closing(sqlite3.connect(uri, uri=True)) as connection:
            return int(connection.execute("SELECT COUNT(*) FROM messages").fetchone()[0])
    except sqlite3.DatabaseError:
        return None


def _recover_mcap(original: Path, copy: Path) -> str:
    """Rewrite ``copy`` (of the cut ``original``) with every complete message it holds."""
    with copy.open("wb") as stream:
        count = _rewrite(_records(original.read_bytes()), stream)
    return f"{original.name}: cut short (no footer); {count} complete messages recovered"


def _records(data: bytes) -> list[McapRecord]:
    """The records of a cut mcap file ``data`` as far as they are complete: those of
    complete chunks, and of an uncompressed chunk cut through."""
    stream = io.BytesIO(data)
    records: list[McapRecord] = []
    end = len(MAGIC)
    try:
        for record in StreamReader(stream, emit_chunks=True).records:
            records.extend(breakup_chunk(record) if isinstance(record, Chunk) else [record])
            end = stream.tell()
    except (McapError, EOFError, struct.error, ValueError):
        records.extend(_partial_chunk(data[end:]))
    return records


def _partial_chunk(data: bytes) -> list[McapRecord]:
    """The complete records at the start of a chunk record cut through (none if the chunk
    is compressed: its records cannot be read before its end)."""
    at = _RECORD_HEAD.size + _CHUNK_HEAD.size
    if len(data) < at + 4 or data[0] != Opcode.CHUNK:
        return []
    (name_length,) = struct.unpack_from("<I", data, at)
    if name_length:  # a compression's name: zstd, lz4
        return []
    inner = io.BytesIO(data[at + 4 + 8:])  # after the empty name and the records' length
    out: list[McapRecord] = []
    with contextlib.suppress(McapError, EOFError, struct.error, ValueError):
        for record in StreamReader(inner, skip_magic=True).records:
            out.append(record)
    return out


def _rewrite(records: Sequence[McapRecord], stream: io.BufferedWriter) -> int:
    """Write ``records`` (header, schemas, channels, messages) as a whole mcap file; the
    messages written."""
    header = next((r for r in records if isinstance(r, Header)), Header("ros2", ""))
    writer = Writer(stream, compression=CompressionType.NONE)
    writer.start(header.profile, header.library)
    schemas: dict[int, int] = {}
    channels: dict[int, int] = {}
    count = 0
    for record in records:
        if isinstance(record, Schema) and record.id not in schemas:
            schemas[record.id] = writer.register_schema(record.name, record.encoding,
                                                        record.data)
        elif isinstance(record, Channel) and record.id not in channels:
            channels[record.id] = writer.register_channel(
                record.topic, record.message_encoding, schemas.get(record.schema_id, 0),
                record.metadata)
        elif isinstance(record, Message) and record.channel_id in channels:
            writer.add_message(channels[record.channel_id], record.log_time, record.data,
                               record.publish_time, record.sequence)
            count += 1
    writer.finish()
    return count
