r"""Spherical kernel density estimation (Benhamou 2023, §7, Eqs. 14–16): equal-area grids,
von Mises–Fisher kernels, reference bandwidth, cumulative isopleths, location- and
movement-based KDE, and a stationarity check.

Kernels
-------
A vMF kernel with concentration :math:`\kappa = 1/h^2` centred on :math:`\mu_i` (Eq. 14a)
can be written with the chord :math:`\lVert c-\mu_i\rVert^2 = 2(1-c\cdot\mu_i)` (Eq. 16):

.. math::
    K_{\rm vMF}(c) = \frac{1}{2\pi h^2(1-e^{-2/h^2})}\exp\Big(-\frac{\lVert c-\mu_i\rVert^2}{2h^2}\Big),
    \qquad
    K_{\rm G}(c) = \frac{1}{2\pi h^2}\exp\Big(-\frac{\lVert c-\mu_i\rVert^2}{2h^2}\Big)\ \text{(Eq. 15)}.

So Benhamou's Gaussian-on-chord kernel (Eq. 15) *is* the vMF kernel up to the factor
:math:`1-e^{-2\kappa}` (< 6·10⁻⁶ for κ > 6); it integrates to :math:`1/(1-e^{-2\kappa})`.
Both are offered (``kernel="vmf"`` exact, ``kernel="gauss"``). Kernels are truncated
where they fall below ``tol`` times their peak, i.e. beyond the angular radius
:math:`\arccos(1+\log(\mathrm{tol})/\kappa)`; the lost mass is ≈ ``tol``.

Grid
----
Cells are regular in longitude :math:`\xi` (``n_lon`` bins) and in the sine of latitude
:math:`s=\sin\psi` (``n_lat`` bins), so every cell has the same area
:math:`a_c = \Delta\xi\,\Delta s = 4\pi/(n_{lon}n_{lat})` (Benhamou §7). A ``cell_deg``
grid has :math:`\Delta\xi = \Delta s = ` ``cell_deg`` in radians, i.e. square
cells of that size at the grid's equator. Near the grid's poles the cells become tall
in latitude (:math:`\Delta\psi = \Delta s/\cos\psi`), and a point evaluation of a narrow
kernel there is a poor quadrature; the grid can therefore be rotated (``pole``), and
:func:`grid_for` puts the pole 90° away from the data's mean direction.

References
----------
.. [1] S. Benhamou, arXiv:2310.05820, 2023, §7 and App. C. doi:10.48550/arXiv.2310.05820
.. [2] B. W. Silverman, Density Estimation for Statistics and Data Analysis, Chapman &
   Hall, 1986.
.. [3] S. Benhamou, "Dynamic approach to space and habitat use based on biased random
   bridges", PLoS ONE 6(1):e14592, 2011. doi:10.1371/journal.pone.0014592
.. [4] S. Benhamou, "Of scales and stationarity in animal movements", Ecol. Lett.
   17:261–272, 2014. doi:10.1111/ele.12225
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np
import pandas as pd
from numba import njit, prange

from .. import _validate
from .mesh import _series, as_unit_vectors, to_lonlat
from .vmf import _frame, angle, vmf_fit

__all__ = [
    "EqualAreaGrid",
    "SphericalKDE",
    "equal_area_grid",
    "grid_for",
    "reference_bandwidth",
    "kde",
    "mkde",
    "isopleths",
    "isopleth_mask",
    "stationarity_thirds",
    "slerp",
]


@dataclass(frozen=True, eq=False)
class EqualAreaGrid:
    """Equal-area grid regular in longitude and sine of latitude, possibly rotated.

    ``rotation`` maps grid-frame coordinates to data-frame coordinates (its third column
    is the grid's pole, its first the direction of grid longitude 0).
    """

    n_lon: int
    n_lat: int
    rotation: np.ndarray

    @property
    def cell_area(self) -> float:
        """Area of every cell (sr)."""
        return 4.0 * np.pi / (self.n_lon * self.n_lat)

    @property
    def shape(self) -> tuple[int, int]:
        return (self.n_lat, self.n_lon)

    @property
    def lon_edges(self) -> np.ndarray:
        return np.linspace(-np.pi, np.pi, self.n_lon + 1)

    @property
    def s_edges(self) -> np.ndarray:
        return np.linspace(-1.0, 1.0, self.n_lat + 1)

    @property
    def lon_centres(self) -> np.ndarray:
        e = self.lon_edges
        return 0.5 * (e[1:] + e[:-1])

    @property
    def s_centres(self) -> np.ndarray:
        e = self.s_edges
        return 0.5 * (e[1:] + e[:-1])

    def _vectors(self, lon, s) -> np.ndarray:
        lon, s = np.meshgrid(lon, s)
        c = np.sqrt(np.clip(1 - s * s, 0, None))
        g = np.stack([c * np.cos(lon), c * np.sin(lon), s], axis=-1)
        return g @ self.rotation.T

    def centres(self) -> np.ndarray:
        """Cell centres as unit vectors in the data frame, shape (n_lat, n_lon, 3)."""
        return self._vectors(self.lon_centres, self.s_centres)

    def corners(self) -> np.ndarray:
        """Cell corners as unit vectors in the data frame, shape (n_lat+1, n_lon+1, 3)."""
        return self._vectors(self.lon_edges, self.s_edges)

    def to_grid_frame(self, vectors) -> np.ndarray:
        """Data-frame vectors → grid-frame vectors."""
        return np.asarray(vectors, float) @ self.rotation


def equal_area_grid(
    cell_deg: float = 1.0, *, pole=(0.0, 0.0, 1.0), meridian=None
) -> EqualAreaGrid:
    r"""Equal-area grid with :math:`\Delta\xi=\Delta s\approx` ``cell_deg`` (rad), pole along ``pole``.

    ``n_lon = round(360/cell_deg)`` and ``n_lat = round(2/Δξ)``; a 1° grid has
    360 × 115 = 41 400 cells of 3.04·10⁻⁴ sr. ``meridian`` (orthogonalised against
    ``pole``) sets grid longitude 0; default: the coordinate axis least aligned with the pole.
    """
    cell_deg = _check_cell_deg(cell_deg)
    n_lon = int(round(360.0 / cell_deg))
    n_lat = max(2, int(round(2.0 / (2 * np.pi / n_lon))))
    p = np.asarray(pole, float).reshape(3)
    if not np.all(np.isfinite(p)) or np.linalg.norm(p) == 0:
        raise ValueError("pole must be a finite non-zero vector")
    p = p / np.linalg.norm(p)
    if meridian is None:
        R = _frame(p)
    else:
        m = np.asarray(meridian, float).reshape(3)
        m = m - (m @ p) * p
        if np.linalg.norm(m) < 1e-9:
            raise ValueError("meridian must not be parallel to pole")
        m /= np.linalg.norm(m)
        R = np.column_stack([m, np.cross(p, m), p])
    R.flags.writeable = False
    return EqualAreaGrid(n_lon, n_lat, R)


def _check_cell_deg(cell_deg) -> float:
    cell_deg = _validate.finite(cell_deg, "cell_deg")
    if not 0 < cell_deg <= 90:
        raise ValueError(f"cell_deg must be in (0, 90], got {cell_deg!r}")
    return cell_deg


def grid_for(vectors, cell_deg: float = 1.0, weights=None) -> EqualAreaGrid:
    """Equal-area grid whose pole is 90° from the data's mean direction (data on the grid's equator).

    ``vectors``: a labelled (time, axis) series, a Recording (its ``gravity``) or an
    (N, 3) array; NaN rows are ignored.
    """
    cell_deg = _check_cell_deg(cell_deg)
    x = as_unit_vectors(vectors, "vectors", allow_nan=True)
    ok = np.isfinite(x).all(axis=1)
    m = x[ok].sum(axis=0) if weights is None else np.asarray(weights, float)[ok] @ x[ok]
    if np.linalg.norm(m) < 1e-12:
        return equal_area_grid(cell_deg)
    m = m / np.linalg.norm(m)
    e = np.eye(3)[np.argmin(np.abs(m))]
    pole = np.cross(m, e)
    return equal_area_grid(cell_deg, pole=pole, meridian=m)


class SphericalKDE(NamedTuple):
    """A density (sr⁻¹) on an :class:`EqualAreaGrid`, shape (n_lat, n_lon), with its bandwidth ``h`` (rad)."""

    density: np.ndarray
    grid: EqualAreaGrid
    h: float

    def integral(self) -> float:
        """Σ density × cell area (≈ 1)."""
        return float(self.density.sum() * self.grid.cell_area)


# ---------------------------------------------------------------------------
# bandwidth
# ---------------------------------------------------------------------------


def reference_bandwidth(
    vectors, weights=None, *, n: int | None = None, method: str = "mle"
) -> float:
    r"""Reference smoothing parameter :math:`h_{ref}=\hat\kappa^{-1/2}\,n^{-1/6}` (Benhamou §7; Silverman's rule).

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        A labelled (time, axis) series, a Recording (its ``gravity``) or an array.
    weights : (N,), optional
        Weights for the mean resultant length :math:`\bar R`.
    n : int, optional
        Sample size in :math:`n^{-1/6}` (default N).
    method : {"mle", "benhamou"}
        κ̂ from :math:`A_3^{-1}(\bar R)` (MLE), or :math:`1/\hat\kappa = 1-\bar R`
        (Benhamou's printed form; the two agree to :math:`O(e^{-2\kappa})` once κ ≳ 3,
        because :math:`A_3(\kappa) = \coth\kappa - 1/\kappa \approx 1-1/\kappa`).
    """
    x = as_unit_vectors(vectors, "vectors")
    fit = vmf_fit(x, weights)
    n = x.shape[0] if n is None else _validate.integer(n, "n", minimum=1)
    if method == "mle":
        inv_k = 1.0 / fit.kappa if fit.kappa > 0 else np.inf
    elif method == "benhamou":
        inv_k = 1.0 - fit.rbar
    else:
        raise ValueError(f"method must be 'mle' or 'benhamou', got {method!r}")
    return float(np.sqrt(inv_k) * n ** (-1.0 / 6.0))


# ---------------------------------------------------------------------------
# numba scatter kernel
# ---------------------------------------------------------------------------


@njit(cache=True, parallel=True)
def _kde_scatter(lon, s, kap, w, n_lon, n_lat, log_tol, exact, out):
    nchunk = out.shape[0]
    npts = lon.shape[0]
    dlon = 2.0 * np.pi / n_lon
    ds = 2.0 / n_lat
    clon = np.empty(n_lon)
    slon = np.empty(n_lon)
    for j in range(n_lon):
        a = -np.pi + (j + 0.5) * dlon
        clon[j] = np.cos(a)
        slon[j] = np.sin(a)
    sc = np.empty(n_lat)
    cc = np.empty(n_lat)
    for r in range(n_lat):
        sc[r] = -1.0 + (r + 0.5) * ds
        cc[r] = np.sqrt(1.0 - sc[r] * sc[r])
    for ch in prange(nchunk):
        acc = out[ch]
        for i in range(ch * npts // nchunk, (ch + 1) * npts // nchunk):
            k = kap[i]
            wi = w[i]
            if wi == 0.0:
                continue
            if exact:
                norm = wi * k / (2.0 * np.pi * (-np.expm1(-2.0 * k)))
            else:
                norm = wi * k / (2.0 * np.pi)
            si = s[i]
            ci = np.sqrt(max(1.0 - si * si, 0.0))
            cl = np.cos(lon[i])
            sl = np.sin(lon[i])
            cos_cut = 1.0 + log_tol / k
            if cos_cut <= -1.0:
                theta = np.pi
                cos_cut = -1.0
            else:
                theta = np.arccos(cos_cut)
            psi = np.arcsin(si)
            lo = psi - theta
            hi = psi + theta
            s_lo = -1.0 if lo <= -0.5 * np.pi else np.sin(lo)
            s_hi = 1.0 if hi >= 0.5 * np.pi else np.sin(hi)
            r0 = max(int((s_lo + 1.0) / ds), 0)
            r1 = min(int((s_hi + 1.0) / ds), n_lat - 1)
            for r in range(r0, r1 + 1):
                sr = sc[r]
                cr = cc[r]
                den = ci * cr
                full = False
                if den < 1e-300:
                    if si * sr >= cos_cut:
                        full = True
                    else:
                        continue
                else:
                    cd = (cos_cut - si * sr) / den
                    if cd <= -1.0:
                        full = True
                    elif cd > 1.0:
                        continue
                if full:
                    j0 = 0
                    j1 = n_lon - 1
                else:
                    half = np.arccos(cd)
                    j0 = int(np.floor((lon[i] - half + np.pi) / dlon - 0.5))
                    j1 = int(np.ceil((lon[i] + half + np.pi) / dlon - 0.5))
                    if j1 - j0 + 1 >= n_lon:
                        j0 = 0
                        j1 = n_lon - 1
                for j in range(j0, j1 + 1):
                    jj = j % n_lon
                    if jj < 0:
                        jj += n_lon
                    cosd = si * sr + ci * cr * (clon[jj] * cl + slon[jj] * sl)
                    acc[r, jj] += norm * np.exp(k * (cosd - 1.0))


def _scatter(x, w, h, grid: EqualAreaGrid, kernel: str, tol: float) -> np.ndarray:
    if kernel not in ("vmf", "gauss"):
        raise ValueError(f"kernel must be 'vmf' or 'gauss', got {kernel!r}")
    _validate.fraction(tol, "tol", open_low=True, open_high=True)
    h = np.broadcast_to(np.asarray(h, float), (x.shape[0],))
    if np.any(~np.isfinite(h)) or np.any(h <= 0):
        raise ValueError("bandwidth h must be finite and > 0")
    g = grid.to_grid_frame(x)
    lon, lat = to_lonlat(g)
    s = np.clip(g[:, 2], -1.0, 1.0)
    nchunk = max(1, min(numba.get_num_threads(), x.shape[0]))
    out = np.zeros((nchunk, grid.n_lat, grid.n_lon))
    _kde_scatter(
        np.ascontiguousarray(lon),
        np.ascontiguousarray(s),
        np.ascontiguousarray(1.0 / h**2),
        np.ascontiguousarray(w, dtype=float),
        grid.n_lon,
        grid.n_lat,
        float(np.log(tol)),
        kernel == "vmf",
        out,
    )
    return out.sum(axis=0) / w.sum()


def kde(
    vectors,
    *,
    grid: EqualAreaGrid | None = None,
    h: float | None = None,
    weights=None,
    kernel: str = "vmf",
    cell_deg: float = 1.0,
    tol: float = 1e-10,
) -> SphericalKDE:
    r"""Location-based spherical KDE (Benhamou Eq. 15 with vMF kernels) on an equal-area grid.

    .. math:: U_c = \frac{\sum_i w_i K_h(c;\mu_i)}{\sum_i w_i}

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Locations on the sphere (normalised here; NaN rows dropped): a labelled (time,
        axis) series, a Recording (its ``gravity``) or an array.
    grid : EqualAreaGrid, optional
        Default :func:`grid_for` the data with ``cell_deg``.
    h : float, optional
        Bandwidth (rad); default :func:`reference_bandwidth`.
    weights : array_like (N,), optional
    kernel : {"vmf", "gauss"}
        Exact vMF (Eq. 14a) or Benhamou's Gaussian-on-chord form (Eq. 15).
    tol : float
        Kernel truncation (relative to its peak).

    Returns
    -------
    SphericalKDE
    """
    x = as_unit_vectors(vectors, "vectors", allow_nan=True)
    ok = np.isfinite(x).all(axis=1)
    if h is not None:
        h = _validate.positive(h, "h")
    cell_deg = _check_cell_deg(cell_deg)
    w = np.ones(x.shape[0]) if weights is None else np.asarray(weights, float)
    if w.shape != (x.shape[0],) or np.any(~np.isfinite(w[ok])) or np.any(w[ok] < 0):
        raise ValueError("weights must be finite, >= 0 and of shape (N,)")
    x, w = x[ok], w[ok]
    if x.shape[0] == 0 or w.sum() <= 0:
        raise ValueError("no data")
    if h is None:
        h = reference_bandwidth(x, w if weights is not None else None)
    grid = grid_for(x, cell_deg, w) if grid is None else grid
    return SphericalKDE(_scatter(x, w, h, grid, kernel, tol), grid, float(h))


def slerp(a, b, t) -> np.ndarray:
    r"""Points at fraction t along the orthodromic arcs a→b (rows), :math:`\frac{\sin((1-t)\omega)a+\sin(t\omega)b}{\sin\omega}`."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    t = np.asarray(t, float)[..., None]
    om = angle(a, b)[..., None]
    with np.errstate(invalid="ignore", divide="ignore"):
        so = np.sin(om)
        p = np.where(
            so > 1e-12,
            (np.sin((1 - t) * om) * a + np.sin(t * om) * b)
            / np.where(so > 1e-12, so, 1.0),
            (1 - t) * a + t * b,
        )
    return p / np.linalg.norm(p, axis=-1, keepdims=True)


def mkde(
    vectors,
    *,
    fs: float | None = None,
    times=None,
    grid: EqualAreaGrid | None = None,
    h: float | None = None,
    step: float | None = None,
    diffusion: float = 0.0,
    max_gap: float = np.inf,
    kernel: str = "vmf",
    cell_deg: float = 1.0,
    tol: float = 1e-10,
) -> SphericalKDE:
    r"""Movement-based spherical KDE: kernels placed along the orthodromic arcs between successive samples.

    Each step :math:`x_k\to x_{k+1}` (duration :math:`\Delta t_k`, arc :math:`\omega_k`) is
    cut into :math:`m_k=\lceil\omega_k/\mathrm{step}\rceil` equal sub-arcs; a kernel sits at
    the middle of each (:func:`slerp` at :math:`\alpha=(j+\tfrac12)/m_k`) with weight
    :math:`\Delta t_k/m_k`, so the density is the fraction of *time* spent near each
    direction. With ``diffusion`` :math:`D` > 0 (rad²/s) the bandwidth grows inside the
    step like a Brownian bridge, :math:`h^2(\alpha) = h^2 + \alpha(1-\alpha)D\Delta t_k`
    — a simplified, unbiased version of Benhamou's biased random bridges [3]_.

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Time-ordered directions: a labelled (time, axis) series with ``attrs["fs"]`` (e.g.
        :func:`tiltlab.filters.gravity`), a Recording with a ``gravity`` variable, or a
        plain array.
    fs, times : sampling rate (Hz) or sample times (s) of a plain array (one is
        required). Labelled data use their ``time`` coordinate and ``fs``; an ``fs`` that
        contradicts ``attrs["fs"]`` is an error, and so is labelled data without ``fs``.
    h : base bandwidth (rad), default :func:`reference_bandwidth` of the samples.
    step : maximal sub-arc length (rad), default h/2.
    diffusion : Brownian-bridge diffusion coefficient (rad²/s), ≥ 0.
    max_gap : steps longer than this (s) are dropped (data gaps).
    """
    x, t, _ = _series(vectors, fs, times)
    n = x.shape[0]
    if n < 2:
        raise ValueError("need at least 2 samples")
    diffusion = _validate.nonnegative(diffusion, "diffusion")
    max_gap = _validate.positive(max_gap, "max_gap", allow_inf=True)
    cell_deg = _check_cell_deg(cell_deg)
    h = reference_bandwidth(x) if h is None else _validate.positive(h, "h")
    step = h / 2 if step is None else _validate.positive(step, "step")
    dt = np.diff(t)
    keep = dt <= max_gap
    a, b, dt = x[:-1][keep], x[1:][keep], dt[keep]
    if a.shape[0] == 0:
        raise ValueError("every step is longer than max_gap")
    om = angle(a, b)
    m = np.maximum(1, np.ceil(om / step)).astype(np.int64)
    k = np.repeat(np.arange(a.shape[0]), m)
    j = np.arange(k.size) - np.repeat(np.cumsum(m) - m, m)
    alpha = (j + 0.5) / m[k]
    pts = slerp(a[k], b[k], alpha)
    w = dt[k] / m[k]
    hh = np.sqrt(h * h + alpha * (1 - alpha) * diffusion * dt[k])
    grid = grid_for(x, cell_deg) if grid is None else grid
    return SphericalKDE(_scatter(pts, w, hh, grid, kernel, tol), grid, float(h))


# ---------------------------------------------------------------------------
# isopleths
# ---------------------------------------------------------------------------


def _dens_area(density, cell_area):
    if isinstance(density, SphericalKDE):
        return density.density.ravel(), np.full(
            density.density.size, density.grid.cell_area
        )
    d = np.asarray(density, float).ravel()
    a = np.broadcast_to(np.asarray(cell_area, float), np.asarray(density).shape).ravel()
    if d.size == 0 or np.any(~np.isfinite(d)) or np.any(d < 0) or np.any(a <= 0):
        raise ValueError("density must be finite and >= 0, areas > 0")
    return d, a


def isopleths(density, cell_area=None, levels=(0.5, 0.95)) -> pd.DataFrame:
    r"""Smallest areas holding given fractions of the distribution (cumulative isopleths).

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
    levels : sequence of float in (0, 1)

    Returns
    -------
    pandas.DataFrame indexed by level: ``threshold`` (density at the isopleth), ``area``
    (sr) and ``sphere_fraction`` (area / 4π).
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
    """Boolean mask (shape of the density) of the cells inside the ``level`` cumulative isopleth."""
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
    r"""Mean direction and dispersion in the first, second and third thirds of a series (Benhamou §7).

    A distribution is meaningful only for a stationary process; Benhamou advises checking
    that mean and variance stay similar across the three thirds. Each row gives the vMF
    fit of one third (and of the whole series): mean direction (vector, longitude,
    latitude in degrees), :math:`\bar R`, κ̂, the angular dispersion
    :math:`\delta=\sqrt{2(1-\bar R)}` (rad; ≈ κ^{-1/2}) and the angle between the third's
    mean and the overall mean (degrees). ``df.attrs`` holds the largest of those angles
    (``max_angle_deg``) and the largest/smallest κ̂ ratio (``kappa_ratio``).

    ``vectors``: a labelled (time, axis) series, a Recording (its ``gravity``) or an
    (N, 3) array, in time order.
    """
    x = as_unit_vectors(vectors, "vectors")
    n = x.shape[0]
    if n < 3:
        raise ValueError("need at least 3 samples")
    w = np.ones(n) if weights is None else np.asarray(weights, float)
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
