"""Build equal-area grids on the sphere and scatter vMF kernels onto them.

The grid (:class:`EqualAreaGrid`, :func:`equal_area_grid`, :func:`grid_for`), the
result type :class:`SphericalKDE`, the checks of their arguments, and the kernel sum
with its two quadratures (:func:`_scatter`; its numba loops are in
:mod:`tiltlab.sphere._kde_kernel`), used by
:func:`~tiltlab.sphere.kde` and :func:`~tiltlab.sphere.mkde`. The grid, kernels and
quadratures are described in :mod:`tiltlab.sphere.kde`, which re-exports the public
names.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .. import _validate
from ._kde_kernel import _kde_scatter
from .mesh import as_unit_vectors, to_lonlat
from .vmf import _check_weights
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
        """Shape (n_lat, n_lon) of a density on the grid."""
        return (self.n_lat, self.n_lon)

    @property
    def lon_edges(self) -> np.ndarray:
        """Longitudes (rad) of the cell edges, (n_lon + 1,)."""
        return np.linspace(-np.pi, np.pi, self.n_lon + 1)

    @property
    def s_edges(self) -> np.ndarray:
        """Sines of the latitudes of the cell edges, (n_lat + 1,)."""
        return np.linspace(-1.0, 1.0, self.n_lat + 1)

    @property
    def lon_centres(self) -> np.ndarray:
        """Longitudes (rad) of the cell centres, (n_lon,)."""
        e = self.lon_edges
        return 0.5 * (e[1:] + e[:-1])

    @property
    def s_centres(self) -> np.ndarray:
        """Sines of the latitudes of the cell centres, (n_lat,)."""
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
        """Express data-frame vectors in the grid frame."""
        return np.asarray(vectors, float) @ self.rotation


def equal_area_grid(
    cell_deg: float = 1.0, *, pole=(0.0, 0.0, 1.0), meridian=None
) -> EqualAreaGrid:
    r"""Build an equal-area grid with :math:`\Delta\xi=\Delta s\approx` ``cell_deg``.

    ``n_lon = round(360/cell_deg)`` and ``n_lat = round(2/Δξ)`` (Δξ in rad); a 1° grid
    has 360 × 115 = 41 400 cells of 3.04·10⁻⁴ sr.

    Parameters
    ----------
    cell_deg : float
        Cell size (°), in (0, 90].
    pole : array_like (3,)
        Direction of the grid's pole.
    meridian : array_like (3,), optional
        Direction of grid longitude 0 (orthogonalised against ``pole``); default: the
        coordinate axis least aligned with the pole.

    Returns
    -------
    EqualAreaGrid
        The grid.
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


def grid_for(vectors, cell_deg: float = 1.0, weights=None) -> EqualAreaGrid:
    """Build an equal-area grid whose pole is 90° from the data's mean direction.

    The data then lie on the grid's equator, where its cells are square.

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        A labelled (time, axis) series, a Recording (its ``gravity``) or an (N, 3)
        array; NaN rows are ignored.
    cell_deg : float
        Cell size (°), in (0, 90].
    weights : array_like (N,), optional
        Weights of the samples in their mean direction.

    Returns
    -------
    EqualAreaGrid
        The grid (the default pole when the data have no mean direction).
    """
    cell_deg = _check_cell_deg(cell_deg)
    x = as_unit_vectors(vectors, "vectors", allow_nan=True)
    ok = np.isfinite(x).all(axis=1)
    w = None if weights is None else _check_weights(weights, x.shape[0], ok=ok)
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


_MAX_CELLS = (
    20_000_000  # grid cells (a 0.045° grid); each accumulator is 8 bytes a cell
)


class _KDESettings(NamedTuple):
    """Grid and kernel settings shared by :func:`~tiltlab.sphere.kde` and ``mkde``."""

    grid: EqualAreaGrid | None = None
    kernel: str = "vmf"
    cell_deg: float = 1.0
    tol: float = 1e-10
    quadrature: str = "mass"


#: samples are split into this many chunks, each summed into its own accumulator (in
#: parallel), then the accumulators are added: a fixed number, so that the sum's
#: rounding, hence the density, does not depend on the number of threads
_CHUNKS = 8


def _settings(options: dict, caller: str) -> _KDESettings:
    """Return the settings record of keyword ``options`` (a ``TypeError`` for others)."""
    unknown = sorted(set(options) - set(_KDESettings._fields))
    if unknown:
        raise TypeError(f"{caller}() got an unexpected keyword argument {unknown[0]!r}")
    return _KDESettings(**options)


def _kappas(h, n: int, quadrature: str) -> np.ndarray:
    """Return the concentrations 1/h² of n kernels, checking the bandwidths ``h``."""
    h = np.broadcast_to(np.asarray(h, float), (n,))
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
    return kap


def _scatter(x, w, h, grid: EqualAreaGrid, settings: _KDESettings) -> np.ndarray:
    """Return the weighted kernel sum of ``x`` (N, 3) on ``grid`` (see ``kde``)."""
    kernel, tol, quadrature = settings.kernel, settings.tol, settings.quadrature
    if kernel not in ("vmf", "gauss"):
        raise ValueError(f"kernel must be 'vmf' or 'gauss', got {kernel!r}")
    if quadrature not in ("mass", "point"):
        raise ValueError(f"quadrature must be 'mass' or 'point', got {quadrature!r}")
    _validate.fraction(tol, "tol", open_low=True, open_high=True)
    kap = _kappas(h, x.shape[0], quadrature)
    g = grid.to_grid_frame(x)
    lon, lat = to_lonlat(g)
    s = np.clip(g[:, 2], -1.0, 1.0)
    ncell = grid.n_lat * grid.n_lon
    per = 2 if quadrature == "mass" else 1  # accumulator (+ scratch) per chunk
    nchunk = max(
        1,
        min(_CHUNKS, x.shape[0], 4 * _MAX_CELLS // (per * ncell)),
    )
    out = np.zeros((nchunk, ncell))
    scratch = np.empty((nchunk, ncell) if quadrature == "mass" else (nchunk, 1))
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
    return out.sum(axis=0).reshape(grid.n_lat, grid.n_lon) / w.sum()


def _settings_grid(settings: _KDESettings, vectors, weights=None) -> EqualAreaGrid:
    """Return ``settings.grid`` (checked), else :func:`grid_for` the data."""
    if settings.grid is None:
        return grid_for(vectors, settings.cell_deg, weights)
    return _check_grid(settings.grid)
