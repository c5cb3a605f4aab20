r"""Geometric complementary filter (6D or 9D), in the spirit of Valenti et al. (2015)."""

from __future__ import annotations

import numpy as np
from numba import njit

from .. import _validate as _v
from ..quaternion import qmul_scalar, rotate_scalar, zoh_step_scalar
from ._common import read_sensors, start_orientation
from ._docs import shared_docs

__all__ = ["complementary"]


@njit(cache=True, nogil=True)
def _complementary_kernel(acc, gyr, mag, use_mag, dt, k_acc, k_mag, q0, out):
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = w, x, y, z
    for k in range(1, acc.shape[0]):
        # exact zero-order-hold propagation q ← q ⊗ exp(ω dt / 2)
        w, x, y, z = zoh_step_scalar(
            w, x, y, z, gyr[k, 0] * dt, gyr[k, 1] * dt, gyr[k, 2] * dt
        )
        # accelerometer: rotate the world-frame measured "up" towards e_z (axis horizontal)
        ax, ay, az = acc[k, 0], acc[k, 1], acc[k, 2]
        an = np.sqrt(ax * ax + ay * ay + az * az)
        if an > 0.0 and k_acc > 0.0:
            ax, ay, az = ax / an, ay / an, az / an
            gx, gy, gz = rotate_scalar(w, x, y, z, ax, ay, az)
            s = np.sqrt(gx * gx + gy * gy)
            if s > 0.0:
                ang = k_acc * np.arctan2(s, gz)
                sh, ch = np.sin(0.5 * ang), np.cos(0.5 * ang)
                # q ← Δq ⊗ q with Δq = (ch, ux, uy, 0)
                w, x, y, z = qmul_scalar(ch, sh * gy / s, -sh * gx / s, 0.0, w, x, y, z)
        if use_mag and k_mag > 0.0:
            mx, my, mz = mag[k, 0], mag[k, 1], mag[k, 2]
            hx, hy, _ = rotate_scalar(w, x, y, z, mx, my, mz)
            if hx != 0.0 or hy != 0.0:
                # azimuth of the horizontal field, counter-clockwise from north (+y)
                phi = np.arctan2(-hx, hy)
                ang = -k_mag * phi
                sh, ch = np.sin(0.5 * ang), np.cos(0.5 * ang)
                # q ← R_z(ang) ⊗ q
                w, x, y, z = qmul_scalar(ch, 0.0, 0.0, sh, w, x, y, z)
        n = np.sqrt(w * w + x * x + y * y + z * z)
        w, x, y, z = w / n, x / n, y / n, z / n
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z


@shared_docs
def complementary(
    acc,
    gyr,
    fs: float | None = None,
    *,
    mag=None,
    tau_acc_s: float = 1.0,
    tau_mag_s: float = 5.0,
    q0=None,
    init_window_s: float = 0.1,
) -> np.ndarray:
    r"""Geometric complementary filter (6D or 9D).

    Prediction :math:`q \leftarrow q \otimes \exp(\omega_k \Delta t/2)`. Correction in
    the world frame, in the spirit of Valenti et al.: the measured up direction
    :math:`g_w = R(q)\hat a_k` is rotated towards :math:`e_z` about the horizontal axis
    :math:`g_w \times e_z` by the fraction :math:`k_a = 1 - e^{-\Delta t/\tau_a}` of the
    angle between them (heading untouched); with a magnetometer, a rotation about
    :math:`e_z` by :math:`-k_m \varphi` where :math:`\varphi` is the azimuth of the
    horizontal part of :math:`R(q)\hat m` from north (+y, ENU) and
    :math:`k_m = 1 - e^{-\Delta t/\tau_m}` (tilt untouched).

    Parameters
    ----------
    %(acc_gyr)s
    %(fs)s
    %(mag)s
    tau_acc_s, tau_mag_s : float
        Time constants (s) of the accelerometer and magnetometer corrections; ``inf``
        disables a correction.
    %(q0_init)s

    Returns
    -------
    numpy.ndarray, shape (N, 4)
    """
    fs, acc, gyr, m, use_mag = read_sensors(fs, acc, gyr, mag)
    dt = 1.0 / fs
    k_acc = -np.expm1(-dt / _v.positive(tau_acc_s, "tau_acc_s", allow_inf=True))
    k_mag = -np.expm1(-dt / _v.positive(tau_mag_s, "tau_mag_s", allow_inf=True))
    q0 = start_orientation(q0, acc, m if use_mag else None, fs, init_window_s)
    out = np.empty((acc.shape[0], 4))
    _complementary_kernel(acc, gyr, m, use_mag, dt, k_acc, k_mag, q0, out)
    return out
