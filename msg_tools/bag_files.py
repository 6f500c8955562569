"""Which files a rosbag2 is stored in: what tells a bag from another run's file without
reading it (``rosbags``' import, 0.2 s, is paid only by a bag that is read)."""

from __future__ import annotations

from pathlib import Path

STORAGE_SUFFIXES = (".mcap", ".db3")


def storage_files(folder: Path) -> list[Path]:
    """The rosbag2 storage files (``.mcap``, ``.db3``) directly in ``folder``, sorted."""
    return sorted(p for p in folder.iterdir() if p.suffix.lower() in STORAGE_SUFFIXES)
