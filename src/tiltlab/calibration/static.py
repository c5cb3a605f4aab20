r"""Static-period detection and per-period statistics for calibration recordings.

A calibration recording (tumble test, gyro bias run) alternates still periods and
re-orientations. Still periods are found either from a trigger channel (Fayat et al.
2021 [1]_ §2.5: the 400 ms preceding each stage-rotation trigger) or, without trigger,
by thresholding a smoothed angular speed. The raw angular speed of an uncalibrated
gyroscope is *not* near zero at rest: Fayat et al. report offsets between −22.6 and
10.5 °/s (5–95th percentiles, §3.1), so a fixed 5 °/s threshold on raw data may find
no still sample at all. :func:`robust_gyro_offset` therefore estimates a first-pass
offset from the quietest windows (lowest variance — independent of the offset
itself) before thresholding.

Intervals are integer arrays of shape (P, 2) holding ``[start, stop)`` sample indices.

References
----------
.. [1] R. Fayat et al., "Inertial measurement of head tilt in rodents: principles and
   applications to vestibular research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.ndimage import uniform_filter1d

from ..intervals import intervals_to_mask, mask_to_intervals
from ._util import CalibrationError, check_fs, vec3

__all__ = [
    "mask_to_intervals",
    "intervals_to_mask",
    "static_intervals_from_trigger",
    "robust_gyro_offset",
    "detect_static",
    "StaticStats",
    "static_means",
    "gyro_offset",
]


def _check_intervals(intervals, n: int) -> np.ndarray:
    iv = np.asarray(intervals, dtype=np.int64).reshape(-1, 2)
    if np.any(iv[:, 0] < 0) or np.any(iv[:, 1] > n) or np.any(iv[:, 1] <= iv[:, 0]):
        raise ValueError(f"intervals must satisfy 0 <= start < stop <= {n}")
    return iv


def static_intervals_from_trigger(trigger, fs: float, *, window_s: float = 0.4, gap_s: float = 0.0,
                                  level: float = 0.5) -> np.ndarray:
    """Still periods defined by a digital trigger: the ``window_s`` preceding each rising edge.

    Fayat et al. [1]_ (§2.5) used the 400 ms of immobility preceding each trigger, which
    the stage emitted at the onset of every new rotation.

    Parameters
    ----------
    trigger : array_like (N,)
        Trigger channel; a rising edge is a crossing of ``level`` from below.
    fs : float
        Sampling rate (Hz).
    window_s : float
        Duration of each still period (s).
    gap_s : float
        Margin left out between the period and the edge (s).
    level : float
        Logic threshold.

    Returns
    -------
    ndarray (P, 2)
        ``[start, stop)`` sample indices; edges too early for a full window are skipped.
    """
    fs = check_fs(fs)
    t = np.asarray(trigger, dtype=float)
    if t.ndim != 1:
        raise ValueError("trigger must be 1-D")
    hi = t > level
    edges = np.flatnonzero(hi[1:] & ~hi[:-1]) + 1
    w, g = int(round(window_s * fs)), int(round(gap_s * fs))
    if w < 1:
        raise ValueError("window_s is shorter than one sample")
    stops = edges - g
    starts = stops - w
    ok = starts >= 0
    return np.column_stack([starts[ok], stops[ok]]).astype(np.int64).reshape(-1, 2)


def robust_gyro_offset(gyr, fs: float, *, window_s: float = 0.5, quantile: float = 0.2) -> np.ndarray:
    """First-pass gyroscope offset from the quietest windows of a recording.

    The record is cut into non-overlapping windows of ``window_s``; the windows whose
    total gyroscope variance is within the lowest ``quantile`` are taken as still, and
    the per-axis median of their samples is returned. Variance does not depend on the
    offset, so this works for offsets of tens of °/s, and it needs only ``quantile`` of
    the record to be still.
    """
    fs = check_fs(fs)
    g = vec3(gyr, "gyr", ndim=2)
    w = max(int(round(window_s * fs)), 2)
    nw = g.shape[0] // w
    if nw < 1:
        raise CalibrationError("recording shorter than one window: cannot estimate a gyro offset")
    blocks = g[: nw * w].reshape(nw, w, 3)
    var = blocks.var(axis=1).sum(axis=1)
    quiet = var <= np.quantile(var, quantile)
    return np.median(blocks[quiet].reshape(-1, 3), axis=0)


def detect_static(gyr, fs: float, *, acc=None, trigger=None, threshold: float = 3.0, smooth_s: float = 0.1,
                  min_duration_s: float = 0.4, merge_gap_s: float = 0.0, trim_s: float | None = None,
                  acc_std_threshold: float | None = None, offset=None, trigger_window_s: float = 0.4) -> np.ndarray:
    r"""Still periods of a calibration recording.

    With a ``trigger`` channel, the ``trigger_window_s`` before each rising edge
    (:func:`static_intervals_from_trigger`). Otherwise: (1) subtract a first-pass gyro
    offset (``offset`` or :func:`robust_gyro_offset`); (2) smooth the angular speed
    :math:`\|\omega - o\|` with a ``smooth_s`` moving average; (3) keep samples below
    ``threshold`` (and, if ``acc`` and ``acc_std_threshold`` are given, whose moving
    standard deviation of :math:`\|a\|` is below it); (4) merge runs separated by less
    than ``merge_gap_s``, shrink each run by ``trim_s`` at both ends (default half the
    smoothing window, which the moving average spreads into the movement) and drop runs
    shorter than ``min_duration_s``.

    Parameters
    ----------
    gyr : array_like (N, 3)
        Angular velocity in °/s (thresholds are in °/s).
    fs : float
        Sampling rate (Hz).
    acc : array_like (N, 3), optional
        Acceleration (g), for the optional acceleration criterion.
    trigger : array_like (N,), optional
        Trigger channel; when given, thresholds are not used.
    threshold : float
        Angular-speed threshold (°/s) on the offset-corrected, smoothed norm.
    smooth_s, min_duration_s, merge_gap_s, trim_s : float
        Durations in seconds.
    acc_std_threshold : float, optional
        Maximum moving standard deviation of ‖a‖ (g).
    offset : array_like (3,), optional
        Gyro offset to subtract instead of the robust first pass.

    Returns
    -------
    ndarray (P, 2)
        ``[start, stop)`` sample indices of the still periods.
    """
    fs = check_fs(fs)
    g = vec3(gyr, "gyr", ndim=2)
    if trigger is not None:
        tr = np.asarray(trigger, dtype=float)
        if tr.shape != (g.shape[0],):
            raise ValueError(f"trigger must have shape ({g.shape[0]},), got {tr.shape}")
        return static_intervals_from_trigger(tr, fs, window_s=trigger_window_s)
    if threshold <= 0:
        raise ValueError("threshold must be positive (°/s)")
    o = robust_gyro_offset(g, fs) if offset is None else vec3(offset, "offset", ndim=1)
    w = max(int(round(smooth_s * fs)), 1)
    speed = uniform_filter1d(np.linalg.norm(g - o, axis=1), w, mode="nearest")
    still = speed < threshold
    if acc is not None and acc_std_threshold is not None:
        a = vec3(acc, "acc", ndim=2)
        if a.shape != g.shape:
            raise ValueError("acc and gyr must have the same shape")
        an = np.linalg.norm(a, axis=1)
        m1 = uniform_filter1d(an, w, mode="nearest")
        m2 = uniform_filter1d(an * an, w, mode="nearest")
        still &= np.sqrt(np.maximum(m2 - m1 * m1, 0.0)) < acc_std_threshold
    iv = mask_to_intervals(still, merge_gap=int(round(merge_gap_s * fs)))
    trim = int(round((0.5 * smooth_s if trim_s is None else trim_s) * fs))
    iv = iv + np.array([trim, -trim])
    return iv[(iv[:, 1] - iv[:, 0]) >= max(int(round(min_duration_s * fs)), 1)]


class StaticStats(NamedTuple):
    """Per-period statistics: ``mean`` (P, 3), ``sem`` (P, 3) standard error of the mean,
    ``std`` (P, 3) and ``n`` (P,) sample counts."""

    mean: np.ndarray
    sem: np.ndarray
    std: np.ndarray
    n: np.ndarray


def static_means(x, intervals, *, full_scale: float | None = None, min_periods: int = 1) -> StaticStats:
    """Mean, standard error and standard deviation of a 3-axis signal in each still period.

    Parameters
    ----------
    x : array_like (N, 3)
    intervals : array_like (P, 2)
    full_scale : float, optional
        Sensor full scale in the units of ``x``; a period containing a sample within
        0.1 % of it is saturated and raises :class:`CalibrationError` (a clipped mean
        would bias any fit).
    min_periods : int
        Minimum number of periods required.

    Notes
    -----
    The standard error assumes independent samples (white noise); with coloured noise it
    is optimistic.
    """
    a = vec3(x, "x", ndim=2)
    iv = _check_intervals(intervals, a.shape[0])
    if iv.shape[0] < min_periods:
        raise CalibrationError(f"found {iv.shape[0]} still periods, at least {min_periods} are needed")
    means, sems, stds, ns = [], [], [], []
    for k, (s, e) in enumerate(iv):
        seg = a[s:e]
        if full_scale is not None and np.any(np.abs(seg) >= 0.999 * full_scale):
            raise CalibrationError(f"still period {k} (samples {s}:{e}) contains saturated samples "
                                   f"(|x| reaches the full scale {full_scale})")
        n = seg.shape[0]
        sd = seg.std(axis=0, ddof=1) if n > 1 else np.full(3, np.nan)
        means.append(seg.mean(axis=0))
        stds.append(sd)
        sems.append(sd / np.sqrt(n))
        ns.append(n)
    return StaticStats(np.array(means).reshape(-1, 3), np.array(sems).reshape(-1, 3),
                       np.array(stds).reshape(-1, 3), np.array(ns, dtype=np.int64))


def gyro_offset(gyr, intervals) -> tuple[np.ndarray, np.ndarray]:
    """Gyroscope offset as the median angular velocity during still periods (Fayat §2.5).

    Returns
    -------
    offset : ndarray (3,)
        Median of all still samples.
    stderr : ndarray (3,)
        Standard error: the larger of the spread of per-period medians over √P (P ≥ 2)
        and the white-noise standard error of a median, 1.2533 σ/√n.
    """
    g = vec3(gyr, "gyr", ndim=2)
    iv = _check_intervals(intervals, g.shape[0])
    if iv.shape[0] == 0:
        raise CalibrationError("no still period: cannot estimate gyroscope offsets")
    allv = np.concatenate([g[s:e] for s, e in iv])
    off = np.median(allv, axis=0)
    if iv.shape[0] >= 2:
        per = np.array([np.median(g[s:e], axis=0) for s, e in iv])
        se = per.std(axis=0, ddof=1) / np.sqrt(per.shape[0])
    else:
        se = np.zeros(3)
    # quantised data can make all period medians equal: never report less than the
    # white-noise standard error of a median
    se = np.maximum(se, 1.2533 * allv.std(axis=0, ddof=1) / np.sqrt(allv.shape[0]))
    return off, se
