"""Small helpers shared by the figure recipes: units in labels, new axes, colour bars."""

from __future__ import annotations

from collections.abc import Mapping

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
    """``attrs["units"]`` of a labelled input, else ``default``."""
    if isinstance(data, (xr.DataArray, xr.Dataset)):
        u = data.attrs.get("units")
        if u is not None:
            return str(u)
    return default


def pretty_units(units: str | None) -> str:
    """Units as printed in labels (``deg/s`` → ``°/s``...); ``""`` for dimensionless."""
    if units is None or str(units) in ("", "1"):
        return ""
    return _PRETTY_UNITS.get(str(units), str(units))


def label(name: str, units: str | None = None) -> str:
    """``"name (units)"``; dimensionless quantities (units ``"1"`` or empty) print no unit."""
    u = pretty_units(units)
    return f"{name} ({u})" if u else name


def new_axes(ax=None, figsize=None, **subplot_kw):
    """``ax`` itself, or a new figure with one axes."""
    if ax is not None:
        return ax
    fig = plt.figure(figsize=figsize)
    return fig.add_subplot(111, **subplot_kw)


def time_of(data, time=None, n: int | None = None) -> np.ndarray:
    """Sample times (s): ``time`` if given, else the ``time`` coordinate, else ``i / attrs['fs']``."""
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
    """Add a legend when the axes holds more than one labelled artist."""
    handles, labels = ax.get_legend_handles_labels()
    if len(labels) > 1:
        kw.setdefault("fontsize", 8)
        ax.legend(**kw)
    return ax


def as_mapping(data, name: str = "") -> Mapping:
    """A mapping name → values (a single array becomes ``{name: array}``)."""
    if isinstance(data, Mapping):
        return data
    return {name: data}
