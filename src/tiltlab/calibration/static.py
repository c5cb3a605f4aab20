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

The thresholding is tiltlab's one still-period detector, :func:`tiltlab.dsp.still_mask`
(smooth → threshold → merge gaps → trim edges → drop short periods); its thresholds are
in °/s, and gyroscopes in rad/s are converted first.

Inputs are Recordings (their ``gyr``), labelled DataArrays (``fs`` and ``units`` from the
attrs) or plain arrays in °/s with an explicit ``fs``.

Intervals are integer arrays of shape (P, 2) holding ``[start, stop)`` sample indices.

References
----------
.. [1] R. Fayat et al., "Inertial measurement of head tilt in rodents: principles and
   applications to vestibular research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np
import xarray as xr

from .._stack import user_stacklevel
from .. import _validate as _v
from .. import units as _units
from .._deprecate import renamed
from ..dsp import still_mask
from ..intervals import intervals_to_mask, mask_to_intervals
from ..quality import QualityWarning
from ._util import CalibrationError, read_in, vec3, window_count

__all__ = [
    "mask_to_intervals",
    "intervals_to_mask",
    "static_intervals_from_trigger",
    "robust_gyro_offset",
    "detect_static",
    "StillCriteria",
    "StaticStats",
    "static_means",
    "gyro_offset",
]


def _check_intervals(intervals, n: int) -> np.ndarray:
    iv = np.asarray(intervals, dtype=np.int64).reshape(-1, 2)
    if np.any(iv[:, 0] < 0) or np.any(iv[:, 1] > n) or np.any(iv[:, 1] <= iv[:, 0]):
        raise ValueError(f"intervals must satisfy 0 <= start < stop <= {n}")
    return iv


def static_intervals_from_trigger(
    trigger,
    fs: float | None = None,
    *,
    window_s: float = 0.4,
    gap_s: float = 0.0,
    level: float = 0.5,
) -> np.ndarray:
    """Still periods defined by a digital trigger: the ``window_s`` preceding each rising edge.

    Fayat et al. [1]_ (§2.5) used the 400 ms of immobility preceding each trigger, which
    the stage emitted at the onset of every new rotation.

    Parameters
    ----------
    trigger : Recording, DataArray or array_like (N,)
        Trigger channel (a Recording's ``trigger`` variable); a rising edge is a
        crossing of ``level`` from below.
    fs : float, optional
        Sampling rate (Hz); read from the attrs of labelled input, mandatory for a
        plain array.
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
    s = _v.signal(trigger, "trigger", fs=fs, width=None, ndim=1)
    fs = s.fs
    window_s = _v.positive(window_s, "window_s")
    gap_s = _v.nonnegative(gap_s, "gap_s")
    level = _v.finite(level, "level")
    hi = s.values > level
    edges = np.flatnonzero(hi[1:] & ~hi[:-1]) + 1
    w, g = int(round(window_s * fs)), int(round(gap_s * fs))
    if w < 1:
        raise ValueError(
            f"window_s = {window_s!r} s is shorter than one sample at fs = {fs:g} Hz"
        )
    stops = edges - g
    starts = stops - w
    ok = starts >= 0
    return np.column_stack([starts[ok], stops[ok]]).astype(np.int64).reshape(-1, 2)


#: Largest gyroscope offset (norm, °/s) that :func:`robust_gyro_offset` accepts by
#: default. Datasheet zero-rate-output tolerances of MEMS gyroscopes are ±1 to ±20 °/s
#: per axis (e.g. MPU-6050 ±20, MPU-9250 ±5, BMI160 ±3 °/s), i.e. at most about
#: √3 · 20 ≈ 35 °/s in norm; Fayat et al.'s 5th–95th percentiles are −22.6 to 10.5 °/s.
MAX_GYRO_OFFSET_DEG_S: float = 40.0


def robust_gyro_offset(
    gyr,
    fs: float | None = None,
    *,
    window_s: float = 0.5,
    quantile: float = 0.2,
    units: str | None = None,
    max_offset_deg_s: float | None = MAX_GYRO_OFFSET_DEG_S,
    on_rotation: str = "warn",
) -> np.ndarray:
    """First-pass gyroscope offset from the quietest windows of a recording.

    The record is cut into non-overlapping windows of ``window_s``; the windows whose
    total gyroscope variance is within the lowest ``quantile`` are taken as still, and
    the per-axis median of their samples is returned. Variance does not depend on the
    offset, so this works for offsets of tens of °/s, and it needs only ``quantile`` of
    the record to be still. Windows holding a non-finite sample (a gap) are left out.

    Sustained rotation is flagged. A steady rotation (an animal circling, a turntable)
    is as quiet as a sensor at rest: its windows have the same low variance, and from
    the gyroscope alone nothing tells a constant rate from an offset (the accelerometer
    does not either for a rotation about the vertical). What does is the size: a
    MEMS gyroscope's offset is bounded by its datasheet tolerance, so an estimate whose
    norm exceeds ``max_offset_deg_s`` (default :data:`MAX_GYRO_OFFSET_DEG_S`, 40 °/s)
    is taken for rotation during the quietest windows — a session with no still
    period — whose removal would erase the movement (and make every sample look
    immobile). It gives a :class:`~tiltlab.quality.QualityWarning` saying so
    (``on_rotation="warn"``, the default, since the estimate is also the first pass of
    :func:`detect_static` and of the ``"auto"`` offsets of :mod:`tiltlab.behavior` and
    :mod:`tiltlab.cohort`), or a :class:`CalibrationError` (``on_rotation="raise"``).

    Parameters
    ----------
    gyr : Recording, DataArray or array_like (N, 3)
        Angular velocity (a Recording's ``gyr``).
    fs : float, optional
        Sampling rate (Hz); read from the attrs of labelled input, mandatory for a
        plain array.
    window_s : float
        Window length (s).
    quantile : float
        Fraction of the windows (the quietest) taken as still, in (0, 1].
    units : str, optional
        Units of a plain-array ``gyr`` (``"deg/s"`` or ``"rad/s"``), used only for the
        plausibility check; labelled input carries its own. A plain array without
        ``units`` is checked as if in °/s, which never refuses a true offset given in
        rad/s (its numbers are smaller) but may miss a rotation given in rad/s.
    max_offset_deg_s : float or None
        Largest plausible offset norm (°/s); ``None`` (or ``inf``) disables the check,
        e.g. for a gyroscope known to have a larger offset.
    on_rotation : {"warn", "raise"}
        What an estimate above ``max_offset_deg_s`` gives: a warning (the estimate is
        still returned) or an error.

    Returns
    -------
    ndarray (3,)
        The offset, in the units of ``gyr``.

    Raises
    ------
    CalibrationError
        A recording shorter than one window, windows that all hold a gap, or, with
        ``on_rotation="raise"``, an estimate larger than ``max_offset_deg_s``
        (sustained rotation; the message gives the rate).

    Warns
    -----
    tiltlab.quality.QualityWarning
        An estimate larger than ``max_offset_deg_s`` (``on_rotation="warn"``).
    """
    s = _v.signal(gyr, "gyr", fs=fs, units=units, allow_nan=True)
    window_s = _v.positive(window_s, "window_s")
    quantile = _v.fraction(quantile, "quantile", open_low=True)
    if max_offset_deg_s is not None:
        max_offset_deg_s = _v.positive(
            max_offset_deg_s, "max_offset_deg_s", allow_inf=True
        )
    if on_rotation not in ("warn", "raise"):
        raise ValueError(f"on_rotation must be 'warn' or 'raise', got {on_rotation!r}")
    g = s.values
    w, nw = window_count(
        g.shape[0], window_s, s.fs, 2, ("recording", ": cannot estimate a gyro offset")
    )
    blocks = g[: nw * w].reshape(nw, w, 3)
    var = blocks.var(axis=1).sum(axis=1)  # NaN for a window that holds a gap
    ok = np.isfinite(var)
    if not ok.any():
        raise CalibrationError(
            f"every {window_s:g}-s window of gyr holds a non-finite sample: cannot "
            "estimate a gyro offset"
        )
    quiet = ok & (var <= np.quantile(var[ok], quantile))
    offset = np.median(blocks[quiet].reshape(-1, 3), axis=0)
    if max_offset_deg_s is not None:
        factor = 1.0 if s.units is None else _units.conversion_factor(s.units, "deg/s")
        rate = float(np.linalg.norm(offset)) * factor
        if rate > max_offset_deg_s:
            msg = (
                f"gyr: even the quietest {window_s:g}-s windows rotate steadily at "
                f"{rate:.3g} °/s, more than a MEMS gyroscope offset can be "
                f"(max_offset_deg_s = {max_offset_deg_s:g} °/s): this looks like "
                "sustained rotation (e.g. circling, or no still period at all), not a "
                "sensor offset, and removing it would erase the movement. Estimate "
                "the offset from a still recording and pass it explicitly, or raise "
                "max_offset_deg_s if the sensor really has this offset"
            )
            if on_rotation == "raise":
                raise CalibrationError(msg)
            warnings.warn(msg, QualityWarning, stacklevel=user_stacklevel())
    return offset


@dataclass(frozen=True)
class StillCriteria:
    """Settings of the threshold still-period detector of :func:`detect_static`.

    The values are checked when :func:`detect_static` uses them.

    Parameters
    ----------
    threshold_deg_s : float
        Angular-speed threshold (°/s) on the offset-corrected, smoothed norm.
    smooth_s : float
        Width (s) of the moving average applied to the angular speed.
    min_duration_s : float
        Shortest still period kept (s).
    merge_gap_s : float
        Still runs separated by less than this (s) are merged.
    trim_s : float, optional
        Duration (s) trimmed at both ends of each run; default half of ``smooth_s``.
    acc_std_threshold_g : float, optional
        Largest moving standard deviation of ‖a‖ (g) at rest; ``None`` disables the
        acceleration criterion.
    """

    threshold_deg_s: float = 3.0
    smooth_s: float = 0.1
    min_duration_s: float = 0.4
    merge_gap_s: float = 0.0
    trim_s: float | None = None
    acc_std_threshold_g: float | None = None


def _criteria(criteria: StillCriteria | None, options: dict) -> StillCriteria:
    # the criteria record with keyword overrides (detect_static's **options)
    crit = StillCriteria() if criteria is None else criteria
    if not isinstance(crit, StillCriteria):
        raise TypeError(f"criteria must be a StillCriteria, got {type(crit).__name__}")
    unknown = sorted(set(options) - set(StillCriteria.__dataclass_fields__))
    if unknown:
        raise TypeError(
            f"detect_static() got unexpected keyword argument(s) {', '.join(unknown)}"
        )
    return replace(crit, **options)


def _acc_norm(acc, gyr, fs, shape) -> np.ndarray:
    # ‖a‖ (g) for the acceleration criterion; a Recording ``gyr`` lends its ``acc``
    if acc is None and isinstance(gyr, xr.Dataset):
        acc = gyr
    if acc is None:
        raise ValueError("acc_std_threshold_g needs acc (the acceleration)")
    a, _ = read_in(acc, "acc", "g", fs=fs, need_fs=False)
    if a.values.shape != shape:
        raise ValueError(
            f"acc and gyr must have the same shape, got {a.values.shape} and {shape}"
        )
    return np.linalg.norm(a.values, axis=1)


@renamed(offset="gyr_offset")
def detect_static(
    gyr,
    fs: float | None = None,
    *,
    units: str | None = None,
    acc=None,
    trigger=None,
    gyr_offset=None,
    trigger_window_s: float = 0.4,
    criteria: StillCriteria | None = None,
    **options,
) -> np.ndarray:
    r"""Find the still periods of a calibration recording.

    With a ``trigger`` channel, the ``trigger_window_s`` before each rising edge
    (:func:`static_intervals_from_trigger`). Otherwise: (1) convert the gyroscope to
    °/s and subtract a first-pass offset (``gyr_offset`` or :func:`robust_gyro_offset`);
    (2)–(5) the still-period detector :func:`tiltlab.dsp.still_mask` on the angular
    speed :math:`\|\omega - o\|`: smoothing by a ``smooth_s`` moving average, samples
    below ``threshold_deg_s`` (and, if ``acc_std_threshold_g`` is given, whose moving
    standard deviation of :math:`\|a\|` is below it), merging of runs separated by
    less than ``merge_gap_s``, trimming of ``trim_s`` at both ends of each run (default
    half the smoothing window, which the moving average spreads into the movement),
    removal of runs shorter than ``min_duration_s``. These settings are the fields of
    :class:`StillCriteria`; pass a record as ``criteria``, or any field as a keyword.

    Parameters
    ----------
    gyr : Recording, DataArray or array_like (N, 3)
        Angular velocity (a Recording's ``gyr``). Labelled input carries its units
        (°/s or rad/s: the thresholds are converted); a plain array is in ``units``,
        default °/s.
    fs : float, optional
        Sampling rate (Hz); read from the attrs of labelled input, mandatory for a
        plain array.
    units : str, optional
        Units of a plain-array ``gyr`` (``"deg/s"`` if not given); for labelled input
        it must agree with the attrs.
    acc : Recording, DataArray or array_like (N, 3), optional
        Acceleration, for the optional acceleration criterion (labelled: converted to
        g; plain: in g). Default: the Recording's ``acc`` when ``gyr`` is a Recording.
    trigger : DataArray or array_like (N,), optional
        Trigger channel; when given, thresholds are not used.
    gyr_offset : array_like (3,), optional
        Gyroscope offset, in the units of ``gyr``, to subtract instead of the robust
        first pass (formerly ``offset``, which still works with a ``FutureWarning``).
    trigger_window_s : float
        Duration of each trigger-defined still period (s).
    criteria : StillCriteria, optional
        Detector settings (default ``StillCriteria()``: 3 °/s, 0.1-s smoothing,
        periods of at least 0.4 s).
    **options
        Fields of :class:`StillCriteria` (``threshold_deg_s``, ``smooth_s``,
        ``min_duration_s``, ``merge_gap_s``, ``trim_s``, ``acc_std_threshold_g``)
        overriding those of ``criteria``.

    Returns
    -------
    ndarray (P, 2)
        ``[start, stop)`` sample indices of the still periods.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import calibration
    >>> rng = np.random.default_rng(0)
    >>> gyr = rng.normal(0.0, 0.2, (500, 3)) + [5.0, -2.0, 1.0]  # offset, °/s
    >>> gyr[200:300, 2] += 90.0 * np.sin(np.linspace(0.0, np.pi, 100))  # one turn
    >>> calibration.detect_static(gyr, 100.0).tolist()
    [[5, 195], [306, 495]]

    Without the first-pass offset, the 5.5 °/s offset hides every still sample:

    >>> calibration.detect_static(gyr, 100.0, gyr_offset=[0.0, 0.0, 0.0]).tolist()
    []
    """
    crit = _criteria(criteria, options)
    s, factor = read_in(gyr, "gyr", "deg/s", fs=fs, units=units)
    g, fs = s.values, s.fs
    if trigger is not None:
        tr = _v.signal(trigger, "trigger", fs=fs, width=None, ndim=1)
        if tr.values.shape != (g.shape[0],):
            raise ValueError(
                f"trigger must have shape ({g.shape[0]},), got {tr.values.shape}"
            )
        return static_intervals_from_trigger(tr.values, fs, window_s=trigger_window_s)
    smooth_s = _v.nonnegative(crit.smooth_s, "smooth_s")
    trim_s = (
        0.5 * smooth_s if crit.trim_s is None else _v.nonnegative(crit.trim_s, "trim_s")
    )
    if gyr_offset is None:
        o = robust_gyro_offset(g, fs)
    else:
        o = vec3(gyr_offset, "gyr_offset", ndim=1) * factor
    acc_std = crit.acc_std_threshold_g
    acc_norm = None
    if acc_std is not None:
        acc_std = _v.positive(acc_std, "acc_std_threshold_g")
        acc_norm = _acc_norm(acc, gyr, fs, g.shape)
    mask = still_mask(
        np.linalg.norm(g - o, axis=1),
        fs,
        threshold=_v.positive(crit.threshold_deg_s, "threshold_deg_s"),
        smooth_s=smooth_s,
        acc_norm=acc_norm,
        acc_std_threshold=acc_std,
        merge_gap_s=crit.merge_gap_s,
        min_duration_s=crit.min_duration_s,
        trim_s=trim_s,
    )
    return mask_to_intervals(mask)


class StaticStats(NamedTuple):
    """Statistics of each still period (result of :func:`static_means`).

    Per-period statistics: ``mean`` (P, 3), ``sem`` (P, 3) standard error of the mean,
    ``std`` (P, 3) and ``n`` (P,) sample counts.
    """

    mean: np.ndarray
    sem: np.ndarray
    std: np.ndarray
    n: np.ndarray


def static_means(
    x,
    intervals,
    *,
    var: str = "acc",
    full_scale: float | None = None,
    min_periods: int = 1,
) -> StaticStats:
    """Mean, standard error and standard deviation of a 3-axis signal in each still period.

    Parameters
    ----------
    x : Recording, DataArray or array_like (N, 3)
        The signal (for a Recording, its variable ``var``); statistics are in its units.
    intervals : array_like (P, 2)
        ``[start, stop)`` sample indices (e.g. from :func:`detect_static`).
    var : str
        Variable read from a Recording.
    full_scale : float, optional
        Sensor full scale in the units of ``x``; a period containing a sample within
        0.1 % of it is saturated and raises :class:`CalibrationError` (a clipped mean
        would bias any fit).
    min_periods : int
        Minimum number of periods required.

    Returns
    -------
    StaticStats
        Per-period ``mean``, ``sem``, ``std`` (P, 3) and sample counts ``n`` (P,).

    Notes
    -----
    The standard error assumes independent samples (white noise); with coloured noise it
    is optimistic. Samples outside the periods may be NaN (gaps); a period that holds a
    non-finite sample is a ``ValueError``.
    """
    # NaN (a gap) is allowed outside the still periods, not inside them
    a = _v.signal(x, "x", var=var, need_fs=False, allow_nan=True).values
    iv = _check_intervals(intervals, a.shape[0])
    for k, (s, e) in enumerate(iv):
        if not np.isfinite(a[s:e]).all():
            raise ValueError(
                f"still period {k} (samples {s}:{e}) holds non-finite samples (a gap): "
                "still periods must lie outside gaps"
            )
    if full_scale is not None:
        full_scale = _v.positive(full_scale, "full_scale")
    min_periods = _v.integer(min_periods, "min_periods", minimum=0)
    if iv.shape[0] < min_periods:
        raise CalibrationError(
            f"found {iv.shape[0]} still periods, at least {min_periods} are needed"
        )
    means, sems, stds, ns = [], [], [], []
    for k, (s, e) in enumerate(iv):
        seg = a[s:e]
        if full_scale is not None and np.any(np.abs(seg) >= 0.999 * full_scale):
            raise CalibrationError(
                f"still period {k} (samples {s}:{e}) contains saturated samples "
                f"(|x| reaches the full scale {full_scale})"
            )
        n = seg.shape[0]
        sd = seg.std(axis=0, ddof=1) if n > 1 else np.full(3, np.nan)
        means.append(seg.mean(axis=0))
        stds.append(sd)
        sems.append(sd / np.sqrt(n))
        ns.append(n)
    return StaticStats(
        np.array(means).reshape(-1, 3),
        np.array(sems).reshape(-1, 3),
        np.array(stds).reshape(-1, 3),
        np.array(ns, dtype=np.int64),
    )


def gyro_offset(gyr, intervals) -> tuple[np.ndarray, np.ndarray]:
    """Gyroscope offset as the median angular velocity during still periods (Fayat §2.5).

    Parameters
    ----------
    gyr : Recording, DataArray or array_like (N, 3)
        Angular velocity (a Recording's ``gyr``).
    intervals : array_like (P, 2)
        Still periods, ``[start, stop)`` sample indices.

    Returns
    -------
    offset : ndarray (3,)
        Median of all still samples, in the units of ``gyr``.
    stderr : ndarray (3,)
        Standard error: the larger of the spread of per-period medians over √P (P ≥ 2)
        and the white-noise standard error of a median, 1.2533 σ/√n.
    """
    g = _v.signal(gyr, "gyr", need_fs=False, allow_nan=True).values
    iv = _check_intervals(intervals, g.shape[0])
    if iv.shape[0] == 0:
        raise CalibrationError("no still period: cannot estimate gyroscope offsets")
    allv = np.concatenate([g[s:e] for s, e in iv])
    if not np.isfinite(allv).all():
        raise ValueError(
            "a still period holds non-finite gyr samples (a gap): still periods must "
            "lie outside gaps"
        )
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
