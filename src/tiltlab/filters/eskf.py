r"""Causal error-state Kalman filter (6D or 9D): attitude and gyro bias.

Nominal state :math:`(q, b)`, error state :math:`(\delta\theta, \delta b)` with the attitude
error in the world frame; accelerometer-direction update with an adaptive variance and a
heading-only magnetometer update (Solà 2017; the ESKF baseline of Zaheer et al. 2023).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._deprecate import renamed
from ._common import (
    check_tuning,
    offset_vector,
    read_sensors,
    start_orientation,
    tuned,
)
from ._eskf_kernel import EskfParams, _eskf_kernel
from ._docs import shared_docs

__all__ = ["EskfTuning", "eskf"]

#: standard gravity (m/s²), the reference of the adaptive accelerometer variance
STANDARD_GRAVITY = 9.80665


class EskfTuning(NamedTuple):
    """Tuning options of :func:`eskf` and their defaults (see its parameters)."""

    gyr_noise: float = 5e-3
    bias_noise: float = 1e-4
    acc_noise: float = 0.2
    norm_gain: float = 10.0
    mag_noise: float = 0.2
    bias_std: float = float(np.radians(1.0))
    tilt_std: float = float(np.radians(2.0))
    heading_std: float = float(np.radians(10.0))


def _eskf_params(t: EskfTuning, fs: float) -> EskfParams:
    """Map the (checked) tuning options to the kernel's parameters (per sample)."""
    dt = 1.0 / fs
    return EskfParams(
        dt=dt,
        q_gyr=t.gyr_noise**2 * dt,
        q_bias=t.bias_noise**2 * dt,
        var_acc=t.acc_noise**2,
        norm_gain=t.norm_gain,
        grav=STANDARD_GRAVITY,
        var_mag=t.mag_noise**2,
    )


def _eskf_covariance(t: EskfTuning, use_mag: bool) -> np.ndarray:
    """Build the initial covariance from the tuning's standard deviations.

    Parameters
    ----------
    t : EskfTuning
        The checked tuning options.
    use_mag : bool
        9D (without a magnetometer the heading variance is zero).

    Returns
    -------
    numpy.ndarray, shape (6, 6)
        Diagonal :math:`P_0`.
    """
    heading = t.heading_std**2 if use_mag else 0.0
    return np.diag([t.tilt_std**2, t.tilt_std**2, heading] + [t.bias_std**2] * 3)


@renamed(b0="gyr_offset")
@tuned(EskfTuning)
@shared_docs
def eskf(
    acc,
    gyr,
    fs: float | None = None,
    *,
    mag=None,
    tuning: EskfTuning,
    q0=None,
    gyr_offset=None,
    init_window_s: float = 0.1,
    return_bias: bool = False,
):
    r"""Causal error-state Kalman filter (ESKF) of attitude and gyro bias, 6D or 9D.

    The ESKF baseline of Zaheer et al. [2]_ in the formulation of Solà [1]_, with the
    attitude error in the **world** frame ("global" error, Solà §7):
    :math:`q_{true} = \mathrm{Exp}(\delta\theta) \otimes q`, :math:`b_{true} = b + \delta b`.

    Parameters
    ----------
    acc : array_like or xarray.DataArray, shape (N, 3)
        Specific force in **m/s²** (its direction is the measurement; its norm drives the
        adaptive variance against standard gravity 9.80665 m/s²). A labelled
        DataArray is converted from its ``units`` attribute (required: e.g. ``"g"``)
        to m/s².
    gyr : array_like or xarray.DataArray, shape (N, 3)
        Angular velocity (rad/s). A labelled DataArray is converted from its
        ``units`` attribute (required: e.g. ``"deg/s"``) to rad/s (see
        :mod:`tiltlab.filters`, "Labelled inputs").
    %(fs)s
    mag : array_like or xarray.DataArray, shape (N, 3), optional
        Magnetometer (any unit; a ``units`` attribute must be a magnetic-field unit):
        9D with a heading-only update, ENU world frame (x east, y magnetic north,
        z up).
    gyr_noise : float
        Gyroscope angular random walk σ_ω (rad/√s), ``>= 0``.
    bias_noise : float
        Gyro-bias random walk σ_b (rad/s/√s), ``>= 0``.
    acc_noise : float
        Per-sample standard deviation σ_a (1, ≈ rad) of the unit accelerometer direction
        at ‖a‖ = g, ``> 0``. The default 0.2 (formerly 0.05) because body accelerations
        that leave ‖a‖ near g pulled the tilt off at 0.05: 43° of tilt RMSE on BROAD's
        fast translation and combined trials against 19° at 0.2, and lower errors on
        every data set with a reference (``benchmarks/bench_defaults.py``; the
        conventions page, "Default parameters").
    norm_gain : float
        κ of the adaptive accelerometer variance, ``>= 0`` (0: not adaptive).
    mag_noise : float
        Per-sample standard deviation σ_ψ (rad) of the magnetic heading, ``> 0``.
    bias_std : float
        Initial standard deviation of the gyro bias (rad/s), ``>= 0``.
    tilt_std, heading_std : float
        Initial standard deviations (rad) of the attitude error about the horizontal
        axes and about world z, ``>= 0``; without magnetometer the heading is relative
        to the start and its initial variance is zero.
    q0 : array_like, shape (4,), optional
        Initial orientation; default :func:`initial_orientation` over
        ``init_window_s`` seconds (with ``mag``: TRIAD, ENU).
    %(offset_bias)s

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Unit quaternions sensor → world, scalar first; with ``return_bias`` a tuple
        ``(q, b)``.

    Notes
    -----
    Indexing as the other filters: ``q[0] = q0``, and sample :math:`k` takes
    :math:`k-1 \to k`.

    **Prediction** (zero-order hold) with :math:`R = R(q_k)`:

    .. math::
        q_k = q_{k-1} \otimes \mathrm{Exp}\big((\omega_k - b)\,\Delta t\big),\qquad
        P \leftarrow F P F^\top + Q,\quad
        F = \begin{pmatrix} I & -R\,\Delta t \\ 0 & I \end{pmatrix},\quad
        Q = \Delta t\,\mathrm{diag}(\sigma_\omega^2 I_3, \sigma_b^2 I_3)

    (world-frame gyro noise :math:`R\,\sigma_\omega^2 I\,R^\top = \sigma_\omega^2 I`).

    **Accelerometer** (three sequential scalar updates, exact for diagonal noise):
    :math:`\hat a_k = a_k/\|a_k\| = R^\top e_z + \nu`, Jacobian
    :math:`H = [R^\top [e_z]_\times,\ 0]` (from :math:`R_{true}^\top e_z \approx
    R^\top e_z + R^\top [e_z]_\times \delta\theta`), variance

    .. math::
        \sigma_a^2 \Big(1 + \big(\kappa\,(\|a_k\| - g)/g\big)^2\Big),

    so that samples with linear acceleration are down-weighted. The heading component
    :math:`\delta\theta_z` is unobservable from gravity.

    **Magnetometer** (heading only): with the field rotated into the corrected world
    frame, :math:`m^w = R\,m_k`, the heading innovation is
    :math:`\psi = \mathrm{atan2}(m^w_x, m^w_y)` (:math:`m^w \approx m_{ENU} - \delta\theta
    \times m_{ENU}`, so :math:`\psi \approx \delta\theta_z`), i.e. :math:`H = e_3^\top`,
    variance :math:`\sigma_\psi^2`. The gain on the tilt components is set to zero
    (:math:`K_{\theta_x} = K_{\theta_y} = 0`) so that magnetic disturbances never tilt
    the estimate; the gain on :math:`\delta\theta_z` and :math:`\delta b` is the Kalman
    gain. No reference field (dip, strength) is needed. Skipped when the field is
    vertical.

    **Covariance update**: Joseph form, valid for any gain,
    :math:`P \leftarrow (I - K H) P (I - K H)^\top + K V K^\top`.

    **Injection and reset** after each sensor's update:
    :math:`q \leftarrow \mathrm{Exp}(\delta\theta) \otimes q`,
    :math:`b \leftarrow b + \delta b`, :math:`\delta x \leftarrow 0`; the reset Jacobian
    of this global (left-multiplied) error, :math:`G = I + [\tfrac12 \delta\theta]_\times`
    (the local error of Solà's text has the opposite sign), is taken as :math:`I` (first
    order).

    Initial covariance :math:`P_0 = \mathrm{diag}(\sigma_{tilt}^2, \sigma_{tilt}^2,
    \sigma_{head}^2, \sigma_{b0}^2 I_3)` (:math:`\sigma_{head} = 0` in 6D). In 6D the
    bias component along gravity is observable only as the sensor's attitude changes.

    References
    ----------
    .. [1] J. Solà, "Quaternion kinematics for the error-state Kalman filter",
       arXiv:1711.02508, 2017.
    .. [2] M. H. Zaheer, S. Y. Yoon and B. K. Higginson, "Orientation estimation for
       instrumented helmet using neural networks", Measurement and Control
       56(7-8):1156-1167, 2023. doi:10.1177/00202940221149062
    """
    fs, acc, gyr, m, use_mag = read_sensors(fs, acc, gyr, mag, acc_si=True)
    tuning = check_tuning(tuning, positive=("acc_noise", "mag_noise"))
    b0 = offset_vector(gyr_offset)
    q0 = start_orientation(q0, acc, m if use_mag else None, fs, init_window_s)
    out_q = np.empty((acc.shape[0], 4))
    out_b = np.empty((acc.shape[0], 3))
    params = _eskf_params(tuning, fs)
    P0 = _eskf_covariance(tuning, use_mag)
    _eskf_kernel(acc, gyr, m, use_mag, params, q0, b0, P0, out_q, out_b)
    return (out_q, out_b) if return_bias else out_q
