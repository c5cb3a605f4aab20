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
from .intervals import intervals_to_mask, mask_to_intervals, samples_below

__all__ = [
    "angular_speed",
    "detect_immobility",
    "speed_modes",
    "valley_threshold",
    "recording_speed",
    "gyro_spectrum",
    "realism_table",
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
    iv = mask_to_intervals(
        s < threshold,
        merge_gap=samples_below(merge_gap_s, fs),  # gaps strictly shorter than merge_gap_s
        min_length=int(np.ceil(min_duration_s * fs)),
    )
    return intervals_to_mask(iv, s.size)


def speed_modes(
    speed,
    *,
    log_range: tuple[float, float] = (-1.0, 3.5),
    bins: int = 120,
    smooth_bins: float = 2.0,
    min_prominence: float = 0.05,
    min_separation: float = 0.5,
) -> dict[str, float]:
    r"""Still mode, moving mode and the valley between them in an angular-speed distribution.

    The histogram of :math:`\log_{10}` speed is smoothed with a Gaussian kernel; among its
    peaks with a prominence of at least ``min_prominence`` times the highest peak, the
    most prominent one and the most prominent one at least ``min_separation`` decades
    away from it are the two modes; the valley is the minimum of the smoothed histogram
    between them (Fayat et al. Fig. A3 place their 12 °/s threshold there by eye).

    Parameters
    ----------
    speed : array_like
        Angular speed (°/s); non-positive and non-finite values are ignored.
    log_range : tuple of float
        Range of :math:`\log_{10}` speed histogrammed.
    bins : int
        Number of histogram bins.
    smooth_bins : float
        Standard deviation of the Gaussian smoothing, in bins.
    min_prominence : float
        Minimum peak prominence, as a fraction of the highest peak.
    min_separation : float
        Minimum distance between the two modes, in decades.

    Returns
    -------
    dict
        ``still_mode``, ``valley``, ``moving_mode`` (°/s) and ``depth`` (smoothed height of
        the valley over that of the lower mode); all NaN when the distribution has no
        second mode.
    """
    s = np.asarray(speed, dtype=float)
    s = s[np.isfinite(s) & (s > 0)]
    nan = {"still_mode": np.nan, "valley": np.nan, "moving_mode": np.nan, "depth": np.nan}
    if s.size < 100:
        return nan
    h, edges = np.histogram(np.log10(s), bins=bins, range=log_range)
    hs = ndimage.gaussian_filter1d(h.astype(float), smooth_bins, mode="constant")
    centres = 0.5 * (edges[:-1] + edges[1:])
    peaks, props = signal.find_peaks(hs, prominence=min_prominence * hs.max())
    if len(peaks) < 2:
        return nan
    order = peaks[np.argsort(props["prominences"])[::-1]]
    first = order[0]
    second = next((p for p in order[1:] if abs(centres[p] - centres[first]) >= min_separation), None)
    if second is None:
        return nan
    lo, hi = sorted((int(first), int(second)))
    valley = lo + int(np.argmin(hs[lo : hi + 1]))
    return {
        "still_mode": float(10.0 ** centres[lo]),
        "valley": float(10.0 ** centres[valley]),
        "moving_mode": float(10.0 ** centres[hi]),
        "depth": float(hs[valley] / min(hs[lo], hs[hi])),
    }


def valley_threshold(speed, **kwargs) -> float:
    """Angular-speed threshold (°/s) at the valley between the still and moving modes.

    See :func:`speed_modes` for the method and keyword arguments.

    Raises
    ------
    ValueError
        If the distribution does not have two modes.
    """
    m = speed_modes(speed, **kwargs)
    if not np.isfinite(m["valley"]):
        raise ValueError("the angular-speed distribution is not bimodal: no valley to put a threshold in")
    return m["valley"]


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


def recording_speed(rec: xr.Dataset, *, offset="auto") -> np.ndarray:
    """Angular speed (°/s) of a Recording, gyroscope offset removed.

    Parameters
    ----------
    rec : xarray.Dataset
        Recording with ``gyr`` and ``fs``.
    offset : "auto", None or array_like (3,)
        ``"auto"``: the true mean offset of a simulated recording (attribute
        ``true_gyr_offset_mean``, °/s) if present, else a first-pass estimate from the
        quietest windows (:func:`tiltlab.calibration.robust_gyro_offset`); ``None``: no
        correction; or the offset in the units of ``rec.gyr``.
    """
    from .calibration import robust_gyro_offset

    units = rec["gyr"].attrs["units"]
    gyr = np.asarray(rec["gyr"].values, dtype=float)
    if isinstance(offset, str):
        if offset != "auto":
            raise ValueError(f"offset must be 'auto', None or 3 numbers, got {offset!r}")
        if "true_gyr_offset_mean" in rec.attrs:
            off = np.asarray(rec.attrs["true_gyr_offset_mean"], float) * _units.conversion_factor("deg/s", units)
        else:
            off = robust_gyro_offset(gyr, float(rec.attrs["fs"]))
    elif offset is None:
        off = np.zeros(3)
    else:
        off = np.asarray(offset, float).reshape(3)
    return angular_speed(gyr - off, units)


def gyro_spectrum(rec: xr.Dataset, *, nperseg_s: float = 5.12) -> tuple[np.ndarray, np.ndarray]:
    """Welch power spectral density of the gyroscope, summed over axes ((°/s)²/Hz).

    Returns
    -------
    f : numpy.ndarray
        Frequencies (Hz).
    psd : numpy.ndarray
        Power spectral density.
    """
    fs = float(rec.attrs["fs"])
    gyr = np.asarray(rec["gyr"].values, float) * _units.conversion_factor(rec["gyr"].attrs["units"], "deg/s")
    nper = min(gyr.shape[0], int(round(nperseg_s * fs)))
    f, p = signal.welch(gyr - gyr.mean(axis=0), fs=fs, nperseg=nper, axis=0)
    return f, p.sum(axis=1)


def realism_table(recs, *, threshold_dps: float = 12.0):
    """Side-by-side activity statistics of several recordings (one column each).

    Rows: duration; still mode, valley, moving mode and valley depth of the angular-speed
    distribution (:func:`speed_modes` on :func:`recording_speed`); fraction of samples
    below ``threshold_dps``; percentiles of ‖acc‖ (g), overall and while moving; the
    largest peak of the gyroscope spectrum above 0.5 Hz, its median frequency (half the
    power above 0.5 Hz lies below it) and the share of power above 10 Hz.

    Parameters
    ----------
    recs : mapping of str to xarray.Dataset
        Recordings by column name.
    threshold_dps : float
        Angular-speed threshold (°/s) separating still and moving samples.

    Returns
    -------
    pandas.DataFrame
    """
    import pandas as pd

    cols = {}
    for name, rec in recs.items():
        sp = recording_speed(rec)
        m = speed_modes(sp)
        acc = np.asarray(rec["acc"].values, float) * _units.conversion_factor(rec["acc"].attrs["units"], "g")
        an = np.linalg.norm(acc, axis=1)
        mov = sp >= threshold_dps
        f, p = gyro_spectrum(rec)
        band = f > 0.5
        cum = np.cumsum(p[band])
        cols[name] = {
            "duration (s)": rec.sizes["time"] / float(rec.attrs["fs"]),
            "still mode (deg/s)": m["still_mode"],
            "valley (deg/s)": m["valley"],
            "moving mode (deg/s)": m["moving_mode"],
            "valley depth (rel. to lower mode)": m["depth"],
            f"fraction < {threshold_dps:g} deg/s": float(np.mean(~mov)),
            "|acc| p5 (g)": np.percentile(an, 5),
            "|acc| p50 (g)": np.percentile(an, 50),
            "|acc| p95 (g)": np.percentile(an, 95),
            "|acc| p5 moving (g)": np.percentile(an[mov], 5) if mov.any() else np.nan,
            "|acc| p95 moving (g)": np.percentile(an[mov], 95) if mov.any() else np.nan,
            "gyro spectral peak (Hz)": f[band][np.argmax(p[band])],
            "gyro median frequency (Hz)": f[band][np.searchsorted(cum, cum[-1] / 2)],
            "gyro power share > 10 Hz": float(p[f > 10].sum() / p.sum()),
        }
    return pd.DataFrame(cols)
