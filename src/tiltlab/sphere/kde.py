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

So Benhamou's Gaussian-on-chord kernel (Eq. 15) *is* the vMF kernel times the factor
:math:`1-e^{-2\kappa}` (1 − 6·10⁻⁶ for κ = 6); it integrates to :math:`1-e^{-2\kappa}`.
Both are offered (``kernel="vmf"`` exact, ``kernel="gauss"``). Kernels are truncated
where they fall below ``tol`` times their peak, i.e. beyond the angular radius
:math:`\arccos(1+\log(\mathrm{tol})/\kappa)`; the lost mass is ≈ ``tol``.

Quadrature
----------
The density is given at the cell centres. With ``quadrature="point"`` it is the kernel
sum evaluated there (Eq. 15 as printed); :math:`\sum_c U_c a_c` is then a midpoint-rule
quadrature, exact to rounding for kernels several cells wide on the grid's equator but
wrong by any amount for kernels narrower than the cells around them — a kernel of
h = 0.05 rad centred on the pole of a 1° grid keeps 21 % of its mass, one of
h = 0.003 rad on the equator 104 %. The default ``quadrature="mass"`` keeps the shape of
the point values but rescales each kernel so that it puts exactly its mass on the grid
(1 for ``"vmf"``, :math:`1-e^{-2\kappa}` for ``"gauss"``): values are taken relative to
the kernel's largest value on the grid (truncated at ``tol`` below it) and divided by
their sum times the cell area. Where the grid resolves the kernel the factor is 1 to
the quadrature's accuracy; a kernel much narrower than the cells goes to the nearest
cell centre(s) (shared equally between equidistant ones, e.g. the first ring of cells
around a grid pole). The integral of a ``"vmf"`` KDE is then 1 to rounding for every
bandwidth and position, and a kernel centred on a grid pole gets the exact mass of every
ring of cells. What no grid quadrature gives is the shape of a kernel inside a cell: for
a kernel narrower than the cells around it the density is not the cell average (its
mass goes to the nearest cell centres, which may lie one cell off where the cells are
tall); :func:`grid_for` (data on the grid's equator) or a finer grid avoids that.

Grid
----
Cells are regular in longitude :math:`\xi` (``n_lon`` bins) and in the sine of latitude
:math:`s=\sin\psi` (``n_lat`` bins), so every cell has the same area
:math:`a_c = \Delta\xi\,\Delta s = 4\pi/(n_{lon}n_{lat})` (Benhamou §7). A ``cell_deg``
grid has :math:`\Delta\xi = \Delta s = ` ``cell_deg`` in radians, i.e. square
cells of that size at the grid's equator. Near the grid's poles the cells become tall
in latitude (:math:`\Delta\psi = \Delta s/\cos\psi`; the first ring around a pole of a 1°
grid reaches 10.7° from it), and a point evaluation of a narrow kernel there is a poor
quadrature (see *Quadrature*); the grid can therefore be rotated (``pole``), and
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

import warnings
from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np
import pandas as pd
from numba import njit, prange

from .. import _validate
from .mesh import _series, as_unit_vectors, to_lonlat
from .vmf import _direction, _frame, angle, vmf_fit

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

    def __post_init__(self):
        _validate.integer(self.n_lon, "n_lon", minimum=1)
        _validate.integer(self.n_lat, "n_lat", minimum=2)
        R = np.asarray(self.rotation, float)
        if (
            R.shape != (3, 3)
            or not np.all(np.isfinite(R))
            or not np.allclose(R.T @ R, np.eye(3), atol=1e-9)
            or np.linalg.det(R) <= 0
        ):
            raise ValueError(
                "rotation must be a proper rotation matrix (3 × 3, orthonormal, det +1)"
            )

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
    if n_lon * n_lat > _MAX_CELLS:
        raise ValueError(
            f"cell_deg = {cell_deg!r} gives {n_lon} × {n_lat} = {n_lon * n_lat:.3g} "
            f"cells, more than {_MAX_CELLS:.0e}; use a coarser grid"
        )
    p = _direction(pole, "pole")
    if meridian is None:
        R = _frame(p)
    else:
        m0 = _direction(meridian, "meridian")
        m = m0 - (m0 @ p) * p
        if np.linalg.norm(m) < 1e-9:
            raise ValueError(
                f"meridian must not be parallel to pole, got meridian = "
                f"{np.asarray(meridian).tolist()} and pole = {np.asarray(pole).tolist()}"
            )
        m /= np.linalg.norm(m)
        R = np.column_stack([m, np.cross(p, m), p])
    R.flags.writeable = False
    return EqualAreaGrid(n_lon, n_lat, R)


def _check_cell_deg(cell_deg) -> float:
    cell_deg = _validate.finite(cell_deg, "cell_deg")
    if not 0 < cell_deg <= 90:
        raise ValueError(f"cell_deg must be in (0, 90], got {cell_deg!r}")
    return cell_deg


def _weights(weights, n: int, ok=None) -> np.ndarray:
    """Weights (N,) finite and >= 0 on the rows kept (``ok``), else an error naming ``weights``."""
    try:
        w = np.asarray(weights, float)
    except (TypeError, ValueError):
        raise ValueError(f"weights must be numeric, got {weights!r}") from None
    if w.shape != (n,):
        raise ValueError(f"weights must have shape ({n},), got {w.shape}")
    ww = w if ok is None else w[ok]
    bad = ~np.isfinite(ww) | (ww < 0)
    if np.any(bad):
        raise ValueError(
            f"weights must be finite and >= 0, got {int(bad.sum())} bad values "
            f"(first: {ww[np.argmax(bad)]!r})"
        )
    return w


def grid_for(vectors, cell_deg: float = 1.0, weights=None) -> EqualAreaGrid:
    """Equal-area grid whose pole is 90° from the data's mean direction (data on the grid's equator).

    ``vectors``: a labelled (time, axis) series, a Recording (its ``gravity``) or an
    (N, 3) array; NaN rows are ignored.
    """
    cell_deg = _check_cell_deg(cell_deg)
    x = as_unit_vectors(vectors, "vectors", allow_nan=True)
    ok = np.isfinite(x).all(axis=1)
    w = None if weights is None else _weights(weights, x.shape[0], ok)
    m = x[ok].sum(axis=0) if w is None else w[ok] @ x[ok]
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

    Raises
    ------
    ValueError
        When the rule gives no usable bandwidth: all samples identical (a single
        sample, or :math:`\bar R = 1`: κ̂ = ∞ and h = 0 — pass ``h`` yourself), or no
        mean direction (zero resultant, e.g. antipodal pairs: κ̂ = 0 and h = ∞).
    """
    if method not in ("mle", "benhamou"):
        raise ValueError(f"method must be 'mle' or 'benhamou', got {method!r}")
    x = as_unit_vectors(vectors, "vectors")
    n = x.shape[0] if n is None else _validate.integer(n, "n", minimum=1)
    rule = f"reference_bandwidth (method={method!r}, h = κ̂^(-1/2) n^(-1/6))"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            fit = vmf_fit(x, weights)
    except ValueError as err:
        if "resultant" not in str(err):
            raise
        raise ValueError(
            f"{rule}: the samples have no mean direction (zero resultant, κ̂ = 0), "
            "so the rule gives h = ∞; pass h explicitly"
        ) from None
    if method == "mle":
        inv_k = 1.0 / fit.kappa if fit.kappa > 0 else np.inf
    else:
        inv_k = 1.0 - fit.rbar
    if not inv_k > 0:
        what = (
            "a single sample"
            if x.shape[0] == 1
            else f"all {x.shape[0]} samples identical"
        )
        raise ValueError(
            f"{rule} gives h = 0 for vectors with {what} (mean resultant length 1, "
            "κ̂ = ∞); pass h explicitly"
        )
    return float(np.sqrt(inv_k) * n ** (-1.0 / 6.0))


# ---------------------------------------------------------------------------
# numba scatter kernel
# ---------------------------------------------------------------------------


@njit(cache=True, parallel=True)
def _kde_scatter(lon, s, kap, w, n_lon, n_lat, log_tol, exact, mass, out, scratch):
    """Add every kernel to ``out`` (one (n_lat, n_lon) accumulator per chunk).

    ``mass=False``: kernel values at the cell centres (point evaluation, truncated at
    ``log_tol`` below the peak). ``mass=True``: the same values, relative to the
    largest one on the grid and truncated at ``log_tol`` below it, divided by their sum
    so that every kernel puts exactly its mass (times the cell area) on the grid;
    ``scratch`` (one row of n_lat·n_lon per chunk) holds them between the passes.
    """
    nchunk = out.shape[0]
    npts = lon.shape[0]
    dlon = 2.0 * np.pi / n_lon
    ds = 2.0 / n_lat
    area = dlon * ds
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
        buf = scratch[ch]
        jlo = np.empty(n_lat, np.int64)
        jhi = np.empty(n_lat, np.int64)
        for i in range(ch * npts // nchunk, (ch + 1) * npts // nchunk):
            k = kap[i]
            wi = w[i]
            if wi == 0.0:
                continue
            si = s[i]
            ci = np.sqrt(max(1.0 - si * si, 0.0))
            cl = np.cos(lon[i])
            sl = np.sin(lon[i])
            if mass:
                # nearest approach bound: the centre of the cell holding the kernel's centre
                r_own = min(max(int((si + 1.0) / ds), 0), n_lat - 1)
                j_own = min(max(int((lon[i] + np.pi) / dlon), 0), n_lon - 1)
                c_own = si * sc[r_own] + ci * cc[r_own] * (
                    clon[j_own] * cl + slon[j_own] * sl
                )
                cos_cut = min(c_own, 1.0) - 1e-12
            else:
                r_own = -1
                cos_cut = 1.0
            if k > 0.0:
                cos_cut += log_tol / k
            else:  # flat kernel (h so large that 1/h² underflows)
                cos_cut = -2.0
            if cos_cut <= -1.0:
                theta = np.pi
                cos_cut = -1.0
            else:
                theta = np.arccos(min(cos_cut, 1.0))
            psi = np.arcsin(si)
            lo = psi - theta
            hi = psi + theta
            s_lo = -1.0 if lo <= -0.5 * np.pi else np.sin(lo)
            s_hi = 1.0 if hi >= 0.5 * np.pi else np.sin(hi)
            r0 = max(int((s_lo + 1.0) / ds), 0)
            r1 = min(int((s_hi + 1.0) / ds), n_lat - 1)
            if mass:
                r0 = min(r0, r_own)
                r1 = max(r1, r_own)
            # columns of the cells of each row inside the truncation cap
            for r in range(r0, r1 + 1):
                sr = sc[r]
                cr = cc[r]
                den = ci * cr
                full = False
                empty = False
                cd = 0.0
                if den < 1e-300:
                    if si * sr >= cos_cut:
                        full = True
                    else:
                        empty = True
                else:
                    cd = (cos_cut - si * sr) / den
                    if cd <= -1.0:
                        full = True
                    elif cd > 1.0:
                        empty = True
                if empty:
                    jlo[r] = 0
                    jhi[r] = -1
                elif full:
                    jlo[r] = 0
                    jhi[r] = n_lon - 1
                else:
                    half = np.arccos(cd)
                    j0 = int(np.floor((lon[i] - half + np.pi) / dlon - 0.5))
                    j1 = int(np.ceil((lon[i] + half + np.pi) / dlon - 0.5))
                    if j1 - j0 + 1 >= n_lon:
                        j0 = 0
                        j1 = n_lon - 1
                    jlo[r] = j0
                    jhi[r] = j1
            if not mass:
                if exact:
                    if k < 1e-8:  # k / (1 - e^{-2k}) -> 1/2 + k/2
                        norm = wi * (0.5 + 0.5 * k) / np.pi
                    else:
                        norm = wi * k / (2.0 * np.pi * (-np.expm1(-2.0 * k)))
                else:
                    norm = wi * k / (2.0 * np.pi)
                for r in range(r0, r1 + 1):
                    sr = sc[r]
                    cr = cc[r]
                    for j in range(jlo[r], jhi[r] + 1):
                        jj = j % n_lon
                        if jj < 0:
                            jj += n_lon
                        cosd = si * sr + ci * cr * (clon[jj] * cl + slon[jj] * sl)
                        acc[r, jj] += norm * np.exp(k * (cosd - 1.0))
                continue
            # mass-conserving: pass 1, cos(distance) of every candidate cell and the largest
            q = 0
            cmax = -2.0
            for r in range(r0, r1 + 1):
                sr = sc[r]
                cr = cc[r]
                for j in range(jlo[r], jhi[r] + 1):
                    jj = j % n_lon
                    if jj < 0:
                        jj += n_lon
                    cosd = si * sr + ci * cr * (clon[jj] * cl + slon[jj] * sl)
                    buf[q] = cosd
                    q += 1
                    if cosd > cmax:
                        cmax = cosd
            if q == 0:  # pragma: no cover - the own cell is always a candidate
                continue
            # pass 2: values relative to the largest, truncated at log_tol below it
            tot = 0.0
            for p in range(q):
                d = buf[p] - cmax
                if d >= 0.0:
                    e = 1.0
                else:
                    x = k * d
                    e = np.exp(x) if x >= log_tol else 0.0
                buf[p] = e
                tot += e
            # the kernel's exact mass: 1 (vMF) or 1 - e^{-2k} (Gaussian-on-chord, Eq. 15)
            m = wi if exact else wi * (-np.expm1(-2.0 * k))
            f = m / (tot * area)
            # pass 3: deposit in the same order
            q = 0
            for r in range(r0, r1 + 1):
                for j in range(jlo[r], jhi[r] + 1):
                    jj = j % n_lon
                    if jj < 0:
                        jj += n_lon
                    acc[r, jj] += f * buf[q]
                    q += 1


_MAX_CELLS = (
    20_000_000  # grid cells (a 0.045° grid); each accumulator is 8 bytes a cell
)


def _scatter(
    x, w, h, grid: EqualAreaGrid, kernel: str, tol: float, quadrature: str
) -> np.ndarray:
    if kernel not in ("vmf", "gauss"):
        raise ValueError(f"kernel must be 'vmf' or 'gauss', got {kernel!r}")
    if quadrature not in ("mass", "point"):
        raise ValueError(f"quadrature must be 'mass' or 'point', got {quadrature!r}")
    _validate.fraction(tol, "tol", open_low=True, open_high=True)
    h = np.broadcast_to(np.asarray(h, float), (x.shape[0],))
    bad = ~np.isfinite(h) | (h <= 0)
    if np.any(bad):
        raise ValueError(
            f"bandwidth h must be finite and > 0, got {h[np.argmax(bad)]!r}"
        )
    with np.errstate(over="ignore", divide="ignore"):
        kap = 1.0 / h**2
    if quadrature == "point" and not np.all(np.isfinite(kap)):
        raise ValueError(
            f"bandwidth h = {h[np.argmax(~np.isfinite(kap))]!r} is too small to "
            "evaluate (1/h² overflows); use quadrature='mass'"
        )
    g = grid.to_grid_frame(x)
    lon, lat = to_lonlat(g)
    s = np.clip(g[:, 2], -1.0, 1.0)
    ncell = grid.n_lat * grid.n_lon
    per = 2 if quadrature == "mass" else 1  # accumulator (+ scratch) per chunk
    nchunk = max(
        1,
        min(numba.get_num_threads(), x.shape[0], 4 * _MAX_CELLS // (per * ncell)),
    )
    out = np.zeros((nchunk, grid.n_lat, grid.n_lon))
    scratch = np.empty((nchunk, ncell) if quadrature == "mass" else (1, 1))
    _kde_scatter(
        np.ascontiguousarray(lon),
        np.ascontiguousarray(s),
        np.ascontiguousarray(kap),
        np.ascontiguousarray(w, dtype=float),
        grid.n_lon,
        grid.n_lat,
        float(np.log(tol)),
        kernel == "vmf",
        quadrature == "mass",
        out,
        scratch,
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
    quadrature: str = "mass",
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
        Kernel truncation (relative to its peak), in (0, 1).
    quadrature : {"mass", "point"}
        ``"mass"`` (default): each kernel puts exactly its mass on the grid, so the
        KDE integrates to 1 for any bandwidth and position; ``"point"``: kernels
        evaluated at the cell centres (see the module notes, *Quadrature*).

    Returns
    -------
    SphericalKDE

    Raises
    ------
    ValueError
        For zero vectors, bad ``weights`` (negative, non-finite, wrong shape, all zero),
        a non-positive or non-finite ``h``, and when the default bandwidth rule fails
        (all samples identical: :func:`reference_bandwidth`).
    """
    x = as_unit_vectors(vectors, "vectors", allow_nan=True)
    ok = np.isfinite(x).all(axis=1)
    if h is not None:
        h = _validate.positive(h, "h")
    cell_deg = _check_cell_deg(cell_deg)
    w = np.ones(x.shape[0]) if weights is None else _weights(weights, x.shape[0], ok)
    x, w = x[ok], w[ok]
    if x.shape[0] == 0:
        raise ValueError("vectors has no finite rows (no data)")
    if w.sum() <= 0:
        raise ValueError("weights are all zero on the finite rows of vectors")
    if not np.isfinite(w.sum()):
        raise ValueError(f"weights sum to {w.sum()!r} (overflow); rescale them")
    if h is None:
        h = reference_bandwidth(x, w if weights is not None else None)
    grid = grid_for(x, cell_deg, w) if grid is None else _check_grid(grid)
    return SphericalKDE(
        _scatter(x, w, h, grid, kernel, tol, quadrature), grid, float(h)
    )


def _check_grid(grid) -> EqualAreaGrid:
    if not isinstance(grid, EqualAreaGrid):
        raise ValueError(
            f"grid must be an EqualAreaGrid (equal_area_grid, grid_for), "
            f"got {type(grid).__name__}"
        )
    return grid


def _rows(v, name: str) -> np.ndarray:
    """Directions (..., 3) normalised; zero or non-finite rows are an error naming ``name``."""
    a = _validate.vectors(v, name, width=3, ndim=None)
    n = np.linalg.norm(a, axis=-1, keepdims=True)
    if np.any(n == 0):
        raise ValueError(
            f"{name} contains {int((n == 0).sum())} zero vectors (no direction)"
        )
    return a / n


def slerp(a, b, t) -> np.ndarray:
    r"""Points at fraction t along the orthodromic arcs a→b (rows), :math:`\frac{\sin((1-t)\omega)a+\sin(t\omega)b}{\sin\omega}`.

    Parameters
    ----------
    a, b : array_like, shape (..., 3)
        Directions (normalised here; zero or non-finite rows are an error).
    t : array_like
        Fractions along the arcs (finite), broadcast with the rows.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Unit vectors; identical ``a`` and ``b`` give that direction for every ``t``.

    Raises
    ------
    ValueError
        When ``a`` and ``b`` are opposite directions (angle within 10⁻¹² rad of π) in
        some row: every great circle through them is a shortest arc, so the path is
        undefined (no direction is chosen arbitrarily; before, the point jumped from
        ``a`` to ``b`` through NaN at t = 1/2). The message names the first row.
    """
    a, b = _rows(a, "a"), _rows(b, "b")
    t = _validate.vectors(t, "t", width=None, ndim=None)[..., None]
    om = angle(a, b)[..., None]
    opposite = (np.sin(om) <= 1e-12) & (np.sum(a * b, axis=-1, keepdims=True) < 0)
    if np.any(opposite):
        k = np.argwhere(opposite[..., 0])
        where = f" (first at index {tuple(int(i) for i in k[0])})" if k.size else ""
        raise ValueError(
            f"a and b are opposite directions in {int(opposite.sum())} row(s){where}: "
            "the great-circle arc between antipodal points is not unique, so slerp is "
            "undefined there"
        )
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
    quadrature: str = "mass",
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
    kernel, cell_deg, tol, quadrature : as in :func:`kde`.

    At most 5·10⁷ kernels are placed (beyond that, an error names ``step``). Two
    successive samples in opposite directions are an error naming them (the arc
    between antipodal points is not unique, see :func:`slerp`).
    """
    x, t, _ = _series(vectors, fs, times)
    n = x.shape[0]
    if n < 2:
        raise ValueError(f"vectors needs at least 2 samples, got {n}")
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
    opposite = (np.sin(om) <= 1e-12) & (np.sum(a * b, axis=-1) < 0)
    if np.any(opposite):
        i = int(np.flatnonzero(keep)[np.argmax(opposite)])
        raise ValueError(
            f"vectors: samples {i} and {i + 1} are opposite directions: the path "
            "between them (a half-turn) has no defined great circle; drop the bad "
            "sample or give a max_gap that excludes that step"
        )
    m = np.maximum(1, np.ceil(om / step))
    if m.sum() > _MAX_KERNELS:
        raise ValueError(
            f"step = {step!r} rad cuts the trajectory into {m.sum():.3g} kernels "
            f"(more than {_MAX_KERNELS:.0e}); increase step"
        )
    m = m.astype(np.int64)
    k = np.repeat(np.arange(a.shape[0]), m)
    j = np.arange(k.size) - np.repeat(np.cumsum(m) - m, m)
    alpha = (j + 0.5) / m[k]
    pts = slerp(a[k], b[k], alpha)
    w = dt[k] / m[k]
    hh = np.sqrt(h * h + alpha * (1 - alpha) * diffusion * dt[k])
    grid = grid_for(x, cell_deg) if grid is None else _check_grid(grid)
    return SphericalKDE(
        _scatter(pts, w, hh, grid, kernel, tol, quadrature), grid, float(h)
    )


_MAX_KERNELS = 50_000_000


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
        raise ValueError(f"vectors needs at least 3 samples, got {n}")
    w = np.ones(n) if weights is None else _weights(weights, n)
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
