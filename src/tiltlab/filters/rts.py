r"""Offline error-state EKF with a Rauch–Tung–Striebel backward pass (6D).

Attitude, gyro bias and scale, velocity and position states; zero-velocity and
bounded-position pseudo-measurements; adaptive accelerometer weighting.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .. import _validate as _v
from ..quaternion import (
    qmul_scalar,
    rotmat_scalar,
    rotvec_to_quat_scalar,
    zoh_step_scalar,
)
from ._common import samples, start_orientation, unlabel
from .smoothers import rest_gyro_bias

__all__ = ["rts_smoother"]

_RTS_N = 15  # error state: attitude (world frame) φ, gyro bias b, velocity v, position p, gyro scale s
_RTS_X = 12  # nominal state besides q: b, v, p, s


@njit(cache=True, nogil=True)
def _rts_transition(w, x, y, z, a, wc0, wc1, wc2, dt, R, F):
    # F = ∂δx_k/∂δx_{k-1} of the world-frame error state (φ, b, v, p, s), evaluated at the
    # predicted attitude q_{k|k-1} (R = R(q)), the corrected rate ω_c and the specific force
    # a_k; returns R a_k
    rotmat_scalar(w, x, y, z, R)
    sx = R[0, 0] * a[0] + R[0, 1] * a[1] + R[0, 2] * a[2]
    sy = R[1, 0] * a[0] + R[1, 1] * a[1] + R[1, 2] * a[2]
    sz = R[2, 0] * a[0] + R[2, 1] * a[1] + R[2, 2] * a[2]
    for i in range(_RTS_N):
        for j in range(_RTS_N):
            F[i, j] = 1.0 if i == j else 0.0
    for i in range(3):
        for j in range(3):
            F[i, 3 + j] = -dt * R[i, j]  # δφ ← δφ − Δt R δb − Δt R diag(ω_c) δs
        F[i, 12] = -dt * R[i, 0] * wc0
        F[i, 13] = -dt * R[i, 1] * wc1
        F[i, 14] = -dt * R[i, 2] * wc2
        F[9 + i, 6 + i] = dt  # δp ← δp + Δt δv
    # δv ← δv − Δt [s]× δφ ;  δp ← δp − Δt²/2 [s]× δφ
    h = 0.5 * dt * dt
    F[6, 1], F[6, 2] = dt * sz, -dt * sy
    F[7, 0], F[7, 2] = -dt * sz, dt * sx
    F[8, 0], F[8, 1] = dt * sy, -dt * sx
    F[9, 1], F[9, 2] = h * sz, -h * sy
    F[10, 0], F[10, 2] = -h * sz, h * sx
    F[11, 0], F[11, 1] = h * sy, -h * sx
    return sx, sy, sz


@njit(cache=True, nogil=True)
def _rts_propagate(F, P, Qd, FP, out):
    # out = F P Fᵀ + diag(Qd), over the non-zeros of the sparse F (≤ 7 per row); FP = F P
    n = _RTS_N
    idx = np.empty((n, n), np.int64)
    cnt = np.zeros(n, np.int64)
    for i in range(n):
        for l in range(n):
            if F[i, l] != 0.0:
                idx[i, cnt[i]] = l
                cnt[i] += 1
    for i in range(n):
        for j in range(n):
            s = 0.0
            for t in range(cnt[i]):
                l = idx[i, t]
                s += F[i, l] * P[l, j]
            FP[i, j] = s
    for i in range(n):
        for j in range(i, n):
            s = 0.0
            for t in range(cnt[j]):
                l = idx[j, t]
                s += FP[i, l] * F[j, l]
            out[i, j] = s
            out[j, i] = s
        out[i, i] += Qd[i]


@njit(cache=True, nogil=True)
def _rts_scalar_update(P, h, r, var, dx, Ph):
    # one scalar measurement r = h·δx + ν, ν ~ N(0, var), innovation taken at the current δx
    n = _RTS_N
    nz = np.empty(n, np.int64)  # h is sparse (1 or 2 non-zeros)
    m = 0
    for j in range(n):
        if h[j] != 0.0:
            nz[m] = j
            m += 1
    for i in range(n):
        s = 0.0
        for t in range(m):
            s += P[i, nz[t]] * h[nz[t]]
        Ph[i] = s
    S = var
    innov = r
    for t in range(m):
        S += h[nz[t]] * Ph[nz[t]]
        innov -= h[nz[t]] * dx[nz[t]]
    if not (S > 0.0):
        return
    for i in range(n):
        dx[i] += Ph[i] * innov / S
    for i in range(n):
        f = Ph[i] / S
        for j in range(i, n):
            v = P[i, j] - f * Ph[j]
            P[i, j] = v
            P[j, i] = v


@njit(cache=True, nogil=True)
def _rts_chol_solve(A, B, L):
    # B ← A⁻¹ B for a symmetric positive-definite A (Cholesky A = L Lᵀ, in place of B);
    # returns False (B untouched) when A is not numerically positive definite
    n = A.shape[0]
    for j in range(n):
        d = A[j, j]
        for l in range(j):
            d -= L[j, l] * L[j, l]
        if not (d > 0.0):
            return False
        d = np.sqrt(d)
        L[j, j] = d
        for i in range(j + 1, n):
            v = A[i, j]
            for l in range(j):
                v -= L[i, l] * L[j, l]
            L[i, j] = v / d
    m = B.shape[1]
    for c in range(m):
        for i in range(n):  # L y = b
            v = B[i, c]
            for l in range(i):
                v -= L[i, l] * B[l, c]
            B[i, c] = v / L[i, i]
        for i in range(n - 1, -1, -1):  # Lᵀ x = y
            v = B[i, c]
            for l in range(i + 1, n):
                v -= L[l, i] * B[l, c]
            B[i, c] = v / L[i, i]
    return True


@njit(cache=True, nogil=True, inline="always")
def _rts_boxplus(w, x, y, z, px, py, pz):
    # exp(φ/2) ⊗ q (world-frame perturbation), normalised
    dw, dx, dy, dz = rotvec_to_quat_scalar(px, py, pz)
    nw, nx, ny, nz = qmul_scalar(dw, dx, dy, dz, w, x, y, z)
    n = np.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
    return nw / n, nx / n, ny / n, nz / n


@njit(cache=True, nogil=True, inline="always")
def _rts_boxminus(w, x, y, z, rw, rx, ry, rz):
    # φ with q = exp(φ/2) ⊗ r:  φ = Log(q ⊗ r⁻¹)
    ew, ex, ey, ez = qmul_scalar(w, x, y, z, rw, -rx, -ry, -rz)
    if ew < 0.0:
        ew, ex, ey, ez = -ew, -ex, -ey, -ez
    s = np.sqrt(ex * ex + ey * ey + ez * ez)
    if s < 1e-12:
        return 2.0 * ex, 2.0 * ey, 2.0 * ez
    f = 2.0 * np.arctan2(s, ew) / s
    return f * ex, f * ey, f * ez


@njit(cache=True, nogil=True)
def _rts_forward_step(
    k,
    acc,
    gyr,
    rest,
    dt,
    grav,
    Qd,
    var_acc,
    norm_gain,
    var_vel,
    var_pos,
    var_zupt,
    q,
    x,
    P,
    q_pred,
    x_pred,
    Pt,
    F,
    FP,
    R,
    h,
    Ph,
    dx,
):
    # one sample of the forward filter: the posterior (q, x, P) at k-1 becomes the one at k,
    # in place; the prediction q_{k|k-1}, x_{k|k-1} is written to q_pred, x_pred
    n = _RTS_N
    w, qx, qy, qz = q[0], q[1], q[2], q[3]
    # ---- prediction with ω_k, a_k (nominal state, then error covariance)
    # ω_c = (ω_k − b) / (1 + s): gyro corrected for bias and scale error
    wc0 = (gyr[k, 0] - x[0]) / (1.0 + x[9])
    wc1 = (gyr[k, 1] - x[1]) / (1.0 + x[10])
    wc2 = (gyr[k, 2] - x[2]) / (1.0 + x[11])
    w, qx, qy, qz = zoh_step_scalar(w, qx, qy, qz, wc0 * dt, wc1 * dt, wc2 * dt)
    nq = np.sqrt(w * w + qx * qx + qy * qy + qz * qz)
    w, qx, qy, qz = w / nq, qx / nq, qy / nq, qz / nq
    sx, sy, sz = _rts_transition(w, qx, qy, qz, acc[k], wc0, wc1, wc2, dt, R, F)
    fz = sz - grav
    # nominal: p ← p + Δt v + Δt²/2 f, v ← v + Δt f, f = R(q) a_k − g e_z
    # (nominal x = (b, v, p, s): b = x[0:3], v = x[3:6], p = x[6:9], s = x[9:12])
    x[6] += dt * x[3] + 0.5 * dt * dt * sx
    x[7] += dt * x[4] + 0.5 * dt * dt * sy
    x[8] += dt * x[5] + 0.5 * dt * dt * fz
    x[3] += dt * sx
    x[4] += dt * sy
    x[5] += dt * fz
    _rts_propagate(F, P, Qd, FP, Pt)
    for i in range(n):
        for j in range(n):
            P[i, j] = Pt[i, j]
    q_pred[0], q_pred[1], q_pred[2], q_pred[3] = w, qx, qy, qz
    for i in range(_RTS_X):
        x_pred[i] = x[i]
    # ---- sequential scalar updates of the error state δx (exact for diagonal noise)
    for i in range(n):
        dx[i] = 0.0
    vv = var_zupt if rest[k] else var_vel
    if vv > 0.0 and np.isfinite(vv):
        for i in range(3):
            h[:] = 0.0
            h[6 + i] = 1.0
            _rts_scalar_update(P, h, -x[3 + i], vv, dx, Ph)
    if var_pos > 0.0 and np.isfinite(var_pos):
        for i in range(3):
            h[:] = 0.0
            h[9 + i] = 1.0
            _rts_scalar_update(P, h, -x[6 + i], var_pos, dx, Ph)
    an = np.sqrt(acc[k, 0] ** 2 + acc[k, 1] ** 2 + acc[k, 2] ** 2)
    if an > 0.0 and var_acc > 0.0 and np.isfinite(var_acc):
        e = norm_gain * (an - grav) / grav
        va = var_acc * (1.0 + e * e)
        # ĝ = R(q)ᵀ e_z (third row of R);  ∂ĝ/∂δφ = Rᵀ [e_z]×
        for i in range(3):
            h[:] = 0.0
            h[0] = R[1, i]
            h[1] = -R[0, i]
            _rts_scalar_update(P, h, acc[k, i] / an - R[2, i], va, dx, Ph)
    # ---- injection: q ← exp(δφ/2) ⊗ q, (b, v, p, s) += δ
    w, qx, qy, qz = _rts_boxplus(w, qx, qy, qz, dx[0], dx[1], dx[2])
    for i in range(_RTS_X):
        x[i] += dx[3 + i]
    for i in range(n):
        for j in range(i + 1, n):
            s = 0.5 * (P[i, j] + P[j, i])
            P[i, j] = s
            P[j, i] = s
    q[0], q[1], q[2], q[3] = w, qx, qy, qz


@njit(cache=True, nogil=True)
def _rts_backward_step(
    acc1,
    gyr1,
    dt,
    Qd,
    q_f,
    x_f,
    P_f,
    q_p1,
    x_p1,
    qs,
    xs,
    R,
    F,
    FP,
    Pt,
    C,
    Lw,
    sc,
    d,
    dx,
):
    # one Rauch–Tung–Striebel step on the error state: the smoothed (qs, xs) at k+1 become
    # the ones at k, in place. acc1, gyr1: the samples k+1; q_f, x_f, P_f: the forward
    # posterior at k; q_p1, x_p1: the forward prediction at k+1
    n = _RTS_N
    wc0 = (gyr1[0] - x_f[0]) / (1.0 + x_f[9])
    wc1 = (gyr1[1] - x_f[1]) / (1.0 + x_f[10])
    wc2 = (gyr1[2] - x_f[2]) / (1.0 + x_f[11])
    _rts_transition(q_p1[0], q_p1[1], q_p1[2], q_p1[3], acc1, wc0, wc1, wc2, dt, R, F)
    _rts_propagate(F, P_f, Qd, FP, Pt)
    d[0], d[1], d[2] = _rts_boxminus(
        qs[0], qs[1], qs[2], qs[3], q_p1[0], q_p1[1], q_p1[2], q_p1[3]
    )
    for i in range(_RTS_X):
        d[3 + i] = xs[i] - x_p1[i]
    # δ = G d with G = P_k|k Fᵀ P_{k+1|k}⁻¹:  solve P_{k+1|k} y = d, then δ = (F P_k|k)ᵀ y;
    # the solve after a symmetric diagonal (Jacobi) scaling, the states' variances
    # differing by many decades
    for i in range(n):
        sc[i] = 1.0 / np.sqrt(Pt[i, i])
    for i in range(n):
        C[i, 0] = d[i] * sc[i]
        for j in range(n):
            Pt[i, j] *= sc[i] * sc[j]
    if not _rts_chol_solve(Pt, C[:, :1], Lw):  # not numerically positive definite: LU
        C[:, :1] = np.linalg.solve(Pt, np.ascontiguousarray(C[:, :1]))
    for i in range(n):
        C[i, 0] *= sc[i]
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += FP[j, i] * C[j, 0]
        dx[i] = s
    qs[0], qs[1], qs[2], qs[3] = _rts_boxplus(
        q_f[0], q_f[1], q_f[2], q_f[3], dx[0], dx[1], dx[2]
    )
    for i in range(_RTS_X):
        xs[i] = x_f[i] + dx[3 + i]


@njit(cache=True, nogil=True)
def _rts_kernel(
    acc,
    gyr,
    rest,
    dt,
    grav,
    q0,
    x0,
    P0,
    Qd,
    var_acc,
    norm_gain,
    var_vel,
    var_pos,
    var_zupt,
    smooth,
    ckpt_q,
    ckpt_x,
    ckpt_P,
    blk_qf,
    blk_xf,
    blk_qp,
    blk_xp,
    blk_Pf,
    out_q,
    out_x,
):
    # forward filter, then (``smooth``) the backward pass over blocks of B samples, last
    # block first. The forward pass keeps its posterior (q, x, P) only every B samples
    # (checkpoint j at sample j·B; ckpt_* have ⌈N/B⌉ rows); each block is recomputed from
    # its checkpoint into blk_* (B + 1 rows: the block and the first sample of the next,
    # whose prediction the block's last backward step needs) and smoothed backwards. The
    # recomputation repeats the same floating-point operations, so the result equals that
    # of storing every sample. Without checkpoints (ckpt_* with 0 rows) the single block
    # holds every sample (N rows) and the forward pass is not repeated: the full-storage
    # smoother.
    # out_x: (N, 12), or (0, 12) when the states are not returned.
    n_s = acc.shape[0]
    n = _RTS_N
    store_x = out_x.shape[0] > 0
    one = ckpt_q.shape[0] == 0  # one block, no checkpoints
    nb = 1 if one else ckpt_q.shape[0]
    blk = blk_qf.shape[0] - 1
    P = P0.copy()
    x = x0.copy()
    q = q0.copy()
    Pt = np.empty((n, n))
    F = np.empty((n, n))
    FP = np.empty((n, n))
    R = np.empty((3, 3))
    h = np.zeros(n)
    Ph = np.empty(n)
    dx = np.empty(n)
    qp1 = np.empty(4)
    xp1 = np.empty(_RTS_X)
    if not smooth:  # forward filter only: nothing stored
        out_q[0, :] = q
        if store_x:
            out_x[0, :] = x
        for k in range(1, n_s):
            _rts_forward_step(
                k,
                acc,
                gyr,
                rest,
                dt,
                grav,
                Qd,
                var_acc,
                norm_gain,
                var_vel,
                var_pos,
                var_zupt,
                q,
                x,
                P,
                qp1,
                xp1,
                Pt,
                F,
                FP,
                R,
                h,
                Ph,
                dx,
            )
            out_q[k, :] = q
            if store_x:
                out_x[k, :] = x
        return
    if one:  # the single block is filled by the first (only) forward pass
        blk_qf[0, :] = q
        blk_xf[0, :] = x
        blk_qp[0, :] = q
        blk_xp[0, :] = x
        blk_Pf[0] = P
    else:
        ckpt_q[0, :] = q
        ckpt_x[0, :] = x
        ckpt_P[0] = P
        blk_qp[0, :] = q  # (unused: a block's first prediction is never read)
        blk_xp[0, :] = x
    for k in range(1, n_s):
        if one:
            _rts_forward_step(
                k,
                acc,
                gyr,
                rest,
                dt,
                grav,
                Qd,
                var_acc,
                norm_gain,
                var_vel,
                var_pos,
                var_zupt,
                q,
                x,
                P,
                blk_qp[k],
                blk_xp[k],
                Pt,
                F,
                FP,
                R,
                h,
                Ph,
                dx,
            )
            blk_qf[k, :] = q
            blk_xf[k, :] = x
            blk_Pf[k] = P
        else:
            _rts_forward_step(
                k,
                acc,
                gyr,
                rest,
                dt,
                grav,
                Qd,
                var_acc,
                norm_gain,
                var_vel,
                var_pos,
                var_zupt,
                q,
                x,
                P,
                qp1,
                xp1,
                Pt,
                F,
                FP,
                R,
                h,
                Ph,
                dx,
            )
            if k % blk == 0:
                j = k // blk
                ckpt_q[j, :] = q
                ckpt_x[j, :] = x
                ckpt_P[j] = P
    # ---- Rauch–Tung–Striebel backward pass on the error state, block by block
    qs = q.copy()  # smoothed = filtered at the last sample
    xs = x.copy()
    out_q[n_s - 1, :] = qs
    if store_x:
        out_x[n_s - 1, :] = xs
    C = np.empty((n, n))
    Lw = np.zeros((n, n))
    sc = np.empty(n)
    d = np.empty(n)
    for j in range(nb - 1, -1, -1):
        s0 = j * blk
        top = min(s0 + blk, n_s - 1)
        if not one:  # recompute the block's forward pass from its checkpoint
            q[:] = ckpt_q[j]
            x[:] = ckpt_x[j]
            P[:, :] = ckpt_P[j]
            blk_qf[0, :] = q
            blk_xf[0, :] = x
            blk_Pf[0] = P
            for k in range(s0 + 1, top + 1):
                i = k - s0
                _rts_forward_step(
                    k,
                    acc,
                    gyr,
                    rest,
                    dt,
                    grav,
                    Qd,
                    var_acc,
                    norm_gain,
                    var_vel,
                    var_pos,
                    var_zupt,
                    q,
                    x,
                    P,
                    blk_qp[i],
                    blk_xp[i],
                    Pt,
                    F,
                    FP,
                    R,
                    h,
                    Ph,
                    dx,
                )
                blk_qf[i, :] = q
                blk_xf[i, :] = x
                blk_Pf[i] = P
        for k in range(top - 1, s0 - 1, -1):
            i = k - s0
            _rts_backward_step(
                acc[k + 1],
                gyr[k + 1],
                dt,
                Qd,
                blk_qf[i],
                blk_xf[i],
                blk_Pf[i],
                blk_qp[i + 1],
                blk_xp[i + 1],
                qs,
                xs,
                R,
                F,
                FP,
                Pt,
                C,
                Lw,
                sc,
                d,
                dx,
            )
            out_q[k, :] = qs
            if store_x:
                out_x[k, :] = xs


#: samples per block of the checkpointed backward pass (see :func:`_rts_plan`; ``None``:
#: store every sample, the full-storage smoother)
_RTS_BLOCK: int | None = 2**14
#: bytes per sample of the block's forward quantities: q, x filtered and predicted, P filtered
_RTS_BLOCK_SAMPLE_BYTES = 8 * (2 * (4 + _RTS_X) + _RTS_N * _RTS_N)  # 2056
#: bytes per checkpoint: q, x, P filtered
_RTS_CKPT_BYTES = 8 * (4 + _RTS_X + _RTS_N * _RTS_N)  # 1928


def _rts_plan(
    n_samples: int,
    block: int | None,
    *,
    smooth: bool = True,
    return_state: bool = False,
) -> dict:
    """The arrays :func:`rts_smoother` allocates for ``n_samples`` samples: their shapes
    (``shapes``: name → shape, every array float64) and bytes.

    ``block``: samples per block of the backward pass (:func:`rts_smoother` uses
    :data:`_RTS_BLOCK`); ``None`` or ``≥ n_samples − 1``: one block, i.e. the
    full-storage smoother without checkpoints. Keys: ``block`` (B), ``checkpoints``
    (⌈N/B⌉, 0 for one block), ``shapes``, ``checkpoint_bytes``, ``block_bytes``
    (independent of N once N > B), ``output_bytes`` and ``total_bytes``.
    """
    n_s = int(n_samples)
    if block is not None and (int(block) != block or block < 1):
        raise ValueError(f"block must be a positive integer or None, got {block!r}")
    blk = n_s if block is None else int(block)
    if not smooth:
        nb, blk, rows = 0, 0, 0
    elif blk >= n_s - 1:  # one block: the full-storage smoother
        blk = max(n_s - 1, 1)
        nb, rows = 1, n_s
    else:
        nb, rows = -(-n_s // blk), blk + 1
    ck = 0 if nb <= 1 else nb
    n = _RTS_N
    shapes = {
        "ckpt_q": (ck, 4),
        "ckpt_x": (ck, _RTS_X),
        "ckpt_P": (ck, n, n),
        "blk_qf": (rows, 4),
        "blk_xf": (rows, _RTS_X),
        "blk_qp": (rows, 4),
        "blk_xp": (rows, _RTS_X),
        "blk_Pf": (rows, n, n),
        "out_q": (n_s, 4),
        "out_x": (n_s if return_state else 0, _RTS_X),
    }
    nbytes = {k: 8 * int(np.prod(v)) for k, v in shapes.items()}
    plan = {
        "block": blk,
        "checkpoints": ck,
        "shapes": shapes,
        "checkpoint_bytes": sum(v for k, v in nbytes.items() if k.startswith("ckpt")),
        "block_bytes": sum(v for k, v in nbytes.items() if k.startswith("blk")),
        "output_bytes": nbytes["out_q"] + nbytes["out_x"],
    }
    plan["total_bytes"] = (
        plan["checkpoint_bytes"] + plan["block_bytes"] + plan["output_bytes"]
    )
    return plan


def rts_smoother(
    acc,
    gyr,
    fs: float | None = None,
    *,
    gyr_noise: float = 5e-3,
    bias_noise: float = 1e-4,
    acc_noise: float = 0.01,
    acc_std: float = 0.05,
    norm_gain: float = 10.0,
    vel_std: float = 0.3,
    pos_std: float = 1.0,
    tau_s: float = 1.0,
    zupt_std: float = 0.01,
    bias_std: float = float(np.radians(0.5)),
    scale_std: float = 0.0,
    scale_noise: float = 0.0,
    bias=None,
    q0=None,
    init_window_s: float = 0.1,
    smooth: bool = True,
    return_state: bool = False,
    max_memory_gb: float = 4.0,
):
    r"""Offline attitude smoother: error-state (multiplicative) EKF with gyro-bias, gyro-scale,
    velocity and position states, followed by a Rauch–Tung–Striebel backward pass.

    **Nominal state** :math:`x = (q, b, v, p, s)`: attitude (sensor → world, z up), gyro bias
    (rad/s), world-frame velocity (m/s) and position (m) of the sensor, and gyro scale
    errors (gyro model :math:`\omega^{meas} = (1 + s) \circ \omega + b`). With the filters'
    indexing (:math:`\omega_k, a_k` take :math:`k-1 \to k`) and
    :math:`\omega^c_k = (\omega_k - b) \oslash (1 + s)`:

    .. math::
        q_k = q_{k-1} \otimes \mathrm{Exp}\big(\omega^c_k\,\Delta t\big),\quad
        f_k = R(q_k)\,a_k - g\,e_z,\quad
        v_k = v_{k-1} + f_k \Delta t,\quad p_k = p_{k-1} + v_{k-1}\Delta t + \tfrac12 f_k \Delta t^2 .

    **Error state** :math:`\delta x = (\delta\phi, \delta b, \delta v, \delta p, \delta s)`
    (15) with the attitude error in the world frame, :math:`q_{true} = \mathrm{Exp}(\delta\phi)
    \otimes q` (Solà [1]_, §7 "global" error), whose transition is :math:`F = I` plus the
    blocks :math:`F_{\phi b} = -\Delta t R`, :math:`F_{\phi s} = -\Delta t R\,
    \mathrm{diag}(\omega^c_k)`, :math:`F_{v\phi} = -\Delta t [f]_\times`,
    :math:`F_{p\phi} = -\tfrac12\Delta t^2 [f]_\times`, :math:`F_{pv} = \Delta t I`
    (:math:`R = R(q_k)`, :math:`f = R a_k`: a tilt error :math:`\delta\phi` leaks
    :math:`g\,\delta\phi` of gravity into the horizontal acceleration), with process noise
    :math:`Q = \Delta t\,\mathrm{diag}(\sigma_\omega^2 I, \sigma_b^2 I, \sigma_a^2 I,
    \sigma_a^2 \Delta t^2/3\, I, \sigma_s^2 I)`.

    **Measurements** (scalar sequential updates, exact for diagonal noise):

    * velocity pseudo-measurement :math:`0 = v + \nu_v`: a hand-held or head-mounted sensor
      does not drift away; variance :math:`\sigma_v^2 \tau f_s` (an independent
      measurement of standard deviation ``vel_std`` every ``tau_s`` seconds) in motion, and a
      zero-velocity update with ``zupt_std²`` per sample during detected rest
      (:func:`rest_gyro_bias`);
    * position pseudo-measurement :math:`0 = p + \nu_p`, variance
      :math:`\sigma_p^2 \tau f_s` (bounded workspace);
    * accelerometer direction :math:`\hat a_k = R(q)^\top e_z + \nu_a`, Jacobian
      :math:`R^\top [e_z]_\times`, variance
      :math:`\sigma_{\hat a}^2 \tau f_s \,\big(1 + (\kappa\,(\|a_k\| - g)/g)^2\big)`,
      down-weighted where the norm departs from gravity (adaptive, ``norm_gain`` = κ).

    After each update the error is injected (:math:`q \leftarrow \mathrm{Exp}(\delta\phi)
    \otimes q`, :math:`(b, v, p, s) \mathrel{+}= \delta`). Integrated acceleration
    constrains tilt far better than the instantaneous direction of :math:`a`: a tilt
    error held for :math:`T` seconds moves the position by :math:`g\,\delta\phi\,T^2/2`.

    **Backward pass** (Rauch, Tung, Striebel [2]_, on the error state): with the forward
    posterior :math:`\hat x_{k|k}, P_{k|k}` and prediction :math:`\hat x_{k+1|k},
    P_{k+1|k} = F P_{k|k} F^\top + Q`,

    .. math::
        G_k = P_{k|k} F^\top P_{k+1|k}^{-1},\qquad
        x^s_k = \hat x_{k|k} \boxplus G_k\,\big(x^s_{k+1} \boxminus \hat x_{k+1|k}\big),

    where :math:`\boxminus` of attitudes is :math:`\mathrm{Log}(q^s \otimes
    \hat q^{-1})`; :math:`G_k` is solved after a symmetric diagonal scaling of
    :math:`P_{k+1|k}`. The forward pass keeps its posterior only at checkpoints and the
    backward pass recomputes it block by block, so memory stays bounded (see Notes).
    Like ``offlineVQF`` (Laidig & Seel [3]_) it uses past and future samples; unlike VQF the bias and the motion acceleration are handled by one
    Gaussian model. 6D only: heading is relative (its error state is unobservable and
    merely carried).

    Parameters
    ----------
    acc : array_like or xarray.DataArray, shape (N, 3)
        Specific force in **m/s²**; a labelled DataArray is converted from its
        ``units`` attribute (required).
    gyr : array_like or xarray.DataArray, shape (N, 3)
        Angular velocity (rad/s); a labelled DataArray is converted from its ``units``
        attribute (required; see :mod:`tiltlab.filters`, "Labelled inputs").
    fs : float, optional
        Sampling rate (Hz): mandatory for plain arrays; with labelled inputs it may
        be omitted when they carry ``attrs["fs"]``, and must agree with it when given.
    gyr_noise : float
        Angular random walk σ_ω (rad/√s), gyro noise plus unmodelled scale errors.
    bias_noise : float
        Bias random walk σ_b (rad/s/√s).
    acc_noise : float
        Velocity random walk σ_a (m/s/√s).
    acc_std, vel_std, pos_std : float
        Standard deviations of the accelerometer-direction (rad), velocity (m/s) and
        position (m) pseudo-measurements per correlation time ``tau_s``; ``inf``
        disables one.
    norm_gain : float
        κ of the adaptive accelerometer variance (0: not adaptive).
    tau_s : float
        Correlation time (s) of the pseudo-measurement errors.
    zupt_std : float
        Per-sample standard deviation (m/s) of the zero-velocity update at rest
        (``inf``: no ZUPT).
    bias_std : float
        Initial standard deviation of the gyro bias (rad/s).
    scale_std, scale_noise : float
        Initial standard deviation (1) and random walk (1/√s) of the gyro scale errors;
        the default 0 switches scale estimation off.
    bias : array_like, shape (3,), optional
        Initial gyro bias (rad/s, whatever the units of a labelled ``gyr``); default
        :func:`rest_gyro_bias`.
    q0 : array_like, shape (4,), optional
        Initial orientation; default :func:`initial_orientation` over
        ``init_window_s`` seconds.
    init_window_s : float
        Initialisation window (s).
    smooth : bool
        Run the backward pass (``False``: forward filter only).
    return_state : bool
        Also return the (smoothed) states :math:`(b, v, p, s)`, shape (N, 12).
    max_memory_gb : float
        Refuse recordings whose arrays (outputs, checkpoints and one block, see Notes)
        would exceed this: about 32 B per sample (128 B with ``return_state``) plus
        34 MB, so the default 4 GB holds about 110 hours at 300 Hz (28 hours with
        ``return_state``). Not checked with ``smooth=False``.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Unit quaternions sensor → world (and the states if ``return_state``).

    Notes
    -----
    **Memory.** A plain RTS smoother stores the forward posterior and prediction of
    every sample: a 15 × 15 covariance plus two attitudes and two (b, v, p, s) states,
    2056 B per sample (2.2 GB for one hour at 300 Hz). Here the forward pass keeps its
    posterior :math:`(q, x, P)` only every :math:`B = 2^{14}` samples (a *checkpoint*,
    1928 B). The backward pass then takes the blocks of :math:`B` samples from the last
    to the first: it restores the block's checkpoint, reruns the forward filter over
    the block (storing its :math:`B + 1` posteriors and predictions, 2056 B each, 34 MB
    in all) and runs the RTS recursion over it. Rerunning repeats the same
    floating-point operations, so the result is that of storing every sample; the cost
    is one more forward pass (about 1.5 × the run time of the full-storage smoother).
    The smoother's own arrays are therefore

    * the output: 32 B per sample (N × 4 quaternions), plus 96 B per sample for the
      (N × 12) states with ``return_state``;
    * the checkpoints: 1928 B per :math:`B` samples, 0.12 B per sample;
    * one block: :math:`(B + 1) \times 2056` B = 34 MB, whatever the length,

    e.g. 0.24 GB for 6 hours at 300 Hz (6.48 M samples; 0.86 GB with
    ``return_state``), on top of the inputs and the transient arrays of the rest
    detection (:func:`rest_gyro_bias`). Recordings of at most :math:`B + 1` samples
    are smoothed in one block without checkpoints.

    References
    ----------
    .. [1] J. Solà, "Quaternion kinematics for the error-state Kalman filter",
       arXiv:1711.02508, 2017.
    .. [2] H. E. Rauch, F. Tung, C. T. Striebel, "Maximum likelihood estimates of linear
       dynamic systems", AIAA Journal 3(8):1445–1450, 1965. doi:10.2514/3.3166
    .. [3] D. Laidig, T. Seel, "VQF: Highly accurate IMU orientation estimation with bias
       estimation and magnetic disturbance rejection", Information Fusion 91:187–204,
       2023. doi:10.1016/j.inffus.2022.10.014
    """
    fs, acc, gyr, _ = unlabel(fs, acc=acc, gyr=gyr, acc_si=True)
    acc = samples(acc, "acc")
    gyr = samples(gyr, "gyr", acc.shape[0])
    max_memory_gb = _v.positive(max_memory_gb, "max_memory_gb", allow_inf=True)
    plan = _rts_plan(
        acc.shape[0], _RTS_BLOCK, smooth=bool(smooth), return_state=bool(return_state)
    )
    need_gb = plan["total_bytes"] / 1e9
    if smooth and need_gb > max_memory_gb:
        raise ValueError(
            f"rts_smoother would allocate {need_gb:.3g} GB for {acc.shape[0]} samples "
            f"(limit max_memory_gb={max_memory_gb:g}): the output "
            f"({plan['output_bytes'] / 1e9:.3g} GB, 32 B per sample, 128 B with "
            f"return_state), {plan['checkpoints']} checkpoints "
            f"({plan['checkpoint_bytes'] / 1e9:.3g} GB) and one block of "
            f"{plan['block']} samples ({plan['block_bytes'] / 1e9:.3g} GB); split "
            "the recording into shorter segments or raise the limit"
        )
    dt = 1.0 / fs
    sig = [
        _v.nonnegative(gyr_noise, "gyr_noise"),
        _v.nonnegative(bias_noise, "bias_noise"),
        _v.nonnegative(acc_noise, "acc_noise"),
    ]
    tau_s = _v.positive(tau_s, "tau_s")
    std = {
        nm: _v.positive(v, nm, allow_inf=True)
        for nm, v in (
            ("acc_std", acc_std),
            ("vel_std", vel_std),
            ("pos_std", pos_std),
            ("zupt_std", zupt_std),
        )
    }
    norm_gain = _v.nonnegative(norm_gain, "norm_gain")
    bias_std = _v.nonnegative(bias_std, "bias_std")
    scale_std = _v.nonnegative(scale_std, "scale_std")
    scale_noise = _v.nonnegative(scale_noise, "scale_noise")
    b_rest, rest = rest_gyro_bias(acc, gyr, fs)
    if bias is None:
        b0 = b_rest
    else:
        b0 = _v.vectors(np.reshape(bias, -1), "bias", width=3, ndim=1)
    an = np.linalg.norm(acc, axis=1)
    grav = float(np.mean(an[rest])) if rest.sum() >= 0.5 * fs else float(np.median(an))
    if not grav > 0:
        raise ValueError("the accelerometer norm vanishes; no gravity can be defined")
    q0 = start_orientation(q0, acc, None, fs, init_window_s)
    x0 = np.concatenate([b0, np.zeros(9)])
    P0 = np.diag(
        np.r_[
            np.radians(2.0) ** 2,
            np.radians(2.0) ** 2,
            1e-6,
            [bias_std**2 + 1e-12] * 3,
            [0.1**2] * 3,
            [1e-6] * 3,
            [scale_std**2 + 1e-12] * 3,
        ]
    )
    Qd = (
        dt
        * np.r_[
            [sig[0] ** 2] * 3,
            [sig[1] ** 2] * 3,
            [sig[2] ** 2] * 3,
            [sig[2] ** 2 * dt * dt / 3.0] * 3,
            [scale_noise**2] * 3,
        ]
    )
    Qd = np.maximum(Qd, 1e-18)
    rate = tau_s * fs
    arrays = {k: np.empty(v) for k, v in plan["shapes"].items()}
    _rts_kernel(
        acc,
        gyr,
        np.ascontiguousarray(rest),
        dt,
        grav,
        q0,
        x0,
        P0,
        Qd,
        std["acc_std"] ** 2 * rate,
        norm_gain,
        std["vel_std"] ** 2 * rate,
        std["pos_std"] ** 2 * rate,
        std["zupt_std"] ** 2,
        bool(smooth),
        *arrays.values(),
    )
    out_q, out_x = arrays["out_q"], arrays["out_x"]
    return (out_q, out_x) if return_state else out_q
