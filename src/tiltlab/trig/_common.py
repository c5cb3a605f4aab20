"""How :mod:`tiltlab.trig` reads per-sample inputs and labels its outputs.

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
    ndim: int | None = None,
    allow_nan: bool = True,
) -> _v.Signal:
    """:func:`tiltlab._validate.signal` with trig's defaults (any leading shape, NaN
    propagates, ``fs`` and units only where asked for)."""
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


def label(values, like: _v.Signal, name: str, units: str | None = None):
    """Per-sample output: a DataArray (time, fs, units) when ``like`` was labelled."""
    if not like.labelled:
        return values
    values = np.asarray(values)
    if values.ndim == 0:
        return xr.DataArray(
            values, name=name, attrs={} if units is None else {"units": units}
        )
    return _v.labelled(values, like, name, units=units)


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


def pair(acc, mag):
    """The magnetometer input: ``mag``, or the Recording ``acc`` when ``mag`` is None."""
    if mag is not None:
        return mag
    if isinstance(acc, xr.Dataset):
        return acc
    raise ValueError("mag is required unless acc is a Recording with a 'mag' variable")


def first_labelled(*signals: _v.Signal) -> _v.Signal:
    """The first labelled signal (to label an output), else the first one."""
    for s in signals:
        if s.labelled:
            return s
    return signals[0]
