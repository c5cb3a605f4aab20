r"""Recording-level entry points: :func:`estimate` (a labelled ``q``) and :func:`gravity`.

:func:`prepare` reads a Recording once (through :func:`tiltlab._validate.signal`: ``fs``
from the attrs and checked against the ``time`` axis, units from the attrs, converted to
SI for the kernels) and :func:`run` runs a registered method on it; :func:`estimate` is
the two together plus the labelling. Parameter searches
(:func:`tiltlab.evaluate.grid_search`) call :func:`prepare` once per Recording and
:func:`run` once per parameter set.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from .. import _validate as _v
from .. import quaternion as quat
from .registry import get_method

__all__ = ["Inputs", "prepare", "run", "estimate", "gravity"]


@dataclass(frozen=True)
class Inputs:
    """A Recording's sensor data in SI, ready for the kernels.

    ``acc`` (m/s²) and ``gyr`` (rad/s) as (N, 3) arrays, ``mag`` (its own unit) or
    ``None``, ``fs`` (Hz) and ``like``: the accelerometer's
    :class:`tiltlab._validate.Signal`, used to label outputs with the Recording's
    ``time`` coordinate.
    """

    acc: np.ndarray
    gyr: np.ndarray
    mag: np.ndarray | None
    fs: float
    like: _v.Signal

    @property
    def use_mag(self) -> bool:
        return self.mag is not None


def prepare(recording: xr.Dataset, *, use_mag: bool = False) -> Inputs:
    """Read a Recording's ``acc``, ``gyr`` (and ``mag``) in SI units.

    Parameters
    ----------
    recording : xarray.Dataset
        A tiltlab Recording: ``acc`` and ``gyr`` (time, axis) with ``units`` attrs,
        optional ``mag``; attrs ``fs``.
    use_mag : bool
        Also read ``mag`` (9D).

    Raises
    ------
    tiltlab._validate.RecordingError
        A missing variable, ``fs`` or unit, an ``fs`` contradicting the time axis, or
        non-finite samples.
    """
    if not isinstance(recording, xr.Dataset):
        raise _v.RecordingError(
            "recording must be an xarray Dataset (a tiltlab Recording), "
            f"got {type(recording).__name__}"
        )
    names = ["acc", "gyr"] + (["mag"] if use_mag else [])
    for name in names:
        if name not in recording:
            hint = " (needed for use_mag=True)" if name == "mag" else ""
            raise _v.RecordingError(f"the Recording has no {name!r} variable{hint}")
    rec = recording[names]
    if "time" in rec.dims:
        rec = rec.transpose("time", ...)
    acc = _v.signal(rec, "acc", to_units="m/s^2")
    gyr = _v.signal(rec, "gyr", to_units="rad/s")
    mag = _v.signal(rec, "mag").values if use_mag else None

    def c(a):
        return None if a is None else np.ascontiguousarray(a, dtype=np.float64)

    return Inputs(c(acc.values), c(gyr.values), c(mag), acc.fs, acc)


def run(method: str, inputs: Inputs, **params) -> np.ndarray:
    """Run a registered method on prepared :class:`Inputs`; returns (N, 4) quaternions.

    Unspecified parameters take the registry's defaults; an unknown method or
    parameter is a ValueError naming it.
    """
    m = get_method(method)
    full = m.resolve(params)
    return m(inputs.acc, inputs.gyr, inputs.fs, inputs.mag, **full)


def attr_value(v):
    """A parameter value as a netCDF-friendly attribute (None → "none", bool → int)."""
    if v is None:
        return "none"
    if isinstance(v, (bool, np.bool_)):
        return int(v)
    if isinstance(v, (np.ndarray, list, tuple)):
        return np.asarray(v, float)
    return v


def estimate(
    recording: xr.Dataset, method: str, *, use_mag: bool = False, **params
) -> xr.DataArray:
    """Estimate the orientation of a Recording with a registered method.

    The Recording is read by :func:`prepare` (``fs`` from its attrs and checked
    against its ``time`` axis; ``acc`` in g or m/s² and ``gyr`` in °/s or rad/s, per
    their ``units`` attrs, converted to SI for the kernels).

    Parameters
    ----------
    recording : xarray.Dataset
        A tiltlab Recording (``acc``, ``gyr``, optional ``mag``; attrs ``fs``).
    method : str
        A name of :data:`tiltlab.filters.METHODS` (:func:`tiltlab.filters.methods`).
    use_mag : bool
        Use the magnetometer (9D, ENU world frame).
    **params
        Method parameters; unspecified ones take the registry's defaults (the
        function's signature), and all are recorded in the output's attrs.

    Returns
    -------
    xarray.DataArray, dims (time, quat)
        ``q``: unit quaternions sensor → world, with the Recording's ``time``
        coordinate and attrs ``fs``, ``method``, ``use_mag``, ``world_frame`` and every
        parameter as ``param_<name>``.
    """
    m = get_method(method)
    if use_mag and not m.supports_mag:
        raise ValueError(
            f"method {method!r} does not use a magnetometer; "
            "use_mag=True is not supported"
        )
    full = m.resolve(params)
    inputs = prepare(recording, use_mag=use_mag)
    q = m(inputs.acc, inputs.gyr, inputs.fs, inputs.mag, **full)
    attrs: dict[str, Any] = {
        "method": method,
        "use_mag": int(bool(use_mag)),
        "units": "1",
        "frame": "sensor->world",
        "world_frame": "ENU" if use_mag else "z up, heading arbitrary",
        **{f"param_{k}": attr_value(v) for k, v in full.items()},
    }
    return _v.labelled(
        q,
        inputs.like,
        "q",
        dims=("time", "quat"),
        coords={"quat": list("wxyz")},
        attrs=attrs,
    )


def gravity(q):
    r"""Tilt :math:`g_s = R(q)^\top e_z`: the gravity-up direction in the sensor frame.

    Parameters
    ----------
    q : xarray.DataArray or array_like, shape (..., 4)
        Quaternions sensor → world, e.g. the output of :func:`estimate` (a DataArray
        with a ``quat`` dimension).

    Returns
    -------
    xarray.DataArray or numpy.ndarray
        For a DataArray: a DataArray named ``gravity`` with ``quat`` replaced by
        ``axis`` (x, y, z), keeping the other coordinates (``time``) and the attrs
        (``fs``, ``method``, parameters), with ``units = "1"`` and
        ``frame = "sensor"``. For a plain array: an ndarray of shape (..., 3).
    """
    if not isinstance(q, xr.DataArray):
        return quat.gravity(_v.vectors(q, "q", width=4, ndim=None, allow_nan=True))
    if "quat" not in q.dims:
        raise ValueError(f"q must have a 'quat' dimension, got dims {q.dims}")
    qa = q.transpose(..., "quat")
    g = quat.gravity(np.asarray(qa.values, dtype=float))
    coords = {k: v for k, v in qa.coords.items() if "quat" not in v.dims}
    attrs = {
        **q.attrs,
        "units": "1",
        "frame": "sensor",
        "long_name": "gravity-up direction (tilt)",
    }
    return xr.DataArray(
        g,
        dims=qa.dims[:-1] + ("axis",),
        coords={**coords, "axis": list("xyz")},
        name="gravity",
        attrs=attrs,
    )
