r"""Immobility (Fayat et al. 2021, §2.9).

A sample is still when the angular speed (norm of the offset-corrected gyroscope, °/s)
is below 12 °/s; still periods separated by gaps shorter than 0.1 s are merged; still
periods shorter than 0.5 s are discarded. The core is :func:`tiltlab.dsp.still_mask`,
tiltlab's one still-period detector. The 12 °/s threshold was chosen by eye at the
valley of the bimodal angular-speed distribution (their Fig. A3);
:func:`~tiltlab.behavior.valley_threshold` finds that valley automatically
(``threshold_deg_s="auto"``).

The gyroscope's units and ``fs`` are read from the data (a Recording or a labelled
DataArray), so a recording in rad/s gives the same mask as the same recording in °/s.
"""

from __future__ import annotations

import numpy as np

from .. import _validate as _v
from ..dsp import still_mask
from ._common import label, read_speed
from .speed import _offset, _read_gyr, _speed, valley_threshold

__all__ = ["detect_immobility", "immobility"]


def _threshold(threshold_deg_s) -> float:
    if isinstance(threshold_deg_s, str):
        raise ValueError(
            f"threshold_deg_s must be a number of °/s or 'auto', got {threshold_deg_s!r}"
        )
    return _v.positive(threshold_deg_s, "threshold_deg_s")


def detect_immobility(
    speed,
    fs=None,
    *,
    threshold_deg_s: float = 12.0,
    merge_gap_s: float = 0.1,
    min_duration_s: float = 0.5,
    units: str | None = None,
):
    """Fayat et al.'s immobility mask from an angular-speed series.

    Parameters
    ----------
    speed : xarray.DataArray or array_like (N,)
        Angular speed (see :func:`~tiltlab.behavior.angular_speed`): a labelled
        DataArray (``fs`` and ``units`` read from its attributes) or a plain array in
        °/s (or ``units``) with ``fs``. NaN is refused: fill or drop gaps first.
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    threshold_deg_s : float
        Speed (°/s) below which a sample is still (Fayat: 12 °/s; strict).
    merge_gap_s : float
        Still periods separated by a gap strictly shorter than this (s) are merged
        (Fayat: 0.1 s).
    min_duration_s : float
        Still periods shorter than this (s), after merging, are discarded (Fayat: 0.5 s).
    units : str, optional
        Units of a plain ``speed`` (default °/s).

    Returns
    -------
    numpy.ndarray of bool (N,) or xarray.DataArray (time)
        True where the animal is immobile; a DataArray ``immobile`` with ``time``,
        ``fs`` and the settings as attributes for labelled input.
    """
    thr = _threshold(threshold_deg_s)
    s = read_speed(speed, fs, units=units, need_fs=True)
    mask = still_mask(
        s.values,
        s.fs,
        threshold=thr,
        merge_gap_s=merge_gap_s,
        min_duration_s=min_duration_s,
    )
    attrs = {
        "threshold_deg_s": thr,
        "threshold_method": "fixed",
        "merge_gap_s": float(merge_gap_s),
        "min_duration_s": float(min_duration_s),
    }
    return label(mask, s, "immobile", attrs=attrs)


def immobility(
    gyr,
    fs=None,
    *,
    threshold_deg_s: float | str = 12.0,
    gyr_offset=None,
    merge_gap_s: float = 0.1,
    min_duration_s: float = 0.5,
    units: str | None = None,
):
    """Immobility mask from a gyroscope (a Recording's ``gyr`` by default).

    Parameters
    ----------
    gyr : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        A Recording (its ``gyr`` and ``fs``), a labelled DataArray, or a plain array
        with ``fs`` and ``units``.
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    threshold_deg_s : float or "auto"
        Angular-speed threshold in °/s, or ``"auto"`` for
        :func:`~tiltlab.behavior.valley_threshold`.
    gyr_offset : "auto", None or array_like (3,)
        Gyroscope offset subtracted first, in the units of ``gyr``; ``"auto"``:
        :func:`tiltlab.calibration.robust_gyro_offset`.
    merge_gap_s, min_duration_s : float
        See :func:`detect_immobility`.
    units : str, optional
        Units of a plain ``gyr`` ('deg/s' or 'rad/s').

    Returns
    -------
    xarray.DataArray of bool (time), or numpy.ndarray for a plain array
        With attributes ``threshold_deg_s``, ``threshold_method``, ``merge_gap_s``,
        ``min_duration_s`` (and ``fs``).
    """
    if isinstance(threshold_deg_s, str) and threshold_deg_s != "auto":
        raise ValueError(
            f"threshold_deg_s must be a number of °/s or 'auto', got {threshold_deg_s!r}"
        )
    s = _read_gyr(gyr, fs, units, need_fs=True)
    speed = _speed(s, _offset(s, gyr_offset, "gyr_offset"))
    if isinstance(threshold_deg_s, str):
        thr, method = (
            valley_threshold(speed),
            "valley of the log angular-speed histogram",
        )
    else:
        thr, method = _threshold(threshold_deg_s), "fixed"
    mask = detect_immobility(
        speed,
        s.fs,
        threshold_deg_s=thr,
        merge_gap_s=merge_gap_s,
        min_duration_s=min_duration_s,
    )
    attrs = {
        "threshold_deg_s": thr,
        "threshold_method": method,
        "merge_gap_s": float(merge_gap_s),
        "min_duration_s": float(min_duration_s),
    }
    return label(np.asarray(mask), s, "immobile", attrs=attrs)
