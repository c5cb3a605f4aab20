r"""Magnetometer calibration: four-point, per-axis min/max and ellipsoid fits.

Magnetometer calibration: Benhamou's four-point procedure, per-axis min/max, and an
ellipsoid (hard- and soft-iron) fit.

A magnetometer reads :math:`r = W m + h + n`: the local field :math:`m` (sensor frame)
distorted by a soft-iron matrix :math:`W` and shifted by a hard-iron offset :math:`h`.
Calibrated values are :math:`\hat m = S(r - h)`.

* **Four-point** (Benhamou 2023 [1]_ §3, Eq. 4): readings with the surge axis horizontal
  pointing N, E, S, W, once resting on the bottom and once on a flank; each axis is
  mapped to ±1 when pointing horizontally North/South. Diagonal S
  (:func:`four_point_mag_calibration`; the poses: :func:`four_point_poses`).
* **Min/max** (§3): :math:`h_i = (r_{max}+r_{min})/2`, :math:`S_{ii} = 2/(r_{max}-r_{min})`.
  Diagonal S; needs each axis to have pointed along ± the field direction explored.
* **Ellipsoid**: :math:`\|S(r-h)\| = B` fitted to readings spread over many orientations
  (:func:`tiltlab.calibration.fit_ellipsoid` with a symmetric S, the usual soft-iron
  gauge). Corrects cross-axis soft iron, which the two diagonal methods cannot.

:func:`apply_mag_calibration` applies any of them, :math:`S(r - h)`; it is tiltlab's one
implementation of that step.

References
----------
.. [1] S. Benhamou, arXiv:2310.05820, 2023. doi:10.48550/arXiv.2310.05820
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import xarray as xr

from .. import _validate as _v
from ..frames import angles_to_quaternion
from ._util import CalibrationError, mat3, vec3
from .accel import EllipsoidFit, fit_ellipsoid

__all__ = [
    "four_point_poses",
    "four_point_mag_calibration",
    "minmax_mag_calibration",
    "fit_mag_ellipsoid",
    "apply_mag_calibration",
]


def _flank(flank_on) -> str:
    if flank_on not in ("left", "right"):
        raise ValueError(f"flank_on must be 'left' or 'right', got {flank_on!r}")
    return flank_on


def four_point_poses(
    flank_on: Literal["left", "right"] = "left",
) -> tuple[np.ndarray, np.ndarray]:
    """Sensor→world (ENU) quaternions of the eight poses of the four-point procedure.

    Parameters
    ----------
    flank_on : {"left", "right"}
        The flank the device rests on during the flank rotation (default left).

    Returns
    -------
    bottom, flank : ndarray (4, 4)
        Surge axis horizontal pointing N, E, S, W (rows), resting on the bottom (level)
        and on the ``flank_on`` flank (bank −90° for the left flank: sway axis down).
        Quaternions are scalar-first (w, x, y, z).
    """
    flank_on = _flank(flank_on)
    az = np.array([np.pi / 2, 0.0, -np.pi / 2, np.pi])  # N, E, S, W, ccw from East
    bank = -np.pi / 2 if flank_on == "left" else np.pi / 2
    bottom = angles_to_quaternion(az, np.zeros(4), np.zeros(4))
    flank = angles_to_quaternion(az, np.zeros(4), np.full(4, bank))
    return np.asarray(bottom), np.asarray(flank)


def four_point_mag_calibration(
    bottom, flank, flank_on: Literal["left", "right"] = "left"
) -> tuple[np.ndarray, np.ndarray]:
    r"""Calibrate a magnetometer by Benhamou's four-point procedure (Eq. 4).

    Benhamou's four-point magnetometer calibration (Eq. 4): hard-iron offset and
    diagonal scale matrix.

    Parameters
    ----------
    bottom, flank : array_like, shape (4, 3)
        Raw readings (U, V, W) with the surge axis horizontal pointing magnetic North,
        East, South, West (rows in that order), device resting on its bottom
        ("bottom rotation") and on a flank ("flank rotation"); :func:`four_point_poses`
        gives these poses.
    flank_on : {"left", "right"}
        The flank the device rests on during the flank rotation (left flank on the
        ground: sway axis down, Benhamou's :math:`a_V>0`, sgn = +1).

    Returns
    -------
    offset : ndarray (3,)
        :math:`((N_U+S_U)/2, (E_V+W_V)/2, (E_W+W_W)/2)` from the relevant rotation.
    matrix : ndarray (3, 3)
        ``diag(2/(N_U−S_U), 2/(E_V−W_V), sgn(a_V)·2/(E_W−W_W))``.

    Notes
    -----
    With :func:`apply_mag_calibration` this reproduces Eqs. 4a–c: each axis reads
    +1 pointing horizontally North and −1 pointing South.
    """
    b = _v.vectors(bottom, "bottom", width=3, ndim=2)
    f = _v.vectors(flank, "flank", width=3, ndim=2)
    if b.shape != (4, 3) or f.shape != (4, 3):
        raise ValueError(
            "bottom and flank must have shape (4, 3) (rows N, E, S, W; columns U, V, W), "
            f"got {b.shape} and {f.shape}"
        )
    flank_on = _flank(flank_on)
    N, E, S, W = range(4)
    sgn = 1.0 if flank_on == "left" else -1.0
    den = np.array([b[N, 0] - b[S, 0], b[E, 1] - b[W, 1], f[E, 2] - f[W, 2]])
    if np.any(den == 0):
        axis = "UVW"[int(np.flatnonzero(den == 0)[0])]
        raise CalibrationError(
            f"degenerate four-point readings: axis {axis} reads the same value in its "
            "two opposite poses (zero range)"
        )
    offset = np.array(
        [(b[N, 0] + b[S, 0]) / 2, (b[E, 1] + b[W, 1]) / 2, (f[E, 2] + f[W, 2]) / 2]
    )
    return offset, np.diag(2.0 / den * np.array([1.0, 1.0, sgn]))


def minmax_mag_calibration(mag) -> tuple[np.ndarray, np.ndarray]:
    """Per-axis min/max calibration: offset ``(max+min)/2`` and ``diag(2/(max-min))``.

    Parameters
    ----------
    mag : Recording, DataArray or array_like (N, 3)
        Raw readings (a Recording's ``mag``) covering, for every axis, both the
        northward and southward extremes.

    Returns
    -------
    offset : numpy.ndarray, shape (3,)
        Hard-iron offset ``(max + min) / 2`` (units of ``mag``).
    matrix : numpy.ndarray, shape (3, 3)
        Diagonal scale matrix ``diag(2 / (max - min))``.
    """
    r = _v.signal(mag, "mag", need_fs=False).values
    lo, hi = r.min(axis=0), r.max(axis=0)
    if np.any(hi - lo <= 0):
        raise CalibrationError(
            "an axis has zero range: rotate the device so that every axis sweeps the field"
        )
    return 0.5 * (hi + lo), np.diag(2.0 / (hi - lo))


def fit_mag_ellipsoid(
    mag, *, field: float | None = None, max_condition: float = 1e4
) -> EllipsoidFit:
    """Hard/soft-iron ellipsoid fit (symmetric soft-iron correction).

    Parameters
    ----------
    mag : Recording, DataArray or array_like (N, 3)
        Raw readings (a Recording's ``mag``) over many orientations (N ≥ 9, spread over
        the sphere).
    field : float, optional
        Local field strength, in the units of ``mag`` (e.g. µT): the corrected norm.
        Default: the mean raw norm about the algebraic centre (only directions matter
        for heading).
    max_condition : float
        Largest accepted condition number (see :func:`fit_ellipsoid`).

    Returns
    -------
    EllipsoidFit
        Hard iron ``offset`` and soft-iron correction ``matrix`` (symmetric), with
        their standard errors and residuals (see :func:`fit_ellipsoid`).
    """
    r = _v.signal(mag, "mag", need_fs=False).values
    if field is None:
        field = float(np.mean(np.linalg.norm(r - r.mean(axis=0), axis=1)))
        if not field > 0:
            raise CalibrationError(
                "the magnetometer readings do not vary (zero spread about their mean): "
                "rotate the device through many orientations"
            )
    else:
        field = _v.positive(field, "field")
    return fit_ellipsoid(
        r,
        radius=field,
        structure="symmetric",
        max_condition=max_condition,
        max_norm_deviation=np.inf,
    )


def apply_mag_calibration(mag, offset, matrix=None):
    r"""Calibrated magnetic vectors :math:`\hat m = S(r - h)`.

    The one implementation of applying a magnetometer calibration (hard-iron offset
    ``h``, soft-iron / scale matrix ``S``) in tiltlab.

    Parameters
    ----------
    mag : Recording, DataArray or array_like (..., 3)
        Raw readings (a Recording's ``mag``). NaN samples stay NaN.
    offset : array_like (3,)
        Hard-iron offset ``h``, in the units of ``mag``.
    matrix : array_like (3, 3), optional
        Soft-iron / scale correction ``S`` (identity if not given).

    Returns
    -------
    ndarray or DataArray
        Same shape as ``mag``; a DataArray (with ``mag``'s ``time`` and ``fs``) for
        labelled input, keeping its units when no ``matrix`` is applied (a matrix may
        rescale them, e.g. to the ±1 of the four-point calibration, so none are
        recorded then).
    """
    s = _v.signal(mag, "mag", need_fs=False, ndim=None, allow_nan=True)
    d = s.values - vec3(offset, "offset", ndim=1)
    if matrix is not None:
        S = mat3(matrix, "matrix")
        if np.linalg.matrix_rank(S) < 3:
            raise ValueError(
                "matrix is singular: a soft-iron / scale correction must be invertible"
            )
        d = d @ S.T
    da = mag["mag"] if isinstance(mag, xr.Dataset) else mag
    dims = tuple(da.dims) if isinstance(da, xr.DataArray) else None
    units = s.units if matrix is None else None
    return _v.labelled(d, s, "mag", units=units, dims=dims)
