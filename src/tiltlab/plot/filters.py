"""Figures of several tilt estimates of one recording.

The estimates' tilt angles against time and their errors against a reference, with one legend for the whole figure.

Inputs are the quaternions that :func:`tiltlab.filters.estimate` returns, by method; the
recipe computes only what it draws (tilt angles and a running RMS of the errors).
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib.pyplot as plt
import numpy as np
from matplotlib import ticker
import xarray as xr

from .. import quaternion as quat
from ._common import label, time_of

__all__ = ["tilt_angle_deg", "running_rms", "plain_log_ticks", "estimates_overview"]


def _quats(q) -> np.ndarray:
    if isinstance(q, xr.DataArray):
        q = q.transpose(..., "quat").values
    q = np.asarray(q, float)
    if q.ndim != 2 or q.shape[1] != 4:
        raise ValueError(f"quaternions must have shape (N, 4), got {q.shape}")
    return q


def tilt_angle_deg(q) -> np.ndarray:
    r"""Inclination of the sensor's z axis from the vertical, :math:`\arccos(g_z)` (degrees).

    Parameters
    ----------
    q : array_like or xarray.DataArray, shape (N, 4)
        Orientations (sensor → world, world z up); rows with NaN give NaN.

    Returns
    -------
    numpy.ndarray, shape (N,)
    """
    qq = _quats(q)
    bad = ~np.all(np.isfinite(qq), axis=1)
    g = quat.gravity(np.where(bad[:, None], [1.0, 0.0, 0.0, 0.0], qq))
    out = np.degrees(np.arccos(np.clip(g[:, 2], -1.0, 1.0)))
    out[bad] = np.nan
    return out


def running_rms(values, window: int) -> np.ndarray:
    """Centred running root-mean-square over ``window`` samples, ignoring NaN.

    Parameters
    ----------
    values : array_like, shape (N,)
        The series (flattened; e.g. per-sample errors in degrees), NaN for missing
        samples.
    window : int
        Window length in samples (≥ 1).

    Returns
    -------
    numpy.ndarray, shape (N,)
        NaN where the window holds no finite value.
    """
    if int(window) < 1:
        raise ValueError(f"window must be at least 1 sample, got {window}")
    v = np.asarray(values, float).ravel()
    ok = np.isfinite(v)
    kernel = np.ones(int(window))
    s = np.convolve(np.where(ok, v * v, 0.0), kernel, "same")
    n = np.convolve(ok.astype(float), kernel, "same")
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, np.sqrt(s / np.where(n > 0, n, 1.0)), np.nan)


def _ticks_within(lo: float, hi: float, subs: tuple[float, ...]) -> int:
    """How many values ``m · 10^k`` (``m`` in ``subs``) lie in ``[lo, hi]``.

    Parameters
    ----------
    lo, hi : float
        Positive axis limits.
    subs : tuple of float
        Mantissas of the candidate ticks.

    Returns
    -------
    int
    """
    if not (lo > 0 and np.isfinite(hi)):
        return len(subs)
    k = np.arange(np.floor(np.log10(lo)), np.ceil(np.log10(hi)) + 1)
    values = np.outer(10.0**k, subs).ravel()
    return int(np.sum((values >= lo * (1 - 1e-9)) & (values <= hi * (1 + 1e-9))))


def plain_log_ticks(ax, axis: str = "y"):
    """Label a log-scaled axis with plain numbers (0.5, 1, 2, 5 …).

    Plain numbers instead of powers of ten, and no minor labels, so that short decades do
    not crowd their labels; a range too short for three of 1, 2, 5 × 10^k (a colour bar
    over less than a decade) is labelled at every integer mantissa (2, 3, 4 …) instead.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes whose ``axis`` is already log-scaled and drawn (limits set).
    axis : {"x", "y"}
        Which axis to label (default ``"y"``).

    Returns
    -------
    matplotlib.axes.Axes
    """
    if axis not in ("x", "y"):
        raise ValueError(f"axis must be 'x' or 'y', got {axis!r}")
    target = ax.yaxis if axis == "y" else ax.xaxis
    lo, hi = sorted(ax.get_ylim() if axis == "y" else ax.get_xlim())
    decades = np.log10(hi / lo) if lo > 0 else np.inf
    subs = (1.0, 2.0, 5.0) if decades <= 2.5 else (1.0,)
    if _ticks_within(lo, hi, subs) < 3:  # a short range: every integer mantissa
        subs = tuple(float(k) for k in range(1, 10))
    target.set_major_locator(ticker.LogLocator(base=10.0, subs=subs))
    target.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    target.set_minor_formatter(ticker.NullFormatter())
    return ax


def estimates_overview(
    estimates: Mapping[str, object],
    *,
    reference=None,
    errors: Mapping[str, object] | None = None,
    time=None,
    fs: float | None = None,
    smooth_s: float = 1.0,
    max_points: int = 4000,
    title: str | None = None,
    figsize: tuple[float, float] | None = None,
):
    """Show several estimates of one recording together.

    Tilt angle against time (top) and,
    when errors are given, a running RMS of each estimate's tilt error (bottom, log
    scale), with one legend for the figure (below the panels).

    Parameters
    ----------
    estimates : mapping str → array_like or xarray.DataArray, shape (N, 4)
        Orientations (sensor → world) by method, all of the same length.
    reference : array_like or xarray.DataArray, shape (N, 4), optional
        Reference orientations (drawn black, dashed, in the top panel).
    errors : mapping str → array_like, optional
        Per-sample tilt errors (degrees) by method (e.g. from
        :func:`tiltlab.evaluate.tilt_errors`); the bottom panel is drawn only when given.
    time : array_like, optional
        Sample times (s); default the ``time`` coordinate of the first estimate.
    fs : float, optional
        Sampling rate (Hz) for the running RMS window; default from ``time``.
    smooth_s : float
        Length (s) of the running-RMS window of the error panel.
    max_points : int
        At most this many points per line are drawn (every k-th sample), so that long
        recordings stay light.
    title : str, optional
        Figure title, above the panels.
    figsize : (float, float), optional
        Default 8.2 inches wide (the book's column holds 8.36 inches at 100 dpi).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not estimates:
        raise ValueError("estimates is empty")
    first = next(iter(estimates.values()))
    t = time_of(first, time)
    n = t.size
    step = max(1, int(np.ceil(n / max(int(max_points), 2))))
    if fs is None:
        fs = 1.0 / float(np.median(np.diff(t))) if n > 1 else 1.0
    two = errors is not None
    fig, axes = plt.subplots(
        2 if two else 1,
        1,
        sharex=True,
        squeeze=False,
        figsize=figsize or (8.2, 5.6 if two else 3.4),
        layout="constrained",
    )
    top = axes[0, 0]
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    colour = {m: colours[i % len(colours)] for i, m in enumerate(estimates)}
    for m, q in estimates.items():
        a = tilt_angle_deg(q)
        if a.size != n:
            raise ValueError(f"estimates[{m!r}] has {a.size} samples, time {n}")
        top.plot(t[::step], a[::step], lw=0.9, color=colour[m], label=m)
    if reference is not None:
        top.plot(
            t[::step],
            tilt_angle_deg(reference)[::step],
            "--",
            lw=1.2,
            color="k",
            label="reference",
        )
    top.set_ylabel(label("tilt of sensor z from vertical", "deg"))
    if two:
        bottom = axes[1, 0]
        window = max(1, int(round(smooth_s * fs)))
        for m, e in errors.items():
            r = running_rms(e, window)
            bottom.plot(t[::step], r[::step], lw=0.9, color=colour.get(m), label=m)
        bottom.set_yscale("log")
        bottom.set_ylabel(label(f"tilt error, {smooth_s:g}-s running RMS", "deg"))
        plain_log_ticks(bottom, "y")
    axes[-1, 0].set_xlabel(label("time", "s"))
    handles, labels = top.get_legend_handles_labels()
    fig.legend(
        handles,
        labels,
        loc="outside lower center",
        ncol=min(4, len(labels)),
        fontsize=8,
        frameon=False,
    )
    if title:
        fig.suptitle(title, fontsize=10)
    return fig
