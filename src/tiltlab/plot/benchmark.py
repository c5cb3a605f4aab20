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


def _highlight_mask(highlight, n: int) -> np.ndarray:
    m = np.asarray(highlight)
    if m.ndim != 1 or m.size != n:
        raise ValueError(
            f"highlight must be a 1-D mask of the {n} samples, got shape {m.shape}"
        )
    if m.dtype != bool:
        if not np.isin(m, (0, 1)).all():
            raise ValueError("highlight must hold booleans (or 0/1)")
        m = m.astype(bool)
    return m


def _covariance_ellipse(xy: np.ndarray, n_sd: float):
    """Centre, full width, full height and angle (degrees) of the n_sd covariance ellipse."""
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    if len(xy) < 3:
        raise ValueError(
            "highlight selects fewer than 3 samples with a finite direction: "
            "no region to draw"
        )
    centre = xy.mean(axis=0)
    evals, evecs = np.linalg.eigh(np.cov(xy, rowvar=False))
    evals = np.clip(evals, 0.0, None)
    angle = np.degrees(np.arctan2(evecs[1, 1], evecs[0, 1]))  # major axis
    return centre, 2 * n_sd * np.sqrt(evals[1]), 2 * n_sd * np.sqrt(evals[0]), angle


def _highlight_region(arrays: dict, highlight, key, n_sd):
    n = len(next(iter(arrays.values())))
    bad = [name for name, v in arrays.items() if len(v) != n]
    if bad:
        raise ValueError(
            f"highlight needs series of equal length; {bad} differ from the first"
        )
    mask = _highlight_mask(highlight, n)
    key = next(iter(arrays)) if key is None else key
    if key not in arrays:
        raise ValueError(f"highlight_series {key!r} is not a title of series")
    if not (np.isfinite(n_sd) and n_sd > 0):
        raise ValueError(f"highlight_sd must be positive, got {n_sd}")
    return _covariance_ellipse(_laea_xy(arrays[key][mask]), n_sd)


def _draw_ellipse(ax, ellipse, label) -> None:
    from matplotlib.patches import Ellipse

    centre, width, height, angle = ellipse
    ax.add_patch(
        Ellipse(centre, width, height, angle=angle, fill=False, ls="--", lw=1.0, ec="k")
    )
    if label:
        top = centre[1] + 0.5 * np.hypot(
            width * np.sin(np.radians(angle)), height * np.cos(np.radians(angle))
        )
        ax.text(
            *(centre[0], top + 0.05),
            label,
            ha="center",
            va="bottom",
            fontsize=7,
            bbox={"fc": "white", "ec": "none", "alpha": 0.7, "pad": 0.5},
        )


def tilt_trajectories_panels(
    series: Mapping[str, object],
    *,
    axes=None,
    time=None,
    cmap: str = "viridis",
    labels=None,
    lw: float = 0.8,
    highlight=None,
    highlight_label: str | None = None,
    highlight_series: str | None = None,
    highlight_sd: float = 2.0,
):
    r"""Draw gravity-direction trajectories side by side on equal-area maps seen from +z.

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
    highlight : array_like of bool, shape (N,), optional
        Samples of an episode to mark (e.g. a behavioural bout). Every panel gets the
        same dashed ellipse around the region of the map that ``highlight_series``
        visits during these samples (see Notes). Default: no ellipse.
    highlight_label : str, optional
        Text written above the ellipse on every panel (default none).
    highlight_series : str, optional
        Title of the series whose masked samples define the region; default the first
        series (the reference).
    highlight_sd : float
        Size of the ellipse in standard deviations (default 2).

    Returns
    -------
    matplotlib.figure.Figure
        The figure; each panel's line holds the projected coordinates (its
        ``get_offsets``/``get_segments`` for a time-coloured line), and with
        ``highlight`` each panel holds one dashed :class:`matplotlib.patches.Ellipse`.

    Notes
    -----
    The region is the covariance ellipse of the projected points
    :math:`p_i = (X_i, Y_i)` of the masked samples: with :math:`\bar p` their mean,
    :math:`S` their sample covariance and :math:`c` = ``highlight_sd``, it is the
    curve of the points :math:`p` with

    .. math:: (p - \bar p)^\top S^{-1} (p - \bar p) = c^2 .

    For Gaussian points the squared Mahalanobis distance on the left has a
    :math:`\chi^2` law with two degrees of freedom, so the ellipse encloses a fraction
    :math:`1 - e^{-c^2/2}` of them (86.5 % at :math:`c = 2`). It is computed on the
    equal-area map, so it is an ellipse on the figure, not a cone on the sphere.
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
    ellipse = None
    if highlight is not None:
        ellipse = _highlight_region(arrays, highlight, highlight_series, highlight_sd)
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
        if ellipse is not None:
            _draw_ellipse(ax, ellipse, highlight_label)
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
