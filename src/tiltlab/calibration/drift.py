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

His Discussion proposes combining the prior with a linear fit of the drift left over the
run; ``"combined"`` implements it in real time (see :func:`correct_drift`).

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

import dataclasses
from typing import NamedTuple

import numpy as np
import pandas as pd
import xarray as xr

from .. import _validate as _v
from ._util import CalibrationError, read_in, vec3

__all__ = [
    "deg_per_hour",
    "integrate_rate",
    "drift_slope",
    "running_slope",
    "hold_changes",
    "DriftCorrection",
    "correct_drift",
    "drift_error_table",
    "allan_deviation",
    "AllanNoise",
    "allan_noise_parameters",
]

_METHODS = ("first_window", "linear_fit", "prior", "combined", "none")


def deg_per_hour(rate_deg_s) -> np.ndarray:
    """Angle accumulated in one hour (°) by a constant rate error (°/s): ``3600 × rate``.

    Parameters
    ----------
    rate_deg_s : array_like
        Rate error(s) (°/s), any shape.

    Returns
    -------
    numpy.ndarray of float
        Accumulated angle (°) after one hour, shape of ``rate_deg_s``.
    """
    return np.asarray(rate_deg_s, dtype=float) * 3600.0


def _integrate(g: np.ndarray, fs: float) -> np.ndarray:
    out = np.zeros_like(g)
    np.cumsum(g[:-1] / fs, axis=0, out=out[1:])
    return out


def integrate_rate(gyr, fs: float | None = None, *, units: str | None = None):
    r"""Integrate a rate per axis into an angle (°).

    Per-axis integrated angle (°) of a rate, :math:`\theta_k = \sum_{j<k}\omega_j/f_s`,
    θ₀ = 0.

    This is LaCanna's per-axis rectangular integration (Appendix A); it is an angle only
    for small rotations about fixed axes (static drift tests).

    Parameters
    ----------
    gyr : Recording, DataArray or array_like (N, 3)
        Angular velocity (a Recording's ``gyr``); labelled input carries its units, a
        plain array is in ``units`` (default °/s).
    fs : float, optional
        Sampling rate (Hz); read from the attrs of labelled input, mandatory for a
        plain array.
    units : str, optional
        Units of a plain-array ``gyr`` (``"deg/s"`` if not given).

    Returns
    -------
    ndarray or DataArray (N, 3)
        Angle in degrees (a DataArray with ``units="deg"`` for labelled input).
    """
    s, _ = read_in(gyr, "gyr", "deg/s", fs=fs, units=units)
    return _v.labelled(_integrate(s.values, s.fs), s, "angle", units="deg")


def _read_angle(angle, fs):
    # an integrated angle carries units "deg" (not a Recording unit): read fs and values
    if isinstance(angle, xr.DataArray) and "units" in angle.attrs:
        units = angle.attrs["units"]
        angle = angle.copy(deep=False)
        angle.attrs = {k: v for k, v in angle.attrs.items() if k != "units"}
        s = _v.signal(angle, "angle", fs=fs)
        return dataclasses.replace(s, attrs={**s.attrs, "units": units})
    return _v.signal(angle, "angle", fs=fs)


def _slope(
    th: np.ndarray, fs: float, start_s: float, stop_s: float | None
) -> np.ndarray:
    a = int(round(start_s * fs))
    b = th.shape[0] if stop_s is None else int(round(stop_s * fs))
    if b - a < 2:
        raise CalibrationError(
            f"fewer than two samples in the slope window [start_s = {start_s:g} s, "
            f"stop_s = {stop_s!r} s) at fs = {fs:g} Hz"
        )
    t = np.arange(a, b) / fs
    tc = t - t.mean()
    seg = th[a:b]
    return tc @ (seg - seg.mean(axis=0)) / (tc @ tc)


def drift_slope(
    angle, fs: float | None = None, *, start_s: float = 0.0, stop_s: float | None = None
) -> np.ndarray:
    """Least-squares slope of an integrated angle over ``[start_s, stop_s)``, per axis.

    Parameters
    ----------
    angle : DataArray or array_like (N, 3)
        Integrated angle (e.g. :func:`integrate_rate`, in °).
    fs : float, optional
        Sampling rate (Hz); read from the attrs of labelled input, mandatory for a
        plain array.
    start_s, stop_s : float
        Window (s from the first sample); ``stop_s=None``: to the end.

    Returns
    -------
    ndarray (3,)
        Slope in the angle's unit per second (°/s for an angle in °).
    """
    s = _read_angle(angle, fs)
    start_s = _v.nonnegative(start_s, "start_s")
    if stop_s is not None:
        stop_s = _v.positive(stop_s, "stop_s")
    return _slope(s.values, s.fs, start_s, stop_s)


def _running_slope(th: np.ndarray, fs: float) -> np.ndarray:
    # least-squares slope (with intercept) of th[0..k] against t for every k; NaN at k=0
    n = np.arange(1, th.shape[0] + 1, dtype=float)[:, None]
    t = (np.arange(th.shape[0]) / fs)[:, None]
    st, stt = np.cumsum(t, axis=0), np.cumsum(t * t, axis=0)
    sr, str_ = np.cumsum(th, axis=0), np.cumsum(t * th, axis=0)
    den = n * stt - st * st
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, (n * str_ - st * sr) / den, np.nan)


def running_slope(angle, fs: float | None = None) -> np.ndarray:
    r"""Least-squares slope of an integrated angle over ``[0, t_k]``, for every sample k.

    The expanding-window fit a real-time system can compute at each sample (cumulative
    sums, one pass): :math:`\hat s_k = (n S_{tr} - S_t S_r)/(n S_{tt} - S_t^2)` with the
    sums over samples ``0..k`` (``n = k + 1``). At the last sample it equals
    :func:`drift_slope` over the whole record.

    Parameters
    ----------
    angle : DataArray or array_like (N, 3)
        Integrated angle (e.g. :func:`integrate_rate`, in °).
    fs : float, optional
        Sampling rate (Hz); read from the attrs of labelled input, mandatory for a
        plain array.

    Returns
    -------
    ndarray (N, 3)
        Slope in the angle's unit per second; NaN at the first sample (one point has
        no slope).
    """
    s = _read_angle(angle, fs)
    return _running_slope(s.values, s.fs)


def hold_changes(angle, fs: float | None = None, *, holds) -> np.ndarray:
    """Change of the mean angle between consecutive still holds (a rotation test).

    LaCanna (2018) rotated the sensor by 1 rad and read the "height" of the integrated
    angle after each rotation (his Table 5). Here each hold's angle is its mean over the
    hold, and the change is the difference between consecutive holds.

    Parameters
    ----------
    angle : DataArray or array_like (N, 3)
        Integrated (drift-corrected) angle, e.g. :func:`correct_drift`'s ``angle`` (°).
    fs : float, optional
        Sampling rate (Hz), read as by :func:`drift_slope` (only checked here: the holds
        are in samples).
    holds : array_like of int, shape (K, 2)
        Half-open sample intervals ``[start, stop)`` of the holds, in time order,
        ``K >= 2``.

    Returns
    -------
    ndarray (K - 1, 3)
        Mean angle of hold ``k + 1`` minus that of hold ``k``, in the angle's unit.
    """
    s = _read_angle(angle, fs)
    h = np.asarray(holds)
    if h.ndim != 2 or h.shape[1] != 2 or h.shape[0] < 2:
        raise ValueError(f"holds must have shape (K, 2) with K >= 2, got {h.shape}")
    if not np.issubdtype(h.dtype, np.integer):
        raise ValueError("holds must hold integer sample indices")
    n = s.values.shape[0]
    if np.any(h[:, 0] < 0) or np.any(h[:, 1] > n) or np.any(h[:, 1] <= h[:, 0]):
        raise ValueError(
            f"holds must be non-empty intervals [start, stop) within the {n} samples"
        )
    if np.any(h[1:, 0] < h[:-1, 1]):
        raise ValueError("holds must be in time order and must not overlap")
    means = np.array([s.values[a:b].mean(axis=0) for a, b in h])
    return np.diff(means, axis=0)


class DriftCorrection(NamedTuple):
    """Result of :func:`correct_drift`.

    ``angle`` (N, 3) corrected integrated angle (°; a DataArray for labelled input),
    ``slope`` (3,) removed rate (°/s), ``method``.
    """

    angle: np.ndarray
    slope: np.ndarray
    method: str


def correct_drift(
    gyr,
    fs: float | None = None,
    *,
    method: str = "first_window",
    window_s: float = 30.0,
    prior_deg_s=None,
    units: str | None = None,
) -> DriftCorrection:
    r"""Integrate a gyroscope and remove a linear drift by one of LaCanna's methods.

    ``"first_window"``, ``"linear_fit"`` and ``"prior"`` remove one slope
    :math:`s` from the integrated angle, :math:`\theta_k - t_k s`. ``"combined"`` is the
    combination LaCanna's Discussion proposes (a prior calibration, then a linear fit of
    the drift left over the run), done in real time: the prior :math:`p` is removed, and
    once ``window_s`` of data are in, the slope :math:`\hat r_k` of a least-squares line
    fitted to the residual :math:`\theta - t\,p` over ``[0, t_k]``
    (:func:`running_slope`) is removed too,

    .. math:: \theta^{c}_k = \theta_k - t_k\,p - t_k\,\hat r_k \quad (t_k \ge
              \text{window\_s}), \qquad \theta^{c}_k = \theta_k - t_k\,p
              \quad\text{before}.

    Each corrected sample uses only data up to it. A least-squares slope is linear in
    the data, so :math:`p + \hat r_k` is the running slope of :math:`\theta` itself:
    the prior matters only before ``window_s``, and the last sample equals the
    ``"linear_fit"`` result (a whole-record post-processed combination would equal the
    linear fit everywhere). A drift that is exactly linear is removed exactly from
    ``window_s`` on, whatever the prior.

    Parameters
    ----------
    gyr, fs
        Angular velocity and sampling rate (Hz), read as by :func:`integrate_rate`,
        which integrates them.
    method : {"first_window", "linear_fit", "prior", "combined", "none"}
        See the module docstring and above.
    window_s : float
        Length of the initial still window for ``"first_window"``, and the data needed
        before ``"combined"`` trusts its running fit (s).
    prior_deg_s : array_like (3,)
        Drift rate (°/s) from an earlier calibration, for ``"prior"`` and
        ``"combined"``.
    units : str, optional
        Units of a plain-array ``gyr`` (default °/s), as in :func:`integrate_rate`.

    Returns
    -------
    DriftCorrection
        The corrected integrated angle (°), the removed slope (°/s; for
        ``"combined"`` the slope removed at the last sample) and the method.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import calibration
    >>> gyr = np.tile([0.3, -0.9, 0.8], (2500, 1))  # a static gyroscope, deg/s
    >>> c = calibration.correct_drift(
    ...     gyr, 25.0, method="combined", prior_deg_s=[0.25, -0.95, 0.8]
    ... )
    >>> np.round(c.slope, 6).tolist(), float(np.abs(c.angle[-1]).max()) < 1e-9
    ([0.3, -0.9, 0.8], True)
    """
    s, _ = read_in(gyr, "gyr", "deg/s", fs=fs, units=units)
    g, fs = s.values, s.fs
    if method not in _METHODS:
        raise ValueError(f"method must be one of {', '.join(_METHODS)}; got {method!r}")
    window_s = _v.positive(window_s, "window_s")
    th = _integrate(g, fs)
    t = np.arange(g.shape[0])[:, None] / fs
    if method == "combined":
        return _combined(th, t, s, fs, window_s, prior_deg_s)
    if method == "none":
        slope = np.zeros(3)
    elif method == "first_window":
        if window_s * fs > g.shape[0]:
            raise CalibrationError(
                f"the record ({g.shape[0] / fs:.1f} s) is shorter than the drift window "
                f"window_s = {window_s:g} s"
            )
        slope = _slope(th, fs, 0.0, window_s)
    elif method == "linear_fit":
        slope = _slope(th, fs, 0.0, None)
    else:  # "prior"
        slope = _prior(prior_deg_s, method)
    angle = _v.labelled(th - t * slope, s, "angle", units="deg")
    return DriftCorrection(angle, np.asarray(slope, float), method)


def _prior(prior_deg_s, method: str) -> np.ndarray:
    if prior_deg_s is None:
        raise ValueError(
            f"method {method!r} needs prior_deg_s, the drift rate (°/s) from an earlier "
            "calibration"
        )
    return vec3(prior_deg_s, "prior_deg_s", ndim=1)


def _combined(th, t, s, fs, window_s, prior_deg_s) -> DriftCorrection:
    # prior removed, then the running least-squares slope of the residual once
    # window_s of data are in (real time: sample k uses samples 0..k only)
    prior = _prior(prior_deg_s, "combined")
    k0 = int(round(window_s * fs))
    if k0 >= th.shape[0]:
        raise CalibrationError(
            f"the record ({th.shape[0] / fs:.1f} s) is shorter than window_s = "
            f"{window_s:g} s, after which the combined method fits the residual drift"
        )
    resid = th - t * prior
    r = _running_slope(resid, fs)
    r[: max(k0, 1)] = 0.0
    angle = _v.labelled(resid - t * r, s, "angle", units="deg")
    return DriftCorrection(angle, prior + r[-1], "combined")


def drift_error_table(angles, fs: float, *, at_s=(60.0, 600.0)) -> pd.DataFrame:
    """Tabulate the angle left by drift corrections of a static record (the truth is 0).

    Parameters
    ----------
    angles : mapping str → array_like (N, 3)
        Corrected integrated angles (°) by method name, e.g. the ``angle`` of
        :func:`correct_drift`; all of the same length.
    fs : float
        Sampling rate (Hz).
    at_s : sequence of float
        Times (s from the first sample) at which the error is read, within the record.

    Returns
    -------
    pandas.DataFrame
        One row per method: the largest |angle| over the axes at each time in ``at_s``
        and at the last sample, the largest over the record, and the RMS over samples
        and axes (°); ``units`` and ``long_name`` in ``attrs``.
    """
    fs = _v.positive(fs, "fs")
    if not angles:
        raise ValueError("angles must name at least one corrected angle")
    arrs = {k: vec3(v, f"angles[{k!r}]", ndim=2) for k, v in angles.items()}
    n = {a.shape[0] for a in arrs.values()}
    if len(n) != 1:
        raise ValueError(f"angles must all have the same length, got {sorted(n)}")
    n = n.pop()
    idx = [int(round(t * fs)) for t in at_s]
    if any(i < 0 or i >= n for i in idx):
        raise ValueError(f"at_s must lie within the record (0 to {(n - 1) / fs:g} s)")
    cols = [f"at {t:g} s" for t in at_s] + ["at end", "max", "rms"]
    rows = {
        k: [*(np.abs(a[i]).max() for i in idx), np.abs(a[-1]).max(), np.abs(a).max()]
        + [float(np.sqrt(np.mean(a * a)))]
        for k, a in arrs.items()
    }
    df = pd.DataFrame.from_dict(rows, orient="index", columns=cols).rename_axis(
        "method"
    )
    long = [f"largest |angle| over the axes {c}" for c in cols[:-2]]
    df.attrs = {
        "units": dict.fromkeys(cols, "deg"),
        "long_name": dict(
            zip(cols, [*long, "largest |angle| over the record", "RMS angle"])
        ),
    }
    return df


def allan_deviation(
    rate,
    fs: float | None = None,
    *,
    taus_s=None,
    n_taus: int = 40,
    var: str = "gyr",
) -> tuple[np.ndarray, np.ndarray]:
    r"""Overlapping Allan deviation of a rate signal.

    .. math:: \sigma^2(\tau) = \frac{1}{2\tau^2 (N - 2m)} \sum_{k=0}^{N-2m-1}
              (\theta_{k+2m} - 2\theta_{k+m} + \theta_k)^2,\qquad \tau = m/f_s,

    with :math:`\theta` the cumulative integral of the rate.

    Parameters
    ----------
    rate : Recording, DataArray or array_like (N,) or (N, 3)
        The rate (for a Recording, its variable ``var``).
    fs : float, optional
        Sampling rate (Hz); read from the attrs of labelled input, mandatory for a
        plain array.
    taus_s : array_like, optional
        Averaging times (s); default ``n_taus`` log-spaced values from 1/fs to N/(10 fs).
    n_taus : int
        Number of default averaging times.
    var : str
        Variable read from a Recording.

    Returns
    -------
    taus : ndarray (K,)
        Averaging times actually used (s; rounded to whole samples, unique).
    adev : ndarray (K,) or (K, 3)
        Allan deviation in the units of ``rate``.
    """
    s = _v.signal(rate, "rate", var=var, fs=fs, width=None, ndim=None)
    fs, x = s.fs, s.values
    if x.ndim not in (1, 2):
        raise ValueError(f"rate must have shape (N,) or (N, k), got {x.shape}")
    n_taus = _v.integer(n_taus, "n_taus", minimum=1)
    one = x.ndim == 1
    x = x.reshape(x.shape[0], -1)
    n = x.shape[0]
    if n < 20:
        raise CalibrationError(
            f"the record ({n} samples) is too short for an Allan deviation (needs 20)"
        )
    if taus_s is None:
        m = np.logspace(0, np.log10(max(n // 10, 2)), n_taus)
        m = np.unique(np.round(m).astype(np.int64))
    else:
        t = _v.vectors(taus_s, "taus_s", width=None, ndim=None).ravel()
        if np.any(t <= 0):
            raise ValueError(f"taus_s must be positive durations (s), got {t[t <= 0]}")
        m = np.unique(np.round(t * fs).astype(np.int64))
        m = m[(m >= 1) & (m <= (n - 1) // 2)]
    theta = np.vstack([np.zeros((1, x.shape[1])), np.cumsum(x, axis=0) / fs])
    out = np.empty((m.size, x.shape[1]))
    for i, mi in enumerate(m):
        d = theta[2 * mi :] - 2 * theta[mi:-mi] + theta[: -2 * mi]
        tau = mi / fs
        out[i] = np.sqrt(np.mean(d * d, axis=0) / (2 * tau * tau))
    return m / fs, out[:, 0] if one else out


class AllanNoise(NamedTuple):
    """Noise parameters read off an Allan deviation curve.

    ``arw`` angle random walk (rate unit·√s, e.g. °/√s — equal to the white-noise
    density in °/s/√Hz), ``bias_instability`` (rate unit), ``tau_min`` (s, where the
    deviation is smallest), ``rrw`` rate random walk (rate unit/√s, NaN if no +1/2 slope).
    """

    arw: np.ndarray
    bias_instability: np.ndarray
    tau_min: np.ndarray
    rrw: np.ndarray


def allan_noise_parameters(taus_s, adev) -> AllanNoise:
    """Read the IEEE-952 noise terms off an Allan deviation curve.

    ``taus_s`` (K,) averaging times (s) and ``adev`` (K,) or (K, k) Allan deviations, as
    returned by :func:`allan_deviation`.

    ARW: median of σ(τ)√τ over the points where the local log-log slope is within
    ±0.15 of −1/2; bias instability: min σ / 0.664; RRW: median of σ(τ)√(3/τ) where the
    slope is within ±0.15 of +1/2.

    Parameters
    ----------
    taus_s : array_like, shape (K,)
        Averaging times τ (s), positive.
    adev : array_like, shape (K,) or (K, k)
        Allan deviations σ(τ) (≥ 0) of one or ``k`` channels, in the rate unit (e.g.
        °/s).

    Returns
    -------
    AllanNoise
        Angle random walk, bias instability, the τ of the minimum (s) and rate random
        walk: floats for 1-D ``adev``, arrays (k,) otherwise; NaN where no point of the
        curve has the needed slope.
    """
    t = _v.vectors(taus_s, "taus_s", width=None, ndim=1)
    if np.any(t <= 0):
        raise ValueError(
            f"taus_s must be positive durations (s), got {t[t <= 0].tolist()[:5]}"
        )
    a = _v.vectors(adev, "adev", width=None, ndim=None)
    if np.any(a < 0):
        raise ValueError(
            f"adev must hold Allan deviations (>= 0), got {int(np.sum(a < 0))} negative values"
        )
    if a.shape[0] != t.size:
        raise ValueError(
            f"adev must have one row per tau ({t.size}), got shape {a.shape}"
        )
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
        rrw.append(
            np.median(a[sel, j] * np.sqrt(3.0 / t[sel])) if sel.any() else np.nan
        )
    f = (lambda v: float(v[0])) if one else np.array
    return AllanNoise(f(arw), f(bi), f(tmin), f(rrw))
