"""What is this file? Recognising data files, and one reader for all of them.

:func:`detect` names what a file looks like in one line (``"tiltlab Recording
(NetCDF)"``, ``"tag-tools NetCDF (variables A, M, P; 50 Hz)"``, ``"BROAD trial
(HDF5)"``, ``"MATLAB v7.3 file with variables accelBuffer(12243×4 double)"``, ``"CSV
with columns …"``); :func:`read` reads any file tiltlab knows into a Recording,
choosing the reader from the file's content rather than its name alone.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import xarray as xr

from ._common import PathLike, ReadError, no_file
from .broad import read_broad
from .csv import read_csv
from .mapping import CsvMapping
from .mat import list_variables, mat_version
from .describe import TEXT_SUFFIXES, _broad_like, detect
from .ncfile import is_recording, netcdf_format, open_netcdf
from .multi import read_multi
from .netcdf import NotRecordingError, load_netcdf
from .tagtools import read_tagtools, sensor_variables

__all__ = ["detect", "read", "TEXT_SUFFIXES"]


def _mapping_dict(
    mapping: Mapping[str, Any] | PathLike | CsvMapping,
) -> tuple[dict, Path | None]:
    if isinstance(mapping, CsvMapping):
        return mapping.to_dict(), None
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
    r"""Read any data file tiltlab knows into a validated Recording.

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
    A CSV needs a mapping; a Recording saved by tiltlab is recognised by its content:

    >>> import tempfile, pathlib
    >>> from tiltlab import io
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> rows = ["ax,ay,az"] + ["0,0,1"] * 50
    >>> _ = (d / "still.csv").write_text("\n".join(rows))
    >>> rec = io.read(d / "still.csv", {"columns": {"acc": ["ax", "ay", "az"]},
    ...                                 "units": {"acc": "g"}, "fs": 25})
    >>> rec.sizes["time"], rec.attrs["fs"]
    (50, 25.0)
    >>> _ = io.save_netcdf(rec, d / "still.nc")
    >>> float(io.read(d / "still.nc").acc[-1, 2])
    1.0
    """
    if mapping is not None:
        return _read_mapped(source, mapping, options)
    path = Path(source)
    if not path.is_file():
        raise ReadError(no_file(path))
    version = mat_version(path)
    kind = netcdf_format(path) if version is None else None
    if kind is not None:
        rec = _read_netcdf_kind(path, kind, options)
        if rec is not None:
            return rec
    if _broad_like(_hdf5_or_mat_names(path, version, kind)):
        # BROAD trials are published in SI units that pass the checks; read_broad
        # takes dataset attributes only
        _no_frame_options(path, options, "a BROAD trial")
        return read_broad(path)
    raise _refusal(path, version)


def _read_mapped(
    source: PathLike | None,
    mapping: Mapping[str, Any] | PathLike | CsvMapping,
    options: dict[str, Any],
) -> xr.Dataset:
    """Read through a mapping: one CSV, or one file per sensor (``"files"``)."""
    raw, base = _mapping_dict(mapping)
    if "files" in raw:
        src = Path(source) if source is not None else None
        if src is not None and src.is_dir():
            base = src
        return read_multi(raw, base=base, **options)
    return read_csv(source, mapping=raw, **options)


def _read_netcdf_kind(
    path: Path, kind: str, options: Mapping[str, Any]
) -> xr.Dataset | None:
    """Read a tiltlab Recording or a tag-tools archive; None for another HDF5 file."""
    try:
        ds = open_netcdf(path)
    except ReadError:
        if kind != "NetCDF-4":
            raise
        return None  # an HDF5 file that is not NetCDF-4 (a BROAD trial, say)
    if is_recording(ds) and kind == "NetCDF-4":
        _no_frame_options(path, options, "a tiltlab Recording")
        check_units = bool(options.get("check_units", True))
        return load_netcdf(path, validate=True, check_units=check_units)
    if sensor_variables(ds):
        return read_tagtools(path, **options)
    if not _broad_like(set(map(str, ds.variables))):
        raise NotRecordingError(path, detect(path))
    return None


def _hdf5_or_mat_names(path: Path, version: str | None, kind: str | None) -> set[str]:
    """List the variables of a MATLAB file, or the top-level names of an HDF5 file."""
    if version is not None:
        return {v[0] for v in list_variables(path)}
    if kind != "NetCDF-4" and path.suffix.lower() not in (".hdf5", ".h5"):
        return set()
    import h5py

    try:
        with h5py.File(path, "r") as f:
            return set(map(str, f.keys()))
    except OSError as exc:
        raise ReadError(
            f"{path}: cannot read HDF5 file ({exc}); truncated or corrupt?"
        ) from None


def _refusal(path: Path, version: str | None) -> ReadError:
    """Why a file tiltlab recognises no reader for is refused, and what to give."""
    what = detect(path)
    if path.suffix.lower() in TEXT_SUFFIXES or what.startswith(("CSV", "TSV")):
        return ReadError(
            f"{path}: a {what}; give a column mapping (mapping=… in Python, --mapping "
            'M.json on the command line), e.g. {"columns": {"acc": ["ax", "ay", "az"]}, '
            '"units": {"acc": "g"}, "fs": 100}'
        )
    if version is not None:
        return ReadError(
            f"{path}: a {what}; tiltlab reads MATLAB matrices through a mapping with "
            '"files" (one file per sensor, tiltlab.io.read_multi), or one matrix with '
            "tiltlab.io.read_matrix"
        )
    return ReadError(f"{path}: a {what}, which tiltlab cannot read")
