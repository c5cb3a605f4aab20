r"""Complementary filters: geometric (6D or 9D, after Valenti et al. 2015) and per-axis.

:func:`complementary` corrects a quaternion towards the accelerometer's vertical (and
the magnetometer's north) by a fraction :math:`1 - e^{-\Delta t/\tau}` per sample.
:func:`complementary_angles` is the per-axis form LaCanna (2018) writes down (his
Introduction) — roll and pitch angles, each
:math:`\alpha_i = a(\alpha_{i-1} + \omega_i\Delta t) + (1 - a)\,\alpha^{acc}_i` —
valid for small tilts about one axis at a time; with :math:`a = e^{-\Delta t/\tau}` it
is the single-axis case of the geometric filter.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .. import _validate as _v
from ..quaternion import qmul_scalar, rotate_scalar, zoh_step_scalar
from ._common import read_sensors, start_orientation
from ._complementary_angles_kernel import complementary_angles_kernel
from ._docs import shared_docs

__all__ = ["complementary", "complementary_angles"]


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


@shared_docs
def complementary_angles(
    acc, gyr, fs: float | None = None, *, a: float | None = None, tau_s: float = 1.0
) -> np.ndarray:
    r"""Estimate roll and pitch with LaCanna's per-axis complementary filter.

    For each of roll (about x) and pitch (about y),

    .. math:: \alpha_i = a\,(\alpha_{i-1} + \omega_i\,\Delta t) + (1 - a)\,
              \alpha^{acc}_i,

    with :math:`\omega` the gyroscope's x (roll) or y (pitch) rate,
    :math:`\alpha^{acc}` the accelerometer's angle (roll ``atan2(a_y, a_z)``, pitch
    ``atan2(-a_x, sqrt(a_y² + a_z²))``) and :math:`\alpha_0 = \alpha^{acc}_0`.
    Unrolled, :math:`\alpha_i = a^i\alpha_0 + \sum_{j=1}^{i} a^{i-j+1}\omega_j\Delta t
    + (1-a)\sum_{j=1}^{i} a^{i-j}\alpha^{acc}_j`: the accelerometer angle is
    low-passed by a first-order filter whose impulse response decays as
    :math:`a^{n} = e^{-n\Delta t/\tau}` for :math:`a = e^{-\Delta t/\tau}`, i.e. time
    constant :math:`\tau = -\Delta t/\ln a \approx \Delta t/(1-a)`; ``a = 1``
    integrates the gyroscope, ``a = 0`` returns the accelerometer angles. Adding a
    gyroscope rate to a fixed axis is exact only for rotations about one axis
    (small tilts otherwise); :func:`complementary` is the 3-D version, with the same
    gain :math:`1-a` per sample.

    Parameters
    ----------
    %(acc_gyr)s
    %(fs)s
    a : float, optional
        Weight of the gyroscope path, ``0 <= a <= 1`` (LaCanna: 0.9 to 1); overrides
        ``tau_s``.
    tau_s : float
        Time constant (s) giving ``a = exp(-1 / (fs tau_s))`` when ``a`` is not given;
        ``inf`` gives ``a = 1``.

    Returns
    -------
    numpy.ndarray, shape (N, 2)
        Roll and pitch (°).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab.filters.complementary import complementary_angles
    >>> acc = np.tile([0.0, 0.5, np.sqrt(3) / 2], (50, 1))  # 30 deg roll, at rest
    >>> np.round(complementary_angles(acc, np.zeros((50, 3)), 25.0)[-1], 6).tolist()
    [30.0, 0.0]
    """
    fs, acc, gyr, _, _ = read_sensors(fs, acc, gyr)
    dt = 1.0 / fs
    if a is None:
        tau_s = _v.positive(tau_s, "tau_s", allow_inf=True)
        a = float(np.exp(-dt / tau_s))
    else:
        a = float(a)
        if not 0.0 <= a <= 1.0:
            raise ValueError(f"a must lie in [0, 1], got {a!r}")
    out = np.empty((acc.shape[0], 2))
    complementary_angles_kernel(acc, gyr, dt, a, out)
    return np.degrees(out)
