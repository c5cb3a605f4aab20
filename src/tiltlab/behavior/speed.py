r"""Angular speed of the head and its distribution (Fayat et al. 2021 §2.9, Fig. A3).

The angular speed is the norm of the (offset-corrected) gyroscope, in °/s whatever the
gyroscope's units: they are read from the data (a Recording's ``gyr`` or a labelled
DataArray) or given with ``units=`` for a plain array. Its log-histogram is bimodal
(still and moving); :func:`speed_modes` finds the two modes and the valley between
them, where Fayat et al. put their 12 °/s immobility threshold by eye.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage, signal

from .. import _validate as _v
from .. import units as _units
from .._deprecate import renamed
from ._common import label, need_gyr, read_behavior_input, read_speed

__all__ = [
    "angular_speed",
    "speed_modes",
    "valley_threshold",
    "recording_speed",
    "gyro_spectrum",
]


#: what to use instead of a gyroscope-based read-out on an accelerometer-only Recording
NO_GYRO_HINT = (
    "on accelerometer-only data use behavior.immobility (its accelerometer rule) and "
    "behavior.dba for activity"
)


def _read_gyr(gyr, fs, units, *, need_fs=False, allow_nan=True, what="angular speed"):
    need_gyr(gyr, what, NO_GYRO_HINT)
    return read_behavior_input(
        gyr,
        "gyr",
        fs=fs,
        units=units,
        need_fs=need_fs,
        need_units=True,
        allow_nan=allow_nan,
    )


def _offset(gyr: _v.Signal, offset, name: str = "gyr_offset") -> np.ndarray:
    """Gyroscope offset in the units of ``gyr``: "auto", None or 3 numbers."""
    if isinstance(offset, str):
        if offset != "auto":
            raise ValueError(
                f"{name} must be 'auto', None or 3 numbers, got {offset!r}"
            )
        from ..calibration import robust_gyro_offset

        if gyr.fs is None:
            raise _v.RecordingError(
                f"{name}='auto' needs the sampling rate fs of gyr (pass fs= or add "
                "attrs['fs'])"
            )
        return np.asarray(
            robust_gyro_offset(gyr.values, gyr.fs, units=gyr.units), float
        )
    if offset is None:
        return np.zeros(3)
    return _v.vectors(offset, name, width=3, ndim=1)


def _speed(gyr: _v.Signal, off: np.ndarray) -> np.ndarray:
    factor = _units.conversion_factor(gyr.units, "deg/s")
    return np.linalg.norm(gyr.values - off, axis=1) * factor


def angular_speed(gyr, fs=None, *, units: str | None = None):
    """Norm of the angular velocity, in °/s.

    Parameters
    ----------
    gyr : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        Angular velocity (offset-corrected for immobility detection): a Recording (its
        ``gyr``), a labelled DataArray, or a plain array with ``units``.
    fs : float, optional
        Sampling rate (Hz), carried to a labelled output (read from its attributes).
    units : str, optional
        Units of a plain ``gyr`` ('deg/s' or 'rad/s'); labelled input carries them.

    Returns
    -------
    numpy.ndarray or xarray.DataArray (time)
        °/s; a DataArray with ``time``, ``fs`` and ``units="deg/s"`` for labelled input.
    """
    s = _read_gyr(gyr, fs, units, what="angular_speed")
    return label(_speed(s, np.zeros(3)), s, "angular_speed", "deg/s")


def speed_modes(
    speed,
    *,
    units: str | None = None,
    log_range: tuple[float, float] = (-1.0, 3.5),
    bins: int = 120,
    smooth_bins: float = 2.0,
    min_prominence: float = 0.05,
    min_separation: float = 0.5,
) -> dict[str, float]:
    r"""Find the still mode, the moving mode and the valley between them.

    They are those of an angular-speed distribution.

    The histogram of :math:`\log_{10}` speed is smoothed with a Gaussian kernel; among
    its peaks with a prominence of at least ``min_prominence`` times the highest peak,
    the most prominent one and the most prominent one at least ``min_separation``
    decades away from it are the two modes; the valley is the minimum of the smoothed
    histogram between them (Fayat et al. Fig. A3 place their 12 °/s threshold there by
    eye).

    Parameters
    ----------
    speed : xarray.DataArray or array_like (N,)
        Angular speed (a labelled DataArray is converted to °/s from its units; a plain
        array is in °/s unless ``units`` says otherwise); NaN and non-positive values
        are ignored.
    units : str, optional
        Units of a plain ``speed``.
    log_range : tuple of float
        Range of :math:`\log_{10}` speed (°/s) histogrammed.
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
        ``still_mode``, ``valley``, ``moving_mode`` (°/s) and ``depth`` (smoothed height
        of the valley over that of the lower mode); all NaN when the distribution has no
        second mode. The modes and the valley are bin centres, so they are resolved to
        one bin, ``(log_range[1] - log_range[0]) / bins`` decades (0.0375 decade, 9 %,
        by default): two similar distributions can report the same value.
    """
    lo_hi = _v.vectors(log_range, "log_range", width=2, ndim=1)
    if lo_hi[0] >= lo_hi[1]:
        raise ValueError(f"log_range must be increasing, got {log_range!r}")
    bins = _v.integer(bins, "bins", minimum=3)
    smooth_bins = _v.nonnegative(smooth_bins, "smooth_bins")
    min_prominence = _v.fraction(min_prominence, "min_prominence")
    min_separation = _v.nonnegative(min_separation, "min_separation")
    s = read_speed(speed, units=units, allow_nan=True).values
    s = s[np.isfinite(s) & (s > 0)]
    nan = {
        "still_mode": np.nan,
        "valley": np.nan,
        "moving_mode": np.nan,
        "depth": np.nan,
    }
    if s.size < 100:
        return nan
    h, edges = np.histogram(np.log10(s), bins=bins, range=tuple(lo_hi))
    hs = ndimage.gaussian_filter1d(h.astype(float), smooth_bins, mode="constant")
    centres = 0.5 * (edges[:-1] + edges[1:])
    peaks, props = signal.find_peaks(hs, prominence=min_prominence * hs.max())
    if len(peaks) < 2:
        return nan
    order = peaks[np.argsort(props["prominences"])[::-1]]
    first = order[0]
    second = next(
        (p for p in order[1:] if abs(centres[p] - centres[first]) >= min_separation),
        None,
    )
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

    Parameters
    ----------
    speed : xarray.DataArray or array_like (N,)
        Angular speed (°/s for a plain array unless ``units`` says otherwise; a labelled
        DataArray is converted from its units); NaN and non-positive values are ignored.
    **kwargs
        Passed to :func:`speed_modes`: ``units``, ``log_range``, ``bins``,
        ``smooth_bins``, ``min_prominence``, ``min_separation``.

    Returns
    -------
    float
        Threshold (°/s): the valley of the smoothed log-speed histogram, resolved to one
        histogram bin.

    Raises
    ------
    ValueError
        If the distribution does not have two modes.
    """
    m = speed_modes(speed, **kwargs)
    if not np.isfinite(m["valley"]):
        raise ValueError(
            "the angular-speed distribution is not bimodal: no valley to put a "
            "threshold in"
        )
    return m["valley"]


@renamed(gyr="data", offset="gyr_offset")
def recording_speed(data, fs=None, *, units: str | None = None, gyr_offset="auto"):
    """Compute the angular speed (°/s) with the gyroscope offset removed.

    Parameters
    ----------
    data : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        The gyroscope: a Recording (its ``gyr``), a labelled DataArray, or a plain
        array with ``units`` (and ``fs`` for ``gyr_offset="auto"``). Formerly ``gyr``.
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    units : str, optional
        Units of a plain ``data``.
    gyr_offset : "auto", None or array_like (3,)
        ``"auto"``: a first-pass estimate from the quietest windows
        (:func:`tiltlab.calibration.robust_gyro_offset`; needs ``fs``); ``None``: no
        correction; or the offset in the units of the gyroscope. Formerly ``offset``.

    Returns
    -------
    numpy.ndarray or xarray.DataArray (time)
        °/s; for labelled input a DataArray with ``time``, ``fs``, ``units`` and the
        offset removed (attribute ``gyr_offset_deg_s``).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import behavior
    >>> gyr = np.tile([3.0, 4.0, 0.0], (200, 1))  # deg/s
    >>> speed = behavior.recording_speed(gyr, 100.0, units="deg/s", gyr_offset=None)
    >>> float(speed[0])
    5.0
    >>> speed = behavior.recording_speed(
    ...     gyr, 100.0, units="deg/s", gyr_offset=[3.0, 0.0, 0.0]
    ... )
    >>> float(speed[0])
    4.0
    """
    need_fs = isinstance(gyr_offset, str) and gyr_offset == "auto"
    s = _read_gyr(data, fs, units, need_fs=need_fs, what="recording_speed")
    off = _offset(s, gyr_offset)
    factor = _units.conversion_factor(s.units, "deg/s")
    attrs = {"gyr_offset_deg_s": (off * factor).tolist()}
    return label(_speed(s, off), s, "angular_speed", "deg/s", attrs=attrs)


def gyro_spectrum(
    gyr, fs=None, *, units: str | None = None, nperseg_s: float = 5.12
) -> tuple[np.ndarray, np.ndarray]:
    """Welch power spectral density of the gyroscope, summed over axes ((°/s)²/Hz).

    Parameters
    ----------
    gyr : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        A Recording (its ``gyr``), a labelled DataArray, or a plain array with ``fs``
        and ``units``.
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    units : str, optional
        Units of a plain ``gyr`` ('deg/s' or 'rad/s').
    nperseg_s : float
        Welch segment length (s), at most the record.

    Returns
    -------
    f : numpy.ndarray
        Frequencies (Hz).
    psd : numpy.ndarray
        Power spectral density.
    """
    nperseg_s = _v.positive(nperseg_s, "nperseg_s")
    need_gyr(gyr, "gyro_spectrum", NO_GYRO_HINT)
    s = read_behavior_input(
        gyr, "gyr", fs=fs, units=units, to_units="deg/s", need_fs=True
    )
    g = s.values
    nper = max(min(g.shape[0], int(round(nperseg_s * s.fs))), 1)
    f, p = signal.welch(g - g.mean(axis=0), fs=s.fs, nperseg=nper, axis=0)
    return f, p.sum(axis=1)
