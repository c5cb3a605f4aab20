"""NetCDF: lossless Recording round trip."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import xarray as xr

from .. import schema
from ._common import PathLike, ReadError


_ATTRS_KEY = "_tiltlab_attrs_json"


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
        file holds NaN).
    """
    path = Path(path)
    if not path.is_file():
        raise ReadError(f"{path}: no such file")
    try:
        with xr.open_dataset(path, engine="h5netcdf") as f:
            ds = f.load()
    except Exception as exc:
        raise ReadError(
            f"{path}: cannot read NetCDF file ({type(exc).__name__}: {exc}); truncated or corrupt?"
        ) from None
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
