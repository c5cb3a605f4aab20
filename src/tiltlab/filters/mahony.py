r"""Mahony's explicit complementary filter with an integral (gyro-bias) term (6D or 9D).

Like Madgwick's, the correction is evaluated at the prior :math:`q_{k-1}` against
:math:`a_k`: a one-sample lag of up to :math:`|\omega|\Delta t` rad under rotation.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .. import _validate as _v
from ..quaternion import qmul_scalar, rotate_scalar
from ._common import read_sensors, start_orientation

__all__ = ["mahony"]


@njit(cache=True, nogil=True)
def _mahony_kernel(acc, gyr, mag, use_mag, dt, kp, ki, q0, b0, out, bias):
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    bx_, by_, bz_ = b0[0], b0[1], b0[2]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = w, x, y, z
    bias[0, 0], bias[0, 1], bias[0, 2] = bx_, by_, bz_
    for k in range(1, acc.shape[0]):
        ox, oy, oz = gyr[k, 0], gyr[k, 1], gyr[k, 2]
        ax, ay, az = acc[k, 0], acc[k, 1], acc[k, 2]
        an = np.sqrt(ax * ax + ay * ay + az * az)
        ex, ey, ez = 0.0, 0.0, 0.0
        have = False
        if an > 0.0:
            ax, ay, az = ax / an, ay / an, az / an
            # estimated gravity-up in the sensor frame: R(q)^T e_z
            vx, vy, vz = rotate_scalar(w, -x, -y, -z, 0.0, 0.0, 1.0)
            ex += ay * vz - az * vy
            ey += az * vx - ax * vz
            ez += ax * vy - ay * vx
            have = True
        if use_mag:
            mx, my, mz = mag[k, 0], mag[k, 1], mag[k, 2]
            mn = np.sqrt(mx * mx + my * my + mz * mz)
            if mn > 0.0:
                mx, my, mz = mx / mn, my / mn, mz / mn
                hx, hy, hz = rotate_scalar(w, x, y, z, mx, my, mz)
                # expected field in the sensor frame: R^T (0, |h_xy|, h_z) (ENU: y north)
                hn = np.sqrt(hx * hx + hy * hy)
                wx, wy, wz = rotate_scalar(w, -x, -y, -z, 0.0, hn, hz)
                wn = np.sqrt(wx * wx + wy * wy + wz * wz)
                wx, wy, wz = wx / wn, wy / wn, wz / wn
                ex += my * wz - mz * wy
                ey += mz * wx - mx * wz
                ez += mx * wy - my * wx
                have = True
        if have:
            bx_ -= ki * ex * dt
            by_ -= ki * ey * dt
            bz_ -= ki * ez * dt
            ox = ox - bx_ + kp * ex
            oy = oy - by_ + kp * ey
            oz = oz - bz_ + kp * ez
        else:
            ox, oy, oz = ox - bx_, oy - by_, oz - bz_
        # q ← (q + Δt/2 q ⊗ (0, Ω)) / ‖·‖
        h = 0.5 * dt
        dw, dx, dy, dz = qmul_scalar(w, x, y, z, 0.0, ox, oy, oz)
        nw, nx, ny, nz = w + h * dw, x + h * dx, y + h * dy, z + h * dz
        n = np.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
        w, x, y, z = nw / n, nx / n, ny / n, nz / n
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z
        bias[k, 0], bias[k, 1], bias[k, 2] = bx_, by_, bz_


def mahony(
    acc,
    gyr,
    fs: float | None = None,
    *,
    mag=None,
    kp: float = 1.0,
    ki: float = 0.03,
    q0=None,
    b0=None,
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
    ``q0`` and ``b0`` (:mod:`tiltlab.filters` lists its defects).

    Parameters
    ----------
    acc, gyr : array_like or xarray.DataArray, shape (N, 3)
        Specific force (any unit) and angular velocity (rad/s).
        Labelled inputs (:class:`xarray.DataArray`) are read by their attributes:
        ``gyr`` is converted from its ``units`` (required) to rad/s, ``acc`` with
        ``units`` to m/s² (see :mod:`tiltlab.filters`, "Labelled inputs").
    fs : float, optional
        Sampling rate (Hz): mandatory for plain arrays; with labelled inputs it may
        be omitted when they carry ``attrs["fs"]``, and must agree with it when given.
    mag : array_like or xarray.DataArray, shape (N, 3), optional
        Magnetometer (any unit; a ``units`` attribute must be a magnetic-field unit):
        9D, ENU world frame.
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
    b0 : array_like, shape (3,), optional
        Initial gyro bias (rad/s, whatever the units of a labelled ``gyr``), default
        zero.
    init_window_s : float
        Initialisation window (s).
    return_bias : bool
        Also return the bias estimates, shape (N, 3) (rad/s).

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
    if b0 is None:
        b0 = np.zeros(3)
    else:
        b0 = _v.vectors(np.reshape(b0, -1), "b0", width=3, ndim=1)
    q0 = start_orientation(q0, acc, m if use_mag else None, fs, init_window_s)
    out = np.empty((acc.shape[0], 4))
    bias = np.empty((acc.shape[0], 3))
    _mahony_kernel(acc, gyr, m, use_mag, 1.0 / fs, kp, ki, q0, b0, out, bias)
    return (out, bias) if return_bias else out
