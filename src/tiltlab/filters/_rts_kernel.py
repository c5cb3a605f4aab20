"""Numba driver of the error-state RTS smoother (:func:`~tiltlab.filters.rts_smoother`).

:func:`_rts_kernel` runs the forward filter over a recording and, when smoothing, the
checkpointed Rauch–Tung–Striebel backward pass block by block, with the one-sample steps
of :mod:`tiltlab.filters._rts_steps`. The arrays it fills are planned by
:func:`tiltlab.filters.rts._rts_plan`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._rts_steps import _RTS_N, _RTS_X, _rts_backward_step, _rts_forward_step


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
