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
]


class CalibrationError(ValueError):
    """Calibration input cannot support the requested fit, or a calibration was misapplied."""


def vec3(x, name: str, *, ndim: int | None = None) -> np.ndarray:
    """A finite float copy of ``x`` with a last dimension of 3 (and ``ndim`` dims)."""
    return _v.vectors(x, name, width=3, ndim=ndim)


def mat3(x, name: str) -> np.ndarray:
    """A finite (3, 3) float matrix."""
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
    """Temperatures in °C from a labelled (``degC`` or ``K``) or plain (°C) input."""
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
