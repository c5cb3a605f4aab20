"""Quaternion algebra: identity, product, conjugate, inverse, norm and rotation.

Also the conversions to and from matrices, rotation vectors, exp and log.
"""

from __future__ import annotations

import numpy as np

import tiltlab._validate as _v
from ._checks import (
    _as2d,
    _broadcast,
    _check_last,
    _finite,
    _real,
    _rotations,
    check_rotation,
    check_unit,
)
from ._kernels import (
    _from_matrix_kernel,
    _from_rotvec_kernel,
    _mul_kernel,
    _rotate_kernel,
    _to_matrix_kernel,
    _to_rotvec_kernel,
)


def identity(n: int | None = None) -> np.ndarray:
    """Return the identity quaternion (1, 0, 0, 0), or ``n`` of them.

    Parameters
    ----------
    n : int, optional
        Number of identity quaternions (≥ 0). The default, ``None``, returns a single
        quaternion of shape (4,).

    Returns
    -------
    numpy.ndarray, shape (4,) or (n, 4)
        The identity quaternion (1, 0, 0, 0) (no rotation), once or ``n`` times.
    """
    if n is None:
        return np.array([1.0, 0.0, 0.0, 0.0])
    n = _v.integer(n, "n", minimum=0)
    out = np.zeros((n, 4))
    out[:, 0] = 1.0
    return out


def mul(p, q) -> np.ndarray:
    r"""Hamilton product :math:`p \otimes q` (broadcast over leading dimensions).

    With sensor → world quaternions, ``mul(p, q)`` applies ``q`` first, then ``p``.

    Parameters
    ----------
    p : array_like, shape (..., 4)
        Left factor (w, x, y, z), applied second.
    q : array_like, shape (..., 4)
        Right factor (w, x, y, z), applied first. The leading dimensions of ``p`` and
        ``q`` broadcast; neither needs to be unit; NaN (a missing sample) propagates.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        The Hamilton products ``p ⊗ q`` (w, x, y, z), with the broadcast shape.
    """
    p, q = _broadcast(("p", _finite(p, 4, "p")), ("q", _finite(q, 4, "q")))
    shape = p.shape
    out = np.empty((int(np.prod(shape[:-1], dtype=np.int64)), 4))
    _mul_kernel(_as2d(p, 4), _as2d(q, 4), out)
    return out.reshape(shape)


def conj(q) -> np.ndarray:
    """Conjugate (w, −x, −y, −z): the inverse of a unit quaternion.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions (w, x, y, z); not modified.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        The conjugates (w, −x, −y, −z), a new array.
    """
    q = np.array(_real(q, "q"), dtype=float)
    _check_last(q, 4, "q")
    q[..., 1:] *= -1.0
    return q


def inv(q) -> np.ndarray:
    r"""Invert quaternions: :math:`q^* / \|q\|^2` (equals :func:`conj` for unit quaternions).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Finite, non-zero quaternions (w, x, y, z); they need not be unit.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        The inverses (w, x, y, z), such that ``mul(q, inv(q))`` is the identity.
    """
    q = _rotations(q, "q")
    return conj(q) / np.sum(q * q, axis=-1, keepdims=True)


def norm(q) -> np.ndarray:
    """Euclidean norm over the last axis.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions (w, x, y, z) (or any vectors on the last axis).

    Returns
    -------
    numpy.ndarray, shape (...)
        The Euclidean norms (1 for unit quaternions).
    """
    return np.linalg.norm(_real(q, "q"), axis=-1)


def normalize(q) -> np.ndarray:
    """Normalise quaternions to unit norm; a zero quaternion is an error.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Finite, non-zero quaternions (w, x, y, z); NaN (a missing sample) propagates.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``q`` divided by its norm: unit quaternions of the same rotations.
    """
    q = _finite(q, 4, "q")
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    if np.any(n == 0):
        raise ValueError(
            f"q has {int(np.sum(n == 0))} zero quaternion(s), which cannot be normalised"
        )
    return q / n


def canonical(q) -> np.ndarray:
    """Return the representative with w ≥ 0 (q and −q are the same rotation).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions (w, x, y, z).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``q`` where w ≥ 0, else ``−q``: the same rotations, with a non-negative scalar
        part.
    """
    q = _real(q, "q")
    return np.where(q[..., :1] < 0, -q, q)


def rotate(q, v) -> np.ndarray:
    r"""Rotate sensor-frame vectors to the world frame: :math:`R(q)\,v`.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Unit sensor → world quaternions (w, x, y, z); not renormalised.
    v : array_like, shape (..., 3)
        Vectors in sensor coordinates, in any unit (kept). The leading dimensions of
        ``q`` and ``v`` broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        The same vectors in world coordinates, in the unit of ``v``, with the broadcast
        leading shape.
    """
    return _rotate(q, v, False)


def rotate_inverse(q, v) -> np.ndarray:
    r"""Rotate world-frame vectors to the sensor frame: :math:`R(q)^\top v`.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Unit sensor → world quaternions, as for :func:`rotate`.
    v : array_like, shape (..., 3)
        Vectors in world coordinates (any unit, kept; broadcast with ``q``).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        ``v`` in sensor coordinates: the inverse rotation of :func:`rotate`.
    """
    return _rotate(q, v, True)


def _rotate(q, v, inverse: bool) -> np.ndarray:
    q, v = _rotations(q, "q"), _finite(v, 3, "v")
    lead = _broadcast(("q", q[..., 0]), ("v", v[..., 0]))[0].shape
    qb = np.broadcast_to(q, lead + (4,))
    vb = np.broadcast_to(v, lead + (3,))
    out = np.empty((int(np.prod(lead, dtype=np.int64)), 3))
    _rotate_kernel(_as2d(qb, 4), _as2d(vb, 3), inverse, out)
    return out.reshape(lead + (3,))


def to_matrix(q) -> np.ndarray:
    """Rotation matrices R(q), shape (..., 3, 3), mapping sensor to world coordinates.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Unit sensor → world quaternions (w, x, y, z), norm 1 within 1e-6.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Rotation matrices; ``R @ v_s`` gives world coordinates of a sensor vector.
    """
    q = _real(q, "q")
    _check_last(q, 4, "q")
    check_unit(q, "q")
    out = np.empty((int(np.prod(q.shape[:-1], dtype=np.int64)), 3, 3))
    _to_matrix_kernel(_as2d(q, 4), out)
    return out.reshape(q.shape[:-1] + (3, 3))


def from_matrix(m) -> np.ndarray:
    """Convert rotation matrices to unit quaternions (w ≥ 0) by Shepperd's method [2]_.

    Parameters
    ----------
    m : array_like, shape (..., 3, 3)
        Rotation matrices (orthonormal within 1e-6, determinant +1) mapping sensor to
        world coordinates.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions (w, x, y, z) with w ≥ 0.
    """
    m = _real(m, "m")
    if m.shape[-2:] != (3, 3):
        raise ValueError(f"m must have shape (..., 3, 3), got {m.shape}")
    check_rotation(m, "m")
    out = np.empty((int(np.prod(m.shape[:-2], dtype=np.int64)), 4))
    _from_matrix_kernel(np.ascontiguousarray(m.reshape(-1, 3, 3)), out)
    return out.reshape(m.shape[:-2] + (4,))


def to_rotvec(q) -> np.ndarray:
    """Rotation vectors (axis × angle, angle in [0, π]) of unit quaternions.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Unit quaternions (w, x, y, z), norm 1 within 1e-6.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Rotation vectors: unit axis times angle (rad), norm in [0, π].
    """
    q = _real(q, "q")
    _check_last(q, 4, "q")
    check_unit(q, "q")
    out = np.empty((int(np.prod(q.shape[:-1], dtype=np.int64)), 3))
    _to_rotvec_kernel(_as2d(q, 4), out)
    return out.reshape(q.shape[:-1] + (3,))


def from_rotvec(r) -> np.ndarray:
    r"""Convert rotation vectors to unit quaternions :math:`(\cos\tfrac{\theta}{2}, \sin\tfrac{\theta}{2}\,\hat r)`.

    Parameters
    ----------
    r : array_like, shape (..., 3)
        Rotation vectors: axis times angle θ (rad); finite.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions (w, x, y, z) of the same rotations.
    """
    r = _finite(r, 3, "r")
    with np.errstate(over="ignore"):
        big = np.isinf(np.linalg.norm(r, axis=-1))
    if np.any(big):
        raise ValueError(
            f"r has {int(big.sum())} rotation vectors too large to represent"
        )
    out = np.empty((int(np.prod(r.shape[:-1], dtype=np.int64)), 4))
    _from_rotvec_kernel(_as2d(r, 3), out)
    return out.reshape(r.shape[:-1] + (4,))


def exp(v) -> np.ndarray:
    r"""Exponential of pure quaternions :math:`(0, v)`: :math:`\exp(v) = (\cos\|v\|, \sin\|v\|\,\hat v)`.

    Note ``exp(r / 2) == from_rotvec(r)``.

    Parameters
    ----------
    v : array_like, shape (..., 3)
        Vector parts of pure quaternions (rad: half the rotation vector); finite.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions (w, x, y, z), a rotation by ``2‖v‖`` rad about ``v``.
    """
    return from_rotvec(2.0 * _real(v, "v"))


def log(q) -> np.ndarray:
    """Logarithm of unit quaternions as the vector part (``to_rotvec(q) / 2``).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Unit quaternions, as for :func:`to_rotvec`.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Vector parts of the logarithms: axis times half the rotation angle (rad), norm
        in [0, π/2].
    """
    return 0.5 * to_rotvec(q)
