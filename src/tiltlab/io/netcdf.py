"""NetCDF: lossless Recording round trip, and opening other projects' NetCDF files.

tiltlab writes NetCDF-4 (HDF5, h5netcdf engine). Files from other tools may be
NetCDF-4 or NetCDF-3 ("classic", read with scipy); :func:`netcdf_format` tells them
apart from their first bytes and :func:`open_netcdf` opens either.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import xarray as xr

from .. import schema
from ._common import PathLike, ReadError


_ATTRS_KEY = "_tiltlab_attrs_json"

_MAGIC = {
    b"CDF\x01": "NetCDF-3 classic",
    b"CDF\x02": "NetCDF-3 64-bit offset",
    b"CDF\x05": "NetCDF-3 64-bit data (CDF-5)",
}


def netcdf_format(path: PathLike) -> str | None:
    """The NetCDF flavour of a file from its first bytes, or None if it is not NetCDF.

    Parameters
    ----------
    path
        File to inspect.

    Returns
    -------
    str or None
        ``"NetCDF-4"`` (an HDF5 file), ``"NetCDF-3 classic"``, ``"NetCDF-3 64-bit
        offset"``, ``"NetCDF-3 64-bit data (CDF-5)"``, or None.
    """
    try:
        with open(path, "rb") as f:
            head = f.read(8)
    except OSError:
        return None
    if head == b"\x89HDF\r\n\x1a\n":
        return "NetCDF-4"
    return _MAGIC.get(head[:4])


def open_netcdf(path: PathLike) -> xr.Dataset:
    """Open any NetCDF file (NetCDF-4 or NetCDF-3) into memory, values as stored.

    Times are not decoded; the engine is chosen from the file's first bytes.

    Parameters
    ----------
    path
        A NetCDF file.

    Returns
    -------
    xarray.Dataset
        The file's content, loaded.

    Raises
    ------
    ReadError
        If the file is missing, not NetCDF, or damaged.
    """
    path = Path(path)
    if not path.is_file():
        raise ReadError(f"{path}: no such file")
    kind = netcdf_format(path)
    if kind is None:
        raise ReadError(
            f"{path}: not a NetCDF file (neither NetCDF-4/HDF5 nor NetCDF-3)"
        )
    if "CDF-5" in kind:
        raise ReadError(
            f"{path}: {kind} file, which the installed NetCDF engines cannot read; "
            "rewrite it as NetCDF-4 (nccopy -k nc4 IN OUT)"
        )
    engine = "h5netcdf" if kind == "NetCDF-4" else "scipy"
    try:
        with xr.open_dataset(
            path, engine=engine, decode_times=False, mask_and_scale=False
        ) as f:
            return f.load()
    except Exception as exc:  # noqa: BLE001 - engines raise many types on damage
        raise ReadError(
            f"{path}: cannot read {kind} file ({type(exc).__name__}: {exc}); "
            "truncated or corrupt?"
        ) from None


def is_recording(ds: xr.Dataset) -> bool:
    """True if an opened NetCDF file holds a tiltlab Recording (or a file tiltlab wrote)."""
    if _ATTRS_KEY in ds.attrs:
        return True
    return "acc" in ds.data_vars and "time" in ds.dims and "fs" in ds.attrs


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


def save_netcdf(ds: xr.Dataset, path: PathLike) -> Path:
    """Write a Dataset to NetCDF-4 (h5netcdf engine) so that :func:`load_netcdf` returns it exactly.

    NetCDF attributes cannot hold booleans, dicts or None, so every attribute (of the
    dataset, its variables and coordinates) is also stored as JSON and restored on load.
    """
    if not isinstance(ds, xr.Dataset):
        raise TypeError(
            f"save_netcdf writes a Recording (xarray.Dataset), got {type(ds).__name__}"
        )
    path = Path(path)
    out = ds.copy()
    record = {"__dataset__": dict(ds.attrs)}
    for name, var in ds.variables.items():
        record[str(name)] = dict(var.attrs)
    try:
        blob = json.dumps(record, default=_json_default)
    except TypeError as exc:
        raise ValueError(f"cannot save attributes: {exc}") from None
    out.attrs = {
        k: v
        for k, v in ds.attrs.items()
        if isinstance(v, (str, int, float, np.number)) and not isinstance(v, bool)
    }
    out.attrs[_ATTRS_KEY] = blob
    for name in out.variables:
        out[name].attrs = {
            k: v
            for k, v in ds[name].attrs.items()
            if isinstance(v, (str, int, float, np.number)) and not isinstance(v, bool)
        }
    path.parent.mkdir(parents=True, exist_ok=True)
    out.to_netcdf(path, engine="h5netcdf", invalid_netcdf=False)
    return path


class NotRecordingError(ReadError):
    """A readable file that is not a tiltlab Recording; the message says what it looks
    like and how to convert it."""

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
        return (NotRecordingError, (self.path, self.looks_like))


def _foreign(path: Path) -> str:
    from .detect import detect  # detect imports this module

    return detect(path)


def load_netcdf(
    path: PathLike, *, validate: bool = False, **validate_kwargs
) -> xr.Dataset:
    """Load a Dataset written by :func:`save_netcdf` (fully into memory).

    Parameters
    ----------
    validate : bool
        Also run :func:`tiltlab.schema.validate` (for Recordings).
    **validate_kwargs
        Passed to :func:`tiltlab.schema.validate` (``allow_nan`` defaults to whether the
        file holds NaN; ``check_units=False`` accepts the unit labels as they are).

    Raises
    ------
    NotRecordingError
        For a readable NetCDF file that is not a Recording (NetCDF-3, tag-tools …):
        the message says what it looks like and which command converts it.
    ReadError
        For a missing or damaged file.
    """
    path = Path(path)
    if not path.is_file():
        raise ReadError(f"{path}: no such file")
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
        from .tagtools import looks_like_tagtools

        if looks_like_tagtools(ds) or "session" not in ds.dims:
            raise NotRecordingError(path, _foreign(path))
    blob = ds.attrs.pop(_ATTRS_KEY, None)
    if blob is not None:
        record = json.loads(blob, object_hook=_json_hook)
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
