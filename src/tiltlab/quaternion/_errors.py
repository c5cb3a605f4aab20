"""Tilt and orientation errors: gravity direction, angle between vectors and errors.

The errors are the error quaternion and the total / heading / tilt error angles.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._algebra import conj, mul
from ._checks import _as2d, _broadcast, _finite, _rotations
from ._kernels import _angle_between_kernel, _error_angles_kernel, _gravity_kernel


def gravity(q):
    r"""Compute the tilt: the gravity-up direction in the sensor frame, :math:`g_s = R(q)^\top e_z`.

    For a sensor at rest, this is the direction of the accelerometer reading
    (the specific force points up). NaN quaternions (missing samples) give NaN.

    Parameters
    ----------
    q : array_like, shape (..., 4), or xarray.DataArray
        Unit sensor → world quaternions (w, x, y, z); finite, non-zero. A DataArray
        (e.g. the output of :func:`tiltlab.filters.estimate`) has a ``quat``
        dimension.

    Returns
    -------
    numpy.ndarray, shape (..., 3), or xarray.DataArray
        Gravity-up directions in sensor coordinates (dimensionless unit vectors for
        unit ``q``). For a DataArray: a DataArray named ``gravity`` with ``quat``
        replaced by ``axis`` (x, y, z) as the last dimension, keeping the other
        coordinates (``time``) and the attributes (``fs``, ``method``, parameters),
        with ``units = "1"``, ``frame = "sensor"`` and a ``long_name``.

    Raises
    ------
    ValueError
        If ``q`` is not numeric, has a wrong shape (no ``quat`` dimension for a
        DataArray), or holds infinite or zero quaternions.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import quaternion
    >>> q = quaternion.from_rotvec([np.pi / 2, 0.0, 0.0])  # rolled 90° about x
    >>> np.round(quaternion.gravity(q), 3) + 0.0
    array([0., 1., 0.])
    """
    if isinstance(q, xr.DataArray):
        return _gravity_labelled(q)
    q = _rotations(q, "q")
    out = np.empty((int(np.prod(q.shape[:-1], dtype=np.int64)), 3))
    _gravity_kernel(_as2d(q, 4), out)
    return out.reshape(q.shape[:-1] + (3,))


def _gravity_labelled(q: xr.DataArray) -> xr.DataArray:
    """:func:`gravity` of a DataArray with a ``quat`` dimension, labelled."""
    if "quat" not in q.dims:
        raise ValueError(f"q must have a 'quat' dimension, got dims {q.dims}")
    qa = q.transpose(..., "quat")
    g = gravity(np.asarray(qa.values, dtype=float))
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


def angle_between(u, v) -> np.ndarray:
    """Angle (rad) between vectors, computed as atan2(‖u×v‖, u·v) (accurate near 0 and π).

    Parameters
    ----------
    u, v : array_like, shape (..., 3)
        Finite, non-zero vectors (any unit, need not be unit vectors); the leading
        dimensions broadcast.

    Returns
    -------
    numpy.ndarray, shape (...)
        Angles in rad, in [0, π].

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import quaternion
    >>> round(float(quaternion.angle_between([1.0, 0, 0], [1.0, 1.0, 0])), 3)
    0.785
    >>> u = [[0, 0, 1.0], [0, 0, 1.0]]
    >>> v = [[0, 1.0, 1.0], [0, 0, -2.0]]
    >>> np.round(np.degrees(quaternion.angle_between(u, v)), 1)
    array([ 45., 180.])
    """
    u, v = _finite(u, 3, "u"), _finite(v, 3, "v")
    for name, a in (("u", u), ("v", v)):
        if np.any(np.sum(a * a, axis=-1) == 0):
            raise ValueError(f"{name} has zero vectors: their direction is undefined")
    lead = _broadcast(("u", u[..., 0]), ("v", v[..., 0]))[0].shape
    out = np.empty(int(np.prod(lead, dtype=np.int64)))
    _angle_between_kernel(
        _as2d(np.broadcast_to(u, lead + (3,)), 3),
        _as2d(np.broadcast_to(v, lead + (3,)), 3),
        out,
    )
    return out.reshape(lead)


def error_quaternion(q_est, q_ref) -> np.ndarray:
    r"""Earth-frame error quaternion :math:`e = q_{est} \otimes q_{ref}^{-1}` (BROAD's definition [3]_).

    Parameters
    ----------
    q_est : array_like, shape (..., 4)
        Estimated sensor → world unit quaternions (w, x, y, z).
    q_ref : array_like, shape (..., 4)
        Reference (ground-truth) sensor → world unit quaternions (w, x, y, z); the
        leading dimensions of ``q_est`` and ``q_ref`` broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Earth-frame error quaternions ``e`` (w, x, y, z).
    """
    return mul(q_est, conj(q_ref))


def error_angles(q_est, q_ref) -> np.ndarray:
    r"""Total, heading and tilt errors (rad) in one pass, stacked on the last axis (..., 3).

    See :func:`total_error`, :func:`heading_error` and :func:`tilt_error`.

    Parameters
    ----------
    q_est : array_like, shape (..., 4)
        Estimated sensor → world quaternions (w, x, y, z); finite, non-zero.
    q_ref : array_like, shape (..., 4)
        Reference (ground-truth) sensor → world quaternions (w, x, y, z); the leading
        dimensions of ``q_est`` and ``q_ref`` broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Columns: total, heading and tilt errors, each in rad, in [0, π].
    """
    p, q = _rotations(q_est, "q_est"), _rotations(q_ref, "q_ref")
    p, q = _broadcast(("q_est", p), ("q_ref", q))
    out = np.empty((int(np.prod(p.shape[:-1], dtype=np.int64)), 3))
    _error_angles_kernel(_as2d(p, 4), _as2d(q, 4), out)
    return out.reshape(p.shape[:-1] + (3,))


def total_error(q_est, q_ref) -> np.ndarray:
    r"""Total orientation error (rad): the angle of :math:`e = q_{est} \otimes q_{ref}^{-1}`, in [0, π].

    Parameters
    ----------
    q_est, q_ref : array_like, shape (..., 4)
        Estimated and reference quaternions, as for :func:`error_angles`.

    Returns
    -------
    numpy.ndarray, shape (...)
        Total errors in rad, in [0, π].

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import quaternion
    >>> q_ref = quaternion.identity(2)
    >>> q_est = quaternion.from_rotvec([[0.0, 0.0, 0.1], [0.2, 0.0, 0.0]])
    >>> np.round(quaternion.total_error(q_est, q_ref), 3)
    array([0.1, 0.2])
    """
    return error_angles(q_est, q_ref)[..., 0]


def heading_error(q_est, q_ref) -> np.ndarray:
    r"""Compute the heading error (rad), in [0, π].

    The angle of the rotation about world z in the heading–inclination decomposition
    of the Earth-frame error, :math:`2\,\mathrm{atan2}(|e_z|, |e_w|)`.

    Parameters
    ----------
    q_est, q_ref : array_like, shape (..., 4)
        Estimated and reference quaternions (as for :func:`error_angles`); only the
        heading part of their difference counts.

    Returns
    -------
    numpy.ndarray, shape (...)
        Heading errors in rad, in [0, π].
    """
    return error_angles(q_est, q_ref)[..., 1]


def tilt_error(q_est, q_ref) -> np.ndarray:
    r"""Tilt (inclination) error (rad): :math:`2\arccos\sqrt{e_w^2 + e_z^2}` of the Earth-frame error.

    Equal to the angle between the two gravity directions in the sensor frame,
    ``angle_between(gravity(q_est), gravity(q_ref))``, and to BROAD's inclination
    error [3]_. Computed as :math:`2\,\mathrm{atan2}(\sqrt{e_x^2+e_y^2}, \sqrt{e_w^2+e_z^2})`
    for accuracy near zero.

    Parameters
    ----------
    q_est, q_ref : array_like, shape (..., 4)
        Estimated and reference quaternions (as for :func:`error_angles`); a rotation
        about world z between them is no tilt error.

    Returns
    -------
    numpy.ndarray, shape (...)
        Tilt (inclination) errors in rad, in [0, π].
    """
    return error_angles(q_est, q_ref)[..., 2]
