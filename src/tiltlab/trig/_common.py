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

import tiltlab._validate as _v
from .._validate import output as label
from .._frames_lab import _angle_units, _label_as, _label_attrs
from .._validate import start_time, windowed

__all__ = [
    "read_input",
    "label",
    "start_time",
    "windowed",
    "pair",
    "first_labelled",
    "angle_function",
    "read_angles",
    "label_like",
]


def read_input(data, name: str, **options) -> _v.Signal:
    """Read one per-sample input with trig's defaults (:func:`tiltlab._validate.signal`).

    Parameters
    ----------
    data : xarray.Dataset, xarray.DataArray or array_like
        A Recording, a labelled DataArray or a plain array.
    name : str
        The argument name (used in messages, and the Recording variable read).
    **options
        Keyword options of :func:`tiltlab._validate.signal`; trig's defaults are
        ``need_fs=False``, ``ndim=None`` and ``allow_nan=True``.

    Returns
    -------
    tiltlab._validate.Signal
        The checked values with their ``fs``, units, time and labelling.
    """
    kw = {"need_fs": False, "ndim": None, "allow_nan": True, **options}
    return _v.signal(data, name, **kw)


def pair(acc, mag):
    """Return the magnetometer input: ``mag``, or the Recording ``acc`` when ``mag`` is None.

    Parameters
    ----------
    acc : xarray.Dataset, xarray.DataArray or array_like
        The acceleration argument (a Recording holding ``mag`` too, or not).
    mag : xarray.DataArray, array_like or None
        The magnetometer argument.

    Returns
    -------
    xarray.Dataset, xarray.DataArray or array_like
        What to read the magnetic field from.
    """
    if mag is not None:
        return mag
    if isinstance(acc, xr.Dataset):
        return acc
    raise ValueError("mag is required unless acc is a Recording with a 'mag' variable")


def first_labelled(*signals: _v.Signal) -> _v.Signal:
    """Return the first labelled signal (to label an output), else the first one.

    Parameters
    ----------
    *signals : tiltlab._validate.Signal
        Inputs read by :func:`read_input`.

    Returns
    -------
    tiltlab._validate.Signal
        The first one that is labelled, else ``signals[0]``.
    """
    for s in signals:
        if s.labelled:
            return s
    return signals[0]


def read_angles(a: xr.DataArray, name: str, *, angle: bool = True):
    """Return the values (float array, ``time`` first) and the DataArray of a labelled angle.

    With ``angle``, ``attrs["units"]`` must be radians or degrees (converted to radians);
    no units means radians. An ``fs`` attribute must be a valid sampling rate.

    Parameters
    ----------
    a : xarray.DataArray
        The labelled argument.
    name : str
        Its name, used in messages.
    angle : bool, optional
        Whether it is an angle (its units are then checked; default True).

    Returns
    -------
    values : numpy.ndarray
        The values in rad (or as given when ``angle`` is False), ``time`` first.
    da : xarray.DataArray
        ``a`` with ``time`` moved first.
    """
    da = a.transpose("time", ...) if "time" in a.dims else a
    try:
        values = np.array(da.values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numeric, got dtype {da.dtype}") from None
    if "fs" in da.attrs:
        _v.check_fs(da.attrs["fs"], name=f"{name} attribute fs")
    if angle and _angle_units(da, name) == "deg":
        values = np.radians(values)
    return values, da


def label_like(values, da: xr.DataArray, name: str, units: str | None, attrs=None):
    """Label ``values`` like ``da``, keeping its ``fs`` (and ``method``).

    The output has ``da``'s dims and coordinates when the shapes agree, else its
    ``time`` coordinate.

    Parameters
    ----------
    values : array_like
        The output values.
    da : xarray.DataArray
        The labelled input to copy labels from.
    name : str
        The output's name.
    units : str or None
        The output's units.
    attrs : dict, optional
        Further attributes.

    Returns
    -------
    xarray.DataArray
        ``values`` labelled like ``da``.
    """
    values = np.asarray(values)
    if values.shape == da.shape:
        return _label_as(values, da, name, units, attrs)
    a = _label_attrs(da, units, attrs)
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
    """Wrap a per-sample function of angles: labelled in, labelled out.

    ``names``: the output's name (a string) or names (one per element of a tuple
    result; a NamedTuple's own field names win). ``units``: the output units (one
    string, or one per output). ``angles``: the parameters that are angles (their
    ``units`` are checked and degrees converted); default all of them.

    Labelled arguments need not share a time axis (``azimuth_change`` takes two
    orientations at consecutive times); they must have matching lengths, and the output
    carries the first labelled argument's ``time``.

    Parameters
    ----------
    names : str or tuple of str
        The output's name(s).
    units : str or sequence of str, optional
        The output's units (default ``"rad"``).
    angles : sequence of str, optional
        The parameters that are angles (default all).

    Returns
    -------
    callable
        The decorator.
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
