"""How :mod:`tiltlab.behavior` reads per-sample inputs and labels its outputs.

Inputs go through :func:`tiltlab._validate.signal` (a Recording's variable, a labelled
DataArray or a plain array); outputs are labelled exactly when the input was
(:func:`tiltlab._validate.output`, :func:`tiltlab._validate.windowed`).
"""

from __future__ import annotations

import functools

import xarray as xr

from .. import _validate as _v
from .._validate import output as label
from .._validate import start_time, windowed

__all__ = [
    "read_behavior_input",
    "read_speed",
    "label",
    "start_time",
    "windowed",
    "need_gyr",
]

#: behavior's reading defaults: (N, 3) finite data; fs only where a function asks for it
read_behavior_input = functools.partial(_v.signal, need_fs=False)


def read_speed(speed, fs=None, *, units=None, need_fs: bool = False, allow_nan=False):
    """Read a 1-D angular speed in °/s.

    Labelled input: converted from its ``units`` attribute (required). Plain input:
    ``units`` if given, else °/s (the unit of every speed threshold in this package).

    Parameters
    ----------
    speed : xarray.DataArray or array_like (N,)
        Angular speed.
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    units : str, optional
        Units of a plain ``speed`` (default °/s).
    need_fs : bool
        Whether the sampling rate is required.
    allow_nan : bool
        Whether NaN samples are accepted.

    Returns
    -------
    tiltlab._validate.Signal
        The speed in °/s, with its ``fs``, time and attributes.
    """
    labelled = isinstance(speed, (xr.DataArray, xr.Dataset))
    if units is None and not labelled:
        units = "deg/s"
    return read_behavior_input(
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


def need_gyr(data, what: str, instead: str = "") -> None:
    """Refuse, naming ``what``, a Recording without a gyroscope.

    ``what`` needs the angular velocity (angular speed, circling); a Recording without
    ``gyr`` (most bio-logging tags) is a :class:`~tiltlab._validate.RecordingError`
    saying so and what to use ``instead``. Other inputs pass (they are read later).

    Parameters
    ----------
    data : object
        The input of ``what``: a Recording is checked, anything else passes.
    what : str
        The name of the read-out, for the message.
    instead : str
        What to use instead, appended to the message.
    """
    if isinstance(data, xr.Dataset) and "gyr" not in data:
        have = ", ".join(v for v in ("acc", "mag") if v in data) or "no sensor"
        tail = f"; {instead}" if instead else ""
        raise _v.RecordingError(
            f"{what} needs a gyroscope: the Recording has no 'gyr' variable "
            f"(it has {have}){tail}"
        )
