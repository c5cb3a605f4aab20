"""Gyro integration, slerp, scipy conversions and random rotations."""

from __future__ import annotations

import numpy as np

import tiltlab._validate as _v
from ._algebra import canonical, identity
from ._checks import (
    _broadcast,
    _check_last,
    _real,
    check_unit,
)
from ._kernels import _integrate_kernel


def integrate_gyro(omega, fs: float, q0=None) -> np.ndarray:
    r"""Integrate sensor-frame angular velocity (rad/s) into orientations.

    :math:`q_{k+1} = q_k \otimes \exp(\omega_k\,\Delta t / 2)`, exact when ω is constant
    over each sampling interval (zero-order hold).

    Parameters
    ----------
    omega : array_like, shape (N, 3)
        Angular velocity in rad/s, sensor frame.
    fs : float
        Sampling rate (Hz); mandatory.
    q0 : array_like, shape (4,), optional
        Initial orientation (default identity).

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        ``q[0] = q0``; ``q[k]`` is the orientation after ``k`` steps.
    """
    fs = _v.check_fs(fs)
    omega = np.ascontiguousarray(_v.vectors(omega, "omega", width=3, ndim=2))
    with np.errstate(over="ignore"):
        big = ~np.isfinite(np.linalg.norm(omega, axis=1))
    if np.any(big):
        raise ValueError(
            f"omega has {int(big.sum())} angular velocities too large to represent"
        )
    if q0 is None:
        q0 = identity()
    else:
        q0 = _v.vectors(q0, "q0", width=4, ndim=1)
        if not np.linalg.norm(q0) > 0:
            raise ValueError(f"q0 must be a non-zero quaternion (w, x, y, z), got {q0}")
        q0 = q0 / np.linalg.norm(q0)
    out = np.empty((omega.shape[0], 4))
    if omega.shape[0]:
        _integrate_kernel(omega, 1.0 / fs, q0, out)
    return out


def slerp(q0, q1, t) -> np.ndarray:
    r"""Spherical linear interpolation of rotations along the shortest path.

    .. math::
        q(t) = \frac{\sin((1-t)\,\Omega)}{\sin\Omega}\,q_0
             + \frac{\sin(t\,\Omega)}{\sin\Omega}\,s\,q_1,\qquad
        s = \begin{cases}-1 & q_0\cdot q_1 < 0\\ +1 & \text{otherwise}\end{cases},

    with :math:`\Omega = 2\,\mathrm{atan2}(\lVert q_0 - s q_1\rVert,
    \lVert q_0 + s q_1\rVert)` the angle between :math:`q_0` and :math:`s q_1` on the
    unit 3-sphere (half the rotation angle between the two orientations), accurate
    near 0. The result turns at constant rate about one axis from :math:`q_0`
    (``t = 0``) to the rotation of :math:`q_1` (``t = 1``; the returned quaternion is
    then :math:`s q_1`, the same rotation).

    Parameters
    ----------
    q0, q1 : array_like, shape (..., 4)
        Unit quaternions (w, x, y, z) (norm 1 within 1e-6); NaN (a missing sample)
        propagates.
    t : array_like, shape (...)
        Fractions along the path (finite; values outside [0, 1] extrapolate along the
        same great circle). ``q0``, ``q1`` and ``t`` broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions.

    Notes
    -----
    * ``q`` and ``−q`` are the same rotation: the sign of ``q1`` is chosen so that the
      path is the shorter one (rotation angle at most 180°). ``slerp(q, -q, t)`` is
      ``q`` for every ``t`` (no motion), never NaN.
    * Two orientations exactly 180° apart (:math:`q_0\cdot q_1 = 0`) are joined by two
      paths of equal length, the half-turns in either sense about the same axis (the
      axis of :math:`q_0^{-1} q_1`). The documented choice is :math:`s = +1`: ``q1``
      is used as given, i.e. the positive half-turn about that axis; pass ``-q1`` for
      the other sense. Just off 180° the shorter path is taken, so the result jumps
      between the two senses as :math:`q_0\cdot q_1` changes sign — unavoidable for any
      shortest-path rule.
    * Below :math:`\Omega = 10^{-6}` the normalised linear interpolation is used (the
      same path to rounding).

    Raises
    ------
    ValueError
        Non-unit, zero or infinite quaternions, non-finite ``t``, or shapes that do not
        broadcast (the message names the argument).
    """
    q0, q1 = _real(q0, "q0"), _real(q1, "q1")
    _check_last(q0, 4, "q0")
    _check_last(q1, 4, "q1")
    check_unit(q0, "q0")
    check_unit(q1, "q1")
    t = _v.vectors(t, "t", width=None, ndim=None)
    q0, q1, tt = _broadcast(("q0", q0), ("q1", q1), ("t", t[..., None]))
    s = np.where(np.sum(q0 * q1, axis=-1, keepdims=True) < 0, -1.0, 1.0)
    q1 = s * q1
    om = 2.0 * np.arctan2(
        np.linalg.norm(q0 - q1, axis=-1, keepdims=True),
        np.linalg.norm(q0 + q1, axis=-1, keepdims=True),
    )
    small = om < 1e-6
    with np.errstate(invalid="ignore", divide="ignore"):
        so = np.sin(np.where(small, 1.0, om))
        out = np.where(
            small,
            (1.0 - tt) * q0 + tt * q1,
            (np.sin((1.0 - tt) * om) * q0 + np.sin(tt * om) * q1) / so,
        )
        return out / np.linalg.norm(out, axis=-1, keepdims=True)


def from_scipy(rot) -> np.ndarray:
    """Scalar-first quaternions from a :class:`scipy.spatial.transform.Rotation`.

    scipy's ``as_quat()`` is scalar-last; this converts explicitly.

    Parameters
    ----------
    rot : scipy.spatial.transform.Rotation
        One rotation or a stack of ``N`` rotations.

    Returns
    -------
    numpy.ndarray, shape (4,) or (N, 4)
        Unit quaternions (w, x, y, z).
    """
    return np.asarray(rot.as_quat(scalar_first=True))


def to_scipy(q):
    """Build a :class:`scipy.spatial.transform.Rotation` from scalar-first quaternions.

    Parameters
    ----------
    q : array_like, shape (4,) or (N, 4)
        Scalar-first quaternions (w, x, y, z); scipy normalises them.

    Returns
    -------
    scipy.spatial.transform.Rotation
        One rotation, or a stack of ``N``, representing ``q``.
    """
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(np.asarray(q, float), scalar_first=True)


def random_quaternions(
    n: int, rng: np.random.Generator | int | None = None
) -> np.ndarray:
    """``n`` uniformly distributed unit quaternions (Shoemake's method), w ≥ 0.

    Parameters
    ----------
    n : int
        Number of quaternions (≥ 0).
    rng : numpy.random.Generator or int or None, optional
        Random generator, or a seed for :func:`numpy.random.default_rng`; ``None``
        (default) draws fresh entropy (not reproducible).

    Returns
    -------
    numpy.ndarray, shape (n, 4)
        Unit quaternions (w, x, y, z) with w ≥ 0, uniform over rotations.
    """
    n = _v.integer(n, "n", minimum=0)
    rng = np.random.default_rng(rng)
    u1, u2, u3 = rng.random((3, n))
    a, b = np.sqrt(1.0 - u1), np.sqrt(u1)
    q = np.column_stack(
        [
            a * np.sin(2 * np.pi * u2),
            a * np.cos(2 * np.pi * u2),
            b * np.sin(2 * np.pi * u3),
            b * np.cos(2 * np.pi * u3),
        ]
    )
    return canonical(q)
