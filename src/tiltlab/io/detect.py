"""What is this file? Recognising data files, and one reader for all of them.

:func:`detect` names what a file looks like in one line (``"tiltlab Recording
(NetCDF)"``, ``"tag-tools NetCDF (variables A, M, P; 50 Hz)"``, ``"BROAD trial
(HDF5)"``, ``"MATLAB v7.3 file with variables accelBuffer(12243×4 double)"``, ``"CSV
with columns …"``); :func:`read` reads any file tiltlab knows into a Recording,
choosing the reader from the file's content rather than its name alone.
"""

from __future__ import annotations

import inspect
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import xarray as xr

from ._common import PathLike, ReadError, no_file
from .broad import _BROAD_VARS, read_broad
from .csv import read_csv
from .mat import describe_mat, list_variables, mat_version
from .netcdf import (
    NotRecordingError,
    is_recording,
    load_netcdf,
    netcdf_format,
    open_netcdf,
)
from .tagtools import _rate, read_tagtools, sensor_variables

__all__ = ["detect", "read", "TEXT_SUFFIXES"]

#: Suffixes read as delimited text (they need a column mapping).
TEXT_SUFFIXES = (".csv", ".tsv", ".txt", ".dat")


def _listing(items: list[str], limit: int = 8) -> str:
    shown = ", ".join(items[:limit])
    return shown + (f" … ({len(items) - limit} more)" if len(items) > limit else "")


def _describe_netcdf(path: Path, kind: str) -> str:
    ds = open_netcdf(path)
    if is_recording(ds):
        return "tiltlab Recording (NetCDF)"
    found = sensor_variables(ds)
    if found:
        names = list(found.values())
        rates = {}
        for n in names:
            try:
                rates[n] = _rate(ds[n], path)
            except ReadError:
                rates[n] = float("nan")
        distinct = sorted(set(rates.values()))
        if len(distinct) == 1:
            rate = f"{distinct[0]:g} Hz"
        else:
            rate = ", ".join(f"{n} {fs:g} Hz" for n, fs in rates.items())
        extra = "" if kind == "NetCDF-4" else f", {kind}"
        return f"tag-tools NetCDF (variables {', '.join(names)}; {rate}{extra})"
    variables = [f"{n}{tuple(ds[n].shape)}" for n in map(str, ds.data_vars)]
    return f"{kind} file with variables {_listing(variables) or 'none'}"


def _broad_like(names: set[str]) -> bool:
    return all(k in names for k in _BROAD_VARS)


def _describe_hdf5(path: Path) -> str:
    import h5py

    try:
        with h5py.File(path, "r") as f:
            names = [str(k) for k in f.keys()]
            shapes = {
                k: tuple(f[k].shape) for k in names if isinstance(f[k], h5py.Dataset)
            }
    except OSError as exc:
        raise ReadError(
            f"{path}: cannot read HDF5 file ({exc}); truncated or corrupt?"
        ) from None
    if _broad_like(set(names)):
        return "BROAD trial (HDF5)"
    listed = [f"{k}{shapes[k]}" if k in shapes else f"{k}/" for k in names]
    return f"HDF5 file with {_listing(listed) or 'nothing in it'}"


def _describe_text(path: Path) -> str:
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            head = [f.readline().rstrip("\r\n") for _ in range(2)]
    except OSError as exc:
        raise ReadError(f"{path}: cannot read ({exc})") from None
    if not head[0]:
        return "empty text file"
    line = head[0]
    sep = max((",", ";", "\t", "|"), key=line.count)
    if line.count(sep) == 0:
        return f"text file starting {line[:60]!r}"
    cols = [c.strip() for c in line.split(sep)]
    kind = {"\t": "TSV", ";": "CSV (';'-separated)", "|": "CSV ('|'-separated)"}.get(
        sep, "CSV"
    )
    return f"{kind} with columns {_listing(cols, 10)}"


def detect(path: PathLike) -> str:
    """One line saying what a data file looks like.

    Parameters
    ----------
    path
        Any file.

    Returns
    -------
    str
        E.g. ``"tiltlab Recording (NetCDF)"``, ``"tag-tools NetCDF (variables A, M,
        P; 50 Hz)"``, ``"BROAD trial (MATLAB v5)"``, ``"MATLAB v7.3 file with variables
        accelBuffer(12243×4 double)"``, ``"CSV with columns t, ax, ay, az"``.

    Raises
    ------
    ReadError
        If the file is missing or damaged beyond recognition.

    Examples
    --------
    >>> from tiltlab import io
    >>> io.detect("session.nc")  # doctest: +SKIP
    'tiltlab Recording (NetCDF)'
    """
    path = Path(path)
    if not path.is_file():
        raise ReadError(no_file(path))
    version = mat_version(path)
    if version is not None:
        names = {v[0] for v in list_variables(path)}
        if _broad_like(names):
            return f"BROAD trial (MATLAB v{version})"
        return describe_mat(path)
    kind = netcdf_format(path)
    if kind == "NetCDF-4":
        try:
            return _describe_netcdf(path, kind)
        except ReadError:
            return _describe_hdf5(path)  # HDF5 that is not NetCDF-4
    if kind is not None:
        if "CDF-5" in kind:
            return f"{kind} file"
        return _describe_netcdf(path, kind)
    if path.suffix.lower() in TEXT_SUFFIXES:
        return _describe_text(path)
    with open(path, "rb") as f:
        head = f.read(512)
    if head and b"\x00" not in head:
        return _describe_text(path)
    return f"file of unknown type ({path.suffix or 'no suffix'})"


def _mapping_dict(mapping: Mapping[str, Any] | PathLike) -> tuple[dict, Path | None]:
    if isinstance(mapping, Mapping):
        return dict(mapping), None
    p = Path(mapping)
    if not p.is_file():
        raise ReadError(f"{p}: no such mapping file")
    try:
        raw = json.loads(p.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise ReadError(
            f"{p}: mapping is not valid JSON (line {exc.lineno}, column {exc.colno}: "
            f"{exc.msg})"
        ) from None
    except UnicodeDecodeError as exc:
        raise ReadError(f"{p}: mapping is not UTF-8 text ({exc})") from None
    if not isinstance(raw, dict):
        raise ReadError(f"{p}: a mapping is a JSON object, got {type(raw).__name__}")
    return raw, p.parent


def _accepts(func, name: str) -> bool:
    try:
        return name in inspect.signature(func).parameters
    except (TypeError, ValueError):
        return False


def _no_frame_options(path: Path, options: Mapping[str, Any], what: str) -> None:
    other = sorted(k for k in options if k != "check_units")
    if other:
        raise ReadError(
            f"{path}: option(s) {', '.join(other)} do not apply to {what}, whose "
            "vectors are already in the sensor frame; leave them out"
        )


def read(
    source: PathLike,
    mapping: Mapping[str, Any] | PathLike | None = None,
    **options: Any,
) -> xr.Dataset:
    """Read any data file tiltlab knows into a validated Recording.

    Parameters
    ----------
    source
        A file: a tiltlab Recording (NetCDF), a tag-tools NetCDF archive, a BROAD trial
        (``.hdf5``/``.mat``), or a CSV (with ``mapping``). With a mapping that has
        ``"files"`` (one file per sensor), ``source`` may be the mapping itself or a
        folder the mapping's paths are relative to.
    mapping : dict or path, optional
        A column/unit mapping (:func:`tiltlab.io.read_csv_mapping`), or a multi-file
        mapping with ``"files"`` (:func:`tiltlab.io.read_multi`).
    **options
        Reader options: ``check_units`` (False accepts unit labels as they are, for
        every reader), ``axes``, ``preset`` and the chosen reader's own keywords.

    Returns
    -------
    xarray.Dataset
        The Recording.

    Raises
    ------
    ReadError
        If the file is missing, damaged, or of a kind that needs a mapping (the message
        says what the file looks like and what to give).

    Examples
    --------
    >>> from tiltlab import io
    >>> rec = io.read("deployment.nc")  # a tag-tools archive  # doctest: +SKIP
    >>> rec = io.read("session.csv", mapping="mapping.json")  # doctest: +SKIP
    """
    from .. import io as _io  # the package: read_multi lives there when available

    if mapping is not None:
        raw, base = _mapping_dict(mapping)
        if "files" in raw:
            read_multi = getattr(_io, "read_multi", None)
            if read_multi is None:
                raise ReadError(
                    'this mapping has "files" (one file per sensor), which needs '
                    "tiltlab.io.read_multi, not available in this version"
                )
            src = Path(source) if source is not None else None
            if src is not None and src.is_dir():
                base = src
            return read_multi(raw, base=base, **options)
        kwargs = dict(options)
        for key in ("check_units", "axes", "preset"):
            if key in kwargs and not _accepts(read_csv, key):
                raw[key] = kwargs.pop(key)
        return read_csv(source, mapping=raw, **kwargs)

    path = Path(source)
    if not path.is_file():
        raise ReadError(no_file(path))
    check_units = bool(options.get("check_units", True))
    version = mat_version(path)
    kind = netcdf_format(path) if version is None else None
    if kind is not None:
        try:
            ds = open_netcdf(path)
        except ReadError:
            if kind != "NetCDF-4":
                raise
            ds = None  # an HDF5 file that is not NetCDF-4 (a BROAD trial, say)
        if ds is not None:
            if is_recording(ds) and kind == "NetCDF-4":
                _no_frame_options(path, options, "a tiltlab Recording")
                return load_netcdf(path, validate=True, check_units=check_units)
            if sensor_variables(ds):
                return read_tagtools(path, **options)
            if not _broad_like(set(map(str, ds.variables))):
                raise NotRecordingError(path, detect(path))
    names: set[str] = set()
    if version is not None:
        names = {v[0] for v in list_variables(path)}
    elif kind == "NetCDF-4" or path.suffix.lower() in (".hdf5", ".h5"):
        import h5py

        try:
            with h5py.File(path, "r") as f:
                names = set(map(str, f.keys()))
        except OSError as exc:
            raise ReadError(
                f"{path}: cannot read HDF5 file ({exc}); truncated or corrupt?"
            ) from None
    if _broad_like(names):
        # BROAD trials are published in SI units that pass the checks; read_broad
        # takes dataset attributes only
        _no_frame_options(path, options, "a BROAD trial")
        return read_broad(path)
    what = detect(path)
    if path.suffix.lower() in TEXT_SUFFIXES or what.startswith(("CSV", "TSV")):
        raise ReadError(
            f"{path}: a {what}; give a column mapping (mapping=… in Python, --mapping "
            'M.json on the command line), e.g. {"columns": {"acc": ["ax", "ay", "az"]}, '
            '"units": {"acc": "g"}, "fs": 100}'
        )
    if version is not None:
        raise ReadError(
            f"{path}: a {what}; tiltlab reads MATLAB matrices through a mapping with "
            '"files" (one file per sensor, tiltlab.io.read_multi), or one matrix with '
            "tiltlab.io.read_matrix"
        )
    raise ReadError(f"{path}: a {what}, which tiltlab cannot read")
