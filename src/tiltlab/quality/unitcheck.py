"""Check that values are plausible for their unit labels: accelerometer, gyroscope, temperature.

The gyroscope is judged against the tilt the accelerometer sees: :func:`check_gyr_units`
is tiltlab's one gyroscope-unit check, used by :func:`tiltlab.schema.validate` (through
:func:`tiltlab.quality.plausibility`) and by every reader.
"""

from __future__ import annotations


import numpy as np
import xarray as xr

from .. import _validate
from .. import units as _units
from ._common import (
    ACC_COUNTS_G,
    ACC_MEDIAN_G,
    Finding,
    GYR_COUNTS_DEG_S,
    GYR_RAD_S_P99,
    TEMP_RANGE_DEGC,
    _finite_rows,
    _name,
    _read,
    _u,
)


def check_acc_units(acc, units: str | None = None, *, var: str = "acc"):
    """Accelerometer magnitude against its unit label.

    Gravity dominates any recording, so the median ``|acc|`` is about 1 g
    (``ACC_MEDIAN_G`` = 0.5–2 g). Labelled g with a median of 4.9–19.6 (= 0.5–2 × 9.81)
    the values are m/s²; labelled m/s² with a median of 0.5–2 they are g: an **error**
    (every number would be off by 9.81). Any other median outside 0.5–2 g is a
    **warning** (no single unit mistake explains it: a scale error, a gravity-compensated
    signal, free fall). Medians beyond 50 g are left to :func:`check_raw_counts`.

    The m/s²-looks-like-g error needs gravity to be there: when the sampling rate is
    known and the acceleration averaged over 1 s keeps less than half of its median
    magnitude (a gravity-free "linear acceleration" signal, whose median in m/s² can be
    about 1), the finding is only a warning.

    Parameters
    ----------
    acc : xarray.Dataset, xarray.DataArray or array_like, shape (N, 3)
        A Recording (its ``fs`` is then used), a labelled DataArray or a plain array.
    units : str, optional
        Units of a plain array.
    var : str
        The variable of a Recording (default ``"acc"``).

    Returns
    -------
    Finding or None
        An error or a warning, or None when the magnitude is plausible.
    """
    name = _name(acc, var)
    v, u, _, fs, _ = _read(acc, name, units=units)
    rows = _finite_rows(v)
    if not rows.size:
        return None
    med = float(np.median(np.linalg.norm(rows, axis=1)))
    g = med * _units.conversion_factor(u, "g")
    lo, hi = ACC_MEDIAN_G
    if lo <= g <= hi or g > ACC_COUNTS_G:
        return None
    other = "m/s^2" if u == "g" else "g"
    gravity_free = False
    if other == "g" and fs is not None and rows.shape[0] > 2 * fs:
        w = max(1, int(round(fs)))
        c = np.cumsum(np.vstack([np.zeros((1, 3)), rows]), axis=0)
        mean_1s = np.linalg.norm((c[w:] - c[:-w]) / w, axis=1)
        gravity_free = float(np.median(mean_1s)) < 0.5 * med
    if gravity_free and lo <= med * _units.conversion_factor(other, "g") <= hi:
        return Finding(
            name,
            "acc_units",
            "warning",
            f"{name}: median magnitude {med:.3g} {_u(u)} is far from gravity's 9.81 and "
            "its 1-s average is small: a gravity-free (linear acceleration) signal, or g "
            "labelled m/s²; tilt needs the gravity-including accelerometer",
            med,
        )
    if lo <= med * _units.conversion_factor(other, "g") <= hi:
        return Finding(
            name,
            "acc_units",
            "error",
            f"{name} is labelled {_u(u)} but its median magnitude is {med:.3g}: "
            f"looks like {_u(other)} (set units={other!r})",
            med,
        )
    return Finding(
        name,
        "acc_units",
        "warning",
        f"{name}: median magnitude {med:.3g} {_u(u)} ({g:.3g} g) is far from the 1 g of "
        f"gravity (expected {lo:g}–{hi:g} g): check its units and scale",
        med,
    )


def _smoothed_directions(
    acc: np.ndarray, w: int, tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """Return the directions of the acceleration averaged over ``w`` samples (centred).

    Also whether each is gravity-dominated (its magnitude within ``tol`` of the median).
    """
    a = np.where(np.isfinite(acc), acc, 0.0)
    c = np.cumsum(np.vstack([np.zeros((1, 3)), a]), axis=0)
    n = a.shape[0]
    lo = np.clip(np.arange(n) - w // 2, 0, n)
    hi = np.clip(lo + w, 0, n)
    sm = (c[hi] - c[lo]) / np.maximum(hi - lo, 1)[:, None]
    norm = np.linalg.norm(sm, axis=1)
    med = float(np.median(norm)) if n else 0.0
    ok = np.isfinite(acc).all(axis=1) & (norm > 0)
    if med > 0:
        ok &= np.abs(norm / med - 1.0) < tol
    d = sm / np.where(norm > 0, norm, 1.0)[:, None]
    return d, ok


#: Window (s) over which the gyroscope's rotation is compared with the accelerometer's
#: tilt, the smallest tilt (degrees) that counts as turning, and the share of turning
#: windows that must contradict the label before it is refused (below: a warning).
GYR_WINDOW_S: float = 1.0
GYR_MIN_TILT_DEG: float = 20.0
GYR_DECISIVE_SHARE: float = 0.6


def _rotation_bound(
    gyr_rad_s: np.ndarray, acc: np.ndarray, fs: float
) -> tuple[int, int, float]:
    """Count the windows whose tilt the gyroscope cannot explain.

    Returns the windows in which the accelerometer turns by more than
    ``GYR_MIN_TILT_DEG``, how many of them the gyroscope cannot explain (it integrates
    to less than a fifth of that tilt), and the median |cosine| between the axis the accelerometer turns
    about and the gyroscope's (perpendicular to gravity) in those windows: the |median
    signed cosine|. The angle between two gravity directions is at most the rotation
    integrated between them, so a correctly labelled gyroscope explains every window,
    whatever its bias or noise.
    """
    n = gyr_rad_s.shape[0]
    w = max(1, int(round(0.25 * fs)))  # direction smoothing (vibration, noise)
    step = max(1, int(round(GYR_WINDOW_S * fs)))
    if n < step + 2 * w:
        return 0, 0, float("nan")
    d, ok = _smoothed_directions(acc, w, 0.05)
    speed = np.linalg.norm(np.where(np.isfinite(gyr_rad_s), gyr_rad_s, 0.0), axis=1)
    integral = np.concatenate([[0.0], np.cumsum(speed) / fs])
    i0 = np.arange(w, n - step - w, step)
    i1 = i0 + step
    good = ok[i0] & ok[i1]
    tilt = np.arccos(np.clip(np.sum(d[i0] * d[i1], axis=1), -1.0, 1.0))
    # the smoothed directions see half a smoothing window beyond each end
    turned = (
        integral[np.minimum(i1 + w // 2 + 1, n)] - integral[np.maximum(i0 - w // 2, 0)]
    )
    turning = good & (tilt > np.radians(GYR_MIN_TILT_DEG))
    unexplained = turning & (turned < tilt / 5.0)
    # does the gyroscope turn about the axis the accelerometer turns about? (its
    # direction does not depend on the unit label; noise and bias point anywhere).
    # Judged over short steps (0.1 s) inside the unexplained windows, where the
    # rotation axis is nearly constant.
    agree = 0.0
    if unexplained.any():
        h = max(1, int(round(0.1 * fs)))
        inside = np.zeros(n, dtype=bool)
        for k0, k1 in zip(i0[unexplained], i1[unexplained], strict=True):
            inside[k0 : k1 - h] = True
        j0 = np.flatnonzero(inside & ok & np.roll(ok, -h))
        j1 = j0 + h
        gsum = np.vstack(
            [np.zeros((1, 3)), np.cumsum(np.nan_to_num(gyr_rad_s), axis=0)]
        )
        rot = gsum[j1] - gsum[j0]
        axis_acc = np.cross(d[j0], d[j1])
        mean_g = d[j0] + d[j1]
        mean_g /= np.maximum(np.linalg.norm(mean_g, axis=1, keepdims=True), 1e-12)
        rot_perp = rot - np.sum(rot * mean_g, axis=1, keepdims=True) * mean_g
        size = np.linalg.norm(axis_acc, axis=1)
        denom = size * np.linalg.norm(rot_perp, axis=1)
        # signed: for a right-handed frame d0 × d1 = −θ ω̂⊥, so the cosine is near −1
        # (near +1 for a left-handed one); noise gives cosines of either sign
        cos = np.sum(axis_acc * rot_perp, axis=1) / np.maximum(denom, 1e-300)
        if size.sum() > 0:
            agree = abs(float(np.sum(cos * size) / size.sum()))
    return int(turning.sum()), int(unexplained.sum()), agree


def check_gyr_units(
    gyr,
    units: str | None = None,
    *,
    acc=None,
    fs: float | None = None,
    var: str = "gyr",
) -> Finding | None:
    """Gyroscope magnitude against its unit label, where decidable.

    * Labelled rad/s: a 99th percentile of ``|gyr|`` above 40 rad/s (2300 °/s, beyond the
      full scale of most MEMS gyroscopes) looks like °/s: a **warning**; above 100 rad/s
      (5700 °/s, beyond any MEMS gyroscope) it cannot be rad/s: an **error**.
    * Labelled °/s: decided from the accelerometer, window by window. Over
      ``GYR_WINDOW_S`` = 1 s, the angle between two gravity directions is at most the
      rotation integrated between them, ``∫|ω| dt``; a gyroscope that, read in °/s,
      integrates to less than a fifth of the tilt in most (``GYR_DECISIVE_SHARE``) of at
      least three windows that turn by more than 20° is in rad/s (or does not work): an
      **error**. Fewer such windows (linear acceleration can turn the accelerometer
      without rotation) are a **warning**. Bias and noise only add to the integral, so
      they cannot cause either; a still or barely turning recording is not judged.

    Parameters
    ----------
    gyr : xarray.Dataset, xarray.DataArray or array_like, shape (N, 3)
        A Recording (its ``acc`` and ``fs`` are then used), a labelled DataArray or a
        plain array.
    units : str, optional
        Units of a plain array.
    acc : array_like, shape (N, 3), optional
        Acceleration (any units) for the °/s case.
    fs : float, optional
        Sampling rate (Hz) for the °/s case.
    var : str
        The variable of a Recording (default ``"gyr"``).

    Returns
    -------
    Finding or None
        An error or a warning, or None when the label is plausible or undecidable.
    """
    name = _name(gyr, var)
    v, u, _, f, _ = _read(gyr, name, units=units)
    if fs is not None:
        f = _validate.check_fs(fs) if f is None else f
    rows = _finite_rows(v)
    if not rows.size:
        return None
    norm = np.linalg.norm(rows, axis=1)
    if u == "rad/s":
        p99 = float(np.percentile(norm, 99))
        warn_at, err_at = GYR_RAD_S_P99
        if p99 <= warn_at or p99 > GYR_COUNTS_DEG_S:  # beyond: check_raw_counts
            return None
        sev = "error" if p99 > err_at else "warning"
        return Finding(
            name,
            "gyr_units",
            sev,
            f"{name} is labelled rad/s but its 99th percentile magnitude is {p99:.4g} "
            f"(> {warn_at:g} rad/s = {np.degrees(warn_at):.0f} °/s"
            + (", beyond any MEMS gyroscope" if sev == "error" else "")
            + "): looks like °/s (set units='deg/s')",
            p99,
        )
    # labelled deg/s: compare the integrated rotation with the accelerometer's tilt
    if acc is None and isinstance(gyr, xr.Dataset) and "acc" in gyr:
        acc = gyr["acc"].values
    if acc is None or f is None:
        return None
    a = np.asarray(acc, dtype=float)
    if a.shape != v.shape or v.shape[1] != 3:
        return None
    rad = v * _units.conversion_factor(u, "rad/s")
    # over the whole recording: the gyroscope must explain the largest tilt (decisive:
    # no linear acceleration holds the accelerometer 45° off for half a second)
    ok = np.isfinite(v).all(axis=1)
    if ok.mean() >= 0.99:
        tilt = _tilt_span(a, f)
        turned_all = float(np.linalg.norm(rad[ok], axis=1).sum() / f)
        if tilt is not None and tilt >= np.radians(45.0) and turned_all < tilt / 5.0:
            return Finding(
                name,
                "gyr_units",
                "error",
                f"{name} is labelled °/s but integrates to {np.degrees(turned_all):.3g}° "
                f"of rotation while the accelerometer tilts by {np.degrees(tilt):.0f}°: "
                "looks like rad/s (set units='rad/s'), or the gyroscope is not working",
                np.degrees(turned_all),
            )
    turning, unexplained, agree = _rotation_bound(rad, a, f)
    if turning < 3 or unexplained == 0:
        return None
    share = unexplained / turning
    # decisive: most turning windows unexplained, and the gyroscope does turn about
    # the accelerometer's axis (it measures the rotation, too small by a unit factor)
    decisive = share >= GYR_DECISIVE_SHARE and agree >= 0.8
    if not decisive and share < 0.2:
        return None
    what = (
        f"in {unexplained} of {turning} one-second windows where the accelerometer "
        f"tilts by more than {GYR_MIN_TILT_DEG:g}°, {name} (read as °/s) integrates to "
        "less than a fifth of that tilt"
    )
    if decisive:
        return Finding(
            name,
            "gyr_units",
            "error",
            f"{name} is labelled °/s but {what}, about the same axis: looks like rad/s "
            "(set units='rad/s')",
            share,
        )
    return Finding(
        name,
        "gyr_units",
        "warning",
        f"{what}: if {name} is really °/s, the accelerometer also sees linear "
        "acceleration; if not, it may be rad/s",
        share,
    )


def _tilt_span(acc: np.ndarray, fs: float) -> float | None:
    """Return a lower bound (rad) of how far the accelerometer's gravity direction turns.

    It is the angle between two of its directions, smoothed over 0.5 s and taken on
    samples whose magnitude is within 10 % of the median (gravity-dominated).
    """
    a = _finite_rows(acc)
    w = max(1, int(round(0.5 * fs)))
    if a.shape[0] < 2 * w:
        return None
    c = np.cumsum(np.vstack([np.zeros((1, 3)), a]), axis=0)
    sm = (c[w:] - c[:-w]) / w
    norm = np.linalg.norm(sm, axis=1)
    med = float(np.median(norm))
    if not med > 0:
        return None
    keep = np.abs(norm / med - 1.0) < 0.1
    if keep.sum() < 2:
        return None
    d = sm[keep] / norm[keep, None]
    i = int(np.argmin(d @ d[0]))
    j = int(np.argmin(d @ d[i]))
    return float(np.arccos(np.clip(d[i] @ d[j], -1.0, 1.0)))


def check_temperature(temp, units: str | None = None, *, var: str = "temp"):
    """Sensor temperature against the −40…85 °C operating range of MEMS sensors.

    Labelled °C with every value in 233–358 (i.e. −40…85 °C in kelvin), or labelled K
    with every value in −40…85, the unit is swapped: an **error** (it shifts every
    temperature correction by 273.15). Other values outside the range are a **warning**
    (a sensor outside its rated range, or a bad channel).

    Parameters
    ----------
    temp : xarray.Dataset, xarray.DataArray or array_like, shape (N,)
        Temperatures: a Recording's ``var``, a labelled DataArray or a plain array.
    units : {"degC", "K"}, optional
        Needed for a plain array (labelled input carries its own).
    var : str
        Which variable of a Recording holds them (default ``"temp"``).

    Returns
    -------
    Finding or None
        None when every value is in the operating range.
    """
    name = _name(temp, var)
    v, u, _, _, _ = _read(temp, name, units=units, need_units=True)
    t = v[np.isfinite(v)]
    if not t.size:
        return None
    lo, hi = TEMP_RANGE_DEGC
    k0 = 273.15
    c = t - k0 if u == "K" else t
    if lo <= c.min() and c.max() <= hi:
        return None
    swapped = c + k0 if u == "K" else c - k0
    if lo <= swapped.min() and swapped.max() <= hi:
        other = "degC" if u == "K" else "K"
        return Finding(
            name,
            "temperature",
            "error",
            f"{name} is labelled {_u(u)} but its values ({np.min(t):.4g}…{np.max(t):.4g}) "
            f"look like {_u(other)} (set units={other!r})",
            float(np.median(t)),
        )
    out = int(np.sum((c < lo) | (c > hi)))
    return Finding(
        name,
        "temperature",
        "warning",
        f"{name}: {out} of {t.size} values are outside the {lo:g}…{hi:g} °C operating "
        f"range of MEMS sensors ({c.min():.4g}…{c.max():.4g} °C): check the channel "
        "and its units",
        float(out / t.size),
    )
