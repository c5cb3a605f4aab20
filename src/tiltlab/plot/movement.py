"""Figure recipes for movement read-outs: changes of heading and flight classes.

Figures of chapter 7 (Benhamou 2023, §7 and §9): the density of the changes of heading
on the sphere beside the circular density of their direction, and the windows of a
heave signal coloured by flight class beside the thresholds in the (CV, period) plane.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from .. import sphere as S
from .mapfigures import kde_map, map_grid
from .maps import project

__all__ = ["heading_change_figure", "flight_classes_figure"]

_CLASS_COLOURS = {
    "hover": "tab:purple",
    "flap": "tab:blue",
    "glide": "tab:green",
    "perched": "tab:orange",
    "none": "0.75",
}


def heading_change_figure(
    kde: S.SphericalKDE,
    angles,
    density,
    *,
    max_size: float,
    direction_labels=None,
    title: str = "changes of heading",
):
    """Map the density of changes of heading beside the density of their direction.

    Parameters
    ----------
    kde : tiltlab.sphere.SphericalKDE
        From :func:`tiltlab.sphere.heading_change_kde` (no turn = the map centre, the
        direction as longitude, the size as the angular distance from the centre).
    angles, density : array_like
        From :func:`tiltlab.sphere.circular_kde` (rad, rad⁻¹).
    max_size : float
        Largest arc size (rad) shown on the map.
    direction_labels : dict of {float: str}, optional
        Names of directions (rad) on the polar panel (e.g. ``{0: "left"}``).
    title : str
        Title of the map.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax, old) = map_grid(2, ncols=2)
    extent = 1.1 * 2 * np.sin(min(float(max_size), np.pi) / 2)
    kde_map(kde, ax=ax, extent=extent, labels={}, title=title)
    size = 0.85 * min(float(max_size), np.pi)
    for d, text in (direction_labels or {}).items():
        xy = project(ax.projection, S.heading_change_vectors([d], [size])[0])
        ax.text(*xy, text, color="w", fontsize=8, ha="center", va="center")
    box = old.get_position()
    old.remove()
    pax = fig.add_axes(box.shrunk(0.8, 0.8).anchored("C", box), projection="polar")
    a = np.append(angles, angles[0])
    f = np.append(density, density[0])
    pax.plot(a, f, color="tab:blue")
    pax.fill(a, f, color="tab:blue", alpha=0.2)
    pax.set_title("direction of the change (rad⁻¹)", fontsize=9)
    if direction_labels:
        pax.set_xticks(
            np.mod(list(direction_labels), 2 * np.pi), list(direction_labels.values())
        )
    pax.set_thetalim(0.0, 2 * np.pi)
    pax.set_theta_zero_location("N")  # oriented as the map: direction 0 at the top
    pax.set_rlabel_position(200)
    pax.tick_params(axis="y", labelsize=7)
    return fig


def flight_classes_figure(heave, classes, *, level: float):
    """Show a heave signal coloured by flight class and the classes' thresholds.

    Parameters
    ----------
    heave : xarray.DataArray
        The heave specific force (``time`` coordinate, ``units`` attribute).
    classes : xarray.Dataset
        From :func:`tiltlab.trig.classify_flight` on ``heave``.
    level : float
        Balance level drawn on the trace (units of ``heave``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(8.4, 3.4), width_ratios=(2.2, 1))
    ax0.plot(heave.time, heave, lw=0.4, color="k")
    ax0.axhline(level, color="0.4", lw=0.5, ls="--")
    half = float(classes.attrs["window_s"]) / 2
    lab = np.asarray(classes.behavior.values, str)
    for t, b in zip(np.asarray(classes.time), lab):
        ax0.axvspan(
            t - half, t + half, color=_CLASS_COLOURS.get(b, "0.9"), alpha=0.3, lw=0
        )
    ax0.set(xlabel="time (s)", ylabel=f"heave ({heave.attrs.get('units', '')})")
    cv, per = np.asarray(classes.cv), 1000 * np.asarray(classes.period)
    for name, col in _CLASS_COLOURS.items():
        m = lab == name
        if m.any():
            ax1.plot(cv[m], per[m], "o", ms=3, color=col, label=name)
    ax1.axvline(classes.attrs["cv_max"], color="0.4", ls="--", lw=0.7)
    ax1.axhline(1000 * classes.attrs["hover_max_s"], color="0.4", ls=":", lw=0.7)
    for p in classes.attrs["flap_range_s"]:
        ax1.axhline(1000 * p, color="0.4", ls=":", lw=0.7)
    ax1.set(xlabel="CV of the crossing delays", ylabel="period T = 2d̄ (ms)")
    ax1.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return fig
