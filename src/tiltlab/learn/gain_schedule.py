r"""Train the gain schedule of :func:`tiltlab.filters.learned_gain` by back-propagation.

The loss of a trial is the root mean square over its scored samples of the chord
between the estimated and the reference gravity directions in the sensor frame,

.. math::
    L = \Big(\frac1{|M|}\sum_{k\in M} \|v(q_k) - v(q^{ref}_k)\|^2\Big)^{1/2},\qquad
    v(q) = R(q)^\top e_z,

where :math:`\|v - v^{ref}\| = 2\sin(\theta/2)` for the inclination error
:math:`\theta` (BROAD's definition [1]_), so :math:`L` is the inclination RMSE to
second order. Its exact gradient with respect to the per-sample gains is computed
by reverse-mode differentiation of the whole filter recursion (back-propagation
through time): one forward pass stores the states :math:`(q_k, b_k, f_k)`, one
backward pass propagates the adjoints :math:`(\lambda_q, \lambda_b, \lambda_f)`
(attitude, gyro bias, low-passed specific force) with the per-step
Jacobians of :func:`~tiltlab.filters.learned_gain`'s step. The chain rule through
:func:`~tiltlab.filters.learned_gain.gain_schedule` then gives the gradient with
respect to the schedule's weights, which L-BFGS [2]_ minimises, starting from the
zero schedule (the tuned parent), with early stopping on validation trials.

References
----------
.. [1] D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD — A Benchmark for Robust
   Inertial Orientation Estimation", Data 6(7):72, 2021. doi:10.3390/data6070072
.. [2] D. C. Liu, J. Nocedal, "On the limited memory BFGS method for large scale
   optimization", Math. Program. 45:503–528, 1989. doi:10.1007/BF01589116
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import pandas as pd
from numba import njit
from scipy.optimize import minimize

from ..filters._shared_kernel import _unit_sample
from ..filters.learned_gain import (
    FEATURES,
    GainWeights,
    _rotation,
    _varying_mahony_kernel,
    gain_features,
    gain_schedule,
    smoothing_factor,
)
from ..quaternion import rotate_scalar

__all__ = [
    "GAIN_LABELS",
    "gain_compare",
    "GainTrial",
    "gain_trial",
    "schedule_loss",
    "train_schedule",
    "fit_standardisation",
]


class GainTrial(NamedTuple):
    """One training sequence: sensors, reference gravity directions and features.

    Attributes
    ----------
    acc, gyr : numpy.ndarray, shape (N, 3)
        Accelerometer (m/s²) and gyroscope (rad/s).
    fs : float
        Sampling rate (Hz).
    v_ref : numpy.ndarray, shape (N, 3)
        Reference gravity-up direction in the sensor frame (rows of NaN unscored).
    mask : numpy.ndarray of bool, shape (N,)
        The scored samples.
    q0 : numpy.ndarray, shape (4,)
        Initial orientation of the filter.
    features : numpy.ndarray, shape (N, F)
        :func:`~tiltlab.filters.learned_gain.gain_features`.
    """

    acc: np.ndarray
    gyr: np.ndarray
    fs: float
    v_ref: np.ndarray
    mask: np.ndarray
    q0: np.ndarray
    features: np.ndarray


def _up(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack(
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1
    )


def gain_trial(acc, gyr, fs: float, q_ref, mask, q0) -> GainTrial:
    """Prepare one sequence for :func:`schedule_loss` (inputs are copied).

    Parameters
    ----------
    acc, gyr : array_like, shape (N, 3)
        Accelerometer (m/s²) and gyroscope (rad/s) samples.
    fs : float
        Sampling rate (Hz).
    q_ref : array_like, shape (N, 4)
        Reference unit quaternions sensor → world (NaN where missing).
    mask : array_like of bool, shape (N,)
        Samples to score (also those with a finite reference only).
    q0 : array_like, shape (4,)
        Initial orientation of the filter (as :func:`~tiltlab.filters.mahony` uses).

    Returns
    -------
    GainTrial
        The prepared sequence.
    """
    acc = np.array(acc, dtype=float)
    gyr = np.array(gyr, dtype=float)
    q_ref = np.asarray(q_ref, dtype=float)
    if acc.ndim != 2 or acc.shape[1] != 3 or gyr.shape != acc.shape:
        raise ValueError(
            f"acc and gyr must both be (N, 3), got {acc.shape}, {gyr.shape}"
        )
    if q_ref.shape != (acc.shape[0], 4):
        raise ValueError(f"q_ref must be ({acc.shape[0]}, 4), got {q_ref.shape}")
    m = np.asarray(mask, dtype=bool) & np.all(np.isfinite(q_ref), axis=1)
    if not m.any():
        raise ValueError(
            "no scored sample: the mask and the finite reference are disjoint"
        )
    return GainTrial(
        acc,
        gyr,
        float(fs),
        _up(np.nan_to_num(q_ref)),
        m,
        np.array(q0, dtype=float),
        gain_features(acc, gyr, fs),
    )


@njit(cache=True, nogil=True, inline="always")
def _rotation_grad(w, x, y, z, l0, l1, l2, r0, r1, r2):
    # gradient over q of l^T R(q) r (R as _rotation writes it): sum_ij l_i r_j R_ij
    m00, m01, m02 = l0 * r0, l0 * r1, l0 * r2
    m10, m11, m12 = l1 * r0, l1 * r1, l1 * r2
    m20, m21, m22 = l2 * r0, l2 * r1, l2 * r2
    gw = 2.0 * (-m01 * z + m02 * y + m10 * z - m12 * x - m20 * y + m21 * x)
    gx = 2.0 * (m01 * y + m02 * z + m10 * y - m12 * w + m20 * z + m21 * w)
    gy = 2.0 * (m01 * x + m02 * w + m10 * x + m12 * z - m20 * w + m21 * z)
    gz = 2.0 * (-m01 * w + m02 * x + m10 * w + m12 * y + m20 * x + m21 * y)
    return (
        gw,
        gx - 4.0 * x * (m11 + m22),
        gy - 4.0 * y * (m00 + m22),
        gz - 4.0 * z * (m00 + m11),
    )


@njit(cache=True, nogil=True, inline="always")
def _error(acc, facc, k, alpha, w, x, y, z):
    # the correction error e of step k from the prior q (as the forward kernel)
    if alpha < 1.0:
        r00, r01, r02, r10, r11, r12, _, _, _ = _rotation(w, x, y, z)
        fx, fy, fz = facc[k, 0], facc[k, 1], facc[k, 2]
        fn = np.sqrt(fx * fx + fy * fy + fz * fz)
        if fn > 0.0:
            cx, cy = fy / fn, -fx / fn
            return r00 * cx + r10 * cy, r01 * cx + r11 * cy, r02 * cx + r12 * cy, True
        return 0.0, 0.0, 0.0, False
    ax, ay, az, an = _unit_sample(acc, k)
    if an > 0.0:
        vx, vy, vz = rotate_scalar(w, -x, -y, -z, 0.0, 0.0, 1.0)
        return ay * vz - az * vy, az * vx - ax * vz, ax * vy - ay * vx, True
    return 0.0, 0.0, 0.0, False


@njit(cache=True, nogil=True, inline="always")
def _error_back(acc, facc, q, k, alpha, have, le, s):
    # adjoint of q_{k-1} (4 values, returned) from the adjoint le of the error e;
    # s (3,), the adjoint of the low-passed specific force f_k, becomes that of f_{k-1}
    w, x, y, z = q[k - 1, 0], q[k - 1, 1], q[k - 1, 2], q[k - 1, 3]
    gw, gx, gy, gz = 0.0, 0.0, 0.0, 0.0
    if alpha < 1.0:
        if have:
            # e = R^T c, c = (u_y, -u_x, 0), u = f / |f|
            r00, r01, r02, r10, r11, r12, _, _, _ = _rotation(w, x, y, z)
            fx, fy, fz = facc[k, 0], facc[k, 1], facc[k, 2]
            fn = np.sqrt(fx * fx + fy * fy + fz * fz)
            ux, uy, uz = fx / fn, fy / fn, fz / fn
            gw, gx, gy, gz = _rotation_grad(
                w, x, y, z, uy, -ux, 0.0, le[0], le[1], le[2]
            )
            lux = -(r10 * le[0] + r11 * le[1] + r12 * le[2])
            luy = r00 * le[0] + r01 * le[1] + r02 * le[2]
            du = ux * lux + uy * luy
            s[0] += (lux - ux * du) / fn
            s[1] += (luy - uy * du) / fn
            s[2] += -uz * du / fn
        # f_k = (1 - alpha) f_{k-1} + alpha R a_k
        hw, hx, hy, hz = _rotation_grad(
            w, x, y, z, alpha * s[0], alpha * s[1], alpha * s[2],
            acc[k, 0], acc[k, 1], acc[k, 2],
        )  # fmt: skip
        s *= 1.0 - alpha
        return gw + hw, gx + hx, gy + hy, gz + hz
    if have:
        # e = a × v  ⇒  adjoint of v = le × a
        ax, ay, az, _ = _unit_sample(acc, k)
        ux = le[1] * az - le[2] * ay
        uy = le[2] * ax - le[0] * az
        uz = le[0] * ay - le[1] * ax
        gw = 2.0 * (-y * ux + x * uy)
        gx = 2.0 * (z * ux + w * uy) - 4.0 * x * uz
        gy = 2.0 * (-w * ux + z * uy) - 4.0 * y * uz
        gz = 2.0 * (x * ux + y * uy)
    return gw, gx, gy, gz


@njit(cache=True, nogil=True)
def _adjoint_kernel(acc, gyr, dt, alpha, gains, q, b, facc, gq, ggain):
    # reverse pass of _varying_mahony_kernel: gq (N, 4) is dL/dq_k of the loss alone;
    # writes ggain (3, N): dL/dkp_k, dL/dki_k, dL/dkb_k (through all later samples)
    h = 0.5 * dt
    lw, lx, ly, lz = 0.0, 0.0, 0.0, 0.0
    mx_, my_, mz_ = 0.0, 0.0, 0.0  # adjoint of the bias
    s = np.zeros(3)  # adjoint of the low-passed specific force
    le = np.zeros(3)  # adjoint of the error
    ggain[:, 0] = 0.0
    for k in range(acc.shape[0] - 1, 0, -1):
        lw, lx, ly, lz = lw + gq[k, 0], lx + gq[k, 1], ly + gq[k, 2], lz + gq[k, 3]
        w, x, y, z = q[k - 1, 0], q[k - 1, 1], q[k - 1, 2], q[k - 1, 3]
        ox, oy, oz = gyr[k, 0] - b[k, 0], gyr[k, 1] - b[k, 1], gyr[k, 2] - b[k, 2]
        kp, ki, kb = gains[0, k], gains[1, k], gains[2, k]
        ex, ey, ez, have = _error(acc, facc, k, alpha, w, x, y, z)
        if have:
            ox, oy, oz = ox + kp * ex, oy + kp * ey, oz + kp * ez
        # p = q + h q ⊗ (0, Ω); q' = p / |p|
        pw = w + h * (-x * ox - y * oy - z * oz)
        px = x + h * (w * ox + y * oz - z * oy)
        py = y + h * (w * oy + z * ox - x * oz)
        pz = z + h * (w * oz + x * oy - y * ox)
        n = np.sqrt(pw * pw + px * px + py * py + pz * pz)
        d = (pw * lw + px * lx + py * ly + pz * lz) / n
        pw_, px_ = (lw - pw / n * d) / n, (lx - px / n * d) / n
        py_, pz_ = (ly - py / n * d) / n, (lz - pz / n * d) / n
        # adjoint of Ω (through q ⊗ (0, Ω))
        gx = h * (-x * pw_ + w * px_ + z * py_ - y * pz_)
        gy = h * (-y * pw_ - z * px_ + w * py_ + x * pz_)
        gz = h * (-z * pw_ + y * px_ - x * py_ + w * pz_)
        r = 1.0
        le[:] = 0.0
        ggain[:, k] = 0.0
        if have:
            # b' = (1 - kb dt) b + kb dt ω - ki dt e;  Ω = ω - b' + kp e
            ggain[0, k] = ex * gx + ey * gy + ez * gz
            ggain[1, k] = dt * (ex * (gx - mx_) + ey * (gy - my_) + ez * (gz - mz_))
            ggain[2, k] = dt * (
                (gyr[k, 0] - b[k - 1, 0]) * (mx_ - gx)
                + (gyr[k, 1] - b[k - 1, 1]) * (my_ - gy)
                + (gyr[k, 2] - b[k - 1, 2]) * (mz_ - gz)
            )
            c = kp + ki * dt
            le[0] = c * gx - ki * dt * mx_
            le[1] = c * gy - ki * dt * my_
            le[2] = c * gz - ki * dt * mz_
            r = 1.0 - kb * dt
        gw_, gx_, gy_, gz_ = _error_back(acc, facc, q, k, alpha, have, le, s)
        # adjoint of q: through p (identity + q ⊗ (0, Ω), Ω fixed) and through e
        lw = pw_ + h * (px_ * ox + py_ * oy + pz_ * oz) + gw_
        lx = px_ + h * (-pw_ * ox - py_ * oz + pz_ * oy) + gx_
        ly = py_ + h * (-pw_ * oy + px_ * oz - pz_ * ox) + gy_
        lz = pz_ + h * (-pw_ * oz - px_ * oy + py_ * ox) + gz_
        mx_, my_, mz_ = r * (mx_ - gx), r * (my_ - gy), r * (mz_ - gz)


def _trial_loss(trial: GainTrial, weights: GainWeights, grad: bool):
    gains, z, free = gain_schedule(trial.features, weights)
    n = trial.acc.shape[0]
    q = np.empty((n, 4))
    b = np.empty((n, 3))
    dt = 1.0 / trial.fs
    alpha = smoothing_factor(weights.tau_acc_s, trial.fs)
    facc = np.empty((n, 3))
    _varying_mahony_kernel(
        trial.acc, trial.gyr, dt, alpha, gains, trial.q0, np.zeros(3), q, b, facc
    )
    v = _up(q)
    m = trial.mask
    d = v[m] - trial.v_ref[m]
    loss = float(np.sqrt(np.mean(np.sum(d * d, axis=1))))
    if not grad:
        return loss, None
    gv = np.zeros((n, 3))
    gv[m] = d / (m.sum() * max(loss, 1e-300))
    w, x, y, zz = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    gq = np.stack(
        [
            2 * (-y * gv[:, 0] + x * gv[:, 1]),
            2 * (zz * gv[:, 0] + w * gv[:, 1]) - 4 * x * gv[:, 2],
            2 * (-w * gv[:, 0] + zz * gv[:, 1]) - 4 * y * gv[:, 2],
            2 * (x * gv[:, 0] + y * gv[:, 1]),
        ],
        axis=1,
    )
    ggain = np.empty((3, n))
    _adjoint_kernel(trial.acc, trial.gyr, dt, alpha, gains, q, b, facc, gq, ggain)
    return loss, (z.T @ (ggain * gains * free).T).T.reshape(-1)


def _with(weights: GainWeights, theta: np.ndarray) -> GainWeights:
    f = len(FEATURES) + 1
    return weights._replace(
        w_p=theta[:f].copy(), w_i=theta[f : 2 * f].copy(), w_b=theta[2 * f :].copy()
    )


def schedule_loss(
    trials: Sequence[GainTrial], weights: GainWeights, *, grad: bool = True
) -> tuple[float, np.ndarray | None]:
    """Mean trial loss (see the module) of a schedule and its exact gradient.

    Parameters
    ----------
    trials : sequence of GainTrial
        The sequences (:func:`gain_trial`).
    weights : GainWeights
        The schedule.
    grad : bool
        Also return the gradient.

    Returns
    -------
    tuple
        ``(loss, gradient)``: the mean over trials of the chord RMSE (≈ inclination
        RMSE in rad) and its gradient with respect to ``concatenate([w_p, w_i, w_b])``
        (None without ``grad``).
    """
    if not trials:
        raise ValueError("schedule_loss needs at least one trial")
    total, g = 0.0, np.zeros(3 * (len(FEATURES) + 1))
    for t in trials:
        loss, gt = _trial_loss(t, weights, grad)
        total += loss
        if grad:
            g += gt
    n = len(trials)
    return total / n, (g / n if grad else None)


def fit_standardisation(trials: Sequence[GainTrial]) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation of the features over all samples of ``trials``.

    Parameters
    ----------
    trials : sequence of GainTrial
        The training sequences.

    Returns
    -------
    tuple of numpy.ndarray
        ``(mean, std)``, each (F,).
    """
    f = np.concatenate([t.features for t in trials])
    return f.mean(axis=0), np.maximum(f.std(axis=0), 1e-12)


def train_schedule(
    train: Sequence[GainTrial],
    validation: Sequence[GainTrial],
    kp: float,
    ki: float,
    kb: float = 0.0,
    tau_acc_s: float = 0.0,
    *,
    l2: float = 1e-4,
    max_iter: int = 60,
) -> tuple[GainWeights, dict]:
    r"""Fit the schedule's weights by L-BFGS on ``train``, early-stopped on ``validation``.

    Minimises :math:`\bar L_{train}(\theta) + \lambda \|\theta\|^2` from
    :math:`\theta = 0` (the parent with ``kp``, ``ki``) and returns the iterate with
    the lowest validation loss (the parent itself if none improves on it).

    Parameters
    ----------
    train, validation : sequence of GainTrial
        Fitting and early-stopping sequences.
    kp, ki, kb : float
        The parent's tuned gains.
    tau_acc_s : float
        The parent's world-frame low-pass time constant (s) of the specific force.
    l2 : float
        Ridge penalty :math:`\lambda` on the weights.
    max_iter : int
        L-BFGS iterations.

    Returns
    -------
    tuple
        ``(weights, history)``: the selected :class:`GainWeights` (feature
        standardisation fitted on ``train``) and a dict with the losses per iteration
        and the training time (s).

    Examples
    --------
    >>> # trials = [gain_trial(acc, gyr, fs, q_ref, movement, q0) for ...]
    >>> # weights, history = train_schedule(trials[:20], trials[20:], 1.0, 0.01)
    """
    t0 = time.perf_counter()
    mean, std = fit_standardisation(train)
    base = GainWeights.parent(kp, ki, kb, tau_acc_s, mean, std)
    theta0 = np.zeros(3 * (len(FEATURES) + 1))

    def fun(theta):
        loss, g = schedule_loss(train, _with(base, theta))
        return loss + l2 * theta @ theta, g + 2 * l2 * theta

    val0 = schedule_loss(validation, base, grad=False)[0] if validation else 0.0
    hist = {"train": [], "validation": [], "theta": []}
    best = [val0, theta0]

    def callback(theta):
        tr = schedule_loss(train, _with(base, theta), grad=False)[0]
        va = (
            schedule_loss(validation, _with(base, theta), grad=False)[0]
            if validation
            else tr
        )
        hist["train"].append(tr)
        hist["validation"].append(va)
        hist["theta"].append(theta.tolist())
        if va < best[0]:
            best[0], best[1] = va, theta.copy()

    minimize(
        fun,
        theta0,
        jac=True,
        method="L-BFGS-B",
        callback=callback,
        options={"maxiter": max_iter},
    )
    hist["validation_parent"] = val0
    hist["seconds"] = time.perf_counter() - t0
    return _with(base, best[1]), hist


#: Row labels of :func:`gain_compare`: the learned schedule and its fixed-gain parent.
GAIN_LABELS = ("learned gain 6D", "learned gain's parent 6D")


def gain_compare(
    folds: Sequence[Sequence[int]],
    weights_dir=None,
    *,
    trials: Sequence[int] | None = None,
    load=None,
) -> pd.DataFrame:
    """Score the learned-gain filter and its fixed-gain parent on held-out trials.

    Each trial is estimated with the weights of the fold that held it out
    (``fold<k>.json`` in ``weights_dir``, checked against its ``SHA256SUMS``): once
    with the learned schedule and once with the same weights' zero schedule (the
    parent, :meth:`~tiltlab.filters.learned_gain.GainWeights.parent`), so the two
    differ only by what was learned.

    Parameters
    ----------
    folds : sequence of sequence of int
        The held-out trials of each fold (``run.json``'s ``folds``).
    weights_dir : str or path, optional
        Folder with ``fold0.json`` … and their ``SHA256SUMS``; default the weights
        shipped with the package (trained on the CNN folds of chapter 5).
    trials : sequence of int, optional
        Trials to score (default: every trial of ``folds``).
    load : callable, optional
        Trial number → Recording (default :func:`tiltlab.datasets.load_broad_trial`).

    Returns
    -------
    pandas.DataFrame
        Rows (method, trial) with :func:`~tiltlab.learn.cv.trial_errors` columns,
        labelled like :func:`~tiltlab.learn.cv.compare`; methods :data:`GAIN_LABELS`.

    Raises
    ------
    ValueError
        A trial that no fold holds out, or a weights file that fails its checksum.
    """
    from pathlib import Path

    from .. import datasets
    from ..filters import estimate
    from ..filters.learned_gain import BROAD_WEIGHTS, GainWeights, load_gain_weights
    from .cv import _label_errors, trial_errors

    fold_of = {int(t): k for k, f in enumerate(folds) for t in f}
    trials = sorted(fold_of) if trials is None else [int(t) for t in trials]
    missing = [t for t in trials if t not in fold_of]
    if missing:
        raise ValueError(f"trials {missing} are held out by no fold")
    load = load or datasets.load_broad_trial
    weights_dir = BROAD_WEIGHTS.parent if weights_dir is None else weights_dir
    weights = {
        k: load_gain_weights(Path(weights_dir) / f"fold{k}.json")
        for k in sorted({fold_of[t] for t in trials})
    }
    rows = []
    for t in trials:
        rec = load(t)
        w = weights[fold_of[t]]
        parent = GainWeights.parent(w.kp, w.ki, w.kb, w.tau_acc_s, w.mean, w.std)
        for label, ww in zip(GAIN_LABELS, (w, parent)):
            q = estimate(rec, "learned_gain", weights=ww)
            rows.append({"method": label, "trial": t} | trial_errors(q.values, rec))
    return _label_errors(pd.DataFrame(rows))
