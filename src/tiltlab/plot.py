"""Figure helpers shared by the book's chapters (matplotlib only; no computation here
beyond what a figure needs to be drawn)."""

from __future__ import annotations

from collections.abc import Sequence

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

__all__ = ["plot_recording", "plot_vectors", "shade_mask"]

_AXIS_COLOURS = {"x": "tab:red", "y": "tab:green", "z": "tab:blue", "w": "0.4"}


def shade_mask(ax, time: np.ndarray, mask: np.ndarray, *, color: str = "0.9", label: str | None = None) -> None:
    """Shade the time spans where ``mask`` is True."""
    mask = np.asarray(mask, bool)
    if not mask.any():
        return
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    for k, (a, b) in enumerate(zip(edges[::2], edges[1::2])):
        ax.axvspan(time[a], time[min(b, len(time) - 1)], color=color, lw=0, zorder=0, label=label if k == 0 else None)


def plot_vectors(ax, time, values, *, labels: Sequence[str] = ("x", "y", "z"), ylabel: str = "", lw: float = 0.7) -> None:
    """Plot the columns of ``values`` (N, k) against ``time`` with the book's axis colours."""
    values = np.asarray(values)
    for k, lab in enumerate(labels):
        ax.plot(time, values[:, k], lw=lw, color=_AXIS_COLOURS.get(lab), label=lab)
    ax.set_ylabel(ylabel)


def plot_recording(
    rec: xr.Dataset,
    variables: Sequence[str] = ("acc", "gyr"),
    *,
    tmin: float | None = None,
    tmax: float | None = None,
    shade: str | None = None,
    title: str | None = None,
    figsize: tuple[float, float] | None = None,
):
    """One panel per variable of a Recording against time, labelled with its units.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording.
    variables : sequence of str
        Variables with dims (time, axis) or (time, quat) to draw.
    tmin, tmax : float, optional
        Time window (s).
    shade : str, optional
        Name of a boolean per-sample variable (e.g. ``"movement"``) to shade.
    """
    sel = rec.sel(time=slice(tmin, tmax))
    t = sel["time"].values
    fig, axes = plt.subplots(len(variables), 1, sharex=True, figsize=figsize or (9, 2.0 * len(variables) + 0.6), squeeze=False)
    for ax, v in zip(axes[:, 0], variables):
        da = sel[v]
        comp = [str(c) for c in da[da.dims[1]].values]
        plot_vectors(ax, t, da.values, labels=comp, ylabel=f"{v} [{da.attrs.get('units', '')}]")
        if shade is not None:
            shade_mask(ax, t, sel[shade].values, label=shade)
        ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, frameon=False)
    axes[-1, 0].set_xlabel("time [s]")
    if title:
        axes[0, 0].set_title(title)
    fig.tight_layout()
    return fig
