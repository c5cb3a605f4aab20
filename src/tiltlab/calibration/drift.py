r"""Gyroscope drift: integrated static angles, LaCanna's three corrections, Allan deviation.

A static gyroscope with offset :math:`b` integrates to an angle growing linearly,
:math:`\theta(t) = b\,t` (+ noise). LaCanna (2018) [1]_ found the drift of MetaWear
C-Pro gyroscopes linear within a run but different between axes, devices and days, and
compared three corrections:

1. ``"first_window"`` — the slope measured over the first 30 s of the run is removed
   at every integration step;
2. ``"linear_fit"`` — a straight line fitted to the whole integrated angle is removed
   (post-processing only);
3. ``"prior"`` — a slope measured in an earlier calibration run is removed.

Drift arithmetic: a rate error of :math:`\epsilon` °/s accumulates
:math:`3600\,\epsilon` ° per hour (:func:`deg_per_hour`; LaCanna: 0.9539 °/s →
3434 °/h, 0.004718 °/s → 16.99 °/h).

Beyond the thesis, the Allan deviation of a long static record separates white rate
noise (angle random walk N: slope −1/2, read at τ = 1 s), bias instability (the flat
minimum, :math:`B = \sigma_{min}/0.664`) and rate random walk (slope +1/2, K read at
τ = 3 s) [2]_.

References
----------
.. [1] C. Q. LaCanna, "Inertial measurement units for tracking human pose and motions:
   testing and calibration", MSc thesis, Rutgers University, 2018.
.. [2] IEEE Std 952-1997, "IEEE standard specification format guide and test procedure
   for single-axis interferometric fiber optic gyros", Annex C (Allan variance).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ._util import CalibrationError, check_fs, vec3

__all__ = [
    "deg_per_hour",
    "integrate_rate",
    "drift_slope",
    "DriftCorrection",
    "correct_drift",
    "allan_deviation",
    "AllanNoise",
    "allan_noise_parameters",
]


def deg_per_hour(rate_deg_s) -> np.ndarray:
    """Angle accumulated in one hour (°) by a constant rate error (°/s): ``3600 × rate``."""
    return np.asarray(rate_deg_s, dtype=float) * 3600.0


def integrate_rate(gyr, fs: float) -> np.ndarray:
    r"""Per-axis integrated angle (°) of a rate (°/s), :math:`\theta_k = \sum_{j<k}\omega_j/f_s`, θ₀ = 0.

    This is LaCanna's per-axis rectangular integration (Appendix A); it is an angle only
    for small rotations about fixed axes (static drift tests).
    """
    fs = check_fs(fs)
    g = vec3(gyr, "gyr", ndim=2)
    out = np.zeros_like(g)
    np.cumsum(g[:-1] / fs, axis=0, out=out[1:])
    return out


def drift_slope(angle, fs: float, *, start_s: float = 0.0, stop_s: float | None = None) -> np.ndarray:
    """Least-squares slope (°/s) of an integrated angle over ``[start_s, stop_s)``, per axis."""
    fs = check_fs(fs)
    th = vec3(angle, "angle", ndim=2)
    a = int(round(start_s * fs))
    b = th.shape[0] if stop_s is None else int(round(stop_s * fs))
    if b - a < 2:
        raise CalibrationError("fewer than two samples in the slope window")
    t = np.arange(a, b) / fs
    tc = t - t.mean()
    seg = th[a:b]
    return tc @ (seg - seg.mean(axis=0)) / (tc @ tc)


class DriftCorrection(NamedTuple):
    """``angle`` (N, 3) corrected integrated angle (°), ``slope`` (3,) removed rate (°/s),
    ``method``."""

    angle: np.ndarray
    slope: np.ndarray
    method: str


def correct_drift(gyr, fs: float, method: str = "first_window", *, window_s: float = 30.0, prior=None) -> DriftCorrection:
    """Integrate a gyroscope and remove a linear drift by one of LaCanna's three methods.

    Parameters
    ----------
    gyr : array_like (N, 3)
        Angular velocity (°/s).
    fs : float
        Sampling rate (Hz).
    method : {"first_window", "linear_fit", "prior", "none"}
        See the module docstring.
    window_s : float
        Length of the initial still window for ``"first_window"`` (s).
    prior : array_like (3,)
        Drift rate (°/s) from an earlier calibration, for ``"prior"``.
    """
    fs = check_fs(fs)
    g = vec3(gyr, "gyr", ndim=2)
    th = integrate_rate(g, fs)
    if method == "none":
        slope = np.zeros(3)
    elif method == "first_window":
        if window_s * fs > g.shape[0]:
            raise CalibrationError(f"record ({g.shape[0] / fs:.1f} s) shorter than the {window_s} s drift window")
        slope = drift_slope(th, fs, stop_s=window_s)
    elif method == "linear_fit":
        slope = drift_slope(th, fs)
    elif method == "prior":
        if prior is None:
            raise ValueError("method 'prior' needs the prior drift rate (°/s)")
        slope = vec3(prior, "prior", ndim=1)
    else:
        raise ValueError(f"unknown method {method!r}")
    t = np.arange(g.shape[0])[:, None] / fs
    return DriftCorrection(th - t * slope, np.asarray(slope, float), method)


def allan_deviation(rate, fs: float, taus=None, *, n_taus: int = 40) -> tuple[np.ndarray, np.ndarray]:
    r"""Overlapping Allan deviation of a rate signal.

    .. math:: \sigma^2(\tau) = \frac{1}{2\tau^2 (N - 2m)} \sum_{k=0}^{N-2m-1}
              (\theta_{k+2m} - 2\theta_{k+m} + \theta_k)^2,\qquad \tau = m/f_s,

    with :math:`\theta` the cumulative integral of the rate.

    Parameters
    ----------
    rate : array_like (N,) or (N, 3)
    fs : float
    taus : array_like, optional
        Averaging times (s); default ``n_taus`` log-spaced values from 1/fs to N/(10 fs).

    Returns
    -------
    taus : ndarray (K,)
        Averaging times actually used (rounded to whole samples, unique).
    adev : ndarray (K,) or (K, 3)
        Allan deviation in the units of ``rate``.
    """
    fs = check_fs(fs)
    x = np.asarray(rate, dtype=float)
    one = x.ndim == 1
    x = x.reshape(x.shape[0], -1)
    n = x.shape[0]
    if n < 20:
        raise CalibrationError("record too short for an Allan deviation")
    if taus is None:
        m = np.unique(np.round(np.logspace(0, np.log10(max(n // 10, 2)), n_taus)).astype(np.int64))
    else:
        m = np.unique(np.round(np.asarray(taus, float) * fs).astype(np.int64))
        m = m[(m >= 1) & (m <= (n - 1) // 2)]
    theta = np.vstack([np.zeros((1, x.shape[1])), np.cumsum(x, axis=0) / fs])
    out = np.empty((m.size, x.shape[1]))
    for i, mi in enumerate(m):
        d = theta[2 * mi:] - 2 * theta[mi:-mi] + theta[: -2 * mi]
        tau = mi / fs
        out[i] = np.sqrt(np.mean(d * d, axis=0) / (2 * tau * tau))
    return m / fs, out[:, 0] if one else out


class AllanNoise(NamedTuple):
    """``arw`` angle random walk (rate unit·√s, e.g. °/√s — equal to the white-noise
    density in °/s/√Hz), ``bias_instability`` (rate unit), ``tau_min`` (s, where the
    deviation is smallest), ``rrw`` rate random walk (rate unit/√s, NaN if no +1/2 slope)."""

    arw: np.ndarray
    bias_instability: np.ndarray
    tau_min: np.ndarray
    rrw: np.ndarray


def allan_noise_parameters(taus, adev) -> AllanNoise:
    """Read the IEEE-952 noise terms off an Allan deviation curve.

    ARW: median of σ(τ)√τ over the points where the local log-log slope is within
    ±0.15 of −1/2; bias instability: min σ / 0.664; RRW: median of σ(τ)√(3/τ) where the
    slope is within ±0.15 of +1/2.
    """
    t = np.asarray(taus, float)
    a = np.asarray(adev, float)
    one = a.ndim == 1
    a = a.reshape(t.size, -1)
    lt, la = np.log(t), np.log(a)
    slope = np.gradient(la, lt, axis=0)
    arw, bi, tmin, rrw = [], [], [], []
    for j in range(a.shape[1]):
        sel = np.abs(slope[:, j] + 0.5) < 0.15
        arw.append(np.median(a[sel, j] * np.sqrt(t[sel])) if sel.any() else np.nan)
        k = int(np.argmin(a[:, j]))
        bi.append(a[k, j] / np.sqrt(2 * np.log(2) / np.pi))
        tmin.append(t[k])
        sel = np.abs(slope[:, j] - 0.5) < 0.15
        rrw.append(np.median(a[sel, j] * np.sqrt(3.0 / t[sel])) if sel.any() else np.nan)
    f = (lambda v: float(v[0])) if one else np.array
    return AllanNoise(f(arw), f(bi), f(tmin), f(rrw))
