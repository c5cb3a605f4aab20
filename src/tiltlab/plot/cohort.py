"""Figures of cohort tables: Tukey boxplots by group and time point, group means over time.

Inputs are long tables — one row per session, columns for the grouping variables and
the features — as a :class:`pandas.DataFrame` or an :class:`xarray.Dataset` (converted
with ``to_dataframe()``). Units come from ``units=`` or from the Dataset variable's
``attrs['units']``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
import xarray as xr

from ._common import Look, finish_axes, label, new_axes

__all__ = ["tukey_boxplot", "group_lines", "tilt_trajectories_figure"]


def _table(data, value: str) -> tuple[pd.DataFrame, str | None]:
    units = None
    if isinstance(data, xr.Dataset):
        if value in data:
            units = data[value].attrs.get("units")
        data = data.to_dataframe().reset_index()
    elif not isinstance(data, pd.DataFrame):
        raise TypeError(
            f"data must be a pandas DataFrame or an xarray Dataset, got {type(data).__name__}"
        )
    if value not in data:
        raise ValueError(f"no column {value!r} in the table")
    return data, units


def _order(df: pd.DataFrame, col: str, order) -> list:
    if order is not None:
        return list(order)
    s = df[col]
    if isinstance(s.dtype, pd.CategoricalDtype):
        return list(s.cat.categories)
    return list(pd.unique(s))


def tukey_boxplot(
    data,
    value: str,
    *,
    by: str,
    hue: str | None = None,
    ax=None,
    order: Sequence | None = None,
    hue_order: Sequence | None = None,
    points: bool = True,
    seed: int = 0,
    **look,
):
    """Tukey boxplots of a feature by category (and sub-category), with the sessions as dots.

    Boxes span the quartiles with the median; whiskers reach the most extreme values
    within 1.5 IQR of the box (Tukey's rule); values beyond are drawn as outliers.

    Parameters
    ----------
    data : pandas.DataFrame or xarray.Dataset
        Long table, one row per session.
    value : str
        Feature column to plot.
    by : str
        Column with the categories on the x axis (e.g. ``"timepoint"``).
    hue : str, optional
        Column with side-by-side boxes within each category (e.g. ``"group"``), with a legend.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default a new figure).
    order, hue_order : sequence, optional
        Category orders (default: categorical order, else order of appearance).
    points : bool
        Overlay the individual values, jittered.
    seed : int
        Seed of the jitter.
    **look
        ``units`` of ``value`` (default the Dataset variable's ``attrs['units']``),
        ``name`` (y label, default ``value``) and ``title``.

    Returns
    -------
    matplotlib.axes.Axes
    """
    style, _ = Look.take(look, ("units", "name", "title"), "tukey_boxplot")
    df, u = _table(data, value)
    units = style.units if style.units is not None else u
    cats = _order(df, by, order)
    hues = _order(df, hue, hue_order) if hue is not None else [None]
    # at most the book's column width (8.4 in); few boxes get narrower
    width = min(8.4, max(4.0, 0.35 * len(cats) * max(1, len(hues))))
    ax = new_axes(ax, figsize=(width, 3.5))
    width = 0.8 / len(hues)
    rng = np.random.default_rng(seed)
    for k, h in enumerate(hues):
        sub = df if h is None else df[df[hue] == h]
        vals = [sub.loc[sub[by] == c, value].dropna().to_numpy(float) for c in cats]
        pos = np.arange(len(cats)) + (k - (len(hues) - 1) / 2) * width
        keep = [i for i, v in enumerate(vals) if v.size]
        colour = f"C{k}"
        if keep:
            ax.boxplot(
                [vals[i] for i in keep],
                positions=pos[keep],
                widths=0.85 * width,
                whis=1.5,
                patch_artist=True,
                manage_ticks=False,
                boxprops={"facecolor": colour, "alpha": 0.35, "edgecolor": colour},
                medianprops={"color": colour, "lw": 2},
                whiskerprops={"color": colour},
                capprops={"color": colour},
                flierprops={"marker": "x", "markeredgecolor": colour},
            )
        if points:
            for i in keep:
                jit = rng.uniform(-0.25, 0.25, vals[i].size) * width
                ax.plot(pos[i] + jit, vals[i], ".", color=colour, ms=4, alpha=0.8)
        ax.plot(
            [],
            [],
            "s",
            color=colour,
            alpha=0.6,
            label=str(h) if h is not None else value,
        )
    ax.set_xticks(np.arange(len(cats)), [str(c) for c in cats])
    return finish_axes(
        ax,
        by,
        label(style.name or value, units),
        legend_title=hue if hue is not None else False,
        title=style.title,
    )


def group_lines(
    data,
    value: str,
    *,
    x: str,
    hue: str,
    ax=None,
    err: str | None = "sem",
    order: Sequence | None = None,
    hue_order: Sequence | None = None,
    **look,
):
    """Centre of a feature per category of ``x`` (e.g. time points), one line per ``hue``.

    Parameters
    ----------
    data : pandas.DataFrame or xarray.Dataset
        Long table, one row per session.
    value : str
        Feature column.
    x : str
        Column on the x axis (e.g. ``"timepoint"``), in ``order``.
    hue : str
        Column with one line per value (e.g. ``"group"``), with a legend.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default a new figure).
    err : {"sem", "sd", "iqr", None}
        Error bars: standard error of the mean or standard deviation around the mean;
        ``"iqr"``: the median with its interquartile range (robust, as in Fayat et al.'s
        trajectories); None: the mean without bars.
    order, hue_order : sequence, optional
        Orders of the categories and of the lines.
    **look
        ``units`` of ``value`` (default the Dataset variable's), ``name`` (y label,
        default ``value``) and ``title``.

    Returns
    -------
    matplotlib.axes.Axes
    """
    if err not in ("sem", "sd", "iqr", None):
        raise ValueError(f"err must be 'sem', 'sd', 'iqr' or None, got {err!r}")
    style, _ = Look.take(look, ("units", "name", "title"), "group_lines")
    df, u = _table(data, value)
    units = style.units if style.units is not None else u
    xs = _order(df, x, order)
    ax = new_axes(ax, figsize=(4.5, 3.2))
    for h in _order(df, hue, hue_order):
        g = df[df[hue] == h].groupby(x, sort=False, observed=True)[value]
        mean = g.mean().reindex(xs)
        if err is None:
            ax.plot(range(len(xs)), mean.to_numpy(float), marker="o", label=str(h))
        elif err == "iqr":
            med = g.median().reindex(xs).to_numpy(float)
            q1 = g.quantile(0.25).reindex(xs).to_numpy(float)
            q3 = g.quantile(0.75).reindex(xs).to_numpy(float)
            ax.errorbar(
                range(len(xs)),
                med,
                yerr=np.vstack([med - q1, q3 - med]),
                marker="o",
                capsize=2,
                label=str(h),
            )
        else:
            spread = g.std(ddof=1).reindex(xs)
            if err == "sem":
                spread = spread / np.sqrt(g.count().reindex(xs))
            ax.errorbar(
                range(len(xs)),
                mean.to_numpy(float),
                yerr=spread.to_numpy(float),
                marker="o",
                capsize=2,
                label=str(h),
            )
    ax.set_xticks(range(len(xs)), [str(v) for v in xs], rotation=45)
    return finish_axes(
        ax, x, label(style.name or value, units), legend_title=hue, title=style.title
    )


_RINGS_DEG = (2.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 90.0)


def _laea(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lambert azimuthal equal-area coordinates of unit vectors about +z."""
    k = np.sqrt(2.0 / np.clip(1.0 + p[..., 2], 1e-12, None))
    return k * p[..., 0], k * p[..., 1]


def tilt_trajectories_figure(
    trajectories: xr.Dataset,
    *,
    groups: Sequence[str] | None = None,
    annotate: bool = True,
):
    r"""Draw mean-tilt trajectories with each baseline at the pole (Fayat Fig. 3e).

    One panel per group (two per row), seen from above the pole in the Lambert azimuthal equal-area
    projection (:math:`X = \sqrt{2/(1+z)}\,x`, :math:`Y = \sqrt{2/(1+z)}\,y`): each
    animal's trajectory in grey, the group's mean direction in red with its time
    first, last and farthest time points labelled, circles at constant angles from the
    baseline.

    Parameters
    ----------
    trajectories : xarray.Dataset
        Output of :func:`tiltlab.cohort.tilt_trajectories`.
    groups : sequence of str, optional
        Panels, in order (default: every group of ``trajectories``).
    annotate : bool
        Label the group mean's first and last time points after baseline and the one
        farthest from it.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (one visible axes per group, in rows of two).

    Raises
    ------
    ValueError
        A group that ``trajectories`` does not hold.

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> from tiltlab import cohort, plot
    >>> mu = np.array([[0.0, 0.0, 1.0], [0.0, 0.2, 1.0], [0.1, 0.0, 1.0], [0.1, 0.1, 1.0]])
    >>> ds = xr.Dataset(
    ...     {f"tilt_immobile_{a}": ("session", mu[:, i]) for i, a in enumerate("xyz")},
    ...     coords={"subject": ("session", ["r1", "r1", "r2", "r2"]),
    ...             "group": ("session", ["A"] * 4),
    ...             "timepoint": ("session", ["baseline", "1d"] * 2)})
    >>> fig = plot.tilt_trajectories_figure(cohort.tilt_trajectories(ds))
    >>> len(fig.axes)
    1
    """
    import matplotlib.pyplot as plt

    names = list(trajectories["group"].values)
    groups = names if groups is None else [str(g) for g in groups]
    unknown = [g for g in groups if g not in names]
    if unknown:
        raise ValueError(f"groups {unknown} are not in the trajectories: {names}")
    largest = np.nanmax(
        np.concatenate(
            [
                trajectories["angle"].values.ravel(),
                trajectories["mean_angle"].values.ravel(),
            ]
        ),
        initial=1.0,
    )
    rings = [r for r in _RINGS_DEG if r <= 1.05 * largest][-4:] or [_RINGS_DEG[0]]
    edge = 1.15 * 2 * np.sin(np.radians(max(rings[-1], largest)) / 2)
    ncols = min(len(groups), 2)  # the book's 8.4-inch text width
    nrows = -(-len(groups) // ncols)
    fig, axes = plt.subplots(
        nrows, ncols, figsize=(4.2 * ncols, 4.0 * nrows), squeeze=False
    )
    for ax in axes.flat[len(groups) :]:
        ax.set_visible(False)
    t = np.linspace(0, 2 * np.pi, 200)
    for ax, g in zip(axes.flat, groups):
        for r in rings:
            rr = 2 * np.sin(np.radians(r) / 2)
            ax.plot(rr * np.cos(t), rr * np.sin(t), color="0.85", lw=0.8, zorder=0)
            ax.text(rr * 0.71, rr * 0.71, f"{r:g}°", color="0.5", fontsize=7)
        mine = trajectories["animal_group"].values == g
        for p in trajectories["point"].values[mine]:
            x, y = _laea(p)
            ax.plot(x, y, color="0.6", lw=0.8, alpha=0.8)
        x, y = _laea(trajectories["mean"].sel(group=g).values)
        ax.plot(x, y, color="tab:red", lw=2.2, marker="o", ms=3.5)
        if annotate:  # the first and last time points after baseline, and the farthest
            angles = trajectories["mean_angle"].sel(group=g).values
            post = np.arange(1, len(angles))
            keep = {1, len(angles) - 1}
            if np.isfinite(angles[1:]).any():
                keep.add(int(post[np.nanargmax(angles[1:])]))
            for k, (xi, yi, tp) in enumerate(
                zip(x, y, trajectories["timepoint"].values)
            ):
                if np.isfinite(xi) and k in keep:
                    ax.annotate(
                        str(tp),
                        (xi, yi),
                        xytext=(3, 3),
                        textcoords="offset points",
                        fontsize=7,
                        color="tab:red",
                    )
        ax.plot([0], [0], marker="+", color="k", ms=8)
        n = int(mine.sum())
        ax.set_title(f"{g} (n = {n})", fontsize=10)
        ax.set_xlim(-edge, edge)
        ax.set_ylim(-edge, edge)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_xlabel("nose (x) →", fontsize=8)
        ax.set_ylabel("left (y) →", fontsize=8)
    fig.tight_layout()
    return fig
