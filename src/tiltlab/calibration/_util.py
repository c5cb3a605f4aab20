"""Input helpers shared by the calibration submodules (private).

Reading data and checking scalars is :mod:`tiltlab._validate`'s job; this module adds
the calibration error and the unit conversions that calibration's conventions need:
gyroscope rates in °/s, accelerations in g, temperatures in °C.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .. import _validate as _v
from .. import units as _units
from .._validate import RecordingError

__all__ = [
    "CalibrationError",
    "vec3",
    "mat3",
    "read_in",
    "read_temp_degc",
    "window_count",
]


class CalibrationError(ValueError):
    """Calibration input cannot support the requested fit, or a calibration was misapplied."""


def vec3(x, name: str, *, ndim: int | None = None) -> np.ndarray:
    """Check ``x`` as 3-vectors: a finite float copy with a last dimension of 3.

    Parameters
    ----------
    x : array_like, shape (..., 3)
        The vectors.
    name : str
        Name used in error messages.
    ndim : int, optional
        Required number of dimensions.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Finite float copy of ``x``.
    """
    return _v.vectors(x, name, width=3, ndim=ndim)


def mat3(x, name: str) -> np.ndarray:
    """Check ``x`` as a finite (3, 3) float matrix.

    Parameters
    ----------
    x : array_like, shape (3, 3)
        The matrix.
    name : str
        Name used in error messages.

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        ``x`` as floats.
    """
    m = np.asarray(x, dtype=float)
    if m.shape != (3, 3):
        raise ValueError(f"{name} must be a 3x3 matrix, got shape {m.shape}")
    if not np.all(np.isfinite(m)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return m


def read_in(
    data,
    name: str,
    target: str,
    *,
    fs=None,
    units: str | None = None,
    var: str | None = None,
    need_fs: bool = True,
    width: int | None = 3,
    ndim: int | None = 2,
    allow_nan: bool = False,
) -> tuple[_v.Signal, float]:
    """Read one input (Recording, labelled DataArray or array) converted to ``target`` units.

    A labelled input must carry a ``units`` attribute; a plain array is in ``units``,
    or, if that is ``None``, already in ``target`` (the unit tiltlab Recordings use:
    ``"deg/s"`` for gyroscopes, ``"g"`` for accelerometers), as documented by every
    public function that calls this.

    Parameters
    ----------
    data : Recording, DataArray or array_like
        The input (for a Recording, its variable ``var`` or ``name``).
    name : str
        Name of the input (error messages; a Recording's variable by default).
    target : str
        Units to convert to.
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    units : str, optional
        Units of a plain array (default ``target``).
    var : str, optional
        Variable read from a Recording.
    need_fs : bool
        Whether a sampling rate is required.
    width, ndim : int or None
        Required last dimension and number of dimensions.
    allow_nan : bool
        Accept NaN samples (gaps).

    Returns
    -------
    signal : tiltlab._validate.Signal
        Values in ``target`` units (``signal.units == target``).
    factor : float
        The factor from the input's units to ``target`` (to convert other quantities
        given in the input's units, e.g. an offset).
    """
    s = _v.signal(
        data,
        name,
        var=var,
        fs=fs,
        units=units,
        need_fs=need_fs,
        width=width,
        ndim=ndim,
        allow_nan=allow_nan,
    )
    if s.units is None:
        if s.labelled:
            raise RecordingError(
                f"{name}: its units are unknown (add attrs['units'] to it, "
                f"e.g. {target!r})"
            )
        u = target
    else:
        u = s.units
    try:
        factor = _units.conversion_factor(u, target)
    except _units.UnitsError as e:
        raise _units.UnitsError(f"{name}: {e}") from None
    if factor != 1.0:
        s = dataclasses.replace(s, values=s.values * factor)
    return dataclasses.replace(s, units=_units.normalise_unit(target)), factor


def read_temp_degc(temp, n: int | None = None, name: str = "temp") -> np.ndarray:
    """Read temperatures in °C from a labelled (``degC`` or ``K``) or plain (°C) input.

    Parameters
    ----------
    temp : DataArray or array_like, shape (N,)
        Temperatures.
    n : int, optional
        Required number of samples.
    name : str
        Name used in error messages.

    Returns
    -------
    numpy.ndarray, shape (N,)
        Temperatures (°C).
    """
    s = _v.signal(temp, name, need_fs=False, width=None, ndim=1)
    t = s.values
    if s.units is not None and s.units == "K":
        t = t - 273.15
    elif s.units is not None and s.units != "degC":
        raise _units.UnitsError(
            f"{name} must be a temperature (degC or K), got units {s.units!r}"
        )
    if n is not None and t.shape != (n,):
        raise ValueError(
            f"{name} must have one value per sample ({n}), got shape {t.shape}"
        )
    return t


def window_count(
    n: int, window_s: float, fs: float, minimum: int, what: tuple[str, str]
) -> tuple[int, int]:
    """Cut ``n`` samples into whole windows of ``window_s`` seconds.

    Parameters
    ----------
    n : int
        Number of samples.
    window_s : float
        Window length (s).
    fs : float
        Sampling rate (Hz).
    minimum : int
        Fewest samples in a window.
    what : tuple of 2 str
        What is cut (``"recording"``) and the end of the error message.

    Returns
    -------
    w : int
        Samples per window (``round(window_s * fs)``, at least ``minimum``).
    k : int
        Number of whole windows (at least 1).

    Raises
    ------
    CalibrationError
        Fewer than ``w`` samples.
    """
    w = max(int(round(window_s * fs)), minimum)
    k = n // w
    if k < 1:
        raise CalibrationError(
            f"the {what[0]} ({n} samples) is shorter than one window of "
            f"window_s = {window_s:g} s{what[1]}"
        )
    return w, k
