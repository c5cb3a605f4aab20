r"""Angle wrapping and rotation → (azimuth, elevation, bank) conversions for labelled data.

These are the :mod:`tiltlab.frames` conversions (:func:`tiltlab.frames.wrap_angle`,
:func:`tiltlab.frames.angles_from_quaternion`, :func:`tiltlab.frames.angles_from_matrix`)
as :mod:`tiltlab.trig` exports them: they accept labelled input and check it.

* A labelled :class:`xarray.DataArray` gives DataArrays back: :func:`wrap_angle` keeps
  the input's dims, coordinates and attributes; the conversions keep its ``time``
  coordinate (and any other coordinate not on the quaternion / matrix dimensions) and
  its ``fs``.
* Quaternions are checked: a norm off 1 by more than ``1e-6`` (finite, non-zero) is
  normalised with a :class:`RuntimeWarning` (the rotation is unambiguous); a zero or
  infinite quaternion is an error naming ``q``; NaN rows (missing samples, e.g.
  :func:`tiltlab.filters.estimate` with ``gaps="segments"``) give NaN angles.
* Matrices must be rotations: a reflection (det −1), a non-orthonormal matrix
  (:math:`\max|C^\top C - I| > 10^{-6}`) or ±inf is an error naming ``matrix``; NaN
  matrices give NaN angles.
"""

from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

from .. import _validate as _v
from .. import frames as _frames
from .. import quaternion as _quat
from ..frames import Orientation
from ._common import label_like

__all__ = ["wrap_angle", "angles_from_quaternion", "angles_from_matrix"]

_UNIT_ATOL = 1e-6


def wrap_angle(angle):
    """Wrap angles (rad) to (−π, π].

    A DataArray gives a DataArray with the same dims, coordinates, attributes and name
    (degrees, ``attrs["units"] == "deg"``, are wrapped to (−180, 180]); anything
    else gives an ndarray. ±inf is an error (no angle); NaN stays NaN.

    Parameters
    ----------
    angle : float, array_like or xarray.DataArray
        Angles (rad; a DataArray may be in degrees, ``attrs["units"] == "deg"``).

    Returns
    -------
    ndarray or xarray.DataArray
        Wrapped angles, in the input's units.

    Raises
    ------
    ValueError
        If ``angle`` holds ±inf, or a DataArray has units other than rad or deg.
    """
    if isinstance(angle, xr.DataArray):
        units = str(angle.attrs.get("units", "rad")).strip().lower()
        v = _v.vectors(angle.values, "angle", width=None, ndim=None, allow_nan=True)
        if units in ("deg", "degree", "degrees", "°"):
            w = np.degrees(_frames.wrap_angle(np.radians(v)))
        elif units in ("rad", "radian", "radians", "1", ""):
            w = _frames.wrap_angle(v)
        else:
            raise ValueError(
                f"angle must be in rad (or deg), got units {angle.attrs['units']!r}"
            )
        return angle.copy(data=w)
    return _frames.wrap_angle(
        _v.vectors(angle, "angle", width=None, ndim=None, allow_nan=True)
    )


def _singular_tol(singular_tol) -> float:
    return _v.nonnegative(singular_tol, "singular_tol")


def _labelled_orientation(o: Orientation, da: xr.DataArray, drop: tuple[str, ...]):
    """Orientation of DataArrays labelled like ``da`` without its ``drop`` dimensions."""
    tmpl = da.isel({d: 0 for d in drop}, drop=True)
    return Orientation(
        *(
            label_like(v, tmpl, name, "rad")
            for v, name in zip(o, Orientation._fields, strict=True)
        )
    )


def angles_from_quaternion(q, singular_tol: float = 1e-9) -> Orientation:
    """Azimuth, elevation, bank of sensor(body)→world quaternions (w, x, y, z), rad.

    See :func:`tiltlab.frames.angles_from_matrix` for the formulas and the singular
    (surge vertical) fallback. ``q``: (..., 4) array, or a DataArray with a ``quat``
    dimension (e.g. :func:`tiltlab.filters.estimate`), which gives DataArrays with its
    ``time`` coordinate and ``fs``. Non-unit quaternions are normalised with a
    :class:`RuntimeWarning`; zero or infinite ones are an error; NaN rows give NaN.

    Parameters
    ----------
    q : array_like (..., 4) or xarray.DataArray
        Sensor(body)→world unit quaternions (w, x, y, z); a DataArray has a ``quat``
        dimension (else its last dimension holds the components).
    singular_tol : float
        Tolerance (≥ 0) on the horizontal norm of the surge axis below which the
        singular (surge vertical) fallback is used.

    Returns
    -------
    Orientation
        Azimuth, elevation and bank (rad); DataArrays for DataArray input.

    Raises
    ------
    ValueError
        If ``q`` has a wrong shape or holds zero or infinite quaternions.
    """
    singular_tol = _singular_tol(singular_tol)
    da = None
    if isinstance(q, xr.DataArray):
        qd = "quat" if "quat" in q.dims else q.dims[-1]
        da = q.transpose(..., qd)
        if "time" in da.dims:
            da = da.transpose("time", ...)
        qv = np.asarray(da.values, dtype=float)
    else:
        qv = q
    qv = _v.vectors(qv, "q", width=4, ndim=None, allow_nan=True)
    if qv.ndim == 1 and qv.size == 0:
        raise ValueError("q must have a last dimension of size 4, got shape (0,)")
    n = np.linalg.norm(qv, axis=-1, keepdims=True)
    zero = n[..., 0] == 0
    if np.any(zero):
        raise ValueError(f"q has {int(zero.sum())} zero quaternion(s): not a rotation")
    off = np.abs(n[..., 0] - 1.0) > _UNIT_ATOL  # NaN compares False
    if np.any(off):
        k = int(np.argmax(off.ravel()))
        warnings.warn(
            f"angles_from_quaternion: {int(off.sum())} quaternion(s) in q are not unit "
            f"(first norm: {float(n.ravel()[k]):.6g}); normalised",
            RuntimeWarning,
            stacklevel=2,
        )
    qv = qv / n
    C = _quat.to_matrix(qv)
    o = _frames.angles_from_matrix(C, singular_tol=singular_tol)
    if da is None:
        return o
    return _labelled_orientation(o, da, (qd,))


def _check_rotation(C: np.ndarray, name: str) -> None:
    _quat.check_rotation(C, name, _UNIT_ATOL)


def angles_from_matrix(matrix, singular_tol: float = 1e-9) -> Orientation:
    r"""Azimuth, elevation and bank (rad) from body→world rotation matrices (..., 3, 3).

    See :func:`tiltlab.frames.angles_from_matrix` for the formulas and the singular
    fallback. ``matrix`` must hold proper rotations: reflections (det −1),
    non-orthonormal matrices and ±inf are errors naming it; NaN matrices give NaN. A
    DataArray whose last two dims are the 3 × 3 matrix gives DataArrays with its other
    coordinates (``time``) and ``fs``.

    Parameters
    ----------
    matrix : array_like (..., 3, 3) or xarray.DataArray
        Body→world rotation matrices.
    singular_tol : float
        Tolerance (≥ 0) on the horizontal norm of the surge axis below which the
        singular fallback is used.

    Returns
    -------
    Orientation
        Azimuth, elevation and bank (rad); DataArrays for DataArray input.

    Raises
    ------
    ValueError
        If ``matrix`` has a wrong shape, is not numeric, holds ±inf or is not a proper
        rotation.
    """
    singular_tol = _singular_tol(singular_tol)
    da = None
    if isinstance(matrix, xr.DataArray):
        if matrix.ndim < 2:
            raise ValueError(
                f"matrix must have shape (..., 3, 3), got dims {matrix.dims}"
            )
        da = matrix.transpose("time", ...) if "time" in matrix.dims else matrix
        C = np.asarray(da.values, dtype=float)
    else:
        try:
            C = np.asarray(matrix, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"matrix must be numeric, got {matrix!r}") from None
    if C.ndim < 2 or C.shape[-2:] != (3, 3):
        raise ValueError(f"matrix must have shape (..., 3, 3), got {C.shape}")
    if np.any(np.isinf(C)):
        raise ValueError(f"matrix has {int(np.isinf(C).sum())} infinite values")
    _check_rotation(C, "matrix")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        o = _frames.angles_from_matrix(C, singular_tol=singular_tol)
    if da is None:
        return o
    return _labelled_orientation(o, da, da.dims[-2:])
