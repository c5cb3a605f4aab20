"""Small helpers shared by the figure recipes: units in labels, new axes, colour bars."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

#: how units are printed in axis labels
_PRETTY_UNITS = {
    "deg": "°",
    "deg/s": "°/s",
    "degC": "°C",
    "uT": "µT",
    "m/s^2": "m/s²",
    "1/sr": "sr⁻¹",
    "sr^-1/2": "sr⁻¹ᐟ²",
}

AXIS_COLOURS = {"x": "tab:red", "y": "tab:green", "z": "tab:blue", "w": "0.4"}


def units_of(data, default: str | None = None) -> str | None:
    """Return ``attrs["units"]`` of a labelled input, else ``default``.

    Parameters
    ----------
    data : object
        A DataArray or Dataset (labelled), or anything else.
    default : str, optional
        The units when ``data`` states none.

    Returns
    -------
    str or None
        The units.
    """
    if isinstance(data, (xr.DataArray, xr.Dataset)):
        u = data.attrs.get("units")
        if u is not None:
            return str(u)
    return default


def pretty_units(units: str | None) -> str:
    """Write units as printed in labels (``deg/s`` → ``°/s``...).

    Parameters
    ----------
    units : str or None
        Units as stored (``"deg"``, ``"m/s^2"`` …).

    Returns
    -------
    str
        The printed form; ``""`` for dimensionless (``None``, ``""`` or ``"1"``).
    """
    if units is None or str(units) in ("", "1"):
        return ""
    return _PRETTY_UNITS.get(str(units), str(units))


def label(name: str, units: str | None = None) -> str:
    """Write an axis label ``"name (units)"``.

    Parameters
    ----------
    name : str
        The quantity.
    units : str, optional
        Its units; dimensionless quantities (``"1"`` or empty) print no unit.

    Returns
    -------
    str
        The label.
    """
    u = pretty_units(units)
    return f"{name} ({u})" if u else name


def new_axes(ax=None, figsize=None, **subplot_kw):
    """Return ``ax`` itself, or a new figure with one axes.

    Parameters
    ----------
    ax : matplotlib.axes.Axes, optional
        Axes to draw on.
    figsize : tuple of float, optional
        Size of a new figure (inches).
    **subplot_kw
        Passed to ``Figure.add_subplot`` (e.g. ``projection``).

    Returns
    -------
    matplotlib.axes.Axes
        The axes to draw on.
    """
    if ax is not None:
        return ax
    fig = plt.figure(figsize=figsize)
    return fig.add_subplot(111, **subplot_kw)


def time_of(data, time=None, n: int | None = None) -> np.ndarray:
    """Return sample times (s) of a series.

    Parameters
    ----------
    data : object
        A DataArray with a ``time`` coordinate or ``attrs['fs']``, or anything when
        ``time`` is given.
    time : array_like, optional
        Times (s); they win when given.
    n : int, optional
        Unused; kept for the callers that pass the number of samples.

    Returns
    -------
    numpy.ndarray
        ``time`` if given, else the ``time`` coordinate, else ``i / attrs['fs']``.

    Raises
    ------
    ValueError
        When the times cannot be known.
    """
    if time is not None:
        return np.asarray(time, float)
    if isinstance(data, xr.DataArray):
        if "time" in data.coords:
            return np.asarray(data["time"].values, float)
        if "fs" in data.attrs:
            return np.arange(data.shape[0]) / float(data.attrs["fs"])
    raise ValueError(
        "time is unknown: pass time= (s) or a DataArray with a time coordinate or attrs['fs']"
    )


def legend_if_many(ax, **kw):
    """Add a legend when the axes holds more than one labelled artist.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes.
    **kw
        Passed to ``Axes.legend`` (font size 8 unless given).

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``.
    """
    handles, labels = ax.get_legend_handles_labels()
    if len(labels) > 1:
        kw.setdefault("fontsize", 8)
        ax.legend(**kw)
    return ax


def as_mapping(data, name: str = "") -> Mapping:
    """Return a mapping name → values (a single array becomes ``{name: array}``).

    Parameters
    ----------
    data : mapping or array_like
        Several named series, or one.
    name : str
        The name of a single series.

    Returns
    -------
    mapping
        ``data`` itself when it is a mapping.
    """
    if isinstance(data, Mapping):
        return data
    return {name: data}


@dataclass(frozen=True)
class Look:
    """Presentation options of a figure recipe, passed as keywords.

    Attributes
    ----------
    title : str, optional
        Axes (or figure) title.
    name, units : str, optional
        Name and units of the plotted quantity (axis or colour-bar label).
    cmap : str or Colormap
        Colour map.
    colorbar : bool
        Draw a colour bar.
    axis_labels : data or sequence of 3 str, optional
        What the sensor axes point to (:func:`tiltlab.plot.axis_names`).
    labels : dict, optional
        Sensor-axis labels for :func:`tiltlab.plot.decorate` (``{}`` for none).
    grid_step_deg : float, optional
        Gridline spacing of a map.
    point_kw : dict, optional
        Style of overlaid points.
    iso_color : str
        Colour of isopleth lines.
    figsize : tuple of float, optional
        Size of a new figure (inches).
    """

    title: str | None = None
    name: str | None = None
    units: str | None = None
    cmap: Any = "viridis"
    colorbar: bool = True
    axis_labels: Any = None
    labels: dict | None = None
    grid_step_deg: float | None = None
    point_kw: dict | None = None
    iso_color: str = "w"
    figsize: tuple[float, float] | None = None

    @classmethod
    def take(
        cls, options: dict, allowed: tuple[str, ...], where: str, *, rest: bool = False
    ) -> tuple[Look, dict]:
        """Split keyword options into a look (the ``allowed`` fields) and the rest.

        Parameters
        ----------
        options : dict
            Keyword options of a recipe (not modified).
        allowed : tuple of str
            The look fields the recipe accepts.
        where : str
            The recipe's name, for the message.
        rest : bool
            Return the other options (for the recipe to pass on) instead of refusing
            them.

        Returns
        -------
        look : Look
            The allowed options given, the defaults for the others.
        others : dict
            The remaining options (empty unless ``rest``).

        Raises
        ------
        TypeError
            An option that is neither allowed nor passed on.
        """
        mine = {k: v for k, v in options.items() if k in allowed}
        others = {k: v for k, v in options.items() if k not in allowed}
        if others and not rest:
            raise TypeError(
                f"{where}() got unexpected keyword argument(s) {sorted(others)}"
            )
        return cls(**mine), others


def finish_axes(ax, xlabel: str, ylabel: str, *, legend_title=None, title=None):
    """Label the axes, add a legend when several lines are labelled, and a title.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes.
    xlabel, ylabel : str
        Axis labels.
    legend_title : str, optional
        Title of the legend; ``False``: no legend.
    title : str, optional
        Axes title.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``.
    """
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if legend_title is not False:
        legend_if_many(ax, title=legend_title)
    if title:
        ax.set_title(title)
    return ax


def legend_below(ax, handles, **kw):
    """Put a legend of ``handles`` below a map, centred and without a frame.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The (map) axes.
    handles : list of matplotlib artists
        Legend entries.
    **kw
        Passed to ``Axes.legend`` (e.g. ``ncol``).

    Returns
    -------
    matplotlib.legend.Legend
        The legend.
    """
    return ax.legend(
        handles=handles,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.02),
        fontsize=8,
        frameon=False,
        **kw,
    )
