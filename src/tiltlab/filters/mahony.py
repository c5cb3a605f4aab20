r"""Mahony's explicit complementary filter with an integral (gyro-bias) term (6D or 9D).

Like Madgwick's, the correction is evaluated at the prior :math:`q_{k-1}` against
:math:`a_k`: a one-sample lag of up to :math:`|\omega|\Delta t` rad under rotation.
"""

from __future__ import annotations

import numpy as np

from .. import _validate as _v
from .._deprecate import renamed
from ._common import offset_vector, read_sensors, start_orientation
from ._mahony_kernel import _mahony_kernel
from ._docs import shared_docs

__all__ = ["mahony"]


@renamed(b0="gyr_offset")
@shared_docs
def mahony(
    acc,
    gyr,
    fs: float | None = None,
    *,
    mag=None,
    kp: float = 1.0,
    ki: float = 0.03,
    q0=None,
    gyr_offset=None,
    init_window_s: float = 0.1,
    return_bias: bool = False,
):
    r"""Mahony's explicit complementary filter with integral (gyro-bias) term.

    .. math::
        e_k = \hat a_k \times R(q)^\top e_z \;+\; \hat m_k \times \hat v_m,\qquad
        b_k = b_{k-1} - k_I\, e_k\, \Delta t,\qquad
        \Omega = \omega_k - b_k + k_P\, e_k

    .. math::
        q_k = \frac{q_{k-1} + \tfrac12\, q_{k-1} \otimes (0, \Omega)\,\Delta t}{\|\cdot\|}

    with :math:`\hat v_m = R(q)^\top (0, \|h_{xy}\|, h_z)` normalised,
    :math:`h = R(q)\hat m` (ENU: magnetic north along +y). ``b`` is the estimated
    gyroscope bias. Equal to ``ahrs.filters.Mahony`` for the same gains, ``Dt = 1/fs``,
    ``q0`` and ``gyr_offset`` (:mod:`tiltlab.filters` lists its defects).

    Parameters
    ----------
    %(acc_gyr)s
    %(fs)s
    %(mag)s
    kp, ki : float
        Proportional (rad/s) and integral (rad/s²) gains, ``>= 0``, with
        ``kp/fs <= 2`` and ``ki/fs² <= 1`` (larger steps diverge). The default
        ``ki = 0.03`` (not the usual 0.3, which ``ahrs`` keeps) because a large integral
        gain turns sustained linear accelerations into a wrong gyro-bias estimate: 29°
        of tilt RMSE on BROAD's fast translation and combined trials against 14° at 0.03
        (``benchmarks/bench_defaults.py``; the conventions page, "Default parameters").
    q0 : array_like, shape (4,), optional
        Initial orientation; default :func:`initial_orientation` over
        ``init_window_s`` seconds.
    %(offset_bias)s

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Unit quaternions sensor → world; with ``return_bias`` a tuple ``(q, b)``.
    """
    fs, acc, gyr, m, use_mag = read_sensors(fs, acc, gyr, mag)
    kp = _v.nonnegative(kp, "kp")
    ki = _v.nonnegative(ki, "ki")
    # one step turns the estimate by at most kp/fs (+ the bias step ki/fs²) radians
    # toward the accelerometer; beyond ~2 rad it overshoots and the filter diverges
    if kp / fs > 2.0 or ki / fs**2 > 1.0:
        raise ValueError(
            f"kp = {kp:g} rad/s and ki = {ki:g} rad/s² are too large for fs = {fs:g} "
            f"Hz: the correction per sample (kp/fs = {kp / fs:.3g} rad, ki/fs² = "
            f"{ki / fs**2:.3g} rad) must stay below 2 and 1 rad, or the filter "
            "overshoots and diverges"
        )
    b0 = offset_vector(gyr_offset)
    q0 = start_orientation(q0, acc, m if use_mag else None, fs, init_window_s)
    out = np.empty((acc.shape[0], 4))
    bias = np.empty((acc.shape[0], 3))
    _mahony_kernel(acc, gyr, m, use_mag, 1.0 / fs, kp, ki, q0, b0, out, bias)
    return (out, bias) if return_bias else out
