r"""Behavioural read-outs from head inertial data: angular speed, immobility, circling.

Immobility follows Fayat et al. 2021, §2.9: a sample is still when the angular speed (norm
of the offset-corrected gyroscope) is below 12 °/s; still periods separated by less than
0.1 s are merged; still periods shorter than 0.5 s are discarded. The 12 °/s threshold was
chosen by eye at the valley of the bimodal angular-speed distribution (their Fig. A3);
:func:`valley_threshold` finds that valley automatically.

The circling index (Fayat §2.10) is the mean azimuthal angular speed — the component of
the angular velocity along the gravity-up direction, :math:`\omega_\parallel = \omega
\cdot g_s` — over periods of movement, in circles per minute; positive values are
counter-clockwise rotations seen from above.

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from scipy import ndimage, signal

from . import units as _units

__all__ = [
    "angular_speed",
    "mask_to_intervals",
    "intervals_to_mask",
    "detect_immobility",
    "valley_threshold",
    "immobility",
    "azimuthal_speed",
    "circling_index",
]


def angular_speed(gyr, units: str = "deg/s") -> np.ndarray:
    """Norm of the angular velocity, in °/s.

    Parameters
    ----------
    gyr : array_like, shape (N, 3)
        Angular velocity (offset-corrected for immobility detection).
    units : str
        Units of ``gyr`` ('deg/s' or 'rad/s').
    """
    g = np.asarray(gyr, dtype=float)
    if g.ndim != 2 or g.shape[1] != 3:
        raise ValueError(f"gyr must have shape (N, 3), got {g.shape}")
    return np.linalg.norm(g, axis=1) * _units.conversion_factor(units, "deg/s")


def mask_to_intervals(mask) -> np.ndarray:
    """Runs of True in a boolean mask as an (k, 2) integer array of half-open ``[start, stop)`` indices."""
    m = np.asarray(mask, dtype=bool)
    if m.ndim != 1:
        raise ValueError("mask must be one-dimensional")
    d = np.diff(np.concatenate([[0], m.view(np.int8), [0]]))
    return np.column_stack([np.flatnonzero(d == 1), np.flatnonzero(d == -1)]).astype(np.int64)


def intervals_to_mask(intervals, n: int) -> np.ndarray:
    """Boolean mask of length ``n`` that is True inside the half-open ``[start, stop)`` intervals."""
    iv = np.asarray(intervals, dtype=np.int64).reshape(-1, 2)
    d = np.zeros(n + 1, dtype=np.int64)
    np.add.at(d, np.clip(iv[:, 0], 0, n), 1)
    np.add.at(d, np.clip(iv[:, 1], 0, n), -1)
    return np.cumsum(d[:-1]) > 0


def detect_immobility(
    speed,
    fs: float,
    *,
    threshold: float = 12.0,
    merge_gap_s: float = 0.1,
    min_duration_s: float = 0.5,
) -> np.ndarray:
    """Fayat et al.'s immobility mask from an angular-speed series.

    Parameters
    ----------
    speed : array_like, shape (N,)
        Angular speed in °/s (see :func:`angular_speed`).
    fs : float
        Sampling rate (Hz).
    threshold : float
        Speed (°/s) below which a sample is still (Fayat: 12 °/s).
    merge_gap_s : float
        Still periods separated by a gap shorter than this (s) are merged (Fayat: 0.1 s).
    min_duration_s : float
        Still periods shorter than this (s), after merging, are discarded (Fayat: 0.5 s).

    Returns
    -------
    numpy.ndarray of bool, shape (N,)
        True where the animal is immobile.
    """
    if fs is None or not np.isfinite(fs) or fs <= 0:
        raise ValueError(f"fs must be a positive number of Hz, got {fs!r}")
    s = np.asarray(speed, dtype=float)
    if s.ndim != 1:
        raise ValueError("speed must be one-dimensional")
    if np.isnan(s).any():
        raise ValueError("speed has NaN values; fill or drop gaps first")
    iv = mask_to_intervals(s < threshold)
    if len(iv) == 0:
        return np.zeros(s.size, dtype=bool)
    # merge: a gap between consecutive still periods shorter than merge_gap_s is filled
    gaps = iv[1:, 0] - iv[:-1, 1]
    keep_break = gaps >= merge_gap_s * fs
    starts = np.concatenate([[iv[0, 0]], iv[1:, 0][keep_break]])
    stops = np.concatenate([iv[:-1, 1][keep_break], [iv[-1, 1]]])
    long_enough = (stops - starts) >= min_duration_s * fs
    return intervals_to_mask(np.column_stack([starts, stops])[long_enough], s.size)


def valley_threshold(
    speed,
    *,
    log_range: tuple[float, float] = (-1.0, 3.5),
    bins: int = 120,
    smooth_bins: float = 2.0,
    min_prominence: float = 0.1,
) -> float:
    """Angular-speed threshold at the valley between the still and moving modes.

    The histogram of :math:`\\log_{10}` speed is smoothed with a Gaussian kernel; its two most
    prominent peaks are taken as the still and moving modes, and the threshold is the
    minimum of the smoothed histogram between them.

    Parameters
    ----------
    speed : array_like
        Angular speed (°/s).
    log_range : tuple of float
        Range of :math:`\\log_{10}` speed histogrammed.
    bins : int
        Number of histogram bins.
    smooth_bins : float
        Standard deviation of the Gaussian smoothing, in bins.
    min_prominence : float
        Minimum peak prominence as a fraction of the highest peak.

    Returns
    -------
    float
        Threshold in °/s.

    Raises
    ------
    ValueError
        If the distribution does not have two modes.
    """
    s = np.asarray(speed, dtype=float)
    s = s[np.isfinite(s) & (s > 0)]
    if s.size < 100:
        raise ValueError("need at least 100 positive speed samples to find a valley")
    h, edges = np.histogram(np.log10(s), bins=bins, range=log_range)
    hs = ndimage.gaussian_filter1d(h.astype(float), smooth_bins, mode="constant")
    peaks, props = signal.find_peaks(hs, prominence=min_prominence * hs.max())
    if len(peaks) < 2:
        raise ValueError("the angular-speed distribution is not bimodal: no valley to put a threshold in")
    top2 = np.sort(peaks[np.argsort(props["prominences"])[-2:]])
    valley = top2[0] + int(np.argmin(hs[top2[0] : top2[1] + 1]))
    centres = 0.5 * (edges[:-1] + edges[1:])
    return float(10.0 ** centres[valley])


def immobility(
    rec: xr.Dataset,
    *,
    threshold: float | str = 12.0,
    gyr_offset=None,
    merge_gap_s: float = 0.1,
    min_duration_s: float = 0.5,
) -> xr.DataArray:
    """Immobility mask of a Recording.

    Parameters
    ----------
    rec : xarray.Dataset
        Recording with ``gyr`` and attribute ``fs``.
    threshold : float or "auto"
        Angular-speed threshold in °/s, or ``"auto"`` for :func:`valley_threshold`.
    gyr_offset : array_like, shape (3,), optional
        Gyroscope offset (in the units of ``rec.gyr``) subtracted first.

    Returns
    -------
    xarray.DataArray of bool (time)
        With attributes ``threshold_deg_s``, ``threshold_method``, ``merge_gap_s``,
        ``min_duration_s``.
    """
    if "fs" not in rec.attrs:
        raise ValueError("the Recording has no 'fs' attribute")
    gyr = np.asarray(rec["gyr"].values, dtype=float)
    if gyr_offset is not None:
        gyr = gyr - np.asarray(gyr_offset, dtype=float)
    speed = angular_speed(gyr, rec["gyr"].attrs["units"])
    if isinstance(threshold, str):
        if threshold != "auto":
            raise ValueError(f"threshold must be a number of °/s or 'auto', got {threshold!r}")
        thr, method = valley_threshold(speed), "valley of the log angular-speed histogram"
    else:
        thr, method = float(threshold), "fixed"
    mask = detect_immobility(speed, float(rec.attrs["fs"]), threshold=thr, merge_gap_s=merge_gap_s, min_duration_s=min_duration_s)
    return xr.DataArray(
        mask,
        coords={"time": rec["time"]},
        dims=("time",),
        name="immobile",
        attrs={"threshold_deg_s": thr, "threshold_method": method, "merge_gap_s": merge_gap_s, "min_duration_s": min_duration_s},
    )


def azimuthal_speed(gyr, g) -> np.ndarray:
    r"""Angular speed about the gravity-up axis, :math:`\omega \cdot \hat g_s` (units of ``gyr``).

    Parameters
    ----------
    gyr : array_like, shape (N, 3)
        Angular velocity in the sensor frame.
    g : array_like, shape (N, 3)
        Gravity-up direction in the sensor frame (normalised here).

    Notes
    -----
    Equal to the z component of the angular velocity expressed in any gravity-aligned
    frame (Fayat §2.10 rotates the gyroscope by the inverse of the quaternion aligning the
    sensor z axis with gravity, then takes z). Positive = counter-clockwise seen from above.
    """
    w = np.asarray(gyr, dtype=float)
    gg = np.asarray(g, dtype=float)
    if w.shape != gg.shape or w.ndim != 2 or w.shape[1] != 3:
        raise ValueError(f"gyr and g must both have shape (N, 3), got {w.shape} and {gg.shape}")
    return np.sum(w * gg, axis=1) / np.linalg.norm(gg, axis=1)


def circling_index(gyr_deg_s, g, moving=None) -> float:
    """Mean azimuthal angular speed over movement, in circles per minute (CCW positive).

    Parameters
    ----------
    gyr_deg_s : array_like, shape (N, 3)
        Offset-corrected angular velocity, °/s.
    g : array_like, shape (N, 3)
        Gravity-up direction in the sensor frame.
    moving : array_like of bool, shape (N,), optional
        Samples to average over (Fayat: periods of movement); default all.
    """
    az = azimuthal_speed(gyr_deg_s, g)
    if moving is not None:
        m = np.asarray(moving, dtype=bool)
        if m.shape != az.shape:
            raise ValueError("moving must have one value per sample")
        if not m.any():
            raise ValueError("no movement samples to average over")
        az = az[m]
    return float(np.mean(az) * 60.0 / 360.0)
