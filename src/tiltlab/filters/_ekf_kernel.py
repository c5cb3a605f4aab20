r"""Numba kernels of the quaternion-state extended Kalman filter (:func:`~tiltlab.filters.ekf`).

The kernel takes its scalar parameters as one record, :data:`EkfParams`, built by
:func:`tiltlab.filters.ekf._ekf_params`.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from ..quaternion import qmul_scalar, rotate_scalar


#: the kernel's scalar parameters (built by :func:`tiltlab.filters.ekf._ekf_params`):
#: dt (s), var_gyr ((rad/s)²), var_acc and var_mag (variances of the unit
#: accelerometer and magnetometer directions)
EkfParams = namedtuple("EkfParams", "dt var_gyr var_acc var_mag")


@njit(cache=True, nogil=True)
def _invert_small(A, m, Ainv, work):
    # Gauss-Jordan with partial pivoting on the leading m x m block of A
    for i in range(m):
        for j in range(m):
            work[i, j] = A[i, j]
            Ainv[i, j] = 1.0 if i == j else 0.0
    for col in range(m):
        piv = col
        best = abs(work[col, col])
        for r in range(col + 1, m):
            if abs(work[r, col]) > best:
                best = abs(work[r, col])
                piv = r
        if piv != col:
            for j in range(m):
                t = work[col, j]
                work[col, j] = work[piv, j]
                work[piv, j] = t
                t = Ainv[col, j]
                Ainv[col, j] = Ainv[piv, j]
                Ainv[piv, j] = t
        d = work[col, col]
        for j in range(m):
            work[col, j] /= d
            Ainv[col, j] /= d
        for r in range(m):
            if r != col:
                f = work[r, col]
                if f != 0.0:
                    for j in range(m):
                        work[r, j] -= f * work[col, j]
                        Ainv[r, j] -= f * Ainv[col, j]


@njit(cache=True, nogil=True)
def _ekf_h_rows(H, row, v, w, x, y, z):
    # rows of d(R(q)^T v)/dq (ahrs/EKF convention, factor 2 included)
    v0, v1, v2 = v[0], v[1], v[2]
    H[row, 0] = 2.0 * (v0 * w + v1 * z - v2 * y)
    H[row, 1] = 2.0 * (v0 * x + v1 * y + v2 * z)
    H[row, 2] = 2.0 * (-v0 * y + v1 * x - v2 * w)
    H[row, 3] = 2.0 * (-v0 * z + v1 * w + v2 * x)
    H[row + 1, 0] = 2.0 * (-v0 * z + v1 * w + v2 * x)
    H[row + 1, 1] = 2.0 * (v0 * y - v1 * x + v2 * w)
    H[row + 1, 2] = 2.0 * (v0 * x + v1 * y + v2 * z)
    H[row + 1, 3] = 2.0 * (-v0 * w - v1 * z + v2 * y)
    H[row + 2, 0] = 2.0 * (v0 * y - v1 * x + v2 * w)
    H[row + 2, 1] = 2.0 * (v0 * z - v1 * w - v2 * x)
    H[row + 2, 2] = 2.0 * (v0 * w + v1 * z - v2 * y)
    H[row + 2, 3] = 2.0 * (v0 * x + v1 * y + v2 * z)


@njit(cache=True, nogil=True)
def _ekf_h_pred(hp, row, v, w, x, y, z):
    # R(q)^T v for a unit q
    hp[row], hp[row + 1], hp[row + 2] = rotate_scalar(w, -x, -y, -z, v[0], v[1], v[2])


@njit(cache=True, nogil=True, inline="always")
def _f_times(ox, oy, oz, p0, p1, p2, p3):
    # F p for F = I + Ω(o) (o = Δt ω / 2) and a 4-vector p
    return (
        p0 - ox * p1 - oy * p2 - oz * p3,
        ox * p0 + p1 + oz * p2 - oy * p3,
        oy * p0 - oz * p1 + p2 + ox * p3,
        oz * p0 + oy * p1 - ox * p2 + p3,
    )


@njit(cache=True, nogil=True)
def _ekf_kernel(acc, gyr, mag, use_mag, prm, m_ref, P0, q0, out):
    # the filter over a recording from q0 and the covariance P0
    dt, var_gyr, var_acc, var_mag = prm.dt, prm.var_gyr, prm.var_acc, prm.var_mag
    a_ref = np.array([0.0, 0.0, 1.0])
    P = P0.copy()
    Pt = np.empty((4, 4))
    FP = np.empty((4, 4))
    W = np.empty((4, 3))
    H = np.empty((6, 4))
    PHt = np.empty((4, 6))
    S = np.empty((6, 6))
    Si = np.empty((6, 6))
    work = np.empty((6, 6))
    K = np.empty((4, 6))
    KH = np.empty((4, 4))
    meas = np.empty(6)
    hp = np.empty(6)
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = w, x, y, z
    hdt = 0.5 * dt
    for k in range(1, acc.shape[0]):
        gx, gy, gz = gyr[k, 0], gyr[k, 1], gyr[k, 2]
        # ---- prediction: q_t = (I + dt/2 Ω(ω)) q, F = I + Ω(dt ω / 2)
        dw, dx, dy, dz = qmul_scalar(w, x, y, z, 0.0, gx, gy, gz)
        tw, tx, ty, tz = w + hdt * dw, x + hdt * dx, y + hdt * dy, z + hdt * dz
        ox, oy, oz = hdt * gx, hdt * gy, hdt * gz
        # W = dq_t/dω (at the prior q)
        W[0, 0], W[0, 1], W[0, 2] = -hdt * x, -hdt * y, -hdt * z
        W[1, 0], W[1, 1], W[1, 2] = hdt * w, -hdt * z, hdt * y
        W[2, 0], W[2, 1], W[2, 2] = hdt * z, hdt * w, -hdt * x
        W[3, 0], W[3, 1], W[3, 2] = -hdt * y, hdt * x, hdt * w
        # FP = F P (column by column)
        for j in range(4):
            FP[0, j], FP[1, j], FP[2, j], FP[3, j] = _f_times(
                ox, oy, oz, P[0, j], P[1, j], P[2, j], P[3, j]
            )
        # Pt = FP F^T + var_gyr W W^T (F times the rows of FP)
        for i in range(4):
            Pt[i, 0], Pt[i, 1], Pt[i, 2], Pt[i, 3] = _f_times(
                ox, oy, oz, FP[i, 0], FP[i, 1], FP[i, 2], FP[i, 3]
            )
            for j in range(4):
                Pt[i, j] += var_gyr * (
                    W[i, 0] * W[j, 0] + W[i, 1] * W[j, 1] + W[i, 2] * W[j, 2]
                )
        # ---- correction
        ax, ay, az = acc[k, 0], acc[k, 1], acc[k, 2]
        an = np.sqrt(ax * ax + ay * ay + az * az)
        m = 0
        if an > 0.0:
            meas[0], meas[1], meas[2] = ax / an, ay / an, az / an
            m = 3
            if use_mag:
                mx, my, mz = mag[k, 0], mag[k, 1], mag[k, 2]
                mn = np.sqrt(mx * mx + my * my + mz * mz)
                if mn > 0.0:
                    meas[3], meas[4], meas[5] = mx / mn, my / mn, mz / mn
                    m = 6
        if m == 0:
            n = np.sqrt(tw * tw + tx * tx + ty * ty + tz * tz)
            w, x, y, z = tw / n, tx / n, ty / n, tz / n
            for i in range(4):
                for j in range(4):
                    P[i, j] = Pt[i, j]
        else:
            # expected measurement at the normalised q_t, Jacobian at the raw q_t (as ahrs)
            n = np.sqrt(tw * tw + tx * tx + ty * ty + tz * tz)
            _ekf_h_pred(hp, 0, a_ref, tw / n, tx / n, ty / n, tz / n)
            _ekf_h_rows(H, 0, a_ref, tw, tx, ty, tz)
            if m == 6:
                _ekf_h_pred(hp, 3, m_ref, tw / n, tx / n, ty / n, tz / n)
                _ekf_h_rows(H, 3, m_ref, tw, tx, ty, tz)
            for i in range(4):
                for r in range(m):
                    PHt[i, r] = (
                        Pt[i, 0] * H[r, 0]
                        + Pt[i, 1] * H[r, 1]
                        + Pt[i, 2] * H[r, 2]
                        + Pt[i, 3] * H[r, 3]
                    )
            for r in range(m):
                for s in range(m):
                    S[r, s] = (
                        H[r, 0] * PHt[0, s]
                        + H[r, 1] * PHt[1, s]
                        + H[r, 2] * PHt[2, s]
                        + H[r, 3] * PHt[3, s]
                    )
                S[r, r] += var_acc if r < 3 else var_mag
            _invert_small(S, m, Si, work)
            for i in range(4):  # K = P Hᵀ S⁻¹
                for r in range(m):
                    acc_ = 0.0
                    for s in range(m):
                        acc_ += PHt[i, s] * Si[s, r]
                    K[i, r] = acc_
            for i in range(4):
                for j in range(4):
                    acc_ = 0.0
                    for r in range(m):
                        acc_ += K[i, r] * H[r, j]
                    KH[i, j] = acc_
            for i in range(4):
                for j in range(4):
                    acc_ = Pt[i, j]
                    for l in range(4):
                        acc_ -= KH[i, l] * Pt[l, j]
                    P[i, j] = acc_
            cw, cx, cy, cz = tw, tx, ty, tz
            for r in range(m):
                v = meas[r] - hp[r]
                cw += K[0, r] * v
                cx += K[1, r] * v
                cy += K[2, r] * v
                cz += K[3, r] * v
            n = np.sqrt(cw * cw + cx * cx + cy * cy + cz * cz)
            w, x, y, z = cw / n, cx / n, cy / n, cz / n
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z
