"""How :mod:`tiltlab.trig` reads per-sample inputs and labels its outputs.

Inputs go through :func:`tiltlab._validate.signal` with trig's defaults (any leading
shape, NaN propagates, ``fs`` and units only where asked for); outputs are labelled
exactly when the input was (:func:`tiltlab._validate.output`,
:func:`tiltlab._validate.windowed`).

Functions that take *angles* (radians) rather than sensor samples are wrapped by
:func:`angle_function`: a labelled :class:`xarray.DataArray` argument (e.g. the
``azimuth`` of :func:`tiltlab.trig.heading` or the ``yaw`` of
:func:`tiltlab.trig.body_rotations`) gives DataArrays back with its coordinates
(``time``) and its ``fs``; ``units`` must be radians (``"rad"``, or ``"1"``) or
degrees (``"deg"``, converted), and labelled arguments must share their ``time``
coordinate.
"""

from __future__ import annotations

import functools
import inspect

import numpy as np
import xarray as xr

from .. import _validate as _v
from .._validate import output as label
from .._validate import start_time, windowed

__all__ = [
    "read",
    "label",
    "start_time",
    "windowed",
    "pair",
    "first_labelled",
    "angle_function",
    "read_angles",
    "label_like",
]

read = functools.partial(_v.signal, need_fs=False, ndim=None, allow_nan=True)


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


_RAD = ("rad", "radian", "radians", "1", "")  # SI: rad = 1
_DEG = ("deg", "degree", "degrees", "°")


def read_angles(a: xr.DataArray, name: str, *, angle: bool = True):
    """Values (float array, ``time`` first) and the (transposed) DataArray of a labelled angle.

    With ``angle``, ``attrs["units"]`` must be radians or degrees (converted to radians);
    no units means radians. An ``fs`` attribute must be a valid sampling rate.
    """
    da = a.transpose("time", ...) if "time" in a.dims else a
    try:
        values = np.array(da.values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numeric, got dtype {da.dtype}") from None
    if "fs" in da.attrs:
        _v.check_fs(da.attrs["fs"], name=f"{name} attribute fs")
    units = da.attrs.get("units")
    if angle and units is not None:
        key = str(units).strip().lower()
        if key in _DEG:
            values = np.radians(values)
        elif key not in _RAD:
            raise ValueError(
                f"{name} must be an angle in rad (or deg), got units {units!r}"
            )
    return values, da


def label_like(values, da: xr.DataArray, name: str, units: str | None, attrs=None):
    """``values`` as a DataArray labelled like ``da`` (its dims and coordinates when the
    shapes agree, else its ``time`` coordinate), with ``fs`` (and ``method``) kept.
    """
    values = np.asarray(values)
    a: dict = {}
    for key in ("fs", "method"):
        if key in da.attrs:
            a[key] = da.attrs[key]
    if units is not None:
        a["units"] = units
    if attrs:
        a.update(attrs)
    if values.shape == da.shape:
        return xr.DataArray(values, dims=da.dims, coords=da.coords, name=name, attrs=a)
    if values.ndim == 0:
        return xr.DataArray(values, name=name, attrs=a)
    time = None
    if "time" in da.coords and da["time"].ndim == 1:
        time = np.asarray(da["time"].values)
    like = _v.Signal(
        np.empty(0), a.get("fs"), None, time, True, {}
    )  # labelled() reads time and fs only
    return _v.labelled(values, like, name, units=units, attrs=a)


def angle_function(names, *, units="rad", angles=None):
    """Decorator for per-sample functions of angles: labelled in, labelled out.

    ``names``: the output's name (a string) or names (one per element of a tuple
    result; a NamedTuple's own field names win). ``units``: the output units (one
    string, or one per output). ``angles``: the parameters that are angles (their
    ``units`` are checked and degrees converted); default all of them.

    Labelled arguments need not share a time axis (``azimuth_change`` takes two
    orientations at consecutive times); they must have matching lengths, and the output
    carries the first labelled argument's ``time``.
    """

    def deco(f):
        sig = inspect.signature(f)

        @functools.wraps(f)
        def wrapper(*args, **kwargs):
            if not any(isinstance(v, xr.DataArray) for v in (*args, *kwargs.values())):
                return f(*args, **kwargs)
            bound = sig.bind(*args, **kwargs)
            das = {}
            for k, v in bound.arguments.items():
                if isinstance(v, xr.DataArray):
                    is_angle = angles is None or k in angles
                    bound.arguments[k], das[k] = read_angles(v, k, angle=is_angle)
            try:
                np.broadcast_shapes(*(np.shape(bound.arguments[k]) for k in das))
            except ValueError:
                shapes = ", ".join(f"{k} {das[k].shape}" for k in das)
                raise ValueError(
                    f"labelled arguments must have matching lengths, got {shapes}"
                ) from None
            out = f(*bound.args, **bound.kwargs)
            like = next(iter(das.values()))
            if isinstance(out, tuple):
                fields = getattr(out, "_fields", None) or names
                us = [units] * len(out) if isinstance(units, str) else units
                vals = [
                    label_like(o, like, n, u)
                    for o, n, u in zip(out, fields, us, strict=True)
                ]
                return type(out)(*vals) if hasattr(out, "_fields") else tuple(vals)
            return label_like(out, like, names, units)

        return wrapper

    return deco
