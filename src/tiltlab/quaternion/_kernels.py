"""Numba kernels of :mod:`tiltlab.quaternion`: inlined scalar helpers and array loops.

The scalar helpers are also used by tiltlab.filters and tiltlab.simulate; the array
loops run behind the public wrappers.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# ---------------------------------------------------------------- scalar helpers
# Inlined into every numba kernel that steps or rotates one quaternion at a time
# (here, in tiltlab.filters and in tiltlab.simulate), so the arithmetic is written once.


@njit(cache=True, inline="always")
def qmul_scalar(aw, ax, ay, az, bw, bx, by, bz):
    """Compute the Hamilton product of two quaternions given by components.

    Parameters
    ----------
    aw, ax, ay, az : float
        Components of the left factor (w, x, y, z).
    bw, bx, by, bz : float
        Components of the right factor (w, x, y, z).

    Returns
    -------
    tuple of float
        The product (w, x, y, z).
    """
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit(cache=True, inline="always")
def rotvec_to_quat_scalar(rx, ry, rz):
    """Convert the rotation vector (rx, ry, rz) to a unit quaternion (series below 1e-4 rad).

    Parameters
    ----------
    rx, ry, rz : float
        Rotation vector components (rad).

    Returns
    -------
    tuple of float
        The unit quaternion (w, x, y, z).
    """
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
    """Step a quaternion by a rotation vector: q ⊗ exp(r / 2), r = ω Δt (not renormalised).

    Parameters
    ----------
    w, x, y, z : float
        The quaternion components.
    rx, ry, rz : float
        The rotation vector (rad), in the frame of ``q``'s sensor.

    Returns
    -------
    tuple of float
        The stepped quaternion (w, x, y, z).
    """
    dw, dx, dy, dz = rotvec_to_quat_scalar(rx, ry, rz)
    return qmul_scalar(w, x, y, z, dw, dx, dy, dz)


@njit(cache=True, inline="always")
def rotmat_scalar(w, x, y, z, R):
    """Write the rotation matrix R(q) of a unit quaternion into the (3, 3) array ``R``.

    Parameters
    ----------
    w, x, y, z : float
        The unit quaternion components.
    R : numpy.ndarray, shape (3, 3)
        Output array, overwritten.
    """
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
    """Rotate one vector by one quaternion: R(q) v = v + 2w(u×v) + 2u×(u×v).

    Parameters
    ----------
    w, x, y, z : float
        The unit quaternion components (u = (x, y, z)).
    vx, vy, vz : float
        The vector components.

    Returns
    -------
    tuple of float
        The rotated vector (x, y, z).
    """
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
