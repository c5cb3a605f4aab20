r"""Quaternion-state extended Kalman filter (6D or 9D), the formulation of ``ahrs``.

The EKF predicts first and corrects with the gravity (and magnetic field) direction, so
it has no one-sample lag.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import _validate as _v
from ._common import check_tuning, init_samples, read_sensors, start_orientation, tuned
from ._ekf_kernel import EkfParams, _ekf_kernel
from ._docs import shared_docs

__all__ = ["EkfTuning", "ekf"]


class EkfTuning(NamedTuple):
    """Noise options of :func:`ekf` and their defaults (see its parameters)."""

    var_gyr: float = 0.3**2
    var_acc: float = 0.5**2
    var_mag: float = 0.8**2


def _ekf_params(t: EkfTuning, fs: float) -> EkfParams:
    """Map the (checked) noise options to the kernel's parameters."""
    return EkfParams(
        dt=1.0 / fs, var_gyr=t.var_gyr, var_acc=t.var_acc, var_mag=t.var_mag
    )


def _dip_from(acc, mag) -> float:
    """Magnetic dip (degrees, positive down) from mean accelerometer and magnetometer."""
    a = np.mean(acc, axis=0)
    mm = np.mean(mag, axis=0)
    s = np.dot(a, mm) / (np.linalg.norm(a) * np.linalg.norm(mm))
    return float(np.degrees(np.arcsin(np.clip(-s, -1.0, 1.0))))


@tuned(EkfTuning)
@shared_docs
def ekf(
    acc,
    gyr,
    fs: float | None = None,
    *,
    mag=None,
    tuning: EkfTuning,
    dip: float | None = None,
    P0=None,
    q0=None,
    init_window_s: float = 0.1,
) -> np.ndarray:
    r"""Quaternion-state extended Kalman filter (6D or 9D), ``ahrs`` formulation.

    State :math:`q` (4), prediction :math:`q_t = (I + \tfrac{\Delta t}{2}\Omega(\omega_k))
    q_{k-1}`, :math:`F = I + \Omega(\tfrac{\Delta t}{2}\omega_k)`,
    :math:`P_t = F P F^\top + \sigma_\omega^2 W W^\top` with
    :math:`W = \partial q_t/\partial\omega`. Measurement
    :math:`z = (\hat a_k, \hat m_k)`, model :math:`h(q) = (R(q)^\top e_z, R(q)^\top r)`
    (world z up, ENU magnetic reference :math:`r = (0, \cos\delta, -\sin\delta)` for
    dip :math:`\delta`), :math:`R = \mathrm{diag}(\sigma_a^2 I_3, \sigma_m^2 I_3)`,
    :math:`K = P_t H^\top (H P_t H^\top + R)^{-1}`, :math:`P = (I - K H) P_t`,
    :math:`q_k = (q_t + K(z - h))/\|\cdot\|`. As in ``ahrs``, :math:`h` is evaluated
    at the normalised and :math:`H` at the unnormalised :math:`q_t` (equal to first
    order).

    Equal to ``ahrs.filters.EKF(frame='NED', magnetic_ref=r, noises=[var_gyr, var_acc,
    var_mag], Dt=1/fs, q0=q0)``; ``ahrs``'s ``frame='ENU'`` is upside down
    (:mod:`tiltlab.filters` lists its defects).

    Parameters
    ----------
    %(acc_gyr)s
    %(fs)s
    %(mag)s
    var_gyr, var_acc, var_mag : float
        Gyroscope noise variance ((rad/s)², ``>= 0``) and measurement variances (``> 0``)
        of the unit accelerometer and magnetometer directions.
    dip : float, optional
        Magnetic dip (inclination) in degrees, positive when the field points down;
        default: measured from the first ``init_window_s`` seconds.
    P0 : array_like, shape (4, 4), optional
        Initial covariance, default identity.
    %(q0_init)s

    Returns
    -------
    numpy.ndarray, shape (N, 4)
    """
    fs, acc, gyr, m, use_mag = read_sensors(fs, acc, gyr, mag)
    tuning = check_tuning(tuning, positive=("var_acc", "var_mag"))
    n0 = init_samples(init_window_s, fs)
    if dip is not None:
        dip = _v.finite(dip, "dip")
    elif use_mag:
        dip = _dip_from(acc[:n0], m[:n0])
    d = np.radians(0.0 if dip is None else dip)
    m_ref = np.array([0.0, np.cos(d), -np.sin(d)])
    if P0 is None:
        P0 = np.eye(4)
    else:
        P0 = np.ascontiguousarray(_v.vectors(P0, "P0", width=4, ndim=2))
        if P0.shape != (4, 4):
            raise ValueError(f"P0 must have shape (4, 4), got {P0.shape}")
    q0 = start_orientation(q0, acc, m if use_mag else None, fs, init_window_s)
    out = np.empty((acc.shape[0], 4))
    params = _ekf_params(tuning, fs)
    _ekf_kernel(acc, gyr, m, use_mag, params, m_ref, P0, q0, out)
    return out
