"""Figures of a calibration: magnetometer readings before and after a hard/soft-iron fit.

The recipe takes the readings (raw and calibrated, computed by the caller with
:func:`tiltlab.calibration.fit_mag_ellipsoid` and
:func:`tiltlab.calibration.apply_mag_calibration`) and only draws them: two projections
of the point clouds on a common scale, with the circle of the target field strength,
and the norm of each reading against time (or sample index).
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from .._validate import signal
from ._common import label, pretty_units

__all__ = ["mag_calibration_figure"]

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
