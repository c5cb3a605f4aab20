"""Equal-area grids on the sphere and the numba scatter of vMF kernels onto them.

The grid (:class:`EqualAreaGrid`, :func:`equal_area_grid`, :func:`grid_for`), the
result type :class:`SphericalKDE`, the checks of their arguments, and the kernel sum
with its two quadratures (:func:`_scatter`, numba :func:`_kde_scatter`), used by
:func:`~tiltlab.sphere.kde` and :func:`~tiltlab.sphere.mkde`. The grid, kernels and
quadratures are described in :mod:`tiltlab.sphere.kde`, which re-exports the public
names.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np
from numba import njit, prange

from .. import _validate
from .mesh import as_unit_vectors, to_lonlat
from .vmf import _direction, _frame

__all__ = [
    "EqualAreaGrid",
    "SphericalKDE",
    "equal_area_grid",
    "grid_for",
]


# ---------------------------------------------------------------------------
# equal-area grid
# ---------------------------------------------------------------------------


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


def _check_grid(grid) -> EqualAreaGrid:
    if not isinstance(grid, EqualAreaGrid):
        raise ValueError(
            f"grid must be an EqualAreaGrid (equal_area_grid, grid_for), "
            f"got {type(grid).__name__}"
        )
    return grid


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
