"""Handle the clocks of real files: time units, epoch times, rate estimates and grids.

Samples are put on a uniform grid exactly, or by linear interpolation. Used by
:func:`tiltlab.io.read_csv` and :func:`tiltlab.io.read_multi`. A logger's time
column is rarely a perfect ``k / fs`` grid: boards deliver samples in bursts, crystals
drift by a percent, and loggers drop samples. Two policies exist:

``"grid"``
    the samples must already sit on a ``k / fs`` grid; missing ones are gaps (refused,
    or NaN rows with ``gaps="nan"``).
``"resample"``
    every variable is interpolated linearly onto a uniform grid at ``fs``; steps longer
    than ``max_gap`` sample periods are real gaps and are never interpolated across.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from .._stack import user_stacklevel
from .. import _validate
from .. import quality as _quality
from .. import schema

#: Sampling rates (Hz) accepted unless told otherwise: a value outside this range almost
#: always means a time column in the wrong unit.
FS_RANGE: tuple[float, float] = (1.0, 20_000.0)

#: Units accepted for a time column, as factors to seconds.
TIME_UNITS: dict[str, float] = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
_TIME_ALIASES = {
    "s": "s",
    "sec": "s",
    "ms": "ms",
    "us": "us",
    "µs": "us",
    "μs": "us",
    "ns": "ns",
}
_TIME_NAMES = {
    "s": "seconds",
    "ms": "milliseconds",
    "us": "microseconds",
    "ns": "nanoseconds",
}
#: The ``time_units`` value for a column of date-time strings.
DATETIME = "datetime"

#: Clock policies (see the module docstring).
CLOCK_POLICIES: tuple[str, ...] = ("grid", "resample")

#: What to do with samples missing from the time column: refuse the file, or put NaN
#: rows in their place.
READ_GAP_POLICIES: tuple[str, ...] = ("raise", "nan")

#: Default longest step (in sample periods) that ``clock="resample"`` interpolates
#: across; a longer one is a real gap.
MAX_GAP: float = 5.0

#: Largest fraction of the samples of a regridded recording that ``gaps="nan"`` may
#: leave missing (NaN). A grid that would be mostly NaN does not come from a logger
#: that dropped samples but from a corrupted timestamp or a reset clock (one bad time
#: value 20 000 s late turns 1000 rows at 100 Hz into 2 001 000 samples, 99.95 % NaN),
#: so the file is refused with the time jump named (:func:`check_missing_fraction`).
MAX_MISSING_FRACTION: float = 0.5

#: A time column whose first sample lies between these many seconds after 1970-01-01
#: (1980 to 2100) holds epoch times.
_EPOCH_RANGE = (10 * 365.25 * 86400, 130 * 365.25 * 86400)


def option_hint(key: str, value: Any, style: str) -> str:
    """Write an option as the user writes it, for messages.

    Parameters
    ----------
    key : str
        The option's name.
    value : object
        Its value.
    style : {"mapping", "python"}
        How the options were given.

    Returns
    -------
    str
        ``"clock": "resample"`` in a mapping (JSON), ``clock='resample'`` as a keyword.
    """
    if style == "mapping":
        return f"{json.dumps(key)}: {json.dumps(value)}"
    return f"{key}={value!r}"


def time_factor(time_units: str, where: str = "") -> float:
    """Convert a time unit (``"s"``, ``"ms"``, ``"us"``, ``"ns"``) to its factor to seconds.

    Parameters
    ----------
    time_units : str
        The unit, or one of its aliases.
    where : str, optional
        Prefix naming the mapping in messages.

    Returns
    -------
    float
        Seconds per unit.

    Raises
    ------
    ValueError
        If the unit is not known.
    """
    key = _TIME_ALIASES.get(str(time_units).strip())
    if key is None:
        raise ValueError(
            f"{where}time_units must be one of 's', 'ms', 'us', 'ns' or 'datetime', "
            f"got {time_units!r}"
        )
    return TIME_UNITS[key]


def unit_name(scale: float) -> str:
    """Name the time unit whose factor to seconds is ``scale``, for messages.

    Parameters
    ----------
    scale : float
        Factor from the time column to seconds.

    Returns
    -------
    str
        ``"s"``, ``"ms"``, ``"us"`` or ``"ns"``, else ``"× <scale> s"``.
    """
    return next(
        (u for u, f in TIME_UNITS.items() if np.isclose(f, scale)), f"× {scale:g} s"
    )


def unit_hint(
    raw_step: float,
    fs_range: tuple[float, float] | None,
    scale: float | None = None,
    style: str = "python",
) -> str:
    """Suggest the time unit that would make ``raw_step`` a plausible sampling interval.

    Units other than the one in use (factor ``scale`` to seconds) are tried in turn.

    Parameters
    ----------
    raw_step : float
        The median step of the time column, in the column's numbers.
    fs_range : (float, float) or None
        Plausible rates (Hz); None uses :data:`FS_RANGE`.
    scale : float, optional
        The factor in use, which is not suggested.
    style : {"python", "mapping"}, optional
        How the options were given, to write the fix.

    Returns
    -------
    str
        ``"; the time column looks like …"``, or ``""`` if no unit fits.
    """
    lo, hi = fs_range or FS_RANGE
    for unit, factor in TIME_UNITS.items():
        if scale is not None and np.isclose(factor, scale):
            continue
        f = 1.0 / (raw_step * factor)
        if lo <= f <= hi:
            return (
                f"; the time column looks like {_TIME_NAMES[unit]}: give "
                f"{option_hint('time_units', unit, style)} (fs would be {f:.6g} Hz)"
            )
    return ""


def to_seconds(
    raw: np.ndarray, time_units: str | float, where: str = ""
) -> tuple[np.ndarray, np.datetime64 | None]:
    """Convert a time column to seconds, relative to its first sample when absolute.

    Parameters
    ----------
    raw : numpy.ndarray, shape (N,)
        The column as read: numbers (integers are kept exact until the first sample is
        subtracted) or, for ``time_units="datetime"``, date-time strings.
    time_units : str or float
        ``"datetime"``, or the factor from the column's numbers to seconds.
    where : str
        Prefix for messages.

    Returns
    -------
    seconds : numpy.ndarray
        Times in seconds. Epoch times (the first sample between 1980 and 2100 when read
        in the given unit) and date-times are returned relative to the first sample.
    origin : numpy.datetime64 or None
        The absolute time of the first sample (UTC, ns) for epoch and date-time
        columns, else None.
    """
    if isinstance(time_units, str) and time_units == DATETIME:
        import pandas as pd

        try:
            try:  # one ISO 8601 layout (fractions of a second may come and go) …
                stamps = pd.to_datetime(pd.Series(raw), utc=True, format="ISO8601")
            except (ValueError, TypeError):  # … or any layout pandas recognises
                stamps = pd.to_datetime(pd.Series(raw), utc=True, format="mixed")
        except (ValueError, TypeError) as exc:
            raise schema.RecordingError(
                f"{where}time column is not date-time text ({exc}); give time_units "
                "'s', 'ms', 'us' or 'ns' for a numeric column"
            ) from None
        if stamps.isna().any():
            i = int(np.argmax(stamps.isna().to_numpy()))
            raise schema.RecordingError(
                f"{where}time column has an empty or unreadable date-time at data row {i}"
            )
        ns = stamps.dt.tz_localize(None).to_numpy().astype("datetime64[ns]")
        origin = ns[0]
        return (ns - origin).astype(np.int64) * 1e-9, origin
    factor = float(time_units)
    values = np.asarray(raw)
    if values.size == 0:
        return values.astype(float), None
    first = float(values[0]) * factor
    if not _EPOCH_RANGE[0] <= first <= _EPOCH_RANGE[1]:
        return values.astype(float) * factor, None
    # epoch times: subtract the first sample before the float conversion
    if np.issubdtype(values.dtype, np.integer):
        rel = (values.astype(np.int64) - np.int64(values[0])).astype(float) * factor
        ns_per_unit = factor * 1e9
        if ns_per_unit >= 1:
            origin_ns = int(values[0]) * int(round(ns_per_unit))
        else:
            origin_ns = int(values[0]) // int(round(1 / ns_per_unit))
    else:
        from decimal import Decimal

        v = values.astype(float)
        rel = (v - v[0]) * factor
        # the decimal number as written, to the nanosecond (no float rounding)
        exact = Decimal(repr(float(v[0]))) * Decimal(repr(factor)) * 1_000_000_000
        origin_ns = int(exact.to_integral_value())
    return rel, np.datetime64(origin_ns, "ns")


def iso_utc(origin: np.datetime64) -> str:
    """Format an absolute time as an ISO-8601 UTC string.

    Parameters
    ----------
    origin : numpy.datetime64
        The time (UTC).

    Returns
    -------
    str
        E.g. ``"2024-05-01T12:00:00+00:00"``.
    """
    import pandas as pd

    return pd.Timestamp(origin).tz_localize("UTC").isoformat()


def check_increasing(time: np.ndarray, column: str, where: str) -> None:
    """Refuse non-finite or non-increasing sample times, naming the data row.

    Parameters
    ----------
    time : numpy.ndarray, shape (N,)
        Sample times (s).
    column : str
        The time column's name.
    where : str
        Prefix (the file) for messages.

    Raises
    ------
    tiltlab.schema.RecordingError
        If a time is not finite or does not increase.
    """
    if not np.all(np.isfinite(time)):
        i = int(np.argmax(~np.isfinite(time)))
        raise schema.RecordingError(
            f"{where}time column {column!r} has non-finite values (data row {i})"
        )
    step = np.diff(time)
    if np.any(step <= 0):
        i = int(np.argmax(step <= 0))
        raise schema.RecordingError(
            f"{where}time column {column!r} is not strictly increasing "
            f"(data row {i + 1}: {time[i + 1]!r} after {time[i]!r})"
        )


def gap_steps(time: np.ndarray, fs: float, max_gap: float) -> np.ndarray:
    """Find the steps ``time[i] → time[i+1]`` longer than ``max_gap / fs``.

    Parameters
    ----------
    time : numpy.ndarray, shape (N,)
        Sample times (s).
    fs : float
        The clock's rate (Hz).
    max_gap : float
        Longest ordinary step, in sample periods.

    Returns
    -------
    numpy.ndarray of int
        The indices ``i`` of the long steps.
    """
    return np.flatnonzero(np.diff(time) > max_gap / fs)


def estimate_rate(time: np.ndarray, max_gap: float = MAX_GAP) -> tuple[float, int]:
    """Estimate a robust sampling rate of an irregular clock.

    The rate is (samples − 1) / duration, leaving out the real gaps (steps longer than
    ``max_gap`` periods) and the samples missing in them. The mean rate, unlike
    1 / median step, is right for bursty clocks (many short steps and a few long ones)
    and for clocks that alternate between two step lengths.

    Parameters
    ----------
    time : numpy.ndarray, shape (N,)
        Sample times (s), strictly increasing.
    max_gap : float, optional
        Longest ordinary step, in sample periods (default :data:`MAX_GAP`).

    Returns
    -------
    fs : float
        Hz.
    n_gaps : int
        Number of steps left out as gaps.
    """
    t = np.asarray(time, dtype=float)
    steps = np.diff(t)
    fs = (t.size - 1) / (t[-1] - t[0])
    gaps = np.zeros(steps.size, dtype=bool)
    for _ in range(10):  # converges in a few rounds: gaps shorten the duration
        new = steps > max_gap / fs
        if new.all():
            break
        fs = (t.size - 1 - new.sum()) / steps[~new].sum()
        if np.array_equal(new, gaps):
            break
        gaps = new
    return float(fs), int(gaps.sum())


def _gap_list(time: np.ndarray, idx: np.ndarray, max_items: int = 5) -> str:
    items = [
        f"{time[i + 1] - time[i]:.3g} s after t = {time[i]:.6g} s (data row {i})"
        for i in idx[:max_items]
    ]
    more = f" and {idx.size - max_items} more" if idx.size > max_items else ""
    n = idx.size
    return f"{n} gap{'s' if n != 1 else ''}: " + ", ".join(items) + more


def raise_gaps(
    time: np.ndarray,
    idx: np.ndarray,
    fs: float,
    max_gap: float,
    column: str,
    where: str,
    style: str,
) -> None:
    """Raise the error for real gaps in a clock read with ``clock="resample"``.

    Parameters
    ----------
    time : numpy.ndarray, shape (N,)
        Sample times (s).
    idx : numpy.ndarray of int
        The gap steps (:func:`gap_steps`).
    fs : float
        The clock's rate (Hz).
    max_gap : float
        Longest ordinary step, in sample periods.
    column : str
        The time column's name.
    where : str
        Prefix (the file) for the message.
    style : {"python", "mapping"}
        How the options were given, to write the fix.

    Raises
    ------
    tiltlab.schema.RecordingError
        Always, listing the gaps and the options that read the file.
    """
    raise schema.RecordingError(
        f"{where}time column {column!r} has steps longer than max_gap = {max_gap:g} "
        f"sample periods ({max_gap / fs:.3g} s at {fs:.6g} Hz), which are not "
        f"interpolated across ({_gap_list(time, idx)}). Read with "
        f"{option_hint('gaps', 'nan', style)} to keep them as NaN on the grid, or, if the "
        "samples only arrive in bursts, give a larger max_gap (e.g. "
        f"{option_hint('max_gap', float(np.ceil(2 * max_gap)), style)})"
    )


def check_missing_fraction(
    time: np.ndarray,
    n_grid: int,
    n_missing: int,
    fs: float,
    column: str,
    where: str,
    gap_idx: np.ndarray | None = None,
) -> None:
    """Refuse a regridding (``gaps="nan"``) that would leave the grid mostly missing.

    More than :data:`MAX_MISSING_FRACTION` of the ``n_grid`` samples missing is refused.

    Parameters
    ----------
    time : numpy.ndarray, shape (N,)
        The time column, in seconds (strictly increasing).
    n_grid, n_missing : int
        Samples of the uniform grid at ``fs``, and how many of them would be NaN.
    fs : float
        Grid rate (Hz).
    column, where : str
        The time column's name and a prefix (the file) for the message.
    gap_idx : numpy.ndarray, optional
        The steps ``time[i] → time[i+1]`` that are gaps; default every step.

    Raises
    ------
    tiltlab.schema.RecordingError
        Naming the fraction and the longest time jump with its data rows.
    """
    if n_grid <= 0 or n_missing <= MAX_MISSING_FRACTION * n_grid:
        return
    steps = np.diff(time)
    idx = np.arange(steps.size) if gap_idx is None else np.asarray(gap_idx)
    i = int(idx[np.argmax(steps[idx])]) if idx.size else int(np.argmax(steps))
    raise schema.RecordingError(
        f"{where}time column {column!r}: filling its gaps with NaN would leave "
        f"{n_missing} of {n_grid} samples at {fs:.6g} Hz missing "
        f"({100.0 * n_missing / n_grid:.4g} %, more than the "
        f"{100.0 * MAX_MISSING_FRACTION:g} % allowed). The longest time jump is "
        f"{steps[i]:.10g} s, from t = {time[i]:.10g} s (data row {i}) to "
        f"t = {time[i + 1]:.10g} s (data row {i + 1}): a corrupted timestamp or a "
        "reset clock? Repair or remove the bad rows, or split the file at the jump"
    )


def uniform_grid(start: float, stop: float, fs: float) -> np.ndarray:
    """Build the grid ``start + k / fs`` for every k with the time inside ``[start, stop]``.

    Parameters
    ----------
    start, stop : float
        The interval (s).
    fs : float
        Grid rate (Hz).

    Returns
    -------
    numpy.ndarray, shape (M,)
        The grid times (s); ``grid[0] == start``.
    """
    n = int(np.floor((stop - start) * fs * (1 + 1e-12) + 1e-9)) + 1
    return start + np.arange(max(n, 0)) / fs


def interpolate(
    time: np.ndarray,
    values: np.ndarray,
    grid: np.ndarray,
    gap_idx: np.ndarray | None = None,
    *,
    quaternion: bool = False,
) -> np.ndarray:
    """Interpolate samples at ``time`` linearly onto ``grid``, NaN inside gaps.

    Each grid value (inside the samples' span) is the straight line between the two
    samples around it; grid times strictly inside the steps listed in ``gap_idx`` are NaN.
    Linear interpolation never overshoots and keeps a still sensor still, but it is a mild
    low-pass filter: a sine at frequency f sampled every T loses up to
    ``1 - sinc²(f T)`` of its amplitude between samples, and nothing is done against
    aliasing when the grid is coarser than the samples. ``quaternion=True`` keeps the
    quaternions in one hemisphere before interpolating and normalises the result.

    Parameters
    ----------
    time : numpy.ndarray, shape (N,)
        Sample times (s), strictly increasing.
    values : numpy.ndarray, shape (N, ...)
        The samples.
    grid : numpy.ndarray, shape (M,)
        Target times (s), inside ``[time[0], time[-1]]``.
    gap_idx : numpy.ndarray of int, optional
        Steps that are real gaps (:func:`gap_steps`).
    quaternion : bool, optional
        Whether ``values`` are unit quaternions (N, 4).

    Returns
    -------
    numpy.ndarray, shape (M, ...)
        The values on the grid.
    """
    v = np.asarray(values, dtype=float)
    v2 = v.reshape(v.shape[0], -1)
    if quaternion:
        v2 = v2.copy()
        flip = np.cumprod(
            np.r_[1.0, np.sign(np.sum(v2[1:] * v2[:-1], axis=1) + 1e-300)]
        )
        v2 *= flip[:, None]
    i = np.clip(np.searchsorted(time, grid, side="right") - 1, 0, time.size - 2)
    w = (grid - time[i]) / (time[i + 1] - time[i])
    out = v2[i] + w[:, None] * (v2[i + 1] - v2[i])
    exact = grid == time[i + 1]  # the last sample itself
    out[exact] = v2[i[exact] + 1]
    if gap_idx is not None and gap_idx.size:
        is_gap = np.zeros(time.size - 1, dtype=bool)
        is_gap[gap_idx] = True
        inside = is_gap[i] & (grid > time[i]) & (grid < time[i + 1])
        out[inside] = np.nan
    if quaternion:
        out /= np.linalg.norm(out, axis=1, keepdims=True)
    return out.reshape((grid.size, *v.shape[1:]))


def describe_resampling(time: np.ndarray, n_out: int, fs: float) -> str:
    """Describe a resampling in one sentence, for ``attrs['resampled']``.

    Parameters
    ----------
    time : numpy.ndarray, shape (N,)
        The original sample times (s).
    n_out : int
        Samples on the grid.
    fs : float
        Grid rate (Hz).

    Returns
    -------
    str
        Original sample count, median and longest step, and the grid.
    """
    steps = np.diff(time)
    return (
        f"{time.size} samples with irregular steps (median {np.median(steps) * 1e3:.4g} "
        f"ms, max {steps.max() * 1e3:.4g} ms) interpolated linearly onto {n_out} "
        f"samples at {fs:.7g} Hz"
    )


def warn_if_downsampled(fs: float, fs_source: float, what: str) -> None:
    """Warn when interpolating onto a coarser grid, which does not remove aliasing.

    Parameters
    ----------
    fs : float
        Grid rate (Hz).
    fs_source : float
        The samples' own rate (Hz).
    what : str
        The file (and stream) named in the warning.

    Warns
    -----
    tiltlab.quality.QualityWarning
        If ``fs`` is below 90 % of ``fs_source``.
    """
    if fs < 0.9 * fs_source:
        import warnings

        warnings.warn(
            f"{what}: the samples come at about {fs_source:.4g} Hz and are interpolated "
            f"onto {fs:.4g} Hz; linear interpolation does not low-pass filter, so "
            f"content above {fs / 2:.4g} Hz aliases. Low-pass filter first, or keep the "
            "native rate",
            _quality.QualityWarning,
            stacklevel=user_stacklevel(),
        )


def place_on_grid(
    time: np.ndarray,
    get: dict[str, np.ndarray],
    fs: float,
    column: str,
    where: str,
    gaps: str,
    style: str,
) -> tuple[np.ndarray, dict[str, np.ndarray], int]:
    """Place the samples of a ``clock="grid"`` time column on the ``k / fs`` grid.

    Samples missing from the time column (steps of about k/fs, k ≥ 2) are refused
    (``gaps="raise"``) or replaced by NaN rows (``"nan"``). A clock that is not on a
    ``k / fs`` grid (jitter, drift) is refused with a hint to read it with
    ``clock="resample"``. With ``"nan"``, a grid that would be more than
    :data:`MAX_MISSING_FRACTION` missing is refused (:func:`check_missing_fraction`).

    Parameters
    ----------
    time : numpy.ndarray, shape (N,)
        Sample times (s), strictly increasing.
    get : dict
        Variable → samples (N, ...).
    fs : float
        Sampling rate (Hz).
    column : str
        The time column's name.
    where : str
        Prefix (the file) for messages.
    gaps : {"raise", "nan"}
        What to do with missing samples.
    style : {"python", "mapping"}
        How the options were given, to write the fix.

    Returns
    -------
    time : numpy.ndarray
        The grid times (s).
    values : dict
        Variable → samples on the grid (NaN rows where samples are missing).
    n_missing : int
        Number of rows inserted.
    """
    segs = _validate.segments(time, fs)
    if len(segs) <= 1:
        return time, get, 0
    pos = (time - time[0]) * fs
    k = np.rint(pos).astype(np.int64)
    off = (np.abs(pos - k) > 0.35) | np.r_[False, np.diff(k) < 1]
    if np.any(off):
        i = int(np.argmax(off))
        steps = np.diff(time) * fs
        raise schema.RecordingError(
            f"{where}time column {column!r} is not on a regular grid of 1/fs = "
            f"{1 / fs:.6g} s (data row {i}: {pos[i]:.2f} sample periods after the "
            f"first; steps range from {steps.min():.3g} to {steps.max():.3g} periods): "
            "the clock jitters or drifts, or fs is wrong. Read with "
            f"{option_hint('clock', 'resample', style)} to interpolate every variable "
            "onto a uniform grid"
        )
    n_missing = int(k[-1] + 1 - k.size)
    if gaps == "raise":
        raise schema.RecordingError(
            f"{where}time column {column!r} skips samples "
            f"({_validate.describe_gaps(time, fs, segs)}"
            + (f"; about {n_missing} samples missing" if n_missing > 0 else "")
            + "): the logger dropped samples, or fs is wrong. "
            f"Read with {option_hint('gaps', 'nan', style)} to keep the gaps as NaN rows "
            "(orientation filters then run on each gap-free segment, "
            "estimate(..., gaps='segments'))"
        )
    n = int(k[-1] + 1)
    check_missing_fraction(time, n, n - k.size, fs, column, where)
    full_time = time[0] + np.arange(n) / fs
    full_time[k] = time
    out = {}
    for var, v in get.items():
        filled = np.full((n, *v.shape[1:]), np.nan)
        filled[k] = v
        out[var] = filled
    return full_time, out, n - k.size


def source_name(path: Path, variable: str | None = None) -> str:
    """Name a file (and variable) for attributes.

    Parameters
    ----------
    path : Path
        The file.
    variable : str, optional
        The variable read from it.

    Returns
    -------
    str
        ``"name.mat:variable"`` or ``"name.csv"``.
    """
    return path.name + (f":{variable}" if variable else "")
