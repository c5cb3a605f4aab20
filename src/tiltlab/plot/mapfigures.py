"""Sphere figure recipes.

Heat maps of time on the sphere, visited facets, KDE maps with
isopleths, grids of maps and residence maps, built on the LAEA primitives of
:mod:`tiltlab.plot.maps`. Each takes its data first (labelled where possible), an optional
``ax``, and adds colour bars and units.
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from .. import axes as _axes
from .. import sphere as S
from ._common import Look, label, legend_below, legend_if_many, units_of
from .maps import (
    tilt_projection,
    project,
    map_axes,
    plot_facets,
    plot_mask,
    plot_grid,
    plot_isopleths,
    plot_points,
    decorate,
    axis_names,
    sphere_3d,
)

__all__ = [
    "map_grid",
    "facet_map",
    "tilt_heatmap",
    "tilt_overview",
    "visited_map",
    "kde_map",
    "tilt_points_map",
    "tilt_trace",
    "residence_figure",
]

#: Widest default figure (inches): the book's column at its display resolution, so that
#: figures are never shrunk and their text stays at least 8 pt.
MAX_WIDTH_IN = 8.4

# ---------------------------------------------------------------------------
# figure recipes
# ---------------------------------------------------------------------------


def _map_ax(ax, centre=(0.0, 0.0, 1.0), figsize=(5, 5)):
    if ax is None:
        fig = plt.figure(figsize=figsize)
        return map_axes(fig, 111, centre=centre)
    if not hasattr(ax, "projection"):
        raise ValueError(
            "ax must be a map axes (tiltlab.plot.map_axes or map_grid), got a plain Axes"
        )
    return ax


def _colorbar(ax, mappable, text: str, **kw):
    kw.setdefault("shrink", 0.7)
    return ax.figure.colorbar(mappable, ax=ax, label=text, **kw)


def _is_map(data) -> bool:
    return isinstance(data, xr.Dataset) and "count" in data and "facet" in data.dims


def _mesh_of(tmap: xr.Dataset, mesh):
    if mesh is not None:
        return mesh
    return S.sphere_mesh(int(tmap.attrs.get("n_vertices", 5000)))


def _as_map(data, mesh):
    """Return a tilt map from a tilt-map Dataset or from tilt vectors (labelled or plain)."""
    if _is_map(data):
        return data, _mesh_of(data, mesh)
    mesh = S.sphere_mesh() if mesh is None else mesh
    return S.tilt_map(data, mesh=mesh), mesh


def map_grid(
    n: int,
    *,
    ncols: int | None = None,
    centre=(0.0, 0.0, 1.0),
    panel_size: float | None = None,
    figsize: tuple[float, float] | None = None,
    **kw,
):
    """Make a figure with ``n`` LAEA map axes in a grid.

    Parameters
    ----------
    n : int
        Number of maps.
    ncols : int, optional
        Maps per row (default ``n`` up to 3).
    centre : array_like (3,) or sequence of them
        Map centre (direction), one for all or one per map.
    panel_size : float, optional
        Width (inches) of one map when ``figsize`` is not given; the height adds room
        for a legend below the map. Default: the grid fits the book's column,
        ``min(4.2, MAX_WIDTH_IN / ncols)``.
    figsize : (float, float), optional
        Figure size (inches); overrides ``panel_size``.
    **kw
        Passed to :func:`laea` (``nose_up``).

    Returns
    -------
    fig : matplotlib.figure.Figure
    axes : list of cartopy GeoAxes
    """
    n = int(n)
    if n < 1:
        raise ValueError(f"n must be at least 1, got {n!r}")
    ncols = min(n, 3) if ncols is None else int(ncols)
    nrows = -(-n // ncols)
    if figsize is None:
        panel = (
            min(4.2, MAX_WIDTH_IN / ncols) if panel_size is None else float(panel_size)
        )
        figsize = (panel * ncols, (panel + 0.5) * nrows)
    fig = plt.figure(figsize=figsize)
    c = np.asarray(centre, float)
    centres = [c] * n if c.ndim == 1 else list(c)
    if len(centres) != n:
        raise ValueError(f"centre must be one direction or {n} of them")
    axes = [
        map_axes(fig, (nrows, ncols, k + 1), centre=centres[k], **kw) for k in range(n)
    ]
    return fig, axes


_FACET_LOOK = ("name", "units", "cmap", "colorbar", "axis_labels", "title")
_KDE_LOOK = (
    "cmap",
    "iso_color",
    "colorbar",
    "labels",
    "axis_labels",
    "grid_step_deg",
    "point_kw",
    "title",
)


def facet_map(
    values,
    mesh: S.SphereMesh | None = None,
    *,
    ax=None,
    log: bool = False,
    decorate_kw: dict | None = None,
    **kw,
):
    """Colour the facets of a triangulated sphere on a LAEA map, with gridlines and a colour bar.

    Parameters
    ----------
    values : array_like or xarray.DataArray, shape (F,)
        A value per facet (NaN facets stay blank); a DataArray gives ``long_name`` and
        ``units`` for the colour-bar label.
    mesh : SphereMesh, optional
        Default the 5000-vertex Fibonacci mesh.
    ax : GeoAxes, optional
        A map axes (:func:`map_axes`, :func:`map_grid`); default a new figure centred on +z.
    log : bool
        Colour by log10 of the values (non-positive values are left blank).
    decorate_kw : dict, optional
        Passed to :func:`decorate`.
    **kw
        The look: ``name`` and ``units`` (colour-bar label and units; default from
        the DataArray, else ``"value"``), ``cmap`` (default ``"viridis"``),
        ``colorbar`` (default True), ``axis_labels`` (what the sensor axes point to,
        :func:`axis_names`; default read from ``values``' attrs, else plain ``+x``,
        ``+y``, ``+z``) and ``title``; any other keyword is passed to
        :func:`plot_facets`.

    Returns
    -------
    GeoAxes
    """
    look, kw = Look.take(kw, _FACET_LOOK, "facet_map", rest=True)
    ax = _map_ax(ax)
    axis_labels = look.axis_labels
    if axis_labels is None and isinstance(values, xr.DataArray):
        axis_labels = values
    name = (
        look.name
        or (values.attrs.get("long_name") if isinstance(values, xr.DataArray) else None)
        or "value"
    )
    units = look.units if look.units is not None else units_of(values)
    v = np.asarray(values, float)
    if log:
        with np.errstate(divide="ignore", invalid="ignore"):
            v = np.where(v > 0, np.log10(v), np.nan)
        name = f"log10 {name}"
    art = plot_facets(ax, v, mesh, cmap=look.cmap, **kw)
    decorate(ax, **({"axis_labels": axis_labels} | (decorate_kw or {})))
    if look.colorbar:
        _colorbar(ax, art, label(name, units))
    if look.title:
        ax.set_title(look.title, fontsize=9)
    return ax


def tilt_heatmap(
    tilt,
    *,
    mesh: S.SphereMesh | None = None,
    quantity: str = "fraction",
    log: bool = True,
    ax=None,
    cmap="magma",
    title: str | None = None,
    **kw,
):
    """Heat map of the time spent on each facet of the sphere (Fayat et al. Fig. 3a–b).

    Parameters
    ----------
    tilt : xarray.Dataset, xarray.DataArray or array_like
        A tilt map (:func:`tiltlab.sphere.tilt_map`) or tilt vectors to map (a labelled
        (time, axis) series with ``fs``, a Recording with ``gravity``, or an (N, 3)
        array). Its ``attrs["axis_labels"]`` name the sensor axes on the map.
    mesh : SphereMesh, optional
        The map's mesh (default the mesh with the map's ``n_vertices``, or 5000 vertices).
    quantity : {"fraction", "time", "count", "density"}
        Variable of the map to colour (``time`` needs a known sampling rate).
    log : bool
        Colour by log10 (facets never visited stay blank either way).
    ax : GeoAxes, optional
        A map axes (:func:`map_axes`, :func:`map_grid`); default a new 5 × 5 in figure
        centred on +z.
    cmap : str or Colormap
        Colour map of the facets (default ``"magma"``).
    title : str, optional
        Title above the map.
    **kw
        Passed to :func:`facet_map`.

    Returns
    -------
    GeoAxes
    """
    tmap, mesh = _as_map(tilt, mesh)
    if quantity not in ("fraction", "time", "count", "density"):
        raise ValueError(
            f"quantity must be 'fraction', 'time', 'count' or 'density', got {quantity!r}"
        )
    if quantity not in tmap:
        raise ValueError(
            f"the map has no {quantity!r} (the sampling rate fs is unknown); use quantity='fraction'"
        )
    da = tmap[quantity].where(tmap["count"] > 0)
    kw.setdefault("axis_labels", _axes.axis_labels(tmap))
    return facet_map(
        da,
        mesh,
        ax=ax,
        name=da.attrs.get("long_name", quantity),
        units=da.attrs.get("units"),
        log=log,
        cmap=cmap,
        title=title,
        **kw,
    )


def tilt_overview(
    tilt,
    *,
    mesh: S.SphereMesh | None = None,
    quantity: str = "fraction",
    log: bool = True,
    cmap="magma",
    traj_kw: dict | None = None,
    figsize=(MAX_WIDTH_IN, 3.8),
):
    """Show a 3-D sphere with the trajectory beside the LAEA heat map of the same tilt map.

    Parameters
    ----------
    tilt : xarray.DataArray, xarray.Dataset or array_like
        Tilt vectors (labelled (time, axis) with ``fs``, a Recording with ``gravity``, or (N, 3)).
    mesh : SphereMesh, optional
        The map's mesh (default the 5000-vertex Fibonacci mesh).
    quantity, log, cmap
        As in :func:`tilt_heatmap`.
    traj_kw : dict, optional
        Style of the trajectory on the 3-D sphere.
    figsize : (float, float)
        Default: the book's column width, 8.4 in.

    Returns
    -------
    matplotlib.figure.Figure
        Panels (a) 3-D sphere and trajectory, (b) LAEA map centred on +z with a colour bar.
    """
    mesh = S.sphere_mesh() if mesh is None else mesh
    tmap = S.tilt_map(tilt, mesh=mesh)
    if quantity not in tmap:
        raise ValueError(
            f"the map has no {quantity!r} (the sampling rate fs is unknown or quantity "
            "is not one of 'fraction', 'time', 'count', 'density')"
        )
    g = S.as_unit_vectors(tilt, "tilt", allow_nan=True)
    fig = plt.figure(figsize=figsize)
    ax3 = fig.add_subplot(121, projection="3d")
    v = tmap[quantity].where(tmap["count"] > 0).values
    with np.errstate(divide="ignore", invalid="ignore"):
        v3 = np.log10(v) if log else v
    sm = sphere_3d(
        ax3,
        v3,
        mesh,
        cmap=cmap,
        trajectory=g,
        traj_kw={"color": "c", "lw": 0.4, "alpha": 0.6} | (traj_kw or {}),
    )
    ax3.set_box_aspect((1, 1, 1), zoom=1.25)  # the sphere fills its panel
    name = ("log10 " if log else "") + tmap[quantity].attrs.get("long_name", quantity)
    ax3.set_title(f"(a) {name} per facet and trajectory", fontsize=9)
    ax = map_axes(fig, 122)
    tilt_heatmap(
        tmap,
        mesh=mesh,
        quantity=quantity,
        log=log,
        ax=ax,
        cmap=cmap,
        norm=sm.norm,
        title="(b) LAEA map centred on +z",
    )
    return fig


def visited_map(
    series: Mapping[str, object],
    *,
    mesh: S.SphereMesh | None = None,
    colors=None,
    alpha: float = 0.75,
    ax=None,
    min_count: int = 1,
    legend: bool = True,
    decorate_kw: dict | None = None,
    title: str | None = None,
):
    """Binarised maps (facets visited at least ``min_count`` times) of several series, overlaid.

    Parameters
    ----------
    series : mapping str → tilt vectors or tilt map
        E.g. ``{"active": g[~immobile], "immobile": g[immobile]}``; later entries are drawn
        on top.
    mesh : SphereMesh, optional
        The mesh of the maps (default a tilt map's own mesh, else the 5000-vertex
        Fibonacci mesh).
    colors : sequence of colours, optional
        One per series (default green, red, blue...).
    alpha : float
        Opacity of the visited facets and of their legend patches, in [0, 1].
    ax : GeoAxes, optional
        A map axes (:func:`map_axes`, :func:`map_grid`); default a new 5 × 5 in figure
        centred on +z.
    min_count : int
        Minimum number of samples (≥ 1) for a facet to count as visited.
    legend : bool
        Add a legend below the map, each series with its visited percentage of the
        sphere (by area).
    decorate_kw : dict, optional
        Passed to :func:`decorate`; the sensor axes are named from the first series
        whose attrs have ``axis_labels``.
    title : str, optional
        Title above the map.

    Returns
    -------
    GeoAxes
    """
    from matplotlib.patches import Patch

    ax = _map_ax(ax)
    colors = (
        list(colors)
        if colors is not None
        else ["tab:green", "tab:red", "tab:blue", "tab:orange", "tab:purple"]
    )
    handles = []
    names = None
    for k, (name, data) in enumerate(series.items()):
        tmap, m = _as_map(data, mesh)
        names = names or tmap.attrs.get("axis_labels")
        c = colors[k % len(colors)]
        plot_mask(ax, S.visited(tmap, min_count=min_count), m, color=c, alpha=alpha)
        frac = S.visited_fraction(tmap, m, min_count=min_count)
        handles.append(
            Patch(
                color=c, alpha=alpha, label=f"{name} ({100 * frac:.1f} % of the sphere)"
            )
        )
    decorate(ax, **({"fontsize": 8, "axis_labels": names} | (decorate_kw or {})))
    if legend:
        legend_below(ax, handles)
    if title:
        ax.set_title(title, fontsize=9)
    return ax


def kde_map(
    kde: S.SphericalKDE,
    *,
    levels=(0.5, 0.95),
    scale: str = "sqrt",
    cut: float | None = None,
    points=None,
    centre=(0.0, 0.0, 1.0),
    extent: float | None = None,
    ax=None,
    **look,
):
    """Map a spherical KDE on a LAEA map with its cumulative isopleths (Benhamou Fig. 5).

    Parameters
    ----------
    kde : tiltlab.sphere.SphericalKDE
        From :func:`tiltlab.sphere.kde` or :func:`tiltlab.sphere.mkde`.
    levels : sequence of float
        Isopleths to draw (fractions of the distribution), each with its line style and
        a legend entry.
    scale : {"sqrt", "linear", "log"}
        Colour scale of the density.
    cut : float, optional
        Show the density only inside this isopleth (e.g. 0.95).
    points : array_like (N, 3) or labelled tilt, optional
        Samples to overlay as dots.
    centre : array_like (3,) or "mean"
        Map centre for a new axes: a direction, or the density's mean direction.
    extent : float, optional
        Half-width of the view in map units (2 = the whole sphere); default global.
    ax : GeoAxes, optional
        Map axes to draw on (default a new figure centred on ``centre``).
    **look
        ``cmap`` and ``iso_color`` (colour map of the density, default
        ``"viridis"``, and colour of the isopleth lines, default white),
        ``colorbar`` (default True), ``labels`` (sensor-axis labels for
        :func:`decorate`, ``{}`` for none), ``axis_labels`` (what the sensor axes
        point to, :func:`axis_names`, when ``labels`` is not given; default read from
        labelled ``points``, else plain ``+x``, ``+y``), ``grid_step_deg`` (gridline
        spacing, default 30°, 10° for a zoomed view), ``point_kw`` (style of the
        points) and ``title``.

    Returns
    -------
    GeoAxes
    """
    from matplotlib.lines import Line2D

    style, _ = Look.take(look, _KDE_LOOK, "kde_map")
    iso_color, point_kw = style.iso_color, style.point_kw
    if not isinstance(kde, S.SphericalKDE):
        raise TypeError(
            f"kde must be a tiltlab.sphere.SphericalKDE, got {type(kde).__name__}"
        )
    if isinstance(centre, str):
        if centre != "mean":
            raise ValueError(f"centre must be a direction or 'mean', got {centre!r}")
        centre = S.vmf_fit(kde.grid.centres().reshape(-1, 3), kde.density.ravel()).mu
    ax = _map_ax(ax, centre=centre)
    d = np.array(kde.density, float)
    if cut is not None:
        d = np.where(S.isopleth_mask(kde, cut), d, np.nan)
    if scale == "sqrt":
        shown, name = np.sqrt(d), label("√density", "sr^-1/2")
    elif scale == "linear":
        shown, name = d, label("density", "1/sr")
    elif scale == "log":
        with np.errstate(divide="ignore", invalid="ignore"):
            shown = np.where(d > 0, np.log10(d), np.nan)
        name = label("log10 density", "1/sr")
    else:
        raise ValueError(f"scale must be 'sqrt', 'linear' or 'log', got {scale!r}")
    art = plot_grid(ax, shown, kde.grid, cmap=style.cmap)
    levels = sorted(float(x) for x in np.atleast_1d(levels))
    styles = ["-", "--", ":", "-."]
    handles = []
    for k, lev in enumerate(levels):
        ls = styles[k % len(styles)]
        plot_isopleths(ax, kde, [lev], colors=iso_color, linestyles=ls)
        handles.append(
            Line2D(
                [],
                [],
                color=iso_color if iso_color != "w" else "k",
                ls=ls,
                label=f"{100 * lev:g} % isopleth",
            )
        )
    if points is not None:
        pts = S.as_unit_vectors(points, "points", allow_nan=True)
        plot_points(
            ax,
            pts,
            **(
                {"ls": "none", "marker": ".", "ms": 1, "color": "darkgreen"}
                | (point_kw or {})
            ),
        )
        handles.append(
            Line2D(
                [],
                [],
                ls="none",
                marker=".",
                color=(point_kw or {}).get("color", "darkgreen"),
                label="samples",
            )
        )
    if extent is not None:
        e = float(extent)
        ax.set_extent([-e, e, -e, e], crs=ax.projection)
    step = (
        style.grid_step_deg
        if style.grid_step_deg is not None
        else (10.0 if extent is not None and extent < 1 else 30.0)
    )
    axis_labels = style.axis_labels
    if axis_labels is None and points is not None and hasattr(points, "attrs"):
        axis_labels = points
    decorate(
        ax, labels=style.labels, axis_labels=axis_labels, grid_step_deg=step, fontsize=8
    )
    if style.colorbar:
        _colorbar(ax, art, name)
    legend_below(ax, handles, ncol=len(handles))
    if style.title:
        ax.set_title(style.title, fontsize=9)
    return ax


def tilt_points_map(
    points,
    *,
    names=None,
    baseline=None,
    ax=None,
    extent: float = 0.8,
    grid_step_deg: float = 10.0,
    axis_labels=None,
    title: str | None = None,
    **kw,
):
    """Mean tilt points (e.g. one per session) on a zoomed LAEA map, optionally with a baseline at the pole.

    Parameters
    ----------
    points : array_like (K, 3) or mapping str → (3,)
        Directions; a mapping names them (legend entries).
    names : sequence of str, optional
        Names of the rows of an array.
    baseline : array_like (3,) or str, optional
        Rotate every point so that the baseline (a direction, or the name of a point)
        sits at the pole (Fayat et al. Fig. 3e): distances to the pole are then distances
        to the baseline.
    ax : GeoAxes, optional
        A map axes (:func:`map_axes`, :func:`map_grid`); default a new 5 × 5 in figure
        centred on +z.
    extent : float
        Half-width of the view in map units.
    grid_step_deg : float
        Spacing of the meridians and parallels (degrees), also printed in the map's
        corner.
    axis_labels : data or sequence of 3 str, optional
        What the sensor axes point to (:func:`axis_names`); default plain ``+x``, ``+y``.
    title : str, optional
        Title above the map.
    **kw
        Marker style.

    Returns
    -------
    GeoAxes
    """
    if isinstance(points, Mapping):
        names, pts = (
            list(points),
            np.stack([np.asarray(v, float) for v in points.values()]),
        )
    else:
        pts = np.atleast_2d(np.asarray(points, float))
        names = (
            list(names)
            if names is not None
            else [f"point {k}" for k in range(len(pts))]
        )
    if len(names) != len(pts):
        raise ValueError(f"{len(names)} names for {len(pts)} points")
    if baseline is not None:
        b = (
            pts[names.index(baseline)]
            if isinstance(baseline, str)
            else np.asarray(baseline, float)
        )
        pts = S.rotate_to_pole(pts, b)
    ax = _map_ax(ax)
    for k, (name, p) in enumerate(zip(names, pts)):
        plot_points(
            ax,
            p[None],
            **({"marker": "o", "ms": 5, "ls": "none", "color": f"C{k}"} | kw),
            label=name,
        )
    ax.set_extent([-extent, extent, -extent, extent], crs=ax.projection)
    decorate(
        ax,
        fontsize=8,
        grid_step_deg=grid_step_deg,
        labels={} if baseline is not None else None,
        axis_labels=axis_labels,
    )
    legend_if_many(ax, loc="upper center", bbox_to_anchor=(0.5, -0.02), frameon=False)
    ax.text(
        0.02,
        0.02,
        f"grid: {grid_step_deg:g}° steps",
        transform=ax.transAxes,
        fontsize=8,
        color="0.3",
    )
    if title:
        ax.set_title(title, fontsize=9)
    return ax


def tilt_trace(tilt, *, ax=None, axis_labels=None, title: str | None = None, **kw):
    """Draw a tilt trajectory on the plane of the tilt LAEA projection (no map axes needed).

    +x points up and +y left, as seen from above; the dashed circle of radius √2 is the
    horizon (tilt 90°). The axis titles name what +x and +y point to when the data say
    (``attrs["axis_labels"]``: "nose (+x)" and "left (+y)" for a rat head).

    Parameters
    ----------
    tilt : xarray.DataArray, xarray.Dataset or array_like
        Tilt vectors (a labelled (time, axis) series, a Recording with ``gravity``, or (N, 3)).
    ax : matplotlib.axes.Axes, optional
        Plain axes to draw on; default a new 4.5 × 4.5 in figure.
    axis_labels : data or sequence of 3 str, optional
        What the sensor axes point to (:func:`axis_names`); default from ``tilt``.
    title : str, optional
        Title above the plot.
    **kw
        Style of the trajectory line.

    Returns
    -------
    matplotlib.axes.Axes
    """
    from ._common import new_axes

    g = S.as_unit_vectors(tilt, "tilt", allow_nan=True)
    nx, ny, _ = axis_names(tilt if axis_labels is None else axis_labels)
    ax = new_axes(ax, figsize=(4.5, 4.5))
    xy = project(tilt_projection(), g)
    ax.plot(
        *xy.T,
        **({"lw": 0.2, "color": "k", "alpha": 0.5, "label": "tilt trajectory"} | kw),
    )
    ax.add_patch(
        plt.Circle(
            (0, 0),
            np.sqrt(2),
            fill=False,
            color="tab:blue",
            ls="--",
            label="horizon (90° tilt)",
        )
    )
    ax.set(
        aspect="equal",
        xlim=(-2.05, 2.05),
        ylim=(-2.05, 2.05),
        xlabel=f"LAEA x: ← {_named(ny, 'y')}   −y →",
        ylabel=f"LAEA y: {_named(nx, 'x')} ↑",
    )
    ax.legend(loc="lower right", fontsize=8)
    if title:
        ax.set_title(title, fontsize=9)
    return ax


def _named(name: str, letter: str) -> str:
    """``"nose (+x)"`` for a named axis, ``"+x"`` for an unnamed one."""
    return f"+{letter}" if name.lower() == letter else f"{name} (+{letter})"


def residence_figure(
    res,
    mesh: S.SphereMesh,
    *,
    series=None,
    cmap="cividis",
    figsize=None,
    panel_titles: tuple[str, str] = (
        "number of visits",
        "mean residence time per visit",
    ),
):
    """Map visits and mean residence time per cap, optionally RT(i), NV(i) along the track.

    Parameters
    ----------
    res : tiltlab.sphere.Residence
        From :func:`tiltlab.sphere.residence` with the mesh's facet centroids as centres.
    mesh : SphereMesh
        The mesh whose centroids were the cap centres.
    series : tuple (time, RT, NV), optional
        Times (s) and values from :func:`tiltlab.sphere.residence_series` (convert its
        sample index to seconds first).
    cmap : str or Colormap
        Colour map of both maps (default ``"cividis"``).
    figsize : (float, float), optional
        Default: two maps side by side, 8.4 in (the book's column) wide; with ``series``
        the trajectory panel spans the column below them.
    panel_titles : (str, str)
        Titles of the visits map and of the residence-time map; the text before
        ``" per "`` names the colour-bar quantity.

    Returns
    -------
    matplotlib.figure.Figure
    """
    rows = 2 if series is not None else 1
    fig = plt.figure(figsize=figsize or (MAX_WIDTH_IN, 3.6 + 2.6 * (rows - 1)))
    heights = [3.6, 2.6][:rows]
    gs = fig.add_gridspec(rows, 2, height_ratios=heights)
    visited = res.n_visits > 0
    for j, (name, v, u) in enumerate(
        [
            (panel_titles[0], res.n_visits.astype(float), "1"),
            (panel_titles[1], res.mean_residence, "s"),
        ]
    ):
        ax = map_axes(fig, gs[0, j])
        facet_map(
            np.where(visited, v, np.nan),
            mesh,
            ax=ax,
            name=name.split(" per ")[0],
            units=u,
            cmap=cmap,
            decorate_kw={"fontsize": 8},
            title=name,
        )
    if series is not None:
        t, rt, nv = series
        ax = fig.add_subplot(gs[1, :])
        ax.plot(t, rt, lw=0.8, label="RT(i): residence time (s)")
        ax.plot(t, nv, lw=0.8, label="NV(i): number of visits")
        ax.set(xlabel=label("time", "s"), ylabel=label("RT (s) / NV", None))
        ax.set_title(
            "along the trajectory (cap centred on the current sample)", fontsize=9
        )
        # inside the panel, so that it does not sit between the maps and the title
        ax.legend(fontsize=8, loc="upper left", frameon=False)
    fig.tight_layout()
    return fig
