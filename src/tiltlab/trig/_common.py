"""How :mod:`tiltlab.trig` reads per-sample inputs and labels its outputs.

Inputs go through :func:`tiltlab._validate.signal` with trig's defaults (any leading
shape, NaN propagates, ``fs`` and units only where asked for); outputs are labelled
exactly when the input was (:func:`tiltlab._validate.output`,
:func:`tiltlab._validate.windowed`).
"""

from __future__ import annotations

import functools

import xarray as xr

from .. import _validate as _v
from .._validate import output as label
from .._validate import start_time, windowed

__all__ = ["read", "label", "start_time", "windowed", "pair", "first_labelled"]

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
