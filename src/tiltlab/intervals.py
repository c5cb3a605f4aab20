"""Runs of True in boolean masks as ``[start, stop)`` sample intervals, and back.

A small base module shared by still-period detection (:mod:`tiltlab.calibration`) and
immobility detection (:mod:`tiltlab.behavior`).
"""

from __future__ import annotations

import numpy as np

from . import _validate as _v

__all__ = ["mask_to_intervals", "intervals_to_mask", "samples_below"]


def mask_to_intervals(mask, *, min_length: int = 1, merge_gap: int = 0) -> np.ndarray:
    """``[start, stop)`` intervals of the True runs of a boolean mask, shape (k, 2).

    Runs separated by at most ``merge_gap`` False samples are merged first, then runs
    shorter than ``min_length`` samples are dropped.

    Parameters
    ----------
    mask : array_like of bool, shape (N,)
        The mask (booleans or 0/1 values).
    min_length : int
        Shortest run kept (samples; default 1, every run).
    merge_gap : int
        Longest run of False samples bridged between two True runs (samples; default
        0, no merging).

    Returns
    -------
    numpy.ndarray of int64, shape (k, 2)
        ``[start, stop)`` sample indices of the runs, in order.
    """
    raw = np.asarray(mask)
    if raw.ndim != 1:
        raise ValueError(f"mask must be 1-D, got shape {raw.shape}")
    if raw.dtype != bool:
        try:
            f = raw.astype(float)
        except (TypeError, ValueError):
            raise ValueError(
                f"mask must be booleans (or 0/1), got dtype {raw.dtype}"
            ) from None
        if not np.all(np.isfinite(f)):
            raise ValueError(
                f"mask has {int(np.sum(~np.isfinite(f)))} non-finite values; "
                "a mask is booleans (or 0/1)"
            )
    m = raw.astype(bool)
    min_length = _v.integer(min_length, "min_length", minimum=0)
    merge_gap = _v.integer(merge_gap, "merge_gap", minimum=0)
    d = np.diff(np.concatenate([[0], m.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
    if starts.size and merge_gap > 0:
        keep = np.concatenate([[True], (starts[1:] - stops[:-1]) > merge_gap])
        starts = starts[keep]
        stops = np.concatenate([stops[:-1][keep[1:]], stops[-1:]])
    iv = np.column_stack([starts, stops]).astype(np.int64).reshape(-1, 2)
    return iv[(iv[:, 1] - iv[:, 0]) >= max(int(min_length), 1)]


def intervals_to_mask(intervals, n: int) -> np.ndarray:
    """Boolean mask of length ``n`` that is True inside the ``[start, stop)`` intervals.

    Parameters
    ----------
    intervals : array_like of int, shape (k, 2)
        ``[start, stop)`` sample indices, ``0 <= start < stop <= n``; they may overlap.
    n : int
        Length of the mask (samples).

    Returns
    -------
    numpy.ndarray of bool, shape (n,)
    """
    n = _v.integer(n, "n", minimum=0)
    raw = np.asarray(intervals)
    if raw.dtype.kind not in "iub":
        f = np.asarray(raw, dtype=float)
        if not np.all(np.isfinite(f)) or np.any(f != np.round(f)):
            raise ValueError("intervals must hold whole sample indices")
    iv = raw.astype(np.int64).reshape(-1, 2)
    if np.any(iv[:, 0] < 0) or np.any(iv[:, 1] > n) or np.any(iv[:, 1] <= iv[:, 0]):
        raise ValueError(f"intervals must satisfy 0 <= start < stop <= {n}")
    d = np.zeros(int(n) + 1, dtype=np.int64)
    np.add.at(d, iv[:, 0], 1)
    np.add.at(d, iv[:, 1], -1)
    return np.cumsum(d[:-1]) > 0


def samples_below(duration_s: float, fs: float) -> int:
    """Largest whole number of samples spanning strictly less than ``duration_s`` at ``fs``.

    Used to turn "gaps shorter than 0.1 s are merged" into ``merge_gap`` for
    :func:`mask_to_intervals`: ``ceil(duration_s·fs) − 1``.

    Parameters
    ----------
    duration_s : float
        Duration (s), non-negative.
    fs : float
        Sampling rate (Hz).

    Returns
    -------
    int
        ``max(ceil(duration_s·fs) − 1, 0)`` samples.
    """
    duration_s = _v.nonnegative(duration_s, "duration_s")
    fs = _v.check_fs(fs)
    return max(int(np.ceil(duration_s * fs)) - 1, 0)
