"""Tables in the binary formats rigs and their tools write: MATLAB, HDF5, Parquet, MDF4, TDMS.

Each reader returns a :class:`~msg_tools.text_table.Table` of every 1-D numeric (or
datetime) column of one length, by name; MDF4 and TDMS also give their units. MATLAB v5
files need only scipy; the others use a well-kept library from the optional extra
``landing_gear_sim[formats]`` (h5py, pyarrow, asammdf, npTDMS), imported only when such a
file is read, with a one-line hint when it is missing.
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Iterable
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from .errors import RunFormatError
from .text_table import MASTER_TIME, Table

INSTALL_HINT = "pip install 'landing_gear_sim[formats]'"


def library(name: str, path: Path) -> ModuleType:
    """The optional library ``name`` for reading ``path``, or an error with the hint to
    install it."""
    try:
        return importlib.import_module(name)
    except ImportError:
        raise RunFormatError(f"{path}: reading {path.suffix} files needs {name.split('.')[0]}:"
                             f" {INSTALL_HINT}") from None


def _vectors(named: Iterable[tuple[str, Any]], units: dict[str, str] | None = None,
             notes: tuple[str, ...] = ()) -> Table:
    """The table of the 1-D numeric or datetime arrays among ``named`` of the most common
    length; the others' lengths kept (a vector 100 samples short had read as missing)."""
    arrays = {}
    for name, value in named:
        array = np.asarray(value).squeeze()
        if array.ndim == 1 and array.size >= 2 and array.dtype.kind in "fiuM":
            arrays[name] = array
    if not arrays:
        return Table({}, units or {}, notes)
    lengths = [a.size for a in arrays.values()]
    common = max(set(lengths), key=lengths.count)
    return Table({n: a for n, a in arrays.items() if a.size == common}, units or {}, notes,
                 other_lengths={n: a.size for n, a in arrays.items() if a.size != common})


def read_mat(path: Path) -> Table:
    """MATLAB: v5 through scipy; v7.3 (HDF5 inside) through h5py. Top-level vectors and
    the vector fields of top-level structs (as ``struct.field`` and ``field``)."""
    import scipy.io

    try:
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always", scipy.io.matlab.MatReadWarning)
            content = scipy.io.loadmat(path, squeeze_me=True, struct_as_record=False)
    except NotImplementedError:  # v7.3
        return read_hdf5(path)
    except Exception as exc:  # scipy raises many types for damaged files
        raise RunFormatError(f"{path}: cannot read MATLAB file ({exc or type(exc).__name__})"
                             ) from None
    named: list[tuple[str, Any]] = []
    for name, value in content.items():
        if name.startswith("__"):
            continue
        fields = getattr(value, "_fieldnames", None)
        if fields:
            named += [(f, getattr(value, f)) for f in fields]
            named += [(f"{name}.{f}", getattr(value, f)) for f in fields]
        else:
            named.append((name, value))
    # what scipy warned of reading it is the run's note, not a line on the user's terminal
    notes = tuple(f"{path}: {w.message}" for w in said
                  if issubclass(w.category, scipy.io.matlab.MatReadWarning))
    for w in said:  # any other warning as it came
        if not issubclass(w.category, scipy.io.matlab.MatReadWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return _vectors(named, notes=notes)


def read_hdf5(path: Path) -> Table:
    """HDF5 (and MATLAB v7.3): every 1-D dataset, by its path and by its last name."""
    h5py = library("h5py", path)
    named: list[tuple[str, Any]] = []

    def visit(name: str, node: Any) -> None:
        if isinstance(node, h5py.Dataset) and node.ndim <= 2 and min(node.shape or (0,)) >= 1:
            named.append((name, node[()]))
            named.append((name.rsplit("/", 1)[-1], named[-1][1]))

    try:
        with h5py.File(path, "r") as file:
            file.visititems(visit)
    except OSError as exc:
        raise RunFormatError(f"{path}: cannot read HDF5 file ({exc})") from None
    return _vectors(named)


def read_parquet(path: Path) -> Table:
    parquet = library("pyarrow.parquet", path)
    try:
        table = parquet.read_table(path)
    except Exception as exc:  # pyarrow raises its own error types
        raise RunFormatError(f"{path}: cannot read Parquet file ({exc})") from None
    return _vectors((n, table.column(n).to_numpy()) for n in table.column_names)


def read_mdf(path: Path) -> Table:
    """MDF 3/4: every channel of every group on the time base of the fastest group, the
    slower ones resampled onto it (said in a note); a name in several groups is taken from
    the fastest of them (asammdf refuses a bare duplicated name: the whole file was)."""
    asammdf = library("asammdf", path)
    try:
        with asammdf.MDF(path) as mdf:
            places = [(name, group, index) for name, found in mdf.channels_db.items()
                      for group, index in found if index != mdf.masters_db.get(group)]
            signals = mdf.select(places, raw=False) if places else []
    except Exception as exc:  # asammdf raises many types for damaged files
        raise RunFormatError(f"{path}: cannot read MDF file ({exc})") from None
    if not signals:
        raise RunFormatError(f"{path}: the MDF file holds no channel")
    chosen: dict[str, Any] = {}
    for signal in sorted(signals, key=lambda s: -_rate_hz(s.timestamps)):
        chosen.setdefault(signal.name, signal)
    base = max(chosen.values(), key=lambda s: _rate_hz(s.timestamps)).timestamps
    slower = sorted({round(_rate_hz(s.timestamps), 3) for s in chosen.values()
                     if not np.array_equal(s.timestamps, base)})
    named = [(MASTER_TIME, base)] + [
        (name, s.samples if np.array_equal(s.timestamps, base) else s.interp(base).samples)
        for name, s in chosen.items()]
    units = {s.name: s.unit for s in chosen.values() if s.unit}
    notes = (f"{path}: channels at {', '.join(f'{r:g}' for r in slower)} Hz resampled onto "
             f"the fastest group's {_rate_hz(base):g} Hz time base",) if slower else ()
    return _vectors(named, {MASTER_TIME: "s", **units}, notes)


def _rate_hz(timestamps: np.ndarray) -> float:
    span = float(timestamps[-1] - timestamps[0]) if timestamps.size > 1 else 0.0
    return (timestamps.size - 1) / span if span > 0 else 0.0


def read_tdms(path: Path) -> Table:
    """TDMS: every channel by name and ``group/name``; the time from the waveform
    properties of the first channel, used when no channel holds it."""
    nptdms = library("nptdms", path)
    try:
        channels = [c for g in nptdms.TdmsFile.read(path).groups() for c in g.channels()]
    except Exception as exc:  # npTDMS raises many types for damaged files
        raise RunFormatError(f"{path}: cannot read TDMS file ({exc})") from None
    named: list[tuple[str, Any]] = []
    units = {}
    for channel in channels:
        data = channel[:]
        named += [(channel.name, data), (f"{channel.group_name}/{channel.name}", data)]
        if str(channel.properties.get("unit_string", "")).strip():  # LabVIEW's default: ""
            units[channel.name] = str(channel.properties["unit_string"])
    if channels and "wf_increment" in channels[0].properties:
        try:
            named.append((MASTER_TIME, channels[0].time_track()))
            units[MASTER_TIME] = "s"
        except KeyError:  # wf_increment without wf_start_offset: no waveform time track
            pass
    return _vectors(named, units)


READERS: dict[str, Callable[[Path], Table]] = {
    ".mat": read_mat, ".h5": read_hdf5, ".hdf5": read_hdf5, ".hdf": read_hdf5,
    ".parquet": read_parquet, ".pq": read_parquet, ".mf4": read_mdf, ".mdf": read_mdf,
    ".tdms": read_tdms,
}
"""Lower-case file suffix → reader."""
