"""Figures of the learned estimators: training curves and per-trial errors by method.

Inputs are plain data (the ``history.json`` mapping and the table of
:func:`tiltlab.learn.compare`), so this module needs no PyTorch.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import FuncFormatter, LogLocator, MaxNLocator
import pandas as pd

from ._common import label, new_axes

__all__ = ["learning_curves", "method_strips"]


def learning_curves(
    history: Mapping[str, Sequence[Mapping[str, float]]],
    *,
    key: str = "qae_deg",
    figsize=None,
):
    """Training curves: ``key`` per epoch, one line per fold, one panel per variant.

    When the history has a validation error (``val_qae_deg``, written by training with
    validation trials), a second row of panels shows it, with the epoch whose weights
    were kept (the lowest validation error) marked by a star.

    Parameters
    ----------
    history : mapping
        ``"<variant>/fold<k>" -> [{"epoch": ..., key: ...}, ...]`` (``history.json``).
    key : str
        ``"qae_deg"`` (mean QAE of the training windows, degrees) or ``"loss"``.
    figsize : (float, float), optional
        Figure size in inches (default: the book's column width, 3.2 in per row).

    Returns
    -------
    matplotlib.figure.Figure
    """
    variants = sorted({name.split("/")[0] for name in history})
    with_val = any("val_qae_deg" in r for rows in history.values() for r in rows)
    n_rows = 2 if with_val else 1
    fig, axes = plt.subplots(
        n_rows,
        len(variants),
        figsize=figsize or (8.4, 3.2 * n_rows),
        sharey="row",
        sharex=True,
        squeeze=False,
    )
    for col, variant in enumerate(variants):
        for k, (name, rows) in enumerate(sorted(history.items())):
            if name.split("/")[0] != variant:
                continue
            epochs = [r["epoch"] for r in rows]
            colour = f"C{k % 10}"
            axes[0, col].plot(
                epochs,
                [r[key] for r in rows],
                marker="o",
                ms=3,
                color=colour,
                label=name.split("/")[1],
            )
            if with_val:
                val = [r.get("val_qae_deg", np.nan) for r in rows]
                axes[1, col].plot(epochs, val, marker="o", ms=3, color=colour)
                if np.isfinite(val).any():
                    best = int(np.nanargmin(val))
                    axes[1, col].plot(
                        epochs[best], val[best], marker="*", ms=12, color=colour
                    )
        axes[0, col].set_title(variant)
        axes[-1, col].set_xlabel("epoch")
        axes[-1, col].xaxis.set_major_locator(MaxNLocator(integer=True))
        axes[0, col].legend(title="model", fontsize=8, frameon=False, ncols=2)
    axes[0, 0].set_ylabel(
        label("training QAE", "deg") if key == "qae_deg" else "training loss"
    )
    if with_val:
        axes[1, 0].set_ylabel(label("validation QAE\n(closed loop)", "deg"))
    fig.tight_layout()
    return fig


def method_strips(
    table: pd.DataFrame,
    metric: str = "inclination",
    *,
    hue: Mapping[int, str] | None = None,
    logy: bool = True,
    ax=None,
    figsize=(8.4, 4),
):
    """Per-trial errors as dots, one column per method, with each method's median.

    Parameters
    ----------
    table : pandas.DataFrame
        Rows with ``method``, ``trial`` and ``metric`` (degrees).
    metric : str
        Column to show.
    hue : mapping, optional
        Trial → group label (e.g. "undisturbed" / "disturbed"), coloured separately.
    logy : bool
        Logarithmic error axis, ticks labelled with plain numbers (1, 3, 10 …).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new figure of size ``figsize``.
    figsize : (float, float)
        Size of a new figure in inches (default: the book's column width).

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, figsize=figsize)
    methods = list(dict.fromkeys(table["method"]))
    groups = sorted(set(hue.values())) if hue else [None]
    colours = dict(zip(groups, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    rng = np.random.default_rng(0)
    for i, m in enumerate(methods):
        rows = table[table["method"] == m].dropna(subset=[metric])
        for g in groups:
            sel = rows if g is None else rows[[hue.get(t) == g for t in rows["trial"]]]
            x = i + rng.uniform(-0.18, 0.18, len(sel))
            ax.scatter(
                x,
                sel[metric],
                s=14,
                color=colours[g],
                alpha=0.8,
                label=g if (i == 0 and g is not None) else None,
            )
        if len(rows):
            med = float(np.median(rows[metric]))
            ax.plot(
                [i - 0.3, i + 0.3],
                [med, med],
                color="k",
                lw=2,
                label="median, all trials" if i == 0 else None,
            )
    ax.set_xticks(range(len(methods)), methods, rotation=20, ha="right")
    ax.set_ylabel(
        label(f"{metric} RMSE per trial" + (", log scale" if logy else ""), "deg")
    )
    if logy:
        ax.set_yscale("log")
        # plain numbers (0.5, 1, 10) read better than powers of ten for errors in degrees
        # and a 1-3-10 sequence labels every decade the dots span, not only 1 and 10
        ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 3.0)))
        ax.yaxis.set_minor_locator(LogLocator(base=10, subs=(2.0, 5.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))
    ax.legend(title="trial" if hue else None, fontsize=8, frameon=False)
    ax.grid(axis="y", alpha=0.3)
    return ax
