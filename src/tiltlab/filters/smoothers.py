r"""Offline (non-causal) tilt: rest-detected gyro bias and the low-pass smoother."""

from __future__ import annotations

import numpy as np

from .. import _validate as _v
from .. import dsp
from .. import quaternion as quat
from .._deprecate import renamed
from ._common import (
    offset_vector,
    samples,
    start_orientation,
    tilt_quaternion,
    unlabel,
)
from ._docs import shared_docs

__all__ = ["rest_gyro_bias", "smoother"]


@shared_docs
def rest_gyro_bias(
    acc,
    gyr,
    fs: float | None = None,
    *,
    window_s: float = 0.5,
    threshold_rad_s: float = np.radians(2.0),
    acc_std_threshold: float = 0.2,
    min_rest_s: float = 0.5,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Gyroscope bias from detected rest periods.

    Rest is found by the one still detector, :func:`tiltlab.dsp.still_mask`: the
    angular speed :math:`\|\omega\|` averaged over a centred window of ``window_s``
    seconds below ``threshold_rad_s``, the moving standard deviation of
    :math:`\|a\|` over the same window below ``acc_std_threshold`` (units of ``acc``),
    and rest periods lasting at least ``min_rest_s`` seconds. The bias is the mean
    :math:`\omega` over the rest samples (zero when there are none).

    Parameters
    ----------
    acc : array_like or xarray.DataArray, shape (N, 3)
        Specific force (``acc_std_threshold`` is in its unit: m/s² for a labelled
        DataArray, which is converted from its ``units`` attribute, required).
    gyr : array_like or xarray.DataArray, shape (N, 3)
        Angular velocity (rad/s; a labelled DataArray is converted to rad/s from its
        ``units`` attribute, which it must have; see :mod:`tiltlab.filters`,
        "Labelled inputs").
    %(fs)s
    window_s : float
        Smoothing window (s).
    threshold_rad_s : float
        Largest mean angular speed (rad/s) at rest.
    acc_std_threshold : float
        Largest moving standard deviation of :math:`\|a\|` at rest (units of ``acc``;
        m/s² for a labelled ``acc``; the default suits m/s²).
    min_rest_s : float
        Shortest rest period kept (s).

    Returns
    -------
    bias : numpy.ndarray, shape (3,)
        In rad/s (also for a labelled ``gyr``).
    rest : numpy.ndarray of bool, shape (N,)
        The rest samples.
    """
    fs, acc, gyr, _ = unlabel(fs, acc=acc, gyr=gyr, acc_si=True)
    acc = samples(acc, "acc")
    gyr = samples(gyr, "gyr", acc.shape[0])
    window_s = _v.positive(window_s, "window_s")
    rest = dsp.still_mask(
        np.linalg.norm(gyr, axis=1),
        fs,
        threshold=_v.positive(threshold_rad_s, "threshold_rad_s"),
        smooth_s=window_s,
        acc_norm=np.linalg.norm(acc, axis=1),
        acc_std_threshold=_v.positive(acc_std_threshold, "acc_std_threshold"),
        min_duration_s=_v.nonnegative(min_rest_s, "min_rest_s"),
    )
    bias = gyr[rest].mean(axis=0) if rest.any() else np.zeros(3)
    return bias, rest


@renamed(bias="gyr_offset")
@shared_docs
def smoother(
    acc,
    gyr,
    fs: float | None = None,
    *,
    cutoff_hz: float = 0.1,
    order: int = 2,
    gyr_offset=None,
    q0=None,
) -> np.ndarray:
    r"""Smooth the tilt offline: zero-phase low-pass of the gyro-integrated specific force.

    The non-causal smoother low-passes the specific force in the gyroscope-integrated
    frame:

    1. Gyro bias :math:`b` from rest periods (:func:`rest_gyro_bias`) unless given.
    2. Strapdown integration :math:`q_g` of :math:`\omega - b` (any start). Because
       :math:`q_g = D(t) \otimes q` with a slowly drifting world-frame offset :math:`D`,
       the specific force in that frame is :math:`R(q_g)\,a = R(D)\,(g\,e_z + \ddot p)`.
    3. A forward–backward Butterworth low-pass (:func:`tiltlab.dsp.lowpass`, cut-off
       ``cutoff_hz``) removes the motion acceleration :math:`\ddot p` (its time average
       is :math:`\Delta v / T \to 0` for bounded velocity) but keeps the slow
       :math:`R(D)\,e_z`: the up direction of the drifting frame.
    4. :math:`q = C \otimes q_g` with :math:`C` the minimal rotation taking that up
       direction to :math:`e_z`; heading remains the gyroscope's (relative, drifting).

    This is the offline analogue of filtering the accelerometer in an almost-inertial
    frame (Laidig & Seel 2023); being zero phase, it has no lag. Gyro-bias states and
    motion acceleration are handled by steps 1 and 3. (Tried and rejected on BROAD:
    down-weighting samples with :math:`|\,\|a\| - g\,|` large, which biases the
    average; a least-squares refinement of :math:`b` from the corrections, no gain.)

    Parameters
    ----------
    acc : array_like or xarray.DataArray, shape (N, 3)
        Specific force in m/s² (the rest detector's threshold is in m/s²); a labelled
        DataArray is converted from its ``units`` attribute (required).
    gyr : array_like or xarray.DataArray, shape (N, 3)
        Angular velocity (rad/s); a labelled DataArray is converted from its ``units``
        attribute (required; see :mod:`tiltlab.filters`, "Labelled inputs").
    %(fs)s
    cutoff_hz : float
        Cut-off (Hz) of the low-pass: below the motion frequencies, above the drift of
        :math:`D` (bias residual, gyro scale errors).
    order : int
        Butterworth order of each pass.
    gyr_offset : array_like, shape (3,), optional
        Known gyroscope offset (bias; rad/s, whatever the units of a labelled
        ``gyr``); default :func:`rest_gyro_bias`. Formerly ``bias`` (still accepted,
        with a FutureWarning).
    q0 : array_like, shape (4,), optional
        Start of the integration (fixes the heading origin); default identity.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
    """
    fs, acc, gyr, _ = unlabel(fs, acc=acc, gyr=gyr, acc_si=True)
    acc = samples(acc, "acc")
    gyr = samples(gyr, "gyr", acc.shape[0])
    if gyr_offset is None:
        b = rest_gyro_bias(acc, gyr, fs)[0]
    else:
        b = offset_vector(gyr_offset)
    w = gyr - b
    q0 = quat.identity() if q0 is None else start_orientation(q0, acc, None, fs, 0.0)
    # filters' indexing: q[k] = q[k-1] ⊗ exp(ω_k Δt / 2)
    qg = quat.integrate_gyro(np.vstack([w[1:], w[-1:]]), fs, q0)
    ag = dsp.lowpass(quat.rotate(qg, acc), fs, cutoff_hz, order=order, name="acc")
    n = np.linalg.norm(ag, axis=1, keepdims=True)
    if np.any(n == 0):
        raise ValueError("the low-passed acceleration vanishes; no tilt can be defined")
    return quat.mul(tilt_quaternion(ag / n), qg)
