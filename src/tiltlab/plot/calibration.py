"""Figures of a calibration: magnetometer fits, norm-error bands, offsets across dates.

The recipe takes the readings (raw and calibrated, computed by the caller with
:func:`tiltlab.calibration.fit_mag_ellipsoid` and
:func:`tiltlab.calibration.apply_mag_calibration`) and only draws them: two projections
of the point clouds on a common scale, with the circle of the target field strength,
and the norm of each reading against time (or sample index).

:func:`norm_error_band_figure` draws the per-orientation norm-error bands of
:func:`tiltlab.calibration.norm_error_band` (Fayat et al. 2021, Fig. 1b) and
:func:`calibration_log_figure` a sensor's offsets against calibration date from
:func:`tiltlab.calibration.calibration_log` (their Fig. 1e).
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import xarray as xr

from .._validate import signal
from ._common import label, new_axes, pretty_units

__all__ = ["mag_calibration_figure", "norm_error_band_figure", "calibration_log_figure"]

_AXES = {"x": 0, "y": 1, "z": 2}


def _readings(data, name: str) -> tuple[np.ndarray, str | None]:
    s = signal(data, name, var="mag", need_fs=False, allow_nan=True)
    return s.values, s.units


def mag_calibration_figure(
    raw,
    calibrated,
    *,
    field: float | None = None,
    time=None,
    units: str | None = None,
    planes: tuple[str, ...] = ("xy", "yz"),
    figsize: tuple[float, float] = (9.0, 3.4),
) -> plt.Figure:
    """Draw magnetometer readings before and after calibration.

    One panel per projection plane (raw readings in red, calibrated ones in blue, the
    circle of radius ``field`` about the origin in black), then a panel of the norm of
    every reading against time, whose legend names the colours: a calibrated
    magnetometer lies on a sphere centred on the origin, so its projections stay within
    the circle (on it for directions in the plane) and its norm is flat.

    Parameters
    ----------
    raw, calibrated : Recording, DataArray or array_like (N, 3)
        Raw readings (a Recording's ``mag``) and the same readings calibrated, in the
        same units.
    field : float, optional
        Target field strength (the calibrated norm), in those units; drawn as a circle
        and a horizontal line. Default: the median calibrated norm.
    time : array_like (N,), optional
        Times of the readings (s); default: the ``time`` coordinate of labelled input,
        else the sample index.
    units : str, optional
        Units of the readings; default ``raw``'s ``attrs["units"]``, else µT.
    planes : tuple of str
        Projection planes, each two of ``"x"``, ``"y"``, ``"z"`` (e.g. ``"xy"``).
    figsize : tuple of float
        Figure size (inches).

    Returns
    -------
    matplotlib.figure.Figure
        The figure (``len(planes) + 1`` axes).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import plot
    >>> rng = np.random.default_rng(0)
    >>> m = rng.normal(size=(200, 3))
    >>> m = 40 * m / np.linalg.norm(m, axis=1, keepdims=True)
    >>> fig = plot.mag_calibration_figure(m * [1.1, 0.9, 1.0] + [10, -5, 3], m)
    >>> len(fig.axes)
    3
    """
    r, raw_units = _readings(raw, "raw")
    c, _ = _readings(calibrated, "calibrated")
    if r.shape != c.shape:
        raise ValueError(
            f"raw and calibrated must have the same shape, got {r.shape} and {c.shape}"
        )
    for p in planes:
        if len(p) != 2 or any(a not in _AXES for a in p) or p[0] == p[1]:
            raise ValueError(f"a plane is two different axes of 'xyz', got {p!r}")
    units = units or raw_units or "uT"
    norm_c = np.linalg.norm(c, axis=1)
    if field is None:
        field = float(np.nanmedian(norm_c))
    if (
        time is None
        and isinstance(raw, xr.DataArray | xr.Dataset)
        and "time" in raw.coords
    ):
        time = raw["time"].values
    t = np.arange(len(r)) if time is None else np.asarray(time, dtype=float)
    if t.shape != (len(r),):
        raise ValueError(f"time must have shape ({len(r)},), got {t.shape}")
    fig, axes = plt.subplots(
        1, len(planes) + 1, figsize=figsize, width_ratios=[1] * len(planes) + [1.6]
    )
    circle = np.linspace(0, 2 * np.pi, 200)
    lim = 1.05 * float(np.nanmax(np.abs(np.concatenate([r, c]))))
    for ax, p in zip(axes, planes):
        i, j = _AXES[p[0]], _AXES[p[1]]
        ax.plot(r[:, i], r[:, j], ".", ms=2, color="C3", label="raw")
        ax.plot(c[:, i], c[:, j], ".", ms=2, color="C0", label="calibrated")
        ax.plot(field * np.cos(circle), field * np.sin(circle), "k-", lw=0.8)
        ax.plot(0, 0, "k+")
        ax.set(xlim=(-lim, lim), ylim=(-lim, lim), aspect="equal")
        ax.set_xlabel(label(f"$m_{p[0]}$", units))
        ax.set_ylabel(label(f"$m_{p[1]}$", units))
    ax = axes[-1]
    ax.plot(t, np.linalg.norm(r, axis=1), lw=0.6, color="C3", label="raw")
    ax.plot(t, norm_c, lw=0.6, color="C0", label="calibrated")
    ax.axhline(field, color="k", lw=0.8, label="field strength")
    ax.set_xlabel("time (s)" if time is not None else "sample")
    ax.set_ylabel(f"norm ({pretty_units(units)})" if pretty_units(units) else "norm")
    ax.legend(fontsize=8, loc="best", framealpha=0.9)
    fig.tight_layout()
    return fig


def norm_error_band_figure(
    bands: Mapping[str, pd.DataFrame],
    *,
    log: bool = True,
    ax=None,
):
    """Draw per-orientation norm-error bands, one line and shaded band per condition.

    Parameters
    ----------
    bands : mapping str → pandas.DataFrame
        Condition name (legend entry, e.g. ``"raw"``, ``"offset corrected"``) → table of
        :func:`tiltlab.calibration.norm_error_band` (columns ``median``, ``low``,
        ``high``, one row per orientation).
    log : bool, default True
        Logarithmic error axis (errors before and after correction differ by orders of
        magnitude).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new 6.5 × 3.2 in figure.

    Returns
    -------
    matplotlib.axes.Axes
        The axes: one median line and one band (``PolyCollection``) per condition.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import calibration, plot
    >>> means = np.random.default_rng(1).normal([0, 0, 1.02], 0.01, (4, 6, 3))
    >>> band = calibration.norm_error_band(means)
    >>> ax = plot.norm_error_band_figure({"raw": band})
    >>> len(ax.lines), len(ax.collections)
    (1, 1)
    """
    if not isinstance(bands, Mapping) or not bands:
        raise ValueError("bands must be a non-empty mapping of name -> band table")
    ax = new_axes(ax, figsize=(6.5, 3.2))
    units = None
    for k, (name, b) in enumerate(bands.items()):
        missing = {"median", "low", "high"} - set(getattr(b, "columns", ()))
        if missing:
            raise ValueError(
                f"bands[{name!r}] must have columns median, low and high; missing "
                f"{sorted(missing)}"
            )
        units = units or b.attrs.get("units", {}).get("median")
        x = np.asarray(b.index)
        ax.fill_between(x, b["low"], b["high"], color=f"C{k}", alpha=0.25, lw=0)
        ax.plot(x, b["median"], color=f"C{k}", lw=1.2, label=str(name))
    if log:
        ax.set_yscale("log")
    ax.set_xlabel("orientation (lattice index)")
    ax.set_ylabel(label("|1 − ‖a‖|", units or "g"))
    ax.legend(fontsize=8, framealpha=0.9)
    return ax


def calibration_log_figure(
    log: pd.DataFrame, *, relative: bool = False, figsize=(8.4, 3.2)
) -> plt.Figure:
    """Draw a sensor's offsets against calibration date, with their standard errors.

    One panel per sensor in the log (accelerometer, gyroscope), one line per axis;
    error bars of ± one standard error where the log has ``*_stderr`` columns.

    Parameters
    ----------
    log : pandas.DataFrame
        Table of :func:`tiltlab.calibration.calibration_log` (a date index, columns
        ``acc_offset_x`` … ``gyr_offset_z``).
    relative : bool, default False
        Draw each offset minus its value at the first date (the drift), so that axes
        with offsets far apart share a scale that shows it.
    figsize : tuple of float
        Figure size (inches).

    Returns
    -------
    matplotlib.figure.Figure
        One axes per sensor present in ``log``.

    Examples
    --------
    >>> import pandas as pd
    >>> from tiltlab import plot
    >>> log = pd.DataFrame(
    ...     {f"acc_offset_{a}": [0.01, 0.012] for a in "xyz"},
    ...     index=pd.to_datetime(["2021-01-01", "2021-06-01"]),
    ... )
    >>> len(plot.calibration_log_figure(log).axes)
    1
    >>> fig = plot.calibration_log_figure(log, relative=True)
    >>> [round(float(v), 3) for v in fig.axes[0].lines[0].get_ydata()]
    [0.0, 0.002]
    """
    if not isinstance(log, pd.DataFrame) or not isinstance(log.index, pd.DatetimeIndex):
        raise ValueError("log must be a DataFrame indexed by date (calibration_log)")
    sensors = [
        s for s in ("acc", "gyr") if all(f"{s}_offset_{a}" in log for a in "xyz")
    ]
    if not sensors:
        raise ValueError(
            "log has no offsets to draw: it needs columns acc_offset_x..z or "
            "gyr_offset_x..z"
        )
    default = {"acc": "g", "gyr": "deg/s"}
    title = {"acc": "accelerometer offset", "gyr": "gyroscope offset"}
    fig, axes = plt.subplots(1, len(sensors), figsize=figsize, squeeze=False)
    for ax, s in zip(axes[0], sensors):
        for k, a in enumerate("xyz"):
            col = f"{s}_offset_{a}"
            se = log.get(f"{col}_stderr")
            y = log[col] - log[col].iloc[0] if relative else log[col]
            ax.errorbar(
                log.index,
                y,
                yerr=None if se is None else se,
                marker="o",
                ms=3,
                lw=1,
                capsize=2,
                color=f"C{k}",
                label=a,
            )
        units = log.attrs.get("units", {}).get(f"{s}_offset_x", default[s])
        name = f"{title[s]} − first" if relative else title[s]
        ax.set_ylabel(label(name, units))
        ax.set_xlabel("calibration date")
        ax.tick_params(axis="x", labelrotation=30)
        ax.legend(title="axis", fontsize=8, framealpha=0.9)
    fig.tight_layout()
    return fig
