r"""Numba kernels of the error-state Kalman filter (:func:`~tiltlab.filters.eskf`).

The kernel takes its scalar parameters as one record, :data:`EskfParams`, built by
:func:`tiltlab.filters.eskf._eskf_params`.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from ..quaternion import (
    qmul_scalar,
    rotate_scalar,
    rotmat_scalar,
    rotvec_to_quat_scalar,
    zoh_step_scalar,
)

_N = 6  # error state: δθ (world frame), δb (sensor frame)


#: the kernel's scalar parameters (built by :func:`tiltlab.filters.eskf._eskf_params`):
#: dt (s); q_gyr, q_bias: process noise of the attitude (rad²) and of the gyro offset
#: ((rad/s)²) per sample; var_acc: variance of the unit accelerometer direction at
#: ‖a‖ = g; norm_gain: κ of the adaptive variance; grav: its reference gravity (m/s²);
#: var_mag: variance of the magnetic heading (rad²)
EskfParams = namedtuple("EskfParams", "dt q_gyr q_bias var_acc norm_gain grav var_mag")


@njit(cache=True, nogil=True)
def _eskf_joseph(P, h, K, var, A, T):
    # Joseph form for one scalar measurement with gain K (optimal or not):
    # P ← (I − K hᵀ) P (I − K hᵀ)ᵀ + var K Kᵀ
    n = _N
    for i in range(n):
        for j in range(n):
            A[i, j] = (1.0 if i == j else 0.0) - K[i] * h[j]
    for i in range(n):
        for j in range(n):
            s = 0.0
            for l in range(n):
                s += A[i, l] * P[l, j]
            T[i, j] = s
    for i in range(n):
        for j in range(i, n):
            s = var * K[i] * K[j]
            for l in range(n):
                s += T[i, l] * A[j, l]
            P[i, j] = s
            P[j, i] = s


@njit(cache=True, nogil=True)
def _eskf_scalar_update(P, h, var, K, A, T):
    # Kalman gain K = P h / (hᵀ P h + var) of one scalar measurement r = h·δx + ν,
    # ν ~ N(0, var), then the Joseph-form update of P; K = 0 if the innovation
    # variance is not positive
    n = _N
    S = var
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += P[i, j] * h[j]
        K[i] = s
        S += h[i] * s
    if not (S > 0.0):
        for i in range(n):
            K[i] = 0.0
        return
    for i in range(n):
        K[i] /= S
    _eskf_joseph(P, h, K, var, A, T)


@njit(cache=True, nogil=True)
def _eskf_kernel(acc, gyr, mag, use_mag, prm, q0, b0, P0, out_q, out_b):
    # the filter over a recording from q0, b0 and the covariance P0
    n = _N
    dt, q_gyr, q_bias, var_acc = prm.dt, prm.q_gyr, prm.q_bias, prm.var_acc
    norm_gain, grav, var_mag = prm.norm_gain, prm.grav, prm.var_mag
    P = P0.copy()
    Pt = np.empty((n, n))
    A = np.empty((n, n))
    T = np.empty((n, n))
    Rm = np.empty((3, 3))
    h = np.zeros(n)
    K = np.empty(n)
    dx = np.empty(n)
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    b0_, b1_, b2_ = b0[0], b0[1], b0[2]
    out_q[0, 0], out_q[0, 1], out_q[0, 2], out_q[0, 3] = w, x, y, z
    out_b[0, 0], out_b[0, 1], out_b[0, 2] = b0_, b1_, b2_
    for k in range(1, acc.shape[0]):
        # ---- prediction: q ← q ⊗ Exp((ω_k − b) Δt), b ← b
        w, x, y, z = zoh_step_scalar(
            w,
            x,
            y,
            z,
            (gyr[k, 0] - b0_) * dt,
            (gyr[k, 1] - b1_) * dt,
            (gyr[k, 2] - b2_) * dt,
        )
        nq = np.sqrt(w * w + x * x + y * y + z * z)
        w, x, y, z = w / nq, x / nq, y / nq, z / nq
        rotmat_scalar(w, x, y, z, Rm)  # R = R(q_k)
        # P ← F P Fᵀ + Q, F = [[I, −Δt R], [0, I]]:
        # Pθθ' = Pθθ − Δt (R Pbθ + Pθb Rᵀ) + Δt² R Pbb Rᵀ, Pθb' = Pθb − Δt R Pbb
        for i in range(3):  # T[:3, :] = rows of F P for δθ: Pθ· − Δt R Pb·
            for j in range(n):
                s = P[i, j]
                for l in range(3):
                    s -= dt * Rm[i, l] * P[3 + l, j]
                T[i, j] = s
        for i in range(3):
            for j in range(3):
                s = T[i, j]
                for l in range(3):
                    s -= dt * T[i, 3 + l] * Rm[j, l]
                Pt[i, j] = s
            for j in range(3):
                Pt[i, 3 + j] = T[i, 3 + j]
                Pt[3 + j, i] = T[i, 3 + j]
        for i in range(3):
            for j in range(3):
                Pt[3 + i, 3 + j] = P[3 + i, 3 + j]
        for i in range(3):
            Pt[i, i] += q_gyr
            Pt[3 + i, 3 + i] += q_bias
        for i in range(n):
            for j in range(i, n):
                s = 0.5 * (Pt[i, j] + Pt[j, i])
                P[i, j] = s
                P[j, i] = s
        # ---- accelerometer: â = a/‖a‖ = Rᵀ e_z + ν, ∂/∂δθ = Rᵀ [e_z]×, adaptive variance
        for i in range(n):
            dx[i] = 0.0
        an = np.sqrt(acc[k, 0] ** 2 + acc[k, 1] ** 2 + acc[k, 2] ** 2)
        if an > 0.0:
            e = norm_gain * (an - grav) / grav
            va = var_acc * (1.0 + e * e)
            for i in range(3):
                for j in range(n):
                    h[j] = 0.0
                h[0] = Rm[1, i]
                h[1] = -Rm[0, i]
                r = acc[k, i] / an - Rm[2, i]
                for j in range(n):
                    r -= h[j] * dx[j]
                _eskf_scalar_update(P, h, va, K, A, T)
                for j in range(n):
                    dx[j] += K[j] * r
            # ---- injection q ← Exp(δθ) ⊗ q, b ← b + δb; reset δx = 0 (G ≈ I)
            dw, ex, ey, ez = rotvec_to_quat_scalar(dx[0], dx[1], dx[2])
            w, x, y, z = qmul_scalar(dw, ex, ey, ez, w, x, y, z)
            nq = np.sqrt(w * w + x * x + y * y + z * z)
            w, x, y, z = w / nq, x / nq, y / nq, z / nq
            b0_ += dx[3]
            b1_ += dx[4]
            b2_ += dx[5]
        # ---- magnetometer, heading only: ψ = atan2(m_E, m_N) of the field in the
        # (tilt-corrected) world frame is δθ_z; no gain on the tilt (K_θx = K_θy = 0)
        if use_mag:
            mx, my, mz = rotate_scalar(w, x, y, z, mag[k, 0], mag[k, 1], mag[k, 2])
            hn = np.sqrt(mx * mx + my * my)
            if hn > 1e-6 * np.sqrt(mx * mx + my * my + mz * mz):
                psi = np.arctan2(mx, my)
                for j in range(n):
                    h[j] = 0.0
                h[2] = 1.0
                S = P[2, 2] + var_mag
                if S > 0.0:
                    for j in range(n):
                        K[j] = P[j, 2] / S
                    K[0] = 0.0
                    K[1] = 0.0
                    _eskf_joseph(P, h, K, var_mag, A, T)  # valid for this gain
                    dw, ex, ey, ez = rotvec_to_quat_scalar(0.0, 0.0, K[2] * psi)
                    w, x, y, z = qmul_scalar(dw, ex, ey, ez, w, x, y, z)
                    nq = np.sqrt(w * w + x * x + y * y + z * z)
                    w, x, y, z = w / nq, x / nq, y / nq, z / nq
                    b0_ += K[3] * psi
                    b1_ += K[4] * psi
                    b2_ += K[5] * psi
        out_q[k, 0], out_q[k, 1], out_q[k, 2], out_q[k, 3] = w, x, y, z
        out_b[k, 0], out_b[k, 1], out_b[k, 2] = b0_, b1_, b2_
