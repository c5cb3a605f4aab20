r"""Circling (Fayat et al. 2021, §2.10).

The circling index is the mean azimuthal angular speed — the component of the angular
velocity along the gravity-up direction, :math:`\omega_\parallel = \omega \cdot \hat
g_s` — over periods of movement, in circles per minute; positive values are
counter-clockwise rotations seen from above.

``gyr`` carries its units (a Recording or a labelled DataArray; a plain array needs
``units=``); ``g`` is the gravity-up direction in the sensor frame, e.g.
:func:`tiltlab.filters.gravity` of an orientation estimate (dims ``time``, ``axis``).
"""

from __future__ import annotations

import numpy as np

from .. import _validate as _v
from ._common import label, need_gyr, read_behavior_input

__all__ = ["azimuthal_speed", "circling_index"]


def _read_pair(gyr, g, units, what="azimuthal_speed"):
    need_gyr(
        gyr,
        what,
        "the rotation about gravity is not observable from an accelerometer; with a "
        "magnetometer, differentiate the heading (tiltlab.trig) instead",
    )
    sw = read_behavior_input(gyr, "gyr", units=units, to_units="deg/s", allow_nan=True)
    sg = read_behavior_input(g, "g", var="gravity", allow_nan=True)
    zero = np.sum(sg.values * sg.values, axis=1) == 0  # NaN rows (gaps) pass
    if np.any(zero):
        raise ValueError(
            f"g has {int(zero.sum())} zero vectors: the gravity direction is undefined "
            "there (use NaN for missing samples)"
        )
    if sw.values.shape != sg.values.shape:
        raise ValueError(
            "gyr and g must both have shape (N, 3) with the same N, got "
            f"{sw.values.shape} and {sg.values.shape}"
        )
    if sw.fs is not None and sg.fs is not None and not np.isclose(sw.fs, sg.fs):
        raise _v.RecordingError(
            f"g: its fs = {sg.fs:g} Hz contradicts gyr's fs = {sw.fs:g} Hz"
        )
    if sw.time is not None and sg.time is not None:
        if not np.allclose(sw.time, sg.time, rtol=0.0, atol=1e-9):
            raise _v.RecordingError("g: its time coordinate differs from gyr's")
    return sw, sg


def azimuthal_speed(gyr, g, *, units: str | None = None):
    r"""Angular speed about the gravity-up axis, :math:`\omega \cdot \hat g_s`, in °/s.

    Parameters
    ----------
    gyr : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        Angular velocity in the sensor frame: a Recording (its ``gyr``), a labelled
        DataArray, or a plain array with ``units``.
    g : xarray.DataArray or array_like (N, 3)
        Gravity-up direction in the sensor frame (normalised here), e.g.
        :func:`tiltlab.filters.gravity`.
    units : str, optional
        Units of a plain ``gyr`` ('deg/s' or 'rad/s').

    Returns
    -------
    numpy.ndarray or xarray.DataArray (time)
        °/s; labelled when ``gyr`` is.

    Notes
    -----
    Equal to the z component of the angular velocity expressed in any gravity-aligned
    frame (Fayat §2.10 rotates the gyroscope by the inverse of the quaternion aligning
    the sensor z axis with gravity, then takes z). Positive = counter-clockwise seen
    from above.
    """
    return _azimuthal(gyr, g, units, "azimuthal_speed")


def _azimuthal(gyr, g, units, what: str):
    sw, sg = _read_pair(gyr, g, units, what)
    w, gg = sw.values, sg.values
    az = np.sum(w * gg, axis=1) / np.linalg.norm(gg, axis=1)
    return label(az, sw, "azimuthal_speed", "deg/s")


def circling_index(gyr, g, *, moving=None, units: str | None = None) -> float:
    """Mean azimuthal angular speed over movement, in circles per minute (CCW positive).

    Parameters
    ----------
    gyr : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        Offset-corrected angular velocity (units from the data, or ``units`` for a
        plain array).
    g : xarray.DataArray or array_like (N, 3)
        Gravity-up direction in the sensor frame (:func:`tiltlab.filters.gravity`).
    moving : array_like of bool (N,), optional
        Samples to average over (Fayat: periods of movement, e.g. the complement of
        :func:`~tiltlab.behavior.immobility`); default all.
    units : str, optional
        Units of a plain ``gyr``.

    Returns
    -------
    float
        Circles per minute, counter-clockwise (seen from above) positive.
    """
    az = np.asarray(_azimuthal(gyr, g, units, "circling_index"))
    if moving is not None:
        m = np.asarray(moving, dtype=bool)
        if m.shape != az.shape:
            raise ValueError(
                f"moving must have one value per sample ({az.size}), got shape {m.shape}"
            )
        if not m.any():
            raise ValueError("no movement samples to average over")
        az = az[m]
    return float(np.mean(az) * 60.0 / 360.0)
