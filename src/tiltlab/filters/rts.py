r"""Offline error-state EKF with a Rauch–Tung–Striebel backward pass (6D).

Attitude, gyro bias and scale, velocity and position states; zero-velocity and
bounded-position pseudo-measurements; adaptive accelerometer weighting.

This module holds the public :func:`rts_smoother` (its parameters, initial state and
noise) and the plan of the arrays it allocates (:func:`_rts_plan`); the numba kernels
are in :mod:`tiltlab.filters._rts_kernel` (one sample of the forward filter and of the
backward pass, and the passes over a recording); :func:`_rts_params` maps the tuning
options (:class:`RtsTuning`) to the kernels' parameter record.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import _validate as _v
from .._deprecate import renamed
from ._common import (
    check_tuning,
    offset_vector,
    samples,
    start_orientation,
    tuned,
    unlabel,
)
from ._rts_kernel import (
    _RTS_N,
    _RTS_X,
    RtsArrays,
    RtsInputs,
    RtsParams,
    _rts_kernel,
)
from .smoothers import rest_gyro_bias
from ._docs import shared_docs

__all__ = ["RtsTuning", "rts_smoother"]

#: samples per block of the checkpointed backward pass (see :func:`_rts_plan`; ``None``:
#: store every sample, the full-storage smoother)
_RTS_BLOCK: int | None = 2**14
#: bytes per sample of the block's forward quantities: q, x filtered and predicted, P filtered
_RTS_BLOCK_SAMPLE_BYTES = 8 * (2 * (4 + _RTS_X) + _RTS_N * _RTS_N)  # 2056
#: bytes per checkpoint: q, x, P filtered
_RTS_CKPT_BYTES = 8 * (4 + _RTS_X + _RTS_N * _RTS_N)  # 1928


class RtsTuning(NamedTuple):
    """Tuning options of :func:`rts_smoother` and their defaults (see its parameters)."""

    gyr_noise: float = 5e-3
    bias_noise: float = 1e-4
    acc_noise: float = 0.01
    acc_std: float = 0.05
    norm_gain: float = 10.0
    vel_std: float = 0.3
    pos_std: float = 1.0
    tau_s: float = 1.0
    zupt_std: float = 0.01
    bias_std: float = float(np.radians(0.5))
    scale_std: float = 0.0
    scale_noise: float = 0.0


#: options of :class:`RtsTuning` that must be > 0 (all but ``tau_s`` may be ``inf``)
_POSITIVE = ("tau_s", "acc_std", "vel_std", "pos_std", "zupt_std")


def _rts_plan(
    n_samples: int,
    block: int | None,
    *,
    smooth: bool = True,
    return_state: bool = False,
) -> dict:
    """Plan the arrays :func:`rts_smoother` allocates for ``n_samples`` samples.

    Their shapes (``shapes``: name → shape, every array float64) and bytes.

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


@renamed(bias="gyr_offset")
@tuned(RtsTuning)
@shared_docs
def rts_smoother(
    acc,
    gyr,
    fs: float | None = None,
    *,
    tuning: RtsTuning,
    gyr_offset=None,
    q0=None,
    init_window_s: float = 0.1,
    smooth: bool = True,
    return_state: bool = False,
    max_memory_gb: float = 4.0,
):
    r"""Smooth the attitude offline: an error-state EKF and a Rauch–Tung–Striebel pass.

    The error-state (multiplicative) EKF has gyro-bias, gyro-scale, velocity and
    position states; a Rauch–Tung–Striebel backward pass follows.

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
    %(fs)s
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
    gyr_offset : array_like, shape (3,), optional
        Initial gyroscope offset (bias; rad/s, whatever the units of a labelled
        ``gyr``); default :func:`rest_gyro_bias`. Formerly ``bias`` (still accepted,
        with a FutureWarning).
    %(q0_init)s
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
    _check_memory(plan, acc.shape[0], max_memory_gb, bool(smooth))
    tuning = check_tuning(tuning, positive=_POSITIVE, inf=_POSITIVE[1:])
    b_rest, rest = rest_gyro_bias(acc, gyr, fs)
    b0 = offset_vector(gyr_offset, b_rest)
    an = np.linalg.norm(acc, axis=1)
    grav = float(np.mean(an[rest])) if rest.sum() >= 0.5 * fs else float(np.median(an))
    if not grav > 0:
        raise ValueError("the accelerometer norm vanishes; no gravity can be defined")
    q0 = start_orientation(q0, acc, None, fs, init_window_s)
    params, Qd, P0 = _rts_params(tuning, fs, grav)
    inputs = RtsInputs(acc, gyr, np.ascontiguousarray(rest), Qd)
    arrays = RtsArrays(*(np.empty(v) for v in plan["shapes"].values()))
    x0 = np.concatenate([b0, np.zeros(9)])
    _rts_kernel(inputs, params, q0, x0, P0, arrays, bool(smooth))
    return (arrays.out_q, arrays.out_x) if return_state else arrays.out_q


def _check_memory(plan: dict, n: int, max_memory_gb: float, smooth: bool) -> None:
    """Refuse a plan over ``max_memory_gb`` (smoothing only), explaining its parts."""
    need_gb = plan["total_bytes"] / 1e9
    if smooth and need_gb > max_memory_gb:
        raise ValueError(
            f"rts_smoother would allocate {need_gb:.3g} GB for {n} samples "
            f"(limit max_memory_gb={max_memory_gb:g}): the output "
            f"({plan['output_bytes'] / 1e9:.3g} GB, 32 B per sample, 128 B with "
            f"return_state), {plan['checkpoints']} checkpoints "
            f"({plan['checkpoint_bytes'] / 1e9:.3g} GB) and one block of "
            f"{plan['block']} samples ({plan['block_bytes'] / 1e9:.3g} GB); split "
            "the recording into shorter segments or raise the limit"
        )


def _rts_params(
    t: RtsTuning, fs: float, grav: float
) -> tuple[RtsParams, np.ndarray, np.ndarray]:
    """Map the (checked) tuning options to the kernels' model.

    The one place where the public options become the kernels' values: the scalar
    parameters (:class:`~tiltlab.filters._rts_kernel.RtsParams`: the pseudo-measurement
    standard deviations per correlation time become variances per sample), the
    diagonal of the discrete process noise and the initial covariance.
    """
    dt = 1.0 / fs
    rate = t.tau_s * fs
    params = RtsParams(
        dt=dt,
        grav=grav,
        var_acc=t.acc_std**2 * rate,
        norm_gain=t.norm_gain,
        var_vel=t.vel_std**2 * rate,
        var_pos=t.pos_std**2 * rate,
        var_zupt=t.zupt_std**2,
    )
    Qd = (
        dt
        * np.r_[
            [t.gyr_noise**2] * 3,
            [t.bias_noise**2] * 3,
            [t.acc_noise**2] * 3,
            [t.acc_noise**2 * dt * dt / 3.0] * 3,
            [t.scale_noise**2] * 3,
        ]
    )
    P0 = np.diag(
        np.r_[
            np.radians(2.0) ** 2,
            np.radians(2.0) ** 2,
            1e-6,
            [t.bias_std**2 + 1e-12] * 3,
            [0.1**2] * 3,
            [1e-6] * 3,
            [t.scale_std**2 + 1e-12] * 3,
        ]
    )
    return params, np.maximum(Qd, 1e-18), P0
