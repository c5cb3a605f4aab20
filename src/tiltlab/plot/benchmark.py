r"""Figure recipes of the tilt benchmark: trajectories of gravity on the sphere (Fayat Fig. 2b).

Each direction :math:`g = (x, y, z)` is drawn with the Lambert azimuthal equal-area
projection centred on :math:`+z` (seen from above), as in the book's tilt maps: with
:math:`k = \sqrt{2 / (1 + z)}`, the map point is

.. math::
    (X, Y) = (-k\,y,\; k\,x),

so :math:`+x` points up and :math:`+y` left; the equator is the circle of radius
:math:`\sqrt 2` and :math:`-z` is the outer circle of radius 2 (where :math:`k` is
undefined: directions within a hair of :math:`-z` are left out).
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib.pyplot as plt
import numpy as np

from .maps import axis_texts

__all__ = ["tilt_trajectories_panels"]


def _laea_xy(v: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.sqrt(2.0 / (1.0 + v[:, 2]))
    k[~np.isfinite(k) | (v[:, 2] <= -1 + 1e-12)] = np.nan
    return np.column_stack([-k * v[:, 1], k * v[:, 0]])


def tilt_trajectories_panels(
    series: Mapping[str, object],
    *,
    axes=None,
    time=None,
    cmap: str = "viridis",
    labels=None,
    lw: float = 0.8,
):
    """Draw gravity-direction trajectories side by side on equal-area maps seen from +z.

    Parameters
    ----------
    series : mapping
        Panel title → directions, array_like of shape (N, 3) (normalised here; rows with
        a NaN or zero norm are left out). All series have the same N when ``time`` is
        given.
    axes : sequence of matplotlib.axes.Axes, optional
        One axes per series; default a new figure with one row of panels.
    time : array_like, optional
        Times (s) of the N samples: the line is coloured by time, with a colour bar.
        Default: one colour per panel.
    cmap : str
        Colour map for ``time``.
    labels : optional
        Axis names for the markers of +x and +y (see :func:`tiltlab.plot.axis_texts`).
    lw : float
        Line width.

    Returns
    -------
    matplotlib.figure.Figure
        The figure; each panel's line holds the projected coordinates (its
        ``get_offsets``/``get_segments`` for a time-coloured line).
    """
    if not isinstance(series, Mapping) or not series:
        raise ValueError("series must be a non-empty mapping title → (N, 3) directions")
    arrays = {}
    for name, v in series.items():
        v = np.asarray(v, dtype=float)
        if v.ndim != 2 or v.shape[1] != 3:
            raise ValueError(f"series[{name!r}] must have shape (N, 3), got {v.shape}")
        with np.errstate(divide="ignore", invalid="ignore"):
            arrays[name] = v / np.linalg.norm(v, axis=1, keepdims=True)
    t = None
    if time is not None:
        t = np.asarray(time, dtype=float).ravel()
        bad = [n for n, v in arrays.items() if len(v) != t.size]
        if bad:
            raise ValueError(f"time has {t.size} samples, series {bad} do not")
    if axes is None:
        n = len(arrays)
        fig, axes = plt.subplots(1, n, figsize=(2.9 * n, 3.1), layout="constrained")
        axes = np.atleast_1d(axes)
    else:
        axes = list(np.ravel(axes))
        if len(axes) != len(arrays):
            raise ValueError(f"axes has {len(axes)} axes for {len(arrays)} series")
        fig = axes[0].figure
    texts = axis_texts(labels)
    circle = np.linspace(0, 2 * np.pi, 361)
    mappable = None
    for ax, (name, v) in zip(axes, arrays.items()):
        xy = _laea_xy(v)
        for r, style in ((np.sqrt(2), ":"), (2.0, "-")):
            ax.plot(r * np.cos(circle), r * np.sin(circle), style, color="0.6", lw=0.6)
        if t is None:
            ax.plot(xy[:, 0], xy[:, 1], lw=lw)
        else:
            from matplotlib.collections import LineCollection

            seg = np.stack([xy[:-1], xy[1:]], axis=1)
            lc = LineCollection(seg, cmap=cmap, lw=lw)
            lc.set_array(0.5 * (t[:-1] + t[1:]))
            lc.set_clim(t.min(), t.max())
            mappable = ax.add_collection(lc)
        ax.plot(0, 0, "+", color="k", ms=6)
        ax.text(0, 2.05, texts["+x"], ha="center", va="bottom", fontsize=8)
        ax.text(-2.05, 0, texts["+y"], ha="right", va="center", fontsize=8)
        ax.set_xlim(-2.4, 2.4)
        ax.set_ylim(-2.3, 2.4)
        ax.set_aspect("equal")
        ax.set_axis_off()
        ax.set_title(str(name), fontsize=9)
    if mappable is not None:
        fig.colorbar(mappable, ax=list(axes), label="time (s)", shrink=0.7)
    return fig
