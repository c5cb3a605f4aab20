r"""Sphere figures.

3-D facet renderings, Lambert azimuthal equal-area (LAEA) maps and
the chapters' map recipes (time-on-sphere heat maps, visited facets, KDE maps with
isopleths, grids of maps with colour bars).

Maps use cartopy's :class:`~cartopy.crs.LambertAzimuthalEqualArea` on a **unit sphere**
(``Globe(semimajor_axis=1, semiminor_axis=1)``): longitude and latitude are those of the
direction in the data frame (:func:`tiltlab.sphere.to_lonlat`: longitude 0 = +x, +90° =
+y, latitude 90° = +z). What the sensor axes point to is read from the data
(``attrs["axis_labels"]``, :func:`tiltlab.axes.axis_labels`): "+x (nose)", "+y (left)"
for a rat head whose Recording says so, "+x (right)", "+y (top)" for a phone, plain
"+x", "+y" when the data do not say.
Nothing here downloads data: no coastlines or Natural Earth features are drawn (they
mean nothing on a unit globe), only gridlines, the equator and labelled sensor axes, so
maps render without network access and without cartopy's data directory. (A bare cartopy
projection *displayed* in a notebook does request coastlines — cartopy's
``_repr_html_`` — so chapters display figures, not projections.)

The LAEA projection preserves areas, so a facet's colour patch has the same share of
the disc (radius 2 for the whole sphere) as the facet has of the sphere; around the
antipode of the map centre shapes are strongly distorted, and facets/cells touching it
are left out.

References
----------
.. [1] J. P. Snyder, Map Projections — A Working Manual, USGS Prof. Paper 1395, 1987,
   pp. 182–190. doi:10.3133/pp1395
"""

from __future__ import annotations


from collections.abc import Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from .. import axes as _axes
from .. import sphere as S

__all__ = [
    "unit_globe",
    "laea",
    "tilt_projection",
    "lonlat_deg",
    "project",
    "map_axes",
    "plot_facets",
    "plot_grid",
    "plot_isopleths",
    "plot_mask",
    "plot_points",
    "decorate",
    "axis_names",
    "axis_texts",
    "sphere_3d",
]

SENSOR_AXES = {
    "+x": (1, 0, 0),
    "-x": (-1, 0, 0),
    "+y": (0, 1, 0),
    "-y": (0, -1, 0),
    "+z": (0, 0, 1),
    "-z": (0, 0, -1),
}


def axis_names(obj: Any = None) -> list[str]:
    """Short names of the +x, +y, +z sensor axes, for figure labels.

    Parameters
    ----------
    obj : Recording, DataArray, tilt map, sequence of 3 str or None
        Data whose ``attrs["axis_labels"]`` say what the axes point to
        (:func:`tiltlab.axes.axis_labels`), or the three names themselves; ``None`` or
        data without labels give ``["x", "y", "z"]``.

    Returns
    -------
    list of str
        One name per axis; a parenthesised detail is preferred to the general word
        (``"forward (nose)"`` → ``"nose"``, ``"up (dorsal)"`` → ``"dorsal"``), so that
        map labels stay short.

    Examples
    --------
    >>> axis_names(["forward (nose)", "left", "up (dorsal)"])
    ['nose', 'left', 'dorsal']
    >>> axis_names(None)
    ['x', 'y', 'z']
    """
    if obj is None:
        names = ["x", "y", "z"]
    elif isinstance(obj, Sequence) and all(isinstance(x, str) for x in obj):
        names = _axes.check_labels(obj)
    else:
        names = _axes.axis_labels(obj)
    out = []
    for name in names:
        name = str(name).strip()
        if "(" in name and name.endswith(")"):
            name = name[name.index("(") + 1 : -1].strip() or name
        out.append(name)
    return out


def axis_texts(obj: Any = None) -> dict[str, str]:
    """Texts of the six sensor-axis markers drawn by :func:`decorate`.

    ``"+x (nose)"`` where the data name the axis (:func:`axis_names`), ``"+x"`` where
    they do not; negative axes are ``"−x"`` etc.

    Parameters
    ----------
    obj : optional
        Data with ``attrs["axis_labels"]`` or three axis names (see
        :func:`axis_names`); None gives plain names.

    Returns
    -------
    dict of str to str
        Keys ``"+x"``, ``"-x"``, ``"+y"``, ``"-y"``, ``"+z"``, ``"-z"`` → texts.

    Examples
    --------
    >>> axis_texts(["right", "top", "out of screen"])["+y"]
    '+y (top)'
    """
    out = {}
    for letter, name in zip("xyz", axis_names(obj)):
        plain = name.lower() == letter
        out[f"+{letter}"] = f"+{letter}" if plain else f"+{letter} ({name})"
        out[f"-{letter}"] = f"−{letter}"
    return out


def unit_globe():
    """Return a cartopy Globe that is the unit sphere.

    Returns
    -------
    cartopy.crs.Globe
        The unit sphere (semi-axes 1).
    """
    import cartopy.crs as ccrs

    return ccrs.Globe(ellipse=None, semimajor_axis=1.0, semiminor_axis=1.0)


def laea(centre=(0.0, 0.0, 1.0), *, nose_up: bool | None = None):
    """LAEA projection centred on the direction ``centre`` (unit sphere).

    For a map centred on +z (a tilt map seen from above) ``nose_up`` (default True
    there) rotates it so that +x points up and +y left, as when looking down on an
    animal whose x axis is forward (the nose of a rat head); other centres keep +z
    (north) up.

    Parameters
    ----------
    centre : array_like, shape (3,)
        Direction of the map centre (any non-zero length; default +z).
    nose_up : bool, optional
        Put longitude 0 (+x) at the top; default True when ``centre`` is +z, else False.

    Returns
    -------
    cartopy.crs.LambertAzimuthalEqualArea
        The projection, on the unit-sphere globe (:func:`unit_globe`).
    """
    import cartopy.crs as ccrs

    lon, lat = S.to_lonlat(np.asarray(centre, float) / np.linalg.norm(centre))
    lon, lat = float(np.degrees(lon)), float(np.degrees(lat))
    if nose_up is None:
        nose_up = lat > 89.999
    if nose_up:
        lon = 180.0  # north-polar aspect: meridian lon0 points down, so lon 0 (nose) points up
    return ccrs.LambertAzimuthalEqualArea(
        central_longitude=lon, central_latitude=lat, globe=unit_globe()
    )


def tilt_projection():
    """Return the projection of a tilt map: centred on +z, +x up, +y left.

    Returns
    -------
    cartopy.crs.LambertAzimuthalEqualArea
        The LAEA projection of the unit sphere seen from above.
    """
    return laea((0.0, 0.0, 1.0))


def lonlat_deg(vectors) -> tuple[np.ndarray, np.ndarray]:
    """Longitude and latitude (degrees) of directions.

    Parameters
    ----------
    vectors : array_like, shape (..., 3)
        Directions (sensor-frame unit vectors).

    Returns
    -------
    lon, lat : numpy.ndarray, shape (...)
        Longitude (degrees, measured from +x towards +y) and latitude (degrees, positive
        towards +z).
    """
    lon, lat = S.to_lonlat(np.asarray(vectors, float))
    return np.degrees(lon), np.degrees(lat)


def _centre(proj) -> np.ndarray:
    p = proj.proj4_params
    return S.from_lonlat(
        np.radians(p.get("lon_0", 0.0)), np.radians(p.get("lat_0", 0.0))
    )


def project(proj, vectors) -> np.ndarray:
    """Projected map coordinates (..., 2) of directions (cartopy transform from lon/lat on the same globe).

    Parameters
    ----------
    proj : cartopy.crs.Projection
        The map projection (e.g. from :func:`laea`, or ``ax.projection``).
    vectors : array_like, shape (..., 3)
        Directions (unit vectors).

    Returns
    -------
    numpy.ndarray, shape (..., 2)
        Map coordinates (x, y) in the projection's units (unit sphere).
    """
    import cartopy.crs as ccrs

    v = np.asarray(vectors, float)
    lon, lat = lonlat_deg(v.reshape(-1, 3))
    xy = proj.transform_points(ccrs.PlateCarree(globe=unit_globe()), lon, lat)[:, :2]
    return xy.reshape(v.shape[:-1] + (2,))


def map_axes(fig, spec=111, centre=(0.0, 0.0, 1.0), **kw):
    """Add a GeoAxes with the LAEA projection centred on ``centre`` (global extent).

    ``spec`` is anything ``fig.add_subplot`` takes: ``121``, a tuple ``(nrows, ncols,
    index)`` or a SubplotSpec.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure to add the axes to.
    spec : int, tuple or SubplotSpec
        Position of the axes (default ``111``, the whole figure).
    centre : array_like, shape (3,)
        Direction of the map centre (default +z).
    **kw
        Passed to :func:`laea` (``nose_up``).

    Returns
    -------
    cartopy.mpl.geoaxes.GeoAxes
    """
    proj = laea(centre, **kw)
    ax = fig.add_subplot(
        *(spec if isinstance(spec, tuple) else (spec,)), projection=proj
    )
    ax.set_global()
    return ax


def _far_from_antipode(proj, vectors, min_deg: float) -> np.ndarray:
    anti = -_centre(proj)
    return np.asarray(vectors, float) @ anti < np.cos(np.radians(min_deg))


def plot_facets(
    ax, values, mesh: S.SphereMesh | None = None, *, antipode_deg: float = 4.0, **kw
):
    """Colour the facets of a triangulated sphere by ``values`` (F,) on a LAEA GeoAxes (``ax.tripcolor``).

    Parameters
    ----------
    ax : cartopy.mpl.geoaxes.GeoAxes
        A LAEA map (e.g. from :func:`map_axes`).
    values : array_like, shape (F,)
        One value per facet of ``mesh``.
    mesh : tiltlab.sphere.SphereMesh, optional
        The triangulated sphere; default :func:`tiltlab.sphere.sphere_mesh`.
    antipode_deg : float
        Facets with a vertex within this angle (degrees) of the map's antipode, where
        the projection tears, are not drawn.
    **kw
        Passed to ``ax.tripcolor`` (``cmap``, ``norm``...; ``shading`` defaults to
        ``"flat"``, ``edgecolors`` to ``"none"``).

    Returns
    -------
    matplotlib.collections.PolyCollection
        The artist returned by ``tripcolor`` (for a colour bar).
    """
    mesh = S.sphere_mesh() if mesh is None else mesh
    values = np.asarray(values, float)
    if values.shape != (mesh.n_faces,):
        raise ValueError(
            f"values must have shape ({mesh.n_faces},), got {values.shape}"
        )
    xy = project(ax.projection, mesh.vertices)
    ok_v = _far_from_antipode(ax.projection, mesh.vertices, antipode_deg)
    keep = ok_v[mesh.faces].all(axis=1)
    kw.setdefault("shading", "flat")
    kw.setdefault("edgecolors", "none")
    return ax.tripcolor(
        xy[:, 0],
        xy[:, 1],
        mesh.faces[keep],
        facecolors=values[keep],
        transform=ax.projection,
        **kw,
    )


def plot_mask(
    ax,
    mask,
    mesh: S.SphereMesh | None = None,
    *,
    color="tab:green",
    alpha: float = 0.6,
    **kw,
):
    """Fill the facets where ``mask`` is True with one colour (binarised map, Fayat Fig. 3c–d).

    Parameters
    ----------
    ax : cartopy.mpl.geoaxes.GeoAxes
        A LAEA map.
    mask : array_like of bool, shape (F,)
        One value per facet of ``mesh``.
    mesh : tiltlab.sphere.SphereMesh, optional
        The triangulated sphere; default :func:`tiltlab.sphere.sphere_mesh`.
    color : colour
        Fill colour of the True facets (False facets are transparent).
    alpha : float
        Opacity of the fill (0–1).
    **kw
        Passed to :func:`plot_facets`.

    Returns
    -------
    matplotlib.collections.PolyCollection
    """
    from matplotlib.colors import ListedColormap

    mask = np.asarray(mask, bool)
    vals = np.where(mask, 1.0, np.nan)
    cmap = ListedColormap([color]).with_extremes(bad=(0.0, 0.0, 0.0, 0.0))
    return plot_facets(ax, vals, mesh, cmap=cmap, vmin=0, vmax=1, alpha=alpha, **kw)


def _grid_xy(ax, grid, antipode_deg):
    corners = grid.corners()
    xy = project(ax.projection, corners)
    far = _far_from_antipode(ax.projection, corners, antipode_deg)
    bad = ~(far[:-1, :-1] & far[1:, :-1] & far[:-1, 1:] & far[1:, 1:])
    return xy, bad


def plot_grid(ax, kde_or_values, grid=None, *, antipode_deg: float = 4.0, **kw):
    """Colour the cells of an equal-area grid (a :class:`~tiltlab.sphere.SphericalKDE` or values + grid) on a LAEA map.

    Parameters
    ----------
    ax : cartopy.mpl.geoaxes.GeoAxes
        A LAEA map.
    kde_or_values : tiltlab.sphere.SphericalKDE or array_like
        A KDE (its ``density`` on its ``grid``), or values of the shape of ``grid``.
    grid : optional
        The equal-area grid of the values; ignored for a KDE.
    antipode_deg : float
        Cells within this angle (degrees) of the map's antipode are masked.
    **kw
        Passed to ``ax.pcolormesh`` (``shading`` defaults to ``"flat"``,
        ``rasterized`` to True).

    Returns
    -------
    matplotlib.collections.QuadMesh
        The artist returned by ``pcolormesh``.

    Raises
    ------
    ValueError
        If the values do not match the grid's shape, or no grid is given.
    """
    if isinstance(kde_or_values, S.SphericalKDE):
        values, grid = kde_or_values.density, kde_or_values.grid
    else:
        values = np.asarray(kde_or_values, float)
    if grid is None or values.shape != grid.shape:
        raise ValueError("values must match the grid's shape")
    xy, bad = _grid_xy(ax, grid, antipode_deg)
    vals = np.ma.masked_array(values, bad | ~np.isfinite(values))
    kw.setdefault("shading", "flat")
    kw.setdefault("rasterized", True)
    return ax.pcolormesh(xy[..., 0], xy[..., 1], vals, transform=ax.projection, **kw)


def plot_isopleths(
    ax, kde_result, levels=(0.5, 0.95), *, antipode_deg: float = 10.0, **kw
):
    """Draw cumulative isopleth lines (e.g. 0.50 and 0.95) of a spherical KDE on a LAEA map.

    Parameters
    ----------
    ax : cartopy.mpl.geoaxes.GeoAxes
        A LAEA map.
    kde_result : tiltlab.sphere.SphericalKDE
        The KDE (``density`` on ``grid``).
    levels : sequence of float
        Cumulative probabilities enclosed by the lines (fractions in (0, 1)).
    antipode_deg : float
        Cells within this angle (degrees) of the map's antipode are masked.
    **kw
        Passed to ``ax.contour`` (``colors`` defaults to ``"k"``, ``linewidths`` to 1).

    Returns
    -------
    matplotlib.contour.QuadContourSet
    """
    grid = kde_result.grid
    thr = S.isopleths(kde_result, levels=levels)["threshold"].to_numpy()
    order = np.argsort(thr)
    c = grid.centres()
    xy = project(ax.projection, c)
    far = _far_from_antipode(ax.projection, c, antipode_deg)
    z = np.ma.masked_array(kde_result.density, ~far)
    kw.setdefault("colors", "k")
    kw.setdefault("linewidths", 1.0)
    cs = ax.contour(
        xy[..., 0], xy[..., 1], z, levels=thr[order], transform=ax.projection, **kw
    )
    return cs


def plot_points(ax, vectors, *, antipode_deg: float = 2.0, **kw):
    """Plot directions (a trajectory or a few points) on a LAEA map; points near the antipode are dropped.

    Parameters
    ----------
    ax : cartopy.mpl.geoaxes.GeoAxes
        A LAEA map.
    vectors : array_like, shape (N, 3) or (3,)
        Directions (unit vectors).
    antipode_deg : float
        Points within this angle (degrees) of the map's antipode become NaN (gaps).
    **kw
        Passed to ``ax.plot`` (line and marker style).

    Returns
    -------
    list of matplotlib.lines.Line2D
    """
    v = np.atleast_2d(np.asarray(vectors, float))
    xy = project(ax.projection, v)
    far = _far_from_antipode(ax.projection, v, antipode_deg)
    xy[~far] = np.nan
    return ax.plot(xy[:, 0], xy[:, 1], transform=ax.projection, **kw)


def decorate(
    ax,
    *,
    labels: dict | None = None,
    axis_labels: Any = None,
    equator: bool = True,
    grid_step_deg: float = 30.0,
    gridline_kw: dict | None = None,
    fontsize: float = 8,
):
    """Gridlines (meridians and parallels every ``grid_step_deg``), the equator and labelled sensor axes.

    ``labels`` maps an axis name of ``SENSOR_AXES`` (``"+x"``, ``"-y"``...) to its text
    (``{}``: no labels). By default the texts are :func:`axis_texts` of
    ``axis_labels``: data whose ``attrs["axis_labels"]`` say what the axes point to (a
    Recording, a tilt series or map), or the three names; ``None`` gives plain
    ``+x``, ``+y``, ``+z``. Axes within 30° of the map's antipode, or outside the axes'
    extent, are not labelled.

    Parameters
    ----------
    ax : cartopy.mpl.geoaxes.GeoAxes
        A LAEA map.
    labels : dict, optional
        Key of ``SENSOR_AXES`` → text; default :func:`axis_texts` of ``axis_labels``.
    axis_labels : optional
        Labelled data or three axis names (see above).
    equator : bool
        Draw the equator (the plane of the x and y axes), default True.
    grid_step_deg : float
        Spacing of meridians and parallels (degrees).
    gridline_kw : dict, optional
        Style of the gridlines, updating the default (grey dotted).
    fontsize : float
        Font size of the axis labels (points).

    Returns
    -------
    cartopy.mpl.geoaxes.GeoAxes
        ``ax``.
    """
    import cartopy.crs as ccrs

    gk = dict(color="0.55", linewidth=0.4, linestyle=":", alpha=0.9)
    gk.update(gridline_kw or {})
    ax.gridlines(
        crs=ccrs.PlateCarree(globe=unit_globe()),
        xlocs=np.arange(-180, 181, grid_step_deg),
        ylocs=np.arange(-90 + grid_step_deg, 90, grid_step_deg),
        **gk,
    )
    if equator:
        lon = np.radians(np.linspace(-180, 180, 721))
        plot_points(
            ax, S.from_lonlat(lon, 0 * lon), color="w", lw=1.2, antipode_deg=1.0
        )
        plot_points(
            ax,
            S.from_lonlat(lon, 0 * lon),
            color="k",
            lw=0.5,
            ls="--",
            antipode_deg=1.0,
        )
    labels = axis_texts(axis_labels) if labels is None else labels
    for key, text in labels.items():
        v = np.asarray(SENSOR_AXES[key], float)
        if not _far_from_antipode(ax.projection, v[None], 30.0)[0]:
            continue
        xy = project(ax.projection, v)
        ax.plot(*xy, "k+", ms=6, transform=ax.projection)
        ax.annotate(
            text,
            xy,
            xytext=(4, 4),
            textcoords="offset points",
            fontsize=fontsize,
            annotation_clip=True,
            bbox=dict(boxstyle="round,pad=0.15", fc="w", ec="none", alpha=0.7),
        )
    return ax


def sphere_3d(
    ax,
    values,
    mesh: S.SphereMesh | None = None,
    *,
    cmap="viridis",
    norm=None,
    trajectory=None,
    traj_kw: dict | None = None,
    elev: float = 35.0,
    azim: float = -150.0,
    nan_color="0.85",
):
    """3-D rendering of a triangulated sphere coloured by ``values`` (F,), optionally with a trajectory.

    ``ax`` must be a 3-D axes (``projection="3d"``); NaN values (e.g. unvisited facets)
    are drawn in ``nan_color``. The trajectory is drawn slightly outside the sphere, only
    where it faces the viewer, and above the facets.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.axes3d.Axes3D
        A 3-D axes.
    values : array_like, shape (F,)
        One value per facet of ``mesh`` (NaN allowed).
    mesh : tiltlab.sphere.SphereMesh, optional
        The triangulated sphere; default :func:`tiltlab.sphere.sphere_mesh`.
    cmap : str or Colormap
        Colour map of the values.
    norm : matplotlib.colors.Normalize, optional
        Value → colour scaling; default linear between the finite minimum and maximum.
    trajectory : array_like, shape (N, 3), optional
        Directions to draw as a line on the sphere.
    traj_kw : dict, optional
        Style of the trajectory line, updating the default (white, width 1).
    elev, azim : float
        Elevation and azimuth of the viewpoint (degrees).
    nan_color : colour
        Colour of NaN facets.

    Returns
    -------
    matplotlib.cm.ScalarMappable
        The colour mapping (for a colour bar).
    """
    from matplotlib import colors as mcolors
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    mesh = S.sphere_mesh() if mesh is None else mesh
    values = np.asarray(values, float)
    norm = norm or mcolors.Normalize(np.nanmin(values), np.nanmax(values))
    cm = plt.get_cmap(cmap)
    fc = cm(norm(np.nan_to_num(values, nan=norm.vmin)))
    fc[~np.isfinite(values)] = mcolors.to_rgba(nan_color)
    pc = Poly3DCollection(
        mesh.vertices[mesh.faces],
        facecolors=fc,
        edgecolors=(0, 0, 0, 0.08),
        linewidths=0.1,
    )
    ax.add_collection3d(pc)
    ax.view_init(elev=elev, azim=azim)
    if trajectory is not None:
        el, az = np.radians(elev), np.radians(azim)
        view = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        t = 1.01 * S.as_unit_vectors(trajectory, "trajectory")
        t[t @ view < 0.05] = np.nan
        (line,) = ax.plot(
            t[:, 0], t[:, 1], t[:, 2], **({"color": "w", "lw": 1.0} | (traj_kw or {}))
        )
        line.set_zorder(pc.get_zorder() + 10)
        ax.computed_zorder = False
    for k, lab in zip(range(3), "xyz"):
        e = np.zeros(3)
        e[k] = 1.35
        ax.plot([0, e[0]], [0, e[1]], [0, e[2]], color="k", lw=0.8)
        ax.text(*(1.08 * e), f"+{lab}", fontsize=9)
    ax.set_xlim(-1, 1)
    ax.set_ylim(-1, 1)
    ax.set_zlim(-1, 1)
    ax.set_box_aspect((1, 1, 1))
    ax.set_axis_off()
    return plt.cm.ScalarMappable(norm=norm, cmap=cm)
