"""Figure of the immobility rules: the angular-speed distribution split by the mask.

Fayat et al. (2021, Fig. A3) show the distribution of a recording's angular speed on a
log axis, the part classified immobile and the part classified moving after their rules
(threshold, merging short gaps, dropping short periods), and the threshold. The recipe
draws that from a speed series and an immobility mask computed by the caller (e.g.
:func:`tiltlab.behavior.detect_immobility`).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._common import label, new_axes, pretty_units, units_of

__all__ = ["immobility_speed_distribution"]


def immobility_speed_distribution(
    speed,
    immobile,
    *,
    threshold: float | None = None,
    bins: int = 60,
    units: str | None = None,
    ax=None,
):
    """Draw the angular-speed distribution, split into immobile and moving samples.

    Three step histograms on common log-spaced bins: every sample (grey, filled), the
    samples the mask calls immobile and those it calls moving. Heights are fractions of
    all the samples drawn, so the immobile and moving heights add up to the raw one in
    every bin. Samples with a speed that is zero, negative or not finite cannot be
    placed on a log axis and are left out of all three.

    Parameters
    ----------
    speed : array_like or xarray.DataArray (N,)
        Angular speed (e.g. :func:`tiltlab.behavior.recording_speed`).
    immobile : array_like of bool (N,)
        Immobility mask of the same samples (e.g.
        :func:`tiltlab.behavior.detect_immobility`).
    threshold : float, optional
        Speed threshold of the rule, drawn as a dashed vertical line (same units).
    bins : int, default 60
        Number of log-spaced bins between the smallest and largest positive speed.
    units : str, optional
        Units of ``speed``; default its ``attrs["units"]``, else °/s.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; default a new 6 × 3.2 in figure.

    Returns
    -------
    matplotlib.axes.Axes
        The axes; its patches are the raw, immobile and moving histograms, in that
        order (``matplotlib.patches.StepPatch``).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import plot
    >>> rng = np.random.default_rng(0)
    >>> speed = np.exp(rng.normal(2.0, 1.2, 1000))
    >>> ax = plot.immobility_speed_distribution(speed, speed < 12.0, threshold=12.0)
    >>> raw, still, moving = (p.get_data().values for p in ax.patches)
    >>> bool(np.allclose(still + moving, raw))
    True
    """
    v = np.asarray(speed, dtype=float)
    m = np.asarray(immobile)
    if v.ndim != 1 or v.size == 0:
        raise ValueError(f"speed must be a non-empty 1-D series, got shape {v.shape}")
    if m.shape != v.shape:
        raise ValueError(
            f"immobile must have the shape of speed {v.shape}, got {m.shape}"
        )
    if m.dtype != bool:
        raise ValueError(f"immobile must be a boolean mask, got dtype {m.dtype}")
    if isinstance(immobile, xr.DataArray) and "time" in getattr(speed, "dims", ()):
        if not np.array_equal(immobile["time"].values, speed["time"].values):
            raise ValueError("immobile and speed must have the same time coordinate")
    if int(bins) < 1:
        raise ValueError(f"bins must be a positive number of bins, got {bins!r}")
    if threshold is not None and not (np.isfinite(threshold) and threshold > 0):
        raise ValueError(f"threshold must be a positive speed, got {threshold!r}")
    ok = np.isfinite(v) & (v > 0)
    if not ok.any():
        raise ValueError("speed has no positive finite sample to draw")
    v, m = v[ok], m[ok]
    lo, hi = v.min(), v.max()
    edges = np.geomspace(lo, hi if hi > lo else lo * 1.01, int(bins) + 1)
    n = v.size
    raw = np.histogram(v, edges)[0] / n
    still = np.histogram(v[m], edges)[0] / n
    moving = np.histogram(v[~m], edges)[0] / n
    ax = new_axes(ax, figsize=(6, 3.2))
    ax.stairs(raw, edges, fill=True, color="0.8", label="all samples")
    ax.stairs(still, edges, color="C0", lw=1.5, label="immobile (after the rules)")
    ax.stairs(moving, edges, color="C3", lw=1.5, label="moving (after the rules)")
    u = units or units_of(speed, "deg/s")
    if threshold is not None:
        ax.axvline(
            threshold,
            color="k",
            ls="--",
            lw=1,
            label=f"threshold {threshold:g} {pretty_units(u)}".rstrip(),
        )
    ax.set_xscale("log")
    ax.set_xlabel(label("angular speed", u) + ", log scale")
    ax.set_ylabel("fraction of samples per bin")
    ax.legend(fontsize=8, framealpha=0.9)
    return ax
