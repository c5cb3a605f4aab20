"""NetCDF: lossless Recording round trip, and opening other projects' NetCDF files.

tiltlab writes NetCDF-4 (HDF5, h5netcdf engine). Files from other tools may be
NetCDF-4 or NetCDF-3 ("classic", read with scipy); :func:`netcdf_format` tells them
apart from their first bytes and :func:`open_netcdf` opens either.

Checksums
---------
:func:`save_netcdf` stores, in the file attribute ``_tiltlab_sha256`` (JSON), the
SHA-256 of every variable (its dimensions, shape, dtype and value bytes, coordinates
included) and of the attribute record. :func:`load_netcdf` recomputes them and refuses
a file whose data changed since it was written (:class:`~tiltlab.io.IntegrityError`,
naming the file and the variable); ``verify=False`` skips the check to salvage what is
intact. Files written before checksums were stored load as before, unchecked;
:func:`netcdf_checksums` returns None for them and ``tiltlab validate`` says "no
checksum stored". The attribute is removed on load, so the round trip stays exact.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import xarray as xr

import tiltlab._deprecate as _deprecate
from .. import schema
from ._common import IntegrityError, PathLike, ReadError, no_file
from .tagtools import looks_like_tagtools
from .ncfile import _ATTRS_KEY, netcdf_format


#: File attribute holding the checksums written by :func:`save_netcdf` (JSON).
CHECKSUM_ATTR = "_tiltlab_sha256"


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return {"__ndarray__": o.tolist(), "dtype": str(o.dtype)}
    raise TypeError(
        f"attribute value {o!r} of type {type(o).__name__} cannot be stored"
    )


def _json_hook(d):
    if "__ndarray__" in d:
        return np.asarray(d["__ndarray__"], dtype=d["dtype"])
    return d


def _variable_digest(var: xr.Variable) -> str:
    """SHA-256 of a variable as it reads back: dimensions, shape, dtype and values.

    Numbers are hashed as their little-endian bytes (NaNs made canonical, so a NaN's
    payload does not count), times as int64 nanoseconds, text as UTF-8 JSON (str and
    bytes alike, as NetCDF gives either back).
    """
    a = np.asarray(var.values)
    kind = a.dtype.kind
    if kind in "biufc":
        a = np.ascontiguousarray(a, dtype=a.dtype.newbyteorder("<"))
        if kind in "fc":
            nan = np.isnan(a)
            if nan.any():
                a = a.copy()
                a[nan] = np.nan
        tag, payload = a.dtype.str, a
    elif kind in "mM":
        unit = "timedelta64[ns]" if kind == "m" else "datetime64[ns]"
        tag = unit
        payload = np.ascontiguousarray(a.astype(unit).view("<i8"))
    else:  # text (U, S, object) and anything else: by value, as text
        items = [
            x.decode("utf-8", "surrogateescape") if isinstance(x, bytes) else str(x)
            for x in a.ravel().tolist()
        ]
        tag = "text"
        payload = json.dumps(items, ensure_ascii=False).encode("utf-8", "surrogatepass")
    head = {"dims": [str(d) for d in var.dims], "shape": list(a.shape), "dtype": tag}
    h = hashlib.sha256(json.dumps(head, sort_keys=True).encode() + b"\0")
    h.update(payload)  # one pass over the raw bytes, no copy for contiguous numbers
    return h.hexdigest()


def _checksum_record(ds: xr.Dataset, blob: str) -> dict:
    return {
        "algorithm": "sha256",
        "attrs": hashlib.sha256(blob.encode("utf-8")).hexdigest(),
        "variables": {
            str(name): _variable_digest(var) for name, var in ds.variables.items()
        },
    }


def netcdf_checksums(path: PathLike) -> dict | None:
    """Read the checksums :func:`save_netcdf` stored in a file, or None if it has none.

    Reads the one attribute only (the data are not read, nor checked: that is what
    :func:`load_netcdf` does). Files written before tiltlab stored checksums, and
    files written by other tools, have none.

    Parameters
    ----------
    path : path-like
        A NetCDF-4 file.

    Returns
    -------
    dict or None
        ``{"algorithm": "sha256", "attrs": HEX, "variables": {name: HEX, ...}}``.

    Raises
    ------
    ReadError
        If the file cannot be read as HDF5 / NetCDF-4.
    IntegrityError
        If the attribute is there but unreadable (damaged).
    """
    import h5py

    path = Path(path)
    if not path.is_file():
        raise ReadError(no_file(path))
    try:
        with h5py.File(path, "r") as f:
            raw = f.attrs.get(CHECKSUM_ATTR)
    except OSError as exc:
        raise ReadError(
            f"{path}: cannot read NetCDF-4 file ({exc}); truncated or corrupt?"
        ) from None
    if raw is None:
        return None
    return _parse_record(path, raw)


def _parse_record(path: Path, raw) -> dict:
    if isinstance(raw, bytes):
        raw = raw.decode("utf-8", "replace")
    try:
        record = json.loads(str(raw))
        ok = (
            isinstance(record, dict)
            and record.get("algorithm") == "sha256"
            and isinstance(record.get("attrs"), str)
            and isinstance(record.get("variables"), dict)
            and all(isinstance(v, str) for v in record["variables"].values())
        )
    except ValueError:
        ok = False
    if not ok:
        raise IntegrityError(
            f"{path}: its checksum record (attribute {CHECKSUM_ATTR}) is damaged; "
            "tiltlab.io.load_netcdf(path, verify=False) reads the file without "
            "checking it",
            path=path,
        )
    return record


def _verify(path: Path, ds: xr.Dataset, record: dict, blob: str | None) -> None:
    """Compare a loaded file (before its attributes are restored) with its record."""
    salvage = (
        "tiltlab.io.load_netcdf(path, verify=False) reads it anyway, to salvage what "
        "is intact"
    )
    stored = record["variables"]
    for name, var in ds.variables.items():
        name = str(name)
        if name not in stored:
            raise IntegrityError(
                f"{path}: variable {name!r} has no stored checksum (added after "
                f"the file was written?); {salvage}",
                path=path,
                variable=name,
            )
        got = _variable_digest(var)
        if got != stored[name]:
            raise IntegrityError(
                f"{path}: checksum mismatch in variable {name!r} (sha256 {got[:12]}…, "
                f"stored {stored[name][:12]}…): its data changed after the file was "
                f"written (corrupted or altered); {salvage}",
                path=path,
                variable=name,
            )
    missing = sorted(set(stored) - {str(n) for n in ds.variables})
    if missing:
        raise IntegrityError(
            f"{path}: variable {missing[0]!r} has a stored checksum but is missing "
            f"from the file; {salvage}",
            path=path,
            variable=missing[0],
        )
    got = None if blob is None else hashlib.sha256(blob.encode("utf-8")).hexdigest()
    if got != record["attrs"]:
        raise IntegrityError(
            f"{path}: checksum mismatch in the attributes ({_ATTRS_KEY}): they changed "
            f"after the file was written; {salvage}",
            path=path,
        )


@_deprecate.renamed(ds="rec")
def save_netcdf(rec: xr.Dataset, path: PathLike) -> Path:
    """Write a Dataset to NetCDF-4 (h5netcdf) so that :func:`load_netcdf` returns it exactly.

    NetCDF attributes cannot hold booleans, dicts or None, so every attribute (of the
    dataset, its variables and coordinates) is also stored as JSON and restored on load.
    The SHA-256 of every variable and of the attributes is stored too (file attribute
    ``_tiltlab_sha256``), and checked by :func:`load_netcdf`. Values are written as
    they are in memory: encodings carried over from a file the Dataset was read from
    (scale factors, packed dtypes, fill values …) are not applied.

    Parameters
    ----------
    rec : xarray.Dataset
        The Dataset (a Recording, or any other).
    path : path-like
        The file to write (replaced if it exists).

    Returns
    -------
    Path
        The file written.
    """
    if not isinstance(rec, xr.Dataset):
        raise TypeError(
            f"save_netcdf writes a Recording (xarray.Dataset), got {type(rec).__name__}"
        )
    path = Path(path)
    out = rec.copy()
    record = {"__dataset__": dict(rec.attrs)}
    for name, var in rec.variables.items():
        record[str(name)] = dict(var.attrs)
    try:
        blob = json.dumps(record, default=_json_default)
    except TypeError as exc:
        raise ValueError(f"cannot save attributes: {exc}") from None
    out.attrs = {
        k: v
        for k, v in rec.attrs.items()
        if isinstance(v, (str, int, float, np.number)) and not isinstance(v, bool)
    }
    out.attrs[_ATTRS_KEY] = blob
    for name, var in out.variables.items():
        var.attrs = {
            k: v
            for k, v in rec[name].attrs.items()
            if isinstance(v, (str, int, float, np.number)) and not isinstance(v, bool)
        }
        # lossy encodings (int16 packing, fill values, coarse time units) would make
        # the file differ from memory: write the values as they are
        var.encoding = {}
    out.attrs[CHECKSUM_ATTR] = json.dumps(_checksum_record(out, blob))
    path.parent.mkdir(parents=True, exist_ok=True)
    out.to_netcdf(path, engine="h5netcdf", invalid_netcdf=False)
    return path


class NotRecordingError(ReadError):
    """A readable file that is not a tiltlab Recording.

    The message says what it looks like and how to convert it.
    """

    def __init__(self, path: PathLike, looks_like: str):
        self.path = Path(path)
        self.looks_like = looks_like
        if looks_like.startswith(("tag-tools", "BROAD")):
            how = (
                f"convert it with `tiltlab convert {path} --out session.nc`, or read "
                "it in Python with tiltlab.io.read(path)"
            )
        else:
            how = (
                "tiltlab reads NetCDF Recordings written by tiltlab.io.save_netcdf and "
                "tag-tools archives (variables A, M … with a sampling_rate); build a "
                "Recording with tiltlab.schema.make_recording and save it"
            )
        super().__init__(
            f"{path}: not a tiltlab Recording (it looks like: {looks_like}); {how}"
        )

    def __reduce__(self):
        """Pickle the error by its path and what the file looks like."""
        return (NotRecordingError, (self.path, self.looks_like))


def _foreign(path: Path) -> str:
    from .describe import detect

    return detect(path)


def load_netcdf(
    path: PathLike, *, validate: bool = False, verify: bool = True, **validate_kwargs
) -> xr.Dataset:
    """Load a Dataset written by :func:`save_netcdf` (fully into memory).

    The checksums stored by :func:`save_netcdf` are verified: a variable (or the
    attributes) whose content changed since the file was written is refused. Files
    without checksums (written before tiltlab stored them, or by other tools) load
    as they are, unchecked; :func:`netcdf_checksums` tells which a file is.

    Parameters
    ----------
    path : path-like
        The file.
    validate : bool
        Also run :func:`tiltlab.schema.validate` (for Recordings).
    verify : bool
        Check the stored checksums (default). ``verify=False`` loads a damaged file
        anyway, e.g. to salvage its intact variables: the values are as read.
    **validate_kwargs
        Passed to :func:`tiltlab.schema.validate` (``allow_nan`` defaults to whether the
        file holds NaN; ``check_units=False`` accepts the unit labels as they are).

    Returns
    -------
    xarray.Dataset
        The Dataset as saved, loaded into memory, attributes restored.

    Raises
    ------
    NotRecordingError
        For a readable NetCDF file that is not a Recording (NetCDF-3, tag-tools …):
        the message says what it looks like and which command converts it.
    IntegrityError
        For a file whose checksums do not match (a :class:`ReadError`): the message
        names the file and the variable.
    ReadError
        For a missing or damaged file.
    """
    path = Path(path)
    if not path.is_file():
        raise ReadError(no_file(path))
    kind = netcdf_format(path)
    if kind is not None and kind != "NetCDF-4":
        raise NotRecordingError(path, _foreign(path))
    try:
        with xr.open_dataset(path, engine="h5netcdf") as f:
            ds = f.load()
    except Exception as exc:
        raise ReadError(
            f"{path}: cannot read NetCDF file ({type(exc).__name__}: {exc}); truncated or corrupt?"
        ) from None
    if _ATTRS_KEY not in ds.attrs and ("time" not in ds.dims or "acc" not in ds):
        # not written by tiltlab, and no Recording layout: say what it is instead of
        # failing later on a missing 'time' or 'acc'
        if looks_like_tagtools(ds) or "session" not in ds.dims:
            raise NotRecordingError(path, _foreign(path))
    raw_sums = ds.attrs.pop(CHECKSUM_ATTR, None)
    blob = ds.attrs.pop(_ATTRS_KEY, None)
    if raw_sums is not None and verify:
        _verify(path, ds, _parse_record(path, raw_sums), blob)
    if blob is not None:
        try:
            record = json.loads(blob, object_hook=_json_hook)
        except ValueError as exc:
            raise ReadError(
                f"{path}: its attribute record ({_ATTRS_KEY}) is damaged ({exc})"
            ) from None
        ds.attrs = record.pop("__dataset__")
        for name, a in record.items():
            if name in ds.variables:
                ds[name].attrs = a
    for name in ds.variables:
        ds[name].encoding = {}
    if validate:
        allow_nan = any(
            bool(np.isnan(ds[v].values).any())
            for v in ds.data_vars
            if ds[v].dtype.kind == "f"
        )
        schema.validate(ds, **{"allow_nan": allow_nan, **validate_kwargs})
    return ds
