r"""Numba kernels of the error-state RTS smoother (:func:`~tiltlab.filters.rts_smoother`).

The error state :math:`\delta x = (\delta\phi, \delta b, \delta v, \delta p, \delta s)`
(:data:`_RTS_N` = 15) and the nominal state besides the attitude, :math:`(b, v, p, s)`
(:data:`_RTS_X` = 12); the transition matrix and covariance propagation, a scalar
measurement update, a Cholesky solve, the :math:`\boxplus`/:math:`\boxminus` of
attitudes, one step of the forward filter and of the Rauch–Tung–Striebel backward
pass, and :func:`_rts_kernel`, the passes over a recording (the forward filter and,
when smoothing, the checkpointed backward pass block by block).

The kernels take records (:data:`RtsParams`: the scalar model parameters, built by
:func:`tiltlab.filters.rts._rts_params`; :class:`RtsInputs`: the samples;
:class:`RtsWork`: the state and scratch arrays; :class:`RtsArrays`: the arrays planned
by :func:`tiltlab.filters.rts._rts_plan`) instead of long positional lists, so that a
value reaches a kernel under its name. The public function and its parameters are in
:mod:`tiltlab.filters.rts`.
"""

from __future__ import annotations

from collections import namedtuple
from typing import NamedTuple

import numpy as np
from numba import njit

from ..quaternion import (
    qmul_scalar,
    rotmat_scalar,
    rotvec_to_quat_scalar,
    zoh_step_scalar,
)

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


#: the scalar parameters of the model (built by :func:`tiltlab.filters.rts._rts_params`):
#: dt (s); grav: gravity (m/s², the mean accelerometer norm at rest); var_acc: variance
#: of the accelerometer direction per sample (before the adaptive factor); norm_gain: κ
#: of the adaptive variance; var_vel, var_pos: variances of the zero-velocity (m²/s², in
#: motion) and zero-position (m²) pseudo-measurements; var_zupt: variance of the
#: zero-velocity update at rest (m²/s²)
RtsParams = namedtuple(
    "RtsParams", "dt grav var_acc norm_gain var_vel var_pos var_zupt"
)


class RtsInputs(NamedTuple):
    """The samples and the discrete process noise."""

    #: specific force (N, 3), m/s²
    acc: np.ndarray
    #: angular velocity (N, 3), rad/s
    gyr: np.ndarray
    #: rest mask (N,)
    rest: np.ndarray
    #: diagonal of the discrete process noise Q (15,)
    Qd: np.ndarray


class RtsWork(NamedTuple):
    """The filter's state (q, x, P: the initial state on entry) and scratch arrays."""

    q: np.ndarray  # (4,) attitude
    x: np.ndarray  # (12,) b, v, p, s
    P: np.ndarray  # (15, 15) error covariance
    qs: np.ndarray  # (4,) smoothed attitude
    xs: np.ndarray  # (12,) smoothed b, v, p, s
    Pt: np.ndarray  # (15, 15)
    F: np.ndarray  # (15, 15)
    FP: np.ndarray  # (15, 15)
    R: np.ndarray  # (3, 3)
    h: np.ndarray  # (15,)
    Ph: np.ndarray  # (15,)
    dx: np.ndarray  # (15,)
    qp1: np.ndarray  # (4,) a prediction that is not kept
    xp1: np.ndarray  # (12,)
    C: np.ndarray  # (15, 15)
    Lw: np.ndarray  # (15, 15)
    sc: np.ndarray  # (15,)
    d: np.ndarray  # (15,)


class RtsArrays(NamedTuple):
    """The arrays planned by :func:`tiltlab.filters.rts._rts_plan`, in its order."""

    ckpt_q: np.ndarray
    ckpt_x: np.ndarray
    ckpt_P: np.ndarray
    blk_qf: np.ndarray
    blk_xf: np.ndarray
    blk_qp: np.ndarray
    blk_xp: np.ndarray
    blk_Pf: np.ndarray
    out_q: np.ndarray
    out_x: np.ndarray


@njit(cache=True, nogil=True, inline="always")
def _rts_forward_step(k, inp, prm, ws, q_pred, x_pred):
    # one sample of the forward filter: the posterior (ws.q, ws.x, ws.P) at k-1 becomes
    # the one at k, in place; the prediction q_{k|k-1}, x_{k|k-1} is written to q_pred,
    # x_pred
    n = _RTS_N
    acc, gyr = inp.acc, inp.gyr
    dt, grav = prm.dt, prm.grav
    # (the records' arrays are bound to names once: no attribute access in the loops)
    q, x, P, R, h, Ph, dx = ws.q, ws.x, ws.P, ws.R, ws.h, ws.Ph, ws.dx
    F, FP, Pt, Qd, rest = ws.F, ws.FP, ws.Pt, inp.Qd, inp.rest
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
    vv = prm.var_zupt if rest[k] else prm.var_vel
    if vv > 0.0 and np.isfinite(vv):
        for i in range(3):
            h[:] = 0.0
            h[6 + i] = 1.0
            _rts_scalar_update(P, h, -x[3 + i], vv, dx, Ph)
    var_pos = prm.var_pos
    if var_pos > 0.0 and np.isfinite(var_pos):
        for i in range(3):
            h[:] = 0.0
            h[9 + i] = 1.0
            _rts_scalar_update(P, h, -x[6 + i], var_pos, dx, Ph)
    an = np.sqrt(acc[k, 0] ** 2 + acc[k, 1] ** 2 + acc[k, 2] ** 2)
    var_acc = prm.var_acc
    if an > 0.0 and var_acc > 0.0 and np.isfinite(var_acc):
        e = prm.norm_gain * (an - grav) / grav
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


@njit(cache=True, nogil=True, inline="always")
def _rts_backward_step(k, i, inp, prm, ws, arr):
    # one Rauch–Tung–Striebel step on the error state: the smoothed (ws.qs, ws.xs) at
    # k+1 become the ones at k, in place, from the forward posterior at k (block row i)
    # and the forward prediction at k+1 (block row i + 1)
    n = _RTS_N
    q_f, x_f, P_f = arr.blk_qf[i], arr.blk_xf[i], arr.blk_Pf[i]
    q_p1, x_p1 = arr.blk_qp[i + 1], arr.blk_xp[i + 1]
    qs, xs, Pt, C, sc, d, dx = ws.qs, ws.xs, ws.Pt, ws.C, ws.sc, ws.d, ws.dx
    F, FP, R, Lw, Qd = ws.F, ws.FP, ws.R, ws.Lw, inp.Qd
    gyr1 = inp.gyr[k + 1]
    wc0 = (gyr1[0] - x_f[0]) / (1.0 + x_f[9])
    wc1 = (gyr1[1] - x_f[1]) / (1.0 + x_f[10])
    wc2 = (gyr1[2] - x_f[2]) / (1.0 + x_f[11])
    _rts_transition(
        q_p1[0],
        q_p1[1],
        q_p1[2],
        q_p1[3],
        inp.acc[k + 1],
        wc0,
        wc1,
        wc2,
        prm.dt,
        R,
        F,
    )
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
def _rts_output(k, q, x, out_q, out_x):
    # row k of the outputs (out_x: (0, 12) when the states are not returned)
    out_q[k, :] = q
    if out_x.shape[0] > 0:
        out_x[k, :] = x


@njit(cache=True, nogil=True)
def _rts_filter_block(s0, top, inp, prm, ws, arr):
    # forward filter from the posterior in ws (that of sample s0) to sample top, storing
    # each posterior and prediction in the block arrays (row k − s0; row 0: sample s0)
    q, x, P = ws.q, ws.x, ws.P
    qf, xf, Pf, qp, xp = arr.blk_qf, arr.blk_xf, arr.blk_Pf, arr.blk_qp, arr.blk_xp
    qf[0, :] = q
    xf[0, :] = x
    Pf[0] = P
    for k in range(s0 + 1, top + 1):
        i = k - s0
        _rts_forward_step(k, inp, prm, ws, qp[i], xp[i])
        qf[i, :] = q
        xf[i, :] = x
        Pf[i] = P


@njit(cache=True, nogil=True)
def _rts_work(q0, x0, P0):
    # the state (a copy of the initial one) and the scratch arrays, allocated here so
    # that the compiler sees them distinct
    n = _RTS_N
    return RtsWork(
        q0.copy(),
        x0.copy(),
        P0.copy(),
        np.empty(4),
        np.empty(_RTS_X),
        np.empty((n, n)),
        np.empty((n, n)),
        np.empty((n, n)),
        np.empty((3, 3)),
        np.zeros(n),
        np.empty(n),
        np.empty(n),
        np.empty(4),
        np.empty(_RTS_X),
        np.empty((n, n)),
        np.zeros((n, n)),
        np.empty(n),
        np.empty(n),
    )


@njit(cache=True, nogil=True)
def _rts_kernel(inp, prm, q0, x0, P0, arr, smooth):
    # forward filter, then (``smooth``) the backward pass over blocks of B samples, last
    # block first. The forward pass keeps its posterior (q, x, P) only every B samples
    # (checkpoint j at sample j·B; ckpt_* have ⌈N/B⌉ rows); each block is recomputed from
    # its checkpoint into blk_* (B + 1 rows: the block and the first sample of the next,
    # whose prediction the block's last backward step needs) and smoothed backwards. The
    # recomputation repeats the same floating-point operations, so the result equals that
    # of storing every sample. Without checkpoints (ckpt_* with 0 rows) the single block
    # holds every sample (N rows) and the forward pass is not repeated: the full-storage
    # smoother. The filter starts from q0, x0 (b, v, p, s) and P0.
    ws = _rts_work(q0, x0, P0)
    n_s = inp.acc.shape[0]
    one = arr.ckpt_q.shape[0] == 0  # one block, no checkpoints
    nb = 1 if one else arr.ckpt_q.shape[0]
    blk = arr.blk_qf.shape[0] - 1
    q, x, P, qs, xs, qp1, xp1 = ws.q, ws.x, ws.P, ws.qs, ws.xs, ws.qp1, ws.xp1
    out_q, out_x = arr.out_q, arr.out_x
    if smooth and one:  # the single block is filled by the first (only) forward pass
        arr.blk_qp[0, :] = q  # (unused: a block's first prediction is never read)
        arr.blk_xp[0, :] = x
        _rts_filter_block(0, n_s - 1, inp, prm, ws, arr)
    else:  # forward filter only (nothing stored), or keeping checkpoints
        if smooth:
            arr.ckpt_q[0, :] = q
            arr.ckpt_x[0, :] = x
            arr.ckpt_P[0] = P
            arr.blk_qp[0, :] = q
            arr.blk_xp[0, :] = x
        else:
            _rts_output(0, q, x, out_q, out_x)
        for k in range(1, n_s):
            _rts_forward_step(k, inp, prm, ws, qp1, xp1)
            if not smooth:
                _rts_output(k, q, x, out_q, out_x)
            elif k % blk == 0:
                j = k // blk
                arr.ckpt_q[j, :] = q
                arr.ckpt_x[j, :] = x
                arr.ckpt_P[j] = P
        if not smooth:
            return
    # ---- Rauch–Tung–Striebel backward pass on the error state, block by block
    qs[:] = q  # smoothed = filtered at the last sample
    xs[:] = x
    _rts_output(n_s - 1, qs, xs, out_q, out_x)
    for j in range(nb - 1, -1, -1):
        s0 = j * blk
        top = min(s0 + blk, n_s - 1)
        if not one:  # recompute the block's forward pass from its checkpoint
            q[:] = arr.ckpt_q[j]
            x[:] = arr.ckpt_x[j]
            P[:, :] = arr.ckpt_P[j]
            _rts_filter_block(s0, top, inp, prm, ws, arr)
        for k in range(top - 1, s0 - 1, -1):
            _rts_backward_step(k, k - s0, inp, prm, ws, arr)
            _rts_output(k, qs, xs, out_q, out_x)
