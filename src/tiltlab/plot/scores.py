"""Figures of estimator errors.

Parameter-grid heat maps and curves, per-trial bars,
error distributions and errors binned by angular speed.

Inputs are the tables that :mod:`tiltlab.evaluate` and :func:`tiltlab.evaluate.grid_search`
return (labelled DataArrays / Datasets, pandas DataFrames). Every recipe takes the data
first and an optional ``ax``, labels its axes with units and adds a legend when it
draws several lines.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
import xarray as xr

from ._common import finish_axes, label, legend_if_many, new_axes, units_of

__all__ = ["score_heatmap", "score_curves", "trial_bars", "ecdf_plot", "binned_errors"]


def _fmt(v) -> str:
    """Write a tick label as a plain number (``0.00001``, not ``1e-05``)."""
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    s = f"{x:g}"
    return np.format_float_positional(x, trim="-") if "e" in s else s


def score_heatmap(
    scores: xr.DataArray,
    *,
    ax=None,
    log: bool = False,
    name: str = "mean error",
    units: str | None = None,
    mark_best: bool = True,
    cmap="viridis",
    title: str | None = None,
    param_units: Mapping[str, str] | None = None,
):
    """Heat map of a score over a two-parameter grid, with the best cell circled and a colour bar.

    Parameters
    ----------
    scores : xarray.DataArray
        Two dimensions (the parameters; e.g. ``grid.sel(shift=0).mean("recording")`` of
        a :func:`tiltlab.evaluate.grid_search` result). The first is drawn on y, the
        second on x; coordinate values label the ticks.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new 4.5 × 3.5 in figure.
    log : bool
        Colour on a logarithmic scale; the colour bar is labelled with plain numbers in
        the score's units.
    name : str
        What the score is (colour-bar label).
    units : str, optional
        Default ``attrs['units']``, else ``"deg"``.
    mark_best : bool
        Circle the minimum.
    cmap : str or Colormap
        Colour map of the cells (default ``"viridis"``).
    title : str, optional
        Axes title.
    param_units : mapping, optional
        Units of the parameters on the axes (a coordinate's ``attrs['units']`` wins);
        default :data:`tiltlab.filters.PARAMETER_UNITS`; a dimensionless one (``"1"``)
        is labelled "(unitless)". Tick labels are plain numbers (``0.00001``, never
        ``1e-05``).

    Returns
    -------
    matplotlib.axes.Axes
    """
    from matplotlib.colors import LogNorm

    from ..filters import PARAMETER_UNITS
    from .filters import plain_log_ticks

    if not isinstance(scores, xr.DataArray) or scores.ndim != 2:
        raise ValueError("scores must be a 2-D DataArray (two parameters)")
    ax = new_axes(ax, figsize=(4.5, 3.5))
    a, b = scores.dims
    v = np.asarray(scores.values, float)
    if log and not (v[np.isfinite(v)] > 0).all():
        raise ValueError("log=True needs positive scores")
    norm = LogNorm(np.nanmin(v), np.nanmax(v)) if log else None
    im = ax.imshow(v, origin="lower", cmap=cmap, aspect="auto", norm=norm)
    ax.set_xticks(
        range(scores.sizes[b]),
        [_fmt(x) for x in scores[b].values] if b in scores.coords else None,
    )
    ax.set_yticks(
        range(scores.sizes[a]),
        [_fmt(x) for x in scores[a].values] if a in scores.coords else None,
    )
    units_by_name = PARAMETER_UNITS if param_units is None else param_units
    for dim, set_label in ((b, ax.set_xlabel), (a, ax.set_ylabel)):
        attrs = scores[dim].attrs if dim in scores.coords else {}
        u = attrs.get("units", units_by_name.get(dim))
        # a dimensionless parameter says so rather than showing no unit at all
        set_label(f"{dim} (unitless)" if u == "1" else label(dim, u))
    if mark_best and np.isfinite(v).any():
        i, j = np.unravel_index(int(np.nanargmin(v)), v.shape)
        ax.plot(j, i, "o", mfc="none", mec="w", ms=14, mew=2, label="best")
    u = units or units_of(scores, "deg")
    cbar = ax.figure.colorbar(
        im, ax=ax, label=label(name, u) + (", log scale" if log else "")
    )
    if log:
        plain_log_ticks(cbar.ax, "y")
    if title:
        ax.set_title(title)
    return ax


def score_curves(
    scores: xr.DataArray,
    x: str,
    *,
    hue: str | None = None,
    ax=None,
    logx: bool = True,
    logy: bool = False,
    name: str = "mean error",
    units: str | None = None,
    title: str | None = None,
):
    """Plot a score against one parameter, one line per value of another dimension.

    Parameters
    ----------
    scores : xarray.DataArray
        One dimension ``x``, or two (``x`` and ``hue``), e.g. the mean over recordings of
        a grid search scored per behavioural state.
    x : str
        Parameter dimension on the abscissa.
    hue : str, optional
        Dimension with one line per value (default: the other dimension, if any).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new 5 × 3.3 in figure.
    logx : bool
        Logarithmic abscissa, with ticks labelled at the parameter values.
    logy : bool
        Logarithmic score axis.
    name : str
        What the score is (y label).
    units : str, optional
        Default ``attrs['units']``, else ``"deg"``.
    title : str, optional
        Axes title.

    Returns
    -------
    matplotlib.axes.Axes
    """
    if x not in scores.dims:
        raise ValueError(f"{x!r} is not a dimension of scores {scores.dims}")
    others = [d for d in scores.dims if d != x]
    if hue is None and others:
        hue = others[0]
    if len(others) > (1 if hue is not None else 0):
        raise ValueError(
            f"scores must have dims ({x!r}[, hue]); reduce the others first: {scores.dims}"
        )
    ax = new_axes(ax, figsize=(5, 3.3))
    xv = scores[x].values
    if hue is None:
        ax.plot(xv, scores.values, "o-", label=scores.name or name)
    else:
        for h in scores[hue].values:
            ax.plot(xv, scores.sel({hue: h}).transpose(x).values, "o-", label=str(h))
    if logx:
        ax.set_xscale("log")
        # ticks at the parameter values: log minor labels overlap on short decades
        ax.set_xticks(xv)
        ax.set_xticklabels([f"{v:g}" for v in xv])
        ax.minorticks_off()
    if logy:
        ax.set_yscale("log")
    return finish_axes(
        ax,
        label(x, scores[x].attrs.get("units")),
        label(name, units or units_of(scores, "deg")),
        legend_title=hue,
        title=title,
    )


def _common_units(df: pd.DataFrame) -> str | None:
    """Return the units every column of a labelled table shares (None if they differ)."""
    units = df.attrs.get("units")
    if isinstance(units, str):
        return units or None
    if isinstance(units, dict):
        found = {str(units.get(c, "")) for c in df.columns}
        return found.pop() if len(found) == 1 and "" not in found else None
    return None


def trial_bars(
    table,
    *,
    ax=None,
    logy: bool = False,
    name: str = "RMSE",
    units: str | None = None,
    legend_title: str = "estimator",
    title: str | None = None,
    figsize=(9, 5),
):
    """Draw grouped bars: one group per trial, one bar per estimator (or any column).

    Parameters
    ----------
    table : pandas.DataFrame or xarray.DataArray
        Rows = trials, columns = estimators (a 2-D DataArray is converted with
        ``to_pandas()``; its ``units`` label the axis).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure of size ``figsize``.
    logy : bool
        Logarithmic value axis (the y label then says "log scale").
    name : str
        What the values are (y label).
    units : str, optional
        Default ``attrs['units']`` (DataFrame: the units all its columns share in
        ``df.attrs['units']``), else ``"deg"``.
    legend_title : str
        Title of the legend (beside the axes) naming the columns.
    title : str, optional
        Axes title.
    figsize : (float, float)
        Size (inches) of the new figure when ``ax`` is not given.

    Returns
    -------
    matplotlib.axes.Axes
    """
    u = (
        units
        or units_of(table)
        or (_common_units(table) if isinstance(table, pd.DataFrame) else None)
        or "deg"
    )
    df = table.to_pandas() if isinstance(table, xr.DataArray) else pd.DataFrame(table)
    ax = new_axes(ax, figsize=figsize)
    df.plot.bar(ax=ax, width=0.8, logy=logy)
    ax.set_ylabel(label(name + (", log scale" if logy else ""), u))
    ax.set_xlabel(df.index.name or "trial")
    ax.legend(
        title=legend_title,
        loc="upper left",
        bbox_to_anchor=(1.005, 1.0),
        frameon=False,
        fontsize=8,
    )
    if title:
        ax.set_title(title)
    return ax


def ecdf_plot(
    errors: Mapping[str, object],
    *,
    mask=None,
    ax=None,
    logx: bool = True,
    name: str = "tilt error",
    units: str | None = None,
    vline: float | None = None,
    vline_label: str | None = None,
    title: str | None = None,
):
    """Empirical cumulative distributions of per-sample errors, one line per estimator.

    Parameters
    ----------
    errors : mapping str → array_like or xarray.DataArray
        Per-sample errors (NaN ignored).
    mask : array_like of bool, optional
        Samples to keep (e.g. immobility).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new 5 × 3.5 in figure.
    logx : bool
        Logarithmic error axis.
    name : str
        What the errors are (x label).
    units : str, optional
        Default the first series' ``attrs['units']``, else ``"deg"``.
    vline : float, optional
        A reference value (e.g. the optical reference's uncertainty), drawn dashed.
    vline_label : str, optional
        Legend entry of the ``vline`` line (default its value to two significant
        digits).
    title : str, optional
        Axes title.

    Returns
    -------
    matplotlib.axes.Axes
        The axes, with one empirical CDF per series and the legend.
    """
    ax = new_axes(ax, figsize=(5, 3.5))
    for k, (m, e) in enumerate(errors.items()):
        v = np.asarray(e, float).ravel()
        if mask is not None:
            v = v[np.asarray(mask, bool).ravel()]
        v = np.sort(v[np.isfinite(v)])
        ax.plot(v, np.arange(1, v.size + 1) / max(v.size, 1), label=m)
    if vline is not None:
        ax.axvline(vline, ls="--", c="purple", label=vline_label or f"{vline:.2g}")
    if logx:
        ax.set_xscale("log")
    ax.set_xlabel(label(name, units or units_of(next(iter(errors.values())), "deg")))
    ax.set_ylabel("cumulative fraction")
    legend_if_many(ax, fontsize=8)
    if title:
        ax.set_title(title)
    return ax


def binned_errors(
    bins: xr.Dataset,
    *,
    ax=None,
    logy: bool = True,
    name: str = "median error",
    units: str = "deg",
    xname: str = "angular speed",
    xunits: str = "deg/s",
    title: str | None = None,
):
    """Median and interquartile range of errors per speed bin, one line per estimator (Fayat Fig. 2f).

    Parameters
    ----------
    bins : xarray.Dataset
        From :func:`tiltlab.evaluate.binned_by_speed`: ``median``, ``q25``, ``q75`` with
        dims (estimator, speed).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new 5 × 3.5 in figure.
    logy : bool
        Logarithmic error axis.
    name, units : str
        y label and units.
    xname, xunits : str
        x label and units (the bin centres).
    title : str, optional
        Axes title.

    Returns
    -------
    matplotlib.axes.Axes
        The axes, with each estimator's median and interquartile band per bin.
    """
    ax = new_axes(ax, figsize=(5, 3.5))
    xdim = [d for d in bins["median"].dims if d != "estimator"][0]
    for m in bins["estimator"].values:
        b = bins.sel(estimator=m)
        med = b["median"].values
        ax.errorbar(
            b[xdim].values,
            med,
            yerr=[med - b["q25"].values, b["q75"].values - med],
            label=str(m),
            capsize=2,
        )
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel(label(xname, xunits))
    ax.set_ylabel(label(name, units))
    legend_if_many(ax, fontsize=8)
    if title:
        ax.set_title(title)
    return ax
