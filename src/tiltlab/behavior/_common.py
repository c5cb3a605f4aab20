"""How :mod:`tiltlab.behavior` reads per-sample inputs and labels its outputs.

A thin layer over :func:`tiltlab._validate.signal` / :func:`tiltlab._validate.labelled`:
inputs may be a Recording (the variable is read by name), a labelled DataArray or a
plain array; outputs are labelled exactly when the input was.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .. import _validate as _v


def read(
    data,
    name: str,
    *,
    var: str | None = None,
    fs=None,
    units: str | None = None,
    to_units: str | None = None,
    need_fs: bool = False,
    need_units: bool = False,
    width: int | None = 3,
    ndim: int | None = 2,
    allow_nan: bool = False,
) -> _v.Signal:
    """:func:`tiltlab._validate.signal`, with a labelled input put time-first."""
    if isinstance(data, xr.DataArray) and "time" in data.dims:
        data = data.transpose("time", ...)
    return _v.signal(
        data,
        name,
        var=var,
        fs=fs,
        units=units,
        to_units=to_units,
        need_fs=need_fs,
        need_units=need_units,
        width=width,
        ndim=ndim,
        allow_nan=allow_nan,
    )


def read_speed(speed, fs=None, *, units=None, need_fs: bool = False, allow_nan=False):
    """A 1-D angular speed in °/s.

    Labelled input: converted from its ``units`` attribute (required). Plain input:
    ``units`` if given, else °/s (the unit of every speed threshold in this package).
    """
    labelled = isinstance(speed, (xr.DataArray, xr.Dataset))
    if units is None and not labelled:
        units = "deg/s"
    return read(
        speed,
        "speed",
        fs=fs,
        units=units,
        to_units="deg/s",
        need_fs=need_fs,
        width=None,
        ndim=1,
        allow_nan=allow_nan,
    )


def label(values, like: _v.Signal, name: str, units: str | None = None, attrs=None):
    """Per-sample output: a DataArray (time, fs, units) when ``like`` was labelled."""
    if not like.labelled:
        return values
    return _v.labelled(np.asarray(values), like, name, units=units, attrs=attrs)


def start_time(like: _v.Signal) -> float:
    """Time (s) of the first sample of a labelled input (0 without a time coordinate)."""
    if like.time is not None and like.time.size:
        return float(like.time[0])
    return 0.0


def windowed(
    values, like: _v.Signal, name: str, *, centre_s, fs_out: float, units=None
):
    """One value per window: a DataArray over window-centre times when ``like`` was
    labelled (``centre_s`` relative to the first sample; ``fs_out`` = windows per s)."""
    if not like.labelled:
        return values
    values = np.asarray(values)
    dims = ("time", "axis") if values.ndim == 2 and values.shape[1] == 3 else ("time",)
    coords = {"time": start_time(like) + np.asarray(centre_s, float)}
    if "axis" in dims:
        coords["axis"] = ["x", "y", "z"]
    attrs = {"fs": float(fs_out)}
    if units is not None:
        attrs["units"] = units
    return xr.DataArray(values, dims=dims, coords=coords, name=name, attrs=attrs)
