"""Tilt and orientation errors: gravity direction, angle between vectors, error
quaternion and the total / heading / tilt error angles.
"""

from __future__ import annotations

import numpy as np

from ._algebra import conj, mul
from ._checks import (
    _as2d,
    _broadcast,
    _check_last,
    _no_inf,
    _no_zero,
    _real,
)
from ._kernels import _angle_between_kernel, _error_angles_kernel, _gravity_kernel


def gravity(q) -> np.ndarray:
    r"""Tilt: the gravity-up direction in the sensor frame, :math:`g_s = R(q)^\top e_z`.

    For a sensor at rest, this is the direction of the accelerometer reading
    (the specific force points up).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Unit sensor → world quaternions (w, x, y, z); finite, non-zero.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Gravity-up directions in sensor coordinates (dimensionless unit vectors for
        unit ``q``).
    """
    q = _real(q, "q")
    _check_last(q, 4, "q")
    _no_zero(_no_inf(q, "q"), "q")
    out = np.empty((int(np.prod(q.shape[:-1], dtype=np.int64)), 3))
    _gravity_kernel(_as2d(q, 4), out)
    return out.reshape(q.shape[:-1] + (3,))


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
    """
    u, v = _real(u, "u"), _real(v, "v")
    _check_last(u, 3, "u")
    _check_last(v, 3, "v")
    for name, a in (("u", u), ("v", v)):
        _no_inf(a, name)
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
    p, q = _real(q_est, "q_est"), _real(q_ref, "q_ref")
    _check_last(p, 4, "q_est")
    _check_last(q, 4, "q_ref")
    _no_zero(_no_inf(p, "q_est"), "q_est")
    _no_zero(_no_inf(q, "q_ref"), "q_ref")
    p, q = _broadcast(("q_est", p), ("q_ref", q))
    out = np.empty((int(np.prod(p.shape[:-1], dtype=np.int64)), 3))
    _error_angles_kernel(_as2d(p, 4), _as2d(q, 4), out)
    return out.reshape(p.shape[:-1] + (3,))


def total_error(q_est, q_ref) -> np.ndarray:
    r"""Total orientation error (rad): the angle of :math:`e = q_{est} \otimes q_{ref}^{-1}`, in [0, π].

    Parameters
    ----------
    q_est : array_like, shape (..., 4)
        Estimated sensor → world quaternions (w, x, y, z); finite, non-zero.
    q_ref : array_like, shape (..., 4)
        Reference (ground-truth) sensor → world quaternions (w, x, y, z); the leading
        dimensions of ``q_est`` and ``q_ref`` broadcast.

    Returns
    -------
    numpy.ndarray, shape (...)
        Total errors in rad, in [0, π].
    """
    return error_angles(q_est, q_ref)[..., 0]


def heading_error(q_est, q_ref) -> np.ndarray:
    r"""Heading error (rad): the angle of the rotation about world z in the heading–inclination
    decomposition of the Earth-frame error, :math:`2\,\mathrm{atan2}(|e_z|, |e_w|)`, in [0, π].

    Parameters
    ----------
    q_est : array_like, shape (..., 4)
        Estimated sensor → world quaternions (w, x, y, z); finite, non-zero.
    q_ref : array_like, shape (..., 4)
        Reference (ground-truth) sensor → world quaternions (w, x, y, z); the leading
        dimensions of ``q_est`` and ``q_ref`` broadcast.

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
    q_est : array_like, shape (..., 4)
        Estimated sensor → world quaternions (w, x, y, z); finite, non-zero.
    q_ref : array_like, shape (..., 4)
        Reference (ground-truth) sensor → world quaternions (w, x, y, z); the leading
        dimensions of ``q_est`` and ``q_ref`` broadcast.

    Returns
    -------
    numpy.ndarray, shape (...)
        Tilt (inclination) errors in rad, in [0, π].
    """
    return error_angles(q_est, q_ref)[..., 2]
