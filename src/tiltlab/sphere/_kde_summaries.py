r"""Summaries of a spherical density and of the series behind it (Benhamou 2023, §7).

Cumulative isopleths (:func:`isopleths`, :func:`isopleth_mask`) of a
:class:`~tiltlab.sphere.SphericalKDE` or of any densities per cell, and the
stationarity check of a series by thirds (:func:`stationarity_thirds`). Re-exported by
:mod:`tiltlab.sphere.kde` and :mod:`tiltlab.sphere`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import _validate
from ._kde_grid import SphericalKDE
from .vmf import _check_weights
from .mesh import as_unit_vectors, to_lonlat
from .vmf import angle, vmf_fit

__all__ = ["isopleths", "isopleth_mask", "stationarity_thirds"]


# ---------------------------------------------------------------------------
# isopleths
# ---------------------------------------------------------------------------


def _dens_area(density, cell_area):
    if isinstance(density, SphericalKDE):
        return density.density.ravel(), np.full(
            density.density.size, density.grid.cell_area
        )
    d = np.asarray(density, float).ravel()
    try:
        a = np.broadcast_to(
            np.asarray(cell_area, float), np.asarray(density).shape
        ).ravel()
    except ValueError:
        raise ValueError(
            f"cell_area must be a number or match density's shape "
            f"{np.asarray(density).shape}, got shape {np.shape(cell_area)}"
        ) from None
    if d.size == 0:
        raise ValueError("density is empty")
    bad = ~np.isfinite(d) | (d < 0)
    if np.any(bad):
        raise ValueError(
            f"density must be finite and >= 0, got {int(bad.sum())} bad values "
            f"(first: {d[np.argmax(bad)]!r})"
        )
    bad = ~np.isfinite(a) | (a <= 0)
    if np.any(bad):
        raise ValueError(f"cell_area must be finite and > 0, got {a[np.argmax(bad)]!r}")
    return d, a


def isopleths(density, cell_area=None, levels=(0.5, 0.95)) -> pd.DataFrame:
    r"""Find the smallest areas holding given fractions of the distribution (isopleths).

    Cells are sorted by decreasing density and their probability masses
    :math:`a_cU_c` summed (jointly, so cells of unequal area are handled) until the level
    is reached (Benhamou §7); the crossing cell is counted in proportion. Masses are
    normalised by their total.

    Parameters
    ----------
    density : SphericalKDE or array
        A KDE or densities per cell (e.g. a tilt map's ``density`` per facet).
    cell_area : float or array
        Cell areas (sr) when ``density`` is an array.
    levels : sequence of float
        Probability masses of the isopleths, each in (0, 1).

    Returns
    -------
    pandas.DataFrame
        Indexed by level: ``threshold`` (density at the isopleth), ``area`` (sr) and
        ``sphere_fraction`` (area / 4π).
    """
    if not isinstance(density, SphericalKDE) and cell_area is None:
        raise ValueError("cell_area is required when density is an array")
    d, a = _dens_area(density, cell_area)
    order = np.argsort(-d, kind="stable")
    mass = d[order] * a[order]
    tot = mass.sum()
    if tot <= 0:
        raise ValueError("density is zero everywhere")
    cum = np.cumsum(mass) / tot
    rows = []
    for lev in np.atleast_1d(levels):
        lev = _validate.fraction(lev, "levels", open_low=True, open_high=True)
        kk = int(min(np.searchsorted(cum, lev), d.size - 1))
        before = cum[kk - 1] if kk > 0 else 0.0
        part = (lev - before) / (mass[kk] / tot) if mass[kk] > 0 else 0.0
        area = a[order[:kk]].sum() + part * a[order[kk]]
        rows.append(
            (float(lev), float(d[order[kk]]), float(area), float(area / (4 * np.pi)))
        )
    return pd.DataFrame(
        rows, columns=["level", "threshold", "area", "sphere_fraction"]
    ).set_index("level")


def isopleth_mask(density, level: float, cell_area=None) -> np.ndarray:
    """Mark the cells inside the ``level`` cumulative isopleth.

    Parameters
    ----------
    density : SphericalKDE or array_like
        A KDE, or densities (sr⁻¹) on equal-area cells.
    level : float
        Probability mass of the isopleth, in (0, 1).
    cell_area : float, optional
        Cell area (sr) of a plain ``density`` (see :func:`isopleths`).

    Returns
    -------
    numpy.ndarray of bool
        True for the cells inside, with the shape of the density.
    """
    level = _validate.fraction(level, "level", open_low=True, open_high=True)
    arr = (
        density.density
        if isinstance(density, SphericalKDE)
        else np.asarray(density, float)
    )
    thr = isopleths(density, cell_area, [level])["threshold"].iloc[0]
    return arr >= thr


# ---------------------------------------------------------------------------
# stationarity
# ---------------------------------------------------------------------------


def stationarity_thirds(vectors, weights=None) -> pd.DataFrame:
    r"""Compare the mean direction and dispersion of the three thirds of a series.

    Benhamou §7.

    A distribution is meaningful only for a stationary process; Benhamou advises checking
    that mean and variance stay similar across the three thirds. Each row gives the vMF
    fit of one third (and of the whole series): mean direction (vector, longitude,
    latitude in degrees), :math:`\bar R`, κ̂, the angular dispersion
    :math:`\delta=\sqrt{2(1-\bar R)}` (rad; ≈ κ^{-1/2}) and the angle between the third's
    mean and the overall mean (degrees). ``df.attrs`` holds the largest of those angles
    (``max_angle_deg``) and the largest/smallest κ̂ ratio (``kappa_ratio``).

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        A labelled (time, axis) series, a Recording (its ``gravity``) or an (N, 3)
        array, in time order (at least 3 samples).
    weights : array_like (N,), optional
        Weights of the samples (finite, >= 0).

    Returns
    -------
    pandas.DataFrame
        One row per third (``first``, ``second``, ``third``) and one for ``all``.
    """
    x = as_unit_vectors(vectors, "vectors")
    n = x.shape[0]
    if n < 3:
        raise ValueError(f"vectors needs at least 3 samples, got {n}")
    w = np.ones(n) if weights is None else _check_weights(weights, n)
    edges = np.linspace(0, n, 4).round().astype(int)
    parts = [
        ("first", slice(edges[0], edges[1])),
        ("second", slice(edges[1], edges[2])),
        ("third", slice(edges[2], edges[3])),
        ("all", slice(0, n)),
    ]
    overall = vmf_fit(x, w).mu
    rows = []
    for name, sl in parts:
        f = vmf_fit(x[sl], w[sl])
        lon, lat = to_lonlat(f.mu)
        rows.append(
            dict(
                part=name,
                n=sl.stop - sl.start,
                mu_x=f.mu[0],
                mu_y=f.mu[1],
                mu_z=f.mu[2],
                lon_deg=np.degrees(lon),
                lat_deg=np.degrees(lat),
                rbar=f.rbar,
                kappa=f.kappa,
                dispersion=np.sqrt(2 * (1 - f.rbar)),
                angle_to_all_deg=np.degrees(angle(f.mu, overall)),
            )
        )
    df = pd.DataFrame(rows).set_index("part")
    thirds = df.iloc[:3]
    df.attrs["max_angle_deg"] = float(thirds["angle_to_all_deg"].max())
    df.attrs["kappa_ratio"] = float(thirds["kappa"].max() / thirds["kappa"].min())
    return df
