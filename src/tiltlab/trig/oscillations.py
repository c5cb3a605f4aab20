r"""Oscillations of a signal about a balance level (Benhamou 2023 §9).

The signal (e.g. the heave specific force) is a labelled DataArray (``fs`` read from its
attributes) or a plain 1-D array with ``fs``. Synthetic flapping/gliding heave for
demonstrations is :func:`tiltlab.simulate.simulate_heave`.
"""

from __future__ import annotations

import numpy as np

import tiltlab._validate as _v
from ..dsp import moving_mean, window_samples
from ._common import read_input, start_time, windowed
from ._types import OscillationStats

__all__ = ["crossing_times", "oscillation_stats"]


def _read_signal(signal, fs):
    return read_input(signal, "signal", fs=fs, need_fs=True, width=None, ndim=1)


def _crossings(x: np.ndarray, fs: float) -> np.ndarray:
    s = np.sign(x)
    # treat exact zeros as belonging to the previous sign to avoid double counting
    for _ in range(2):
        z = s == 0
        if not np.any(z):
            break
        s[z] = np.concatenate([[1.0], s[:-1]])[z]
    i = np.nonzero(s[:-1] * s[1:] < 0)[0]
    frac = x[i] / (x[i] - x[i + 1])
    return (i + frac) / fs


def crossing_times(signal, fs=None, *, level: float = 0.0) -> np.ndarray:
    """Find the times (s) at which ``signal`` crosses ``level`` (either direction).

    Linearly interpolated between samples.

    Parameters
    ----------
    signal : xarray.DataArray or array_like (N,)
        The signal; a labelled DataArray carries ``fs`` (and its times are then on its
        ``time`` coordinate), a plain array needs ``fs``.
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    level : float
        Balance level, in the units of ``signal``.

    Returns
    -------
    numpy.ndarray
        Crossing times in s (from the first sample, or on the input's time axis).
    """
    level = _v.finite(level, "level")
    s = _read_signal(signal, fs)
    t = _crossings(s.values - level, s.fs)
    return t + start_time(s) if s.labelled else t


def oscillation_stats(
    signal,
    fs=None,
    *,
    level: float,
    window_s: float,
    smooth_s: float | None = None,
) -> OscillationStats:
    r"""Compute crossing statistics per Δt window (§9).

    The mean delay d̄ between successive crossings of a balance level, its CV, and the
    period T = 2d̄.

    For a regular oscillation CV ≪ 1; for random fluctuations the delays are close
    to exponential (CV ≈ 1). The balance level is the static value of the signal,
    e.g. +g on the heave axis for tiltlab specific force (−g in Benhamou's sign).
    Windows with fewer than two intervals give NaN (no statistic can be formed).
    Each interval is assigned to the window containing its midpoint.

    Parameters
    ----------
    signal : xarray.DataArray or array_like (N,)
        The signal (``fs`` from the attributes of a DataArray).
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    level : float
        Balance level, in the units of ``signal``.
    window_s : float
        Window duration Δt (s).
    smooth_s : float, optional
        Not in [1]_: a centred moving average of that duration
        (:func:`tiltlab.dsp.moving_mean`) applied before detecting crossings, to
        suppress the spurious extra crossings that sensor noise creates near the
        balance level.

    Returns
    -------
    OscillationStats
        Window-centre times (s) and statistics; DataArrays over those times for a
        labelled ``signal``.
    """
    level = _v.finite(level, "level")
    s = _read_signal(signal, fs)
    fs = s.fs
    x = s.values
    if smooth_s is not None:
        x = moving_mean(x, window_samples(smooth_s, fs, name="smooth_s"))
    k = window_samples(window_s, fs)
    nb = x.shape[0] // k
    t = _crossings(x - level, fs)
    d = np.diff(t)
    mid = (t[1:] + t[:-1]) / 2
    w = np.floor(mid * fs / k).astype(int)
    keep = w < nb
    w, d = w[keep], d[keep]
    cnt = np.bincount(w, minlength=nb).astype(float)
    s1 = np.bincount(w, weights=d, minlength=nb)
    s2 = np.bincount(w, weights=d**2, minlength=nb)
    with np.errstate(invalid="ignore", divide="ignore"):
        m = np.where(cnt >= 2, s1 / cnt, np.nan)
        var = np.where(cnt >= 2, s2 / cnt - m**2, np.nan)
        cv = np.sqrt(np.maximum(var, 0)) / m
    centre = (np.arange(nb) * k + k / 2) / fs
    if not s.labelled:
        return OscillationStats(centre, m, cv, 2 * m, cnt.astype(int))

    def lab(v, name, units):
        return windowed(v, s, name, centre_s=centre, fs_out=fs / k, units=units)

    return OscillationStats(
        start_time(s) + centre,
        lab(m, "mean_delay", "s"),
        lab(cv, "cv", "1"),
        lab(2 * m, "period", "s"),
        lab(cnt.astype(int), "n_intervals", None),
    )
