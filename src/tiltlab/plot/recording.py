"""Time-series figures: Recordings, named series in stacked panels, angular speed.

Every recipe takes its data first (labelled where possible: units come from
``attrs["units"]`` and times from the ``time`` coordinate), an optional ``ax`` and
returns the axes (or the figure for multi-panel recipes). Axis labels always carry units;
plots with several lines get a legend.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from .. import axes as _axes
from ._common import (
    Look,
    AXIS_COLOURS,
    label,
    legend_if_many,
    new_axes,
    pretty_units,
    time_of,
    units_of,
)

__all__ = [
    "shade_mask",
    "plot_vectors",
    "plot_recording",
    "series_panels",
    "speed_trace",
    "speed_histogram",
]

_AXIS_COLOURS = AXIS_COLOURS


def _thicken(legend, lw: float = 2.0):
    """Widen the line samples of a legend so that thin data lines stay identifiable.

    Parameters
    ----------
    legend : matplotlib.legend.Legend or None
        The legend (``None`` is ignored).
    lw : float
        Minimum line width (points) of its line samples.

    Returns
    -------
    matplotlib.legend.Legend or None
    """
    if legend is not None:
        for line in legend.get_lines():
            width = max(lw, line.get_linewidth())
            style = line.get_linestyle()
            line.set_linewidth(width)
            if style in _LEGEND_DASHES:
                # dashes scale with the width: a short legend sample of a thick
                # dash-dot line would show one long dash and look solid
                line.set_dashes([d / width for d in _LEGEND_DASHES[style]])
    return legend


#: Dash patterns (points, at any width) that fit a legend sample several times.
_LEGEND_DASHES = {"--": (4.0, 2.0), "-.": (4.0, 1.5, 1.2, 1.5), ":": (1.2, 1.5)}


#: Default width (inches) of the full-width figures: the book's column at 100 dpi.
FIG_WIDTH = 8.4


def shade_mask(
    ax,
    time: np.ndarray,
    mask: np.ndarray,
    *,
    color: str = "0.9",
    label: str | None = None,
) -> None:
    """Shade the time spans where ``mask`` is True.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes to shade (drawn behind the data, ``zorder`` 0).
    time : array_like, shape (N,)
        Sample times (s).
    mask : array_like of bool, shape (N,)
        True on the samples to shade; each run of True samples becomes one span.
    color : str
        Matplotlib colour of the spans (default ``"0.9"``, light grey).
    label : str, optional
        Legend entry of the first span.
    """
    mask = np.asarray(mask, bool)
    time = np.asarray(time, float)
    if not mask.any():
        return
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    for k, (a, b) in enumerate(zip(edges[::2], edges[1::2])):
        ax.axvspan(
            time[a],
            time[min(b, len(time) - 1)],
            color=color,
            lw=0,
            zorder=0,
            label=label if k == 0 else None,
        )


def plot_vectors(
    ax,
    time,
    values,
    *,
    labels: Sequence[str] = ("x", "y", "z"),
    ylabel: str = "",
    lw: float = 0.7,
) -> None:
    """Plot the columns of ``values`` (N, k) against ``time`` with the book's axis colours.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes to draw on.
    time : array_like, shape (N,)
        Abscissa of the samples (e.g. times in s).
    values : array_like, shape (N, k)
        One line per column, for the first ``len(labels)`` columns.
    labels : sequence of str
        Component names (legend entries; ``x``, ``y``, ``z``, ``w`` get fixed colours,
        also when followed by a description, as in ``"x (forward)"``).
    ylabel : str
        Y-axis label (default none).
    lw : float
        Line width (points).
    """
    values = np.asarray(values)
    for k, lab in enumerate(labels):
        colour = _AXIS_COLOURS.get(str(lab).split(" ")[0])
        ax.plot(time, values[:, k], lw=lw, color=colour, label=lab)
    ax.set_ylabel(ylabel)


def plot_recording(
    rec: xr.Dataset,
    variables: Sequence[str] = ("acc", "gyr"),
    *,
    tmin: float | None = None,
    tmax: float | None = None,
    shade=None,
    shade_label: str | None = None,
    title: str | None = None,
    figsize: tuple[float, float] | None = None,
):
    """One panel per variable of a Recording against time, labelled with its units.

    Vector components are named from the Recording's ``attrs["axis_labels"]`` when it
    has them (``"x (forward)"``), else ``x``, ``y``, ``z``.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording.
    variables : sequence of str
        Variables with dims (time, axis) or (time, quat) to draw.
    tmin, tmax : float, optional
        Time window (s).
    shade : str or array_like of bool, optional
        Samples to shade: the name of a boolean per-sample variable (e.g.
        ``"movement"``), or a boolean mask of the Recording's length (e.g. still periods
        from ``calibration.intervals_to_mask``).
    shade_label : str, optional
        Legend entry of the shaded spans (default: the variable name, or "shaded").
    title : str, optional
        Title above the first panel.
    figsize : (float, float), optional
        Figure size (inches); default the book's width, 2 in per panel plus 0.6 in.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if shade is not None and not isinstance(shade, str):
        mask = np.asarray(shade, bool)
        if mask.shape != (rec.sizes["time"],):
            raise ValueError(
                f"shade must have shape ({rec.sizes['time']},), got {mask.shape}"
            )
        rec = rec.assign(_shade=("time", mask))
        shade_label = shade_label or "shaded"
        shade = "_shade"
    sel = rec.sel(time=slice(tmin, tmax))
    t = sel["time"].values
    fig, axes = plt.subplots(
        len(variables),
        1,
        sharex=True,
        figsize=figsize or (FIG_WIDTH, 2.0 * len(variables) + 0.6),
        squeeze=False,
    )
    for ax, v in zip(axes[:, 0], variables):
        da = sel[v]
        comp = [str(c) for c in da[da.dims[1]].values]
        if da.dims[1] == "axis" and len(comp) == 3:
            names = _axes.axis_labels(rec)
            comp = [c if n == c else f"{c} ({n})" for c, n in zip(comp, names)]
        plot_vectors(
            ax, t, da.values, labels=comp, ylabel=label(v, da.attrs.get("units", ""))
        )
        if shade is not None:
            shade_mask(ax, t, sel[shade].values, label=shade_label or shade)
        _thicken(
            ax.legend(
                loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, frameon=False
            )
        )
    axes[-1, 0].set_xlabel(label("time", "s"))
    if title:
        axes[0, 0].set_title(title)
    fig.tight_layout()
    return fig


def series_panels(
    panels: Mapping[str, Mapping[str, object]],
    *,
    time=None,
    units: str | Mapping[str, str] | None = None,
    xlabel: str = "time",
    xunits: str = "s",
    styles: Mapping[str, dict] | None = None,
    ylim: Mapping[str, tuple] | None = None,
    logy: bool | Sequence[str] = False,
    sharex: bool = True,
    **look,
):
    """Stacked panels of named series against a common time axis, one legend per panel.

    The recipe behind "estimate against reference" figures (Benhamou angles against the
    optical reference, filters against a smoother, drift corrections, body rotations).

    Parameters
    ----------
    panels : mapping str → mapping str → array_like or xarray.DataArray
        Panel y-label → {line label → values (N,)}.
    time : array_like, optional
        Common abscissa; default the ``time`` coordinate (or ``i / attrs['fs']``) of the
        first labelled series.
    units : str or mapping, optional
        Units of every panel, or per panel label; default the first series' ``attrs['units']``.
    xlabel, xunits : str
        Abscissa label and units.
    styles : mapping, optional
        Line label → keyword arguments of ``ax.plot`` (e.g. ``{"optical": dict(lw=2, color="0.7")}``).
        Lines named after a sensor axis (``x``, ``y``, ``z``, ``w``, also followed by a
        description) get the book's fixed axis colours, as in :func:`plot_recording`,
        unless a style gives another colour.
    ylim : mapping, optional
        Panel label → y limits.
    logy : bool or sequence of str
        Log scale for all panels, or for the named ones.
    sharex : bool
        Share the time axis between the panels.
    **look
        ``title`` (above the first panel) and ``figsize`` (inches; default the
        book's width, 1.9 in per panel).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not panels:
        raise ValueError("panels is empty")
    style, _ = Look.take(look, ("title", "figsize"), "series_panels")
    styles = styles or {}
    fig, axes = plt.subplots(
        len(panels),
        1,
        sharex=sharex,
        squeeze=False,
        figsize=style.figsize or (FIG_WIDTH, 1.9 * len(panels) + 0.8),
    )
    for ax, (name, lines) in zip(axes[:, 0], panels.items()):
        if not isinstance(lines, Mapping):
            lines = {name: lines}
        first = next(iter(lines.values()))
        for lab, y in lines.items():
            yy = np.asarray(y, float)
            if time is not None or isinstance(y, xr.DataArray):
                x = time_of(y, time)
            else:
                x = np.arange(len(yy))
            if len(x) != len(yy):
                raise ValueError(
                    f"{name!r}/{lab!r}: {len(yy)} values for {len(x)} times"
                )
            colour = (
                {"color": _AXIS_COLOURS[str(lab).split(" ")[0]]}
                if (str(lab).split(" ")[0] in _AXIS_COLOURS)
                else {}
            )
            ax.plot(
                x, yy, label=lab, **({"lw": 0.8} | colour | dict(styles.get(lab, {})))
            )
        u = units.get(name) if isinstance(units, Mapping) else units
        ax.set_ylabel(label(name, u if u is not None else units_of(first)))
        if logy is True or (not isinstance(logy, bool) and name in logy):
            ax.set_yscale("log")
        if ylim and name in ylim:
            ax.set_ylim(*ylim[name])
        # beside the panel, never on the data
        legend_if_many(ax, loc="upper left", bbox_to_anchor=(1.005, 1.0), frameon=False)
        _thicken(ax.get_legend())
    axes[-1, 0].set_xlabel(label(xlabel, xunits))
    if style.title:
        axes[0, 0].set_title(style.title)
    fig.tight_layout()
    return fig


def speed_trace(
    speed,
    *,
    time=None,
    threshold: float | None = None,
    mask=None,
    mask_label: str = "immobile",
    units: str | None = None,
    log: bool = True,
    ax=None,
    window: tuple[float, float] | None = None,
):
    """Angular speed against time, with an immobility threshold and shaded immobile spans.

    Parameters
    ----------
    speed : array_like or xarray.DataArray, shape (N,)
        Angular speed; a DataArray gives its time coordinate and units.
    time : array_like, optional
        Sample times (s) for a plain array.
    threshold : float, optional
        Threshold drawn as a dashed line (same units).
    mask : array_like of bool, optional
        Samples to shade (e.g. :func:`tiltlab.behavior.immobility`).
    mask_label : str
        Legend entry of the shaded spans.
    units : str, optional
        Default ``attrs['units']``, else ``"deg/s"``.
    log : bool
        Logarithmic speed axis.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure (book width, 3 in high).
    window : (float, float), optional
        Time window (s) to show.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, figsize=(FIG_WIDTH, 3))
    u = units or units_of(speed, "deg/s")
    y = np.asarray(speed, float)
    t = (
        time_of(speed, time)
        if (time is not None or isinstance(speed, xr.DataArray))
        else np.arange(len(y))
    )
    keep = (
        np.ones(len(y), bool) if window is None else (t >= window[0]) & (t < window[1])
    )
    ax.plot(t[keep], y[keep], lw=0.5, color="k", label="angular speed")
    if threshold is not None:
        ax.axhline(
            threshold,
            color="tab:orange",
            ls="--",
            label=f"threshold {threshold:g} {pretty_units(u)}",
        )
    if mask is not None:
        shade_mask(
            ax,
            t[keep],
            np.asarray(mask, bool)[keep],
            color="tab:orange",
            label=mask_label,
        )
        for p in ax.patches:
            p.set_alpha(0.25)
    if log:
        ax.set_yscale("log")
    ax.set_xlabel(label("time", "s"))
    ax.set_ylabel(label("angular speed", u))
    legend_if_many(ax, loc="upper right")
    _thicken(ax.get_legend())
    return ax


def speed_histogram(
    speeds,
    *,
    thresholds: float | Mapping[str, float] | None = None,
    bins=80,
    units: str | None = None,
    density: bool = True,
    ax=None,
):
    """Histogram(s) of log10 angular speed, with immobility thresholds as vertical lines.

    Parameters
    ----------
    speeds : array_like, xarray.DataArray or mapping str → array_like
        One speed series, or several (one step histogram each, with a legend).
    thresholds : float or mapping str → float, optional
        Threshold(s) (same units) drawn as vertical lines; a single value is labelled
        with its units ("threshold 12 °/s"), a mapping by its names.
    bins : int or array_like
        Bins in log10 speed.
    units : str, optional
        Default the first series' ``attrs['units']``, else ``"deg/s"``.
    density : bool
        Normalise each histogram to unit area (probability density per log10 unit);
        False plots sample counts.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new 6 × 3 in figure.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, figsize=(6, 3))
    series = speeds if isinstance(speeds, Mapping) else {"angular speed": speeds}
    u = units or units_of(next(iter(series.values())), "deg/s")
    many = len(series) > 1
    for name, s in series.items():
        v = np.asarray(s, float)
        v = v[np.isfinite(v) & (v > 0)]
        ax.hist(
            np.log10(v),
            bins=bins,
            density=density,
            histtype="step" if many else "stepfilled",
            lw=1.5,
            color=None if many else "0.5",
            label=name,
        )
    if thresholds is not None:
        th = (
            thresholds
            if isinstance(thresholds, Mapping)
            else {f"{thresholds:g} {pretty_units(u)}".strip(): thresholds}
        )
        for k, (name, v) in enumerate(th.items()):
            ax.axvline(
                np.log10(v),
                color=f"C{k + 1}",
                ls="--",
                lw=1.0,
                label=f"threshold {name}",
            )
    ax.set_xlabel(label("log10 angular speed", u))
    ax.set_ylabel("density" if density else "count")
    # beside the axes, never over the histograms or the threshold lines
    legend_if_many(ax, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    return ax
