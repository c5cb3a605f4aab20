r"""Quaternion kernels (numba) over arrays of unit quaternions.

Conventions (the book's conventions page states them once):

* scalar first: ``q = (w, x, y, z)``;
* a quaternion rotates **sensor → world**: a vector with sensor coordinates
  :math:`v_s` has world coordinates :math:`v_w = R(q)\,v_s = q \otimes v_s \otimes q^*`;
* world z points up, so the tilt (gravity-up direction in the sensor frame) is
  :math:`g_s = R(q)^\top e_z`;
* angular velocity is expressed in the sensor frame, so orientation propagates as
  :math:`\dot q = \tfrac12\, q \otimes (0, \omega)`.

Every public function accepts arrays with any leading shape (``(..., 4)`` for
quaternions, ``(..., 3)`` for vectors, ``(..., 3, 3)`` for matrices), broadcasts
its arguments, never modifies its inputs and returns new arrays. The loops run in
``@njit(cache=True)`` kernels.

Inputs are checked before the kernels run (:class:`ValueError` naming the argument):
NaN marks a missing sample and propagates, but a complex value (never cut to its real
part), an infinite value, a zero quaternion or
vector (no rotation, no direction), a non-unit quaternion where a rotation matrix or
angle is derived from it (:func:`to_matrix`, :func:`to_rotvec`, tolerance 1e-6) and a
matrix that is not a rotation (:func:`from_matrix`: orthonormal within 1e-6, det +1)
are errors, never silently wrong or NaN output.

References
----------
.. [1] J. Solà, "Quaternion kinematics for the error-state Kalman filter",
   arXiv:1711.02508, 2017.
.. [2] S. W. Shepperd, "Quaternion from rotation matrix", J. Guidance and Control
   1(3):223–224, 1978. doi:10.2514/3.55767b
.. [3] D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD — A Benchmark for Robust
   Inertial Orientation Estimation", Data 6(7):72, 2021. doi:10.3390/data6070072
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import _validate as _v

__all__ = [
    "identity",
    "mul",
    "conj",
    "inv",
    "norm",
    "normalize",
    "canonical",
    "rotate",
    "rotate_inverse",
    "to_matrix",
    "from_matrix",
    "to_rotvec",
    "from_rotvec",
    "exp",
    "log",
    "gravity",
    "angle_between",
    "error_quaternion",
    "error_angles",
    "tilt_error",
    "heading_error",
    "total_error",
    "integrate_gyro",
    "slerp",
    "from_scipy",
    "to_scipy",
    "random_quaternions",
]


# ---------------------------------------------------------------- scalar helpers
# Inlined into every numba kernel that steps or rotates one quaternion at a time
# (here, in tiltlab.filters and in tiltlab.simulate), so the arithmetic is written once.


@njit(cache=True, inline="always")
def qmul_scalar(aw, ax, ay, az, bw, bx, by, bz):
    """Hamilton product of two quaternions given by components; returns (w, x, y, z)."""
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit(cache=True, inline="always")
def rotvec_to_quat_scalar(rx, ry, rz):
    """Unit quaternion of the rotation vector (rx, ry, rz), with series below 1e-4 rad."""
    th2 = rx * rx + ry * ry + rz * rz
    th = np.sqrt(th2)
    if th < 1e-4:
        # sin(th/2)/th and cos(th/2) by series (error < 1e-20)
        f = 0.5 - th2 / 48.0 + th2 * th2 / 3840.0
        c = 1.0 - th2 / 8.0 + th2 * th2 / 384.0
    else:
        f = np.sin(0.5 * th) / th
        c = np.cos(0.5 * th)
    return c, f * rx, f * ry, f * rz


@njit(cache=True, inline="always")
def zoh_step_scalar(w, x, y, z, rx, ry, rz):
    """q ⊗ exp(r / 2) for the rotation vector r = ω Δt (not renormalised)."""
    dw, dx, dy, dz = rotvec_to_quat_scalar(rx, ry, rz)
    return qmul_scalar(w, x, y, z, dw, dx, dy, dz)


@njit(cache=True, inline="always")
def rotmat_scalar(w, x, y, z, R):
    """Write the rotation matrix R(q) of a unit quaternion into the (3, 3) array ``R``."""
    R[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    R[0, 1] = 2.0 * (x * y - w * z)
    R[0, 2] = 2.0 * (x * z + w * y)
    R[1, 0] = 2.0 * (x * y + w * z)
    R[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    R[1, 2] = 2.0 * (y * z - w * x)
    R[2, 0] = 2.0 * (x * z - w * y)
    R[2, 1] = 2.0 * (y * z + w * x)
    R[2, 2] = 1.0 - 2.0 * (x * x + y * y)


@njit(cache=True, inline="always")
def rotate_scalar(w, x, y, z, vx, vy, vz):
    """R(q) v for one quaternion and one vector, via v + 2w(u×v) + 2u×(u×v)."""
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (
        vx + w * tx + (y * tz - z * ty),
        vy + w * ty + (z * tx - x * tz),
        vz + w * tz + (x * ty - y * tx),
    )


# ---------------------------------------------------------------- kernels


@njit(cache=True)
def _mul_kernel(p, q, out):
    for i in range(p.shape[0]):
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = qmul_scalar(
            p[i, 0], p[i, 1], p[i, 2], p[i, 3], q[i, 0], q[i, 1], q[i, 2], q[i, 3]
        )


@njit(cache=True)
def _rotate_kernel(q, v, inverse, out):
    # v' = R(q) v (or R(q)^T v) using v' = v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)
    for i in range(q.shape[0]):
        w, x, y, z = q[i, 0], q[i, 1], q[i, 2], q[i, 3]
        if inverse:
            x, y, z = -x, -y, -z
        out[i, 0], out[i, 1], out[i, 2] = rotate_scalar(
            w, x, y, z, v[i, 0], v[i, 1], v[i, 2]
        )


@njit(cache=True)
def _to_matrix_kernel(q, out):
    for i in range(q.shape[0]):
        w, x, y, z = q[i, 0], q[i, 1], q[i, 2], q[i, 3]
        out[i, 0, 0] = 1.0 - 2.0 * (y * y + z * z)
        out[i, 0, 1] = 2.0 * (x * y - w * z)
        out[i, 0, 2] = 2.0 * (x * z + w * y)
        out[i, 1, 0] = 2.0 * (x * y + w * z)
        out[i, 1, 1] = 1.0 - 2.0 * (x * x + z * z)
        out[i, 1, 2] = 2.0 * (y * z - w * x)
        out[i, 2, 0] = 2.0 * (x * z - w * y)
        out[i, 2, 1] = 2.0 * (y * z + w * x)
        out[i, 2, 2] = 1.0 - 2.0 * (x * x + y * y)


@njit(cache=True)
def _from_matrix_kernel(m, out):
    # Shepperd's method: pivot on the largest of (trace, diagonal) for stability
    for i in range(m.shape[0]):
        m00, m01, m02 = m[i, 0, 0], m[i, 0, 1], m[i, 0, 2]
        m10, m11, m12 = m[i, 1, 0], m[i, 1, 1], m[i, 1, 2]
        m20, m21, m22 = m[i, 2, 0], m[i, 2, 1], m[i, 2, 2]
        tr = m00 + m11 + m22
        if tr >= m00 and tr >= m11 and tr >= m22:
            s = 2.0 * np.sqrt(1.0 + tr)
            w = 0.25 * s
            x = (m21 - m12) / s
            y = (m02 - m20) / s
            z = (m10 - m01) / s
        elif m00 >= m11 and m00 >= m22:
            s = 2.0 * np.sqrt(1.0 + m00 - m11 - m22)
            w = (m21 - m12) / s
            x = 0.25 * s
            y = (m01 + m10) / s
            z = (m02 + m20) / s
        elif m11 >= m22:
            s = 2.0 * np.sqrt(1.0 + m11 - m00 - m22)
            w = (m02 - m20) / s
            x = (m01 + m10) / s
            y = 0.25 * s
            z = (m12 + m21) / s
        else:
            s = 2.0 * np.sqrt(1.0 + m22 - m00 - m11)
            w = (m10 - m01) / s
            x = (m02 + m20) / s
            y = (m12 + m21) / s
            z = 0.25 * s
        n = np.sqrt(w * w + x * x + y * y + z * z)
        if w < 0.0:
            n = -n
        out[i, 0] = w / n
        out[i, 1] = x / n
        out[i, 2] = y / n
        out[i, 3] = z / n


@njit(cache=True)
def _to_rotvec_kernel(q, out):
    for i in range(q.shape[0]):
        w, x, y, z = q[i, 0], q[i, 1], q[i, 2], q[i, 3]
        if w < 0.0:
            w, x, y, z = -w, -x, -y, -z
        s = np.sqrt(x * x + y * y + z * z)
        if s < 1e-6:
            # theta / s = 2 atan(s / w) / s, Taylor series in (s / w)
            r = s / w
            f = 2.0 / w * (1.0 - r * r / 3.0 + r * r * r * r / 5.0)
        else:
            f = 2.0 * np.arctan2(s, w) / s
        out[i, 0] = f * x
        out[i, 1] = f * y
        out[i, 2] = f * z


@njit(cache=True)
def _from_rotvec_kernel(r, out):
    for i in range(r.shape[0]):
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = rotvec_to_quat_scalar(
            r[i, 0], r[i, 1], r[i, 2]
        )


@njit(cache=True)
def _gravity_kernel(q, out):
    for i in range(q.shape[0]):
        w, x, y, z = q[i, 0], q[i, 1], q[i, 2], q[i, 3]
        out[i, 0] = 2.0 * (x * z - w * y)
        out[i, 1] = 2.0 * (y * z + w * x)
        out[i, 2] = w * w - x * x - y * y + z * z


@njit(cache=True)
def _error_angles_kernel(p, q, out):
    # columns: total, heading, inclination of the Earth-frame error e = p ⊗ q⁻¹
    for i in range(p.shape[0]):
        w, x, y, z = qmul_scalar(
            p[i, 0], p[i, 1], p[i, 2], p[i, 3], q[i, 0], -q[i, 1], -q[i, 2], -q[i, 3]
        )
        aw = abs(w)
        out[i, 0] = 2.0 * np.arctan2(np.sqrt(x * x + y * y + z * z), aw)
        if aw == 0.0 and z == 0.0:
            out[i, 1] = 0.0  # heading undefined for a pure 180° tilt: no heading part
        else:
            out[i, 1] = 2.0 * np.arctan2(abs(z), aw)
        out[i, 2] = 2.0 * np.arctan2(np.sqrt(x * x + y * y), np.sqrt(w * w + z * z))


@njit(cache=True)
def _angle_between_kernel(u, v, out):
    for i in range(u.shape[0]):
        cx = u[i, 1] * v[i, 2] - u[i, 2] * v[i, 1]
        cy = u[i, 2] * v[i, 0] - u[i, 0] * v[i, 2]
        cz = u[i, 0] * v[i, 1] - u[i, 1] * v[i, 0]
        d = u[i, 0] * v[i, 0] + u[i, 1] * v[i, 1] + u[i, 2] * v[i, 2]
        out[i] = np.arctan2(np.sqrt(cx * cx + cy * cy + cz * cz), d)


@njit(cache=True)
def _integrate_kernel(omega, dt, q0, out):
    # q_{k+1} = q_k ⊗ exp(ω_k dt / 2): exact for ω constant over each step
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = w, x, y, z
    for k in range(omega.shape[0] - 1):
        nw, nx, ny, nz = zoh_step_scalar(
            w, x, y, z, omega[k, 0] * dt, omega[k, 1] * dt, omega[k, 2] * dt
        )
        n = np.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
        w, x, y, z = nw / n, nx / n, ny / n, nz / n
        out[k + 1, 0], out[k + 1, 1], out[k + 1, 2], out[k + 1, 3] = w, x, y, z


# ---------------------------------------------------------------- wrappers


def _real(a, name: str) -> np.ndarray:
    """``a`` as a float array; complex input is refused by name (never cut to its
    real part)."""
    raw = np.asarray(a)
    if raw.dtype.kind == "c":
        raise ValueError(
            f"{name} holds complex numbers (dtype {raw.dtype}); quaternions and vectors "
            f"are real: pass {name}.real explicitly if that is what you mean"
        )
    return np.asarray(raw, float)


def _as2d(a: np.ndarray, width: int) -> np.ndarray:
    return np.ascontiguousarray(a.reshape(-1, width), dtype=np.float64)


def _check_last(a: np.ndarray, width: int, name: str) -> None:
    if a.ndim == 0 or a.shape[-1] != width:
        raise ValueError(
            f"{name} must have last dimension {width}, got shape {a.shape}"
        )


def _broadcast(*named) -> list[np.ndarray]:
    """``np.broadcast_arrays`` of ``(name, array)`` pairs; a mismatch names them."""
    try:
        return np.broadcast_arrays(*(a for _, a in named))
    except ValueError:
        shapes = " and ".join(f"{n} {a.shape}" for n, a in named)
        raise ValueError(
            f"{' and '.join(n for n, _ in named)} have incompatible shapes: {shapes}"
        ) from None


def _no_inf(a: np.ndarray, name: str) -> np.ndarray:
    """``a`` unchanged; infinite values raise (NaN, a missing sample, passes)."""
    if np.any(np.isinf(a)):
        raise ValueError(f"{name} has {int(np.sum(np.isinf(a)))} infinite values")
    return a


def _no_zero(q: np.ndarray, name: str) -> np.ndarray:
    """``q`` unchanged; a zero quaternion, which is no rotation, raises."""
    if np.any(np.sum(q * q, axis=-1) == 0):
        raise ValueError(f"{name} has zero quaternions, which are not rotations")
    return q


def check_unit(q: np.ndarray, name: str = "q", atol: float = 1e-6) -> None:
    """Raise unless every finite quaternion of ``q`` (…, 4) has norm 1 within ``atol``.

    NaN quaternions (missing samples) pass; infinities do not.
    """
    if np.any(np.isinf(q)):
        raise ValueError(f"{name} has infinite values")
    n = np.linalg.norm(q, axis=-1)
    bad = np.abs(n - 1.0) > atol  # NaN compares False
    if np.any(bad):
        k = int(np.argmax(bad.ravel()))
        raise ValueError(
            f"{name} must hold unit quaternions: {int(bad.sum())} have a norm other than "
            f"1 (first: {float(n.ravel()[k]):.6g}); normalise them first "
            "(a zero quaternion is not a rotation)"
        )


def check_rotation(m: np.ndarray, name: str = "m", atol: float = 1e-6) -> None:
    """Raise unless every finite (3, 3) matrix of ``m`` is a proper rotation
    (orthonormal within ``atol``, determinant +1). NaN matrices pass; infinities do not."""
    if np.any(np.isinf(m)):
        raise ValueError(f"{name} has infinite values")
    M = m[np.all(np.isfinite(m), axis=(-2, -1))]
    if M.size == 0:
        return
    err = np.abs(np.swapaxes(M, -1, -2) @ M - np.eye(3)).max(axis=(-2, -1))
    if np.any(err > atol):
        raise ValueError(
            f"{name} must hold rotation matrices (orthonormal, det +1): "
            f"max |MᵀM − I| = {float(err.max()):.3g}"
        )
    det = np.linalg.det(M)
    if np.any(det < 0):
        raise ValueError(
            f"{name} must hold rotation matrices (det +1), got {int(np.sum(det < 0))} "
            "reflection(s) (det −1)"
        )


def identity(n: int | None = None) -> np.ndarray:
    """The identity quaternion (1, 0, 0, 0), or ``n`` of them.

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
    p, q = _real(p, "p"), _real(q, "q")
    _check_last(p, 4, "p")
    _check_last(q, 4, "q")
    p, q = _broadcast(("p", _no_inf(p, "p")), ("q", _no_inf(q, "q")))
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
    """Inverse :math:`q^* / \\|q\\|^2` (equals :func:`conj` for unit quaternions).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Finite, non-zero quaternions (w, x, y, z); they need not be unit.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        The inverses (w, x, y, z), such that ``mul(q, inv(q))`` is the identity.
    """
    q = _real(q, "q")
    _check_last(q, 4, "q")
    _no_zero(_no_inf(q, "q"), "q")
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
    """Unit quaternions; a zero quaternion is an error.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Finite, non-zero quaternions (w, x, y, z); NaN (a missing sample) propagates.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``q`` divided by its norm: unit quaternions of the same rotations.
    """
    q = _no_inf(_real(q, "q"), "q")
    _check_last(q, 4, "q")
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    if np.any(n == 0):
        raise ValueError(
            f"q has {int(np.sum(n == 0))} zero quaternion(s), which cannot be normalised"
        )
    return q / n


def canonical(q) -> np.ndarray:
    """The representative with w ≥ 0 (q and −q are the same rotation).

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
        Unit sensor → world quaternions (w, x, y, z); not renormalised.
    v : array_like, shape (..., 3)
        Vectors in world coordinates, in any unit (kept). The leading dimensions of
        ``q`` and ``v`` broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        The same vectors in sensor coordinates, in the unit of ``v``, with the broadcast
        leading shape.
    """
    return _rotate(q, v, True)


def _rotate(q, v, inverse: bool) -> np.ndarray:
    q, v = _real(q, "q"), _real(v, "v")
    _check_last(q, 4, "q")
    _check_last(v, 3, "v")
    _no_zero(_no_inf(q, "q"), "q")
    _no_inf(v, "v")
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
    """Unit quaternions (w ≥ 0) from rotation matrices (Shepperd's method [2]_).

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
    r"""Unit quaternions :math:`(\cos\tfrac{\theta}{2}, \sin\tfrac{\theta}{2}\,\hat r)` from rotation vectors.

    Parameters
    ----------
    r : array_like, shape (..., 3)
        Rotation vectors: axis times angle θ (rad); finite.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions (w, x, y, z) of the same rotations.
    """
    r = _no_inf(_real(r, "r"), "r")
    _check_last(r, 3, "r")
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
        Unit quaternions (w, x, y, z), norm 1 within 1e-6.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Vector parts of the logarithms: axis times half the rotation angle (rad), norm
        in [0, π/2].
    """
    return 0.5 * to_rotvec(q)


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
    """A :class:`scipy.spatial.transform.Rotation` from scalar-first quaternions.

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
