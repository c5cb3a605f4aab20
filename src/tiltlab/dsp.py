r"""Signal-processing primitives shared by calibration, filters and behaviour (layer 3).

One implementation each:

* :func:`lowpass` — the zero-phase Butterworth low-pass (forward–backward
  ``scipy.signal.sosfiltfilt``; effective order ``2·order``, no lag). Edge handling is
  fixed: odd-extension padding of ``min(N − 1, 3·(2·n_sections + 1))`` samples, so short
  records are filtered too; a single sample is returned unchanged.
* :func:`moving_mean`, :func:`moving_std` — centred running statistics (``nearest`` edges).
* :func:`still_mask` — the still/rest detector core: a speed threshold on an (optionally
  smoothed) angular speed, an optional acceleration-steadiness criterion, then merging of
  short gaps, trimming of the edges and removal of short periods. Fayat's immobility
  (§2.9), the tumble-test still periods and the filters' rest detection are all this
  function with different settings.

Durations are converted to samples with one rule: a gap is merged when it spans strictly
less than ``merge_gap_s``; a period is kept when it spans at least ``min_duration_s``
(:func:`tiltlab.intervals.samples_below`, ``ceil``).
"""

from __future__ import annotations

import numpy as np
from scipy import signal as _signal
from scipy.ndimage import uniform_filter1d

from . import _validate as _v
from .intervals import intervals_to_mask, mask_to_intervals, samples_below

__all__ = ["lowpass", "moving_mean", "moving_std", "still_mask", "window_samples"]


def window_samples(
    window_s: float, fs: float, *, minimum: int = 1, name: str = "window_s"
) -> int:
    """Return the number of samples in a window of ``window_s`` seconds at ``fs``.

    The duration is rounded to the nearest sample, and at least ``minimum``.

    Parameters
    ----------
    window_s : float
        Window duration (s), positive.
    fs : float
        Sampling rate (Hz).
    minimum : int
        Smallest number of samples returned (≥ 1; default 1).
    name : str
        Name of ``window_s`` in error messages.

    Returns
    -------
    int
        ``max(round(window_s * fs), minimum)``.
    """
    window_s = _v.positive(window_s, name)
    fs = _v.check_fs(fs)
    minimum = _v.integer(minimum, "minimum", minimum=1)
    return max(int(round(window_s * fs)), minimum)


#: the largest Butterworth order accepted per pass (higher orders only add ringing and
#: rounding: the zero-phase filter already has twice the order)
MAX_ORDER = 32


def lowpass(
    x, fs: float, cutoff_hz: float, *, order: int = 2, name: str = "x"
) -> np.ndarray:
    """Zero-phase Butterworth low-pass along the first axis.

    Parameters
    ----------
    x : array_like, shape (N, ...)
        Samples (time first).
    fs : float
        Sampling rate (Hz).
    cutoff_hz : float
        Cut-off frequency (Hz), ``0 < cutoff_hz < fs/2``.
    order : int
        Butterworth order of each pass, 1 to :data:`MAX_ORDER` (the forward–backward
        filter has order ``2·order``).
    name : str
        Name of ``x`` in error messages.

    Returns
    -------
    numpy.ndarray
        A new array of the shape of ``x``.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(1000) / 100.0
    >>> y = lowpass(np.sin(2 * np.pi * 0.5 * t) + np.sin(2 * np.pi * 20 * t), 100.0, 2.0)
    >>> bool(np.abs(y[100:-100] - np.sin(2 * np.pi * 0.5 * t[100:-100])).max() < 0.01)
    True
    """
    fs = _v.check_fs(fs)
    cutoff_hz = _v.positive(cutoff_hz, "cutoff_hz")
    order = _v.integer(order, "order", minimum=1, maximum=MAX_ORDER)
    if cutoff_hz >= fs / 2:
        raise ValueError(
            f"cutoff_hz must be below the Nyquist frequency {fs / 2:g} Hz, got {cutoff_hz:g}"
        )
    a = _v.vectors(x, name, width=None, ndim=None)
    if a.ndim == 0:
        raise ValueError(f"{name} must have a time dimension")
    if a.shape[0] < 2:
        return a.copy()
    sos = _signal.butter(order, cutoff_hz, btype="low", fs=fs, output="sos")
    padlen = min(a.shape[0] - 1, 3 * (2 * sos.shape[0] + 1))
    return _signal.sosfiltfilt(sos, a, axis=0, padlen=padlen)


def moving_mean(x, n: int) -> np.ndarray:
    """Centred running mean over ``n`` samples along the first axis (``nearest`` edges).

    Parameters
    ----------
    x : array_like, shape (N, ...)
        Samples (time first).
    n : int
        Window length (samples, ≥ 1).

    Returns
    -------
    numpy.ndarray
        A new array of the shape of ``x``.
    """
    n = _v.integer(n, "n", minimum=1)
    x = _v.vectors(x, "x", width=None, ndim=None)
    if x.ndim == 0:
        raise ValueError("x must have a time dimension, got a scalar")
    return uniform_filter1d(x, n, axis=0, mode="nearest")


def moving_std(x, n: int) -> np.ndarray:
    r"""Centred running standard deviation of a 1-D series over ``n`` samples.

    :math:`\sqrt{\max(\overline{x^2} - \bar x^2, 0)}` (clipped: the running mean of tiny
    squares can round below the squared mean).

    Parameters
    ----------
    x : array_like, shape (N,)
        A 1-D series.
    n : int
        Window length (samples, ≥ 1).

    Returns
    -------
    numpy.ndarray, shape (N,)
        The running standard deviation (population, ``ddof=0``), in the unit of ``x``.
    """
    x = _v.vectors(x, "x", width=None, ndim=1)
    m1 = moving_mean(x, n)
    m2 = moving_mean(x * x, n)
    return np.sqrt(np.maximum(m2 - m1 * m1, 0.0))


def still_mask(
    speed,
    fs: float,
    *,
    threshold: float,
    smooth_s: float = 0.0,
    acc_norm=None,
    acc_std_threshold: float | None = None,
    merge_gap_s: float = 0.0,
    min_duration_s: float = 0.0,
    trim_s: float = 0.0,
) -> np.ndarray:
    r"""Find the samples where a speed stays below a threshold: the still/rest detector core.

    1. Optionally smooth ``speed`` with a centred ``smooth_s`` moving average.
    2. Candidate samples: smoothed speed ``< threshold`` and, if ``acc_norm`` and
       ``acc_std_threshold`` are given, a moving standard deviation of ‖a‖ (same window,
       at least 3 samples) below ``acc_std_threshold``.
    3. Merge candidate runs separated by gaps spanning strictly less than ``merge_gap_s``.
    4. Shrink every run by ``trim_s`` at both ends (the smoothing spreads movement into
       the still period by half a window).
    5. Keep runs spanning at least ``min_duration_s``.

    Parameters
    ----------
    speed : array_like, shape (N,)
        A non-negative speed (any unit; ``threshold`` is in the same unit). NaN is refused.
    fs : float
        Sampling rate (Hz).
    threshold : float
        Speed below which a sample is still.
    smooth_s, merge_gap_s, min_duration_s, trim_s : float
        Durations in seconds (0 disables the step).
    acc_norm : array_like, shape (N,), optional
        Norm of the acceleration, for the steadiness criterion.
    acc_std_threshold : float, optional
        Largest moving standard deviation of ``acc_norm`` (its unit) at rest.

    Returns
    -------
    numpy.ndarray of bool, shape (N,)
    """
    fs = _v.check_fs(fs)
    s = _v.vectors(speed, "speed", width=None, ndim=1)
    if np.any(s < 0):
        raise ValueError(
            f"speed must be non-negative, got {int(np.sum(s < 0))} negative values "
            f"(min {float(s.min()):g})"
        )
    threshold = _v.positive(threshold, "threshold")
    smooth_s = _v.nonnegative(smooth_s, "smooth_s")
    merge_gap_s = _v.nonnegative(merge_gap_s, "merge_gap_s")
    min_duration_s = _v.nonnegative(min_duration_s, "min_duration_s")
    trim_s = _v.nonnegative(trim_s, "trim_s")
    n = max(int(round(smooth_s * fs)), 1)
    if n > 1:
        s = moving_mean(s, n)
    still = s < threshold
    if acc_norm is not None and acc_std_threshold is not None:
        an = _v.vectors(acc_norm, "acc_norm", width=None, ndim=1)
        if an.shape != s.shape:
            raise ValueError(
                f"acc_norm must have one value per sample ({s.size}), got {an.size}"
            )
        still &= moving_std(an, max(n, 3)) < _v.positive(
            acc_std_threshold, "acc_std_threshold"
        )
    iv = mask_to_intervals(still, merge_gap=samples_below(merge_gap_s, fs))
    trim = int(round(trim_s * fs))
    if trim:
        iv = iv + np.array([trim, -trim])
    min_len = max(int(np.ceil(min_duration_s * fs - 1e-9)), 1)
    iv = iv[(iv[:, 1] - iv[:, 0]) >= min_len]
    return intervals_to_mask(iv, s.size)
