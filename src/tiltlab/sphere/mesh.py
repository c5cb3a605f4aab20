r"""Triangulate the unit sphere and count directions on it (tilt maps).

Fibonacci lattice, spherical Delaunay facets, exact areas, vectorised point location
and tilt maps (Fayat et al. 2021, §2.7 and §3.3).

The vertices are a spherical Fibonacci lattice; the convex hull of points on the unit
sphere is their spherical Delaunay triangulation (each hull facet's circumscribed
circle on the sphere is the intersection of the sphere with the facet's plane, and no
lattice point lies above that plane). Facet areas are the exact spherical-triangle areas
(spherical excess) from the Van Oosterom–Strackee formula

.. math::
    \tan\frac{E}{2} = \frac{|a\cdot(b\times c)|}{1 + a\cdot b + b\cdot c + c\cdot a}.

Point location is a numba *visibility walk*: a cube-map look-up table gives, for each
of ``6 m²`` cells, the facet containing the cell centre; from there the walk crosses
the edge whose great circle separates the current facet from the query point until the
point is inside (one or two steps on average). No Python loop runs over samples or
facets.

**Boundary rule.** A facet is *closed*: a unit vector :math:`p` is inside facet
:math:`(a,b,c)` (counter-clockwise seen from outside) when the three normalised edge
tests :math:`p\cdot\widehat{(b\times c)},\;p\cdot\widehat{(c\times a)},\;
p\cdot\widehat{(a\times b)}` are all :math:`\ge -\varepsilon` (:math:`\varepsilon`
= ``EDGE_EPS`` rad). A vector on a shared edge or vertex therefore lies in several
facets; it is assigned to the **lowest-index** one, so every sample is counted exactly
once.

References
----------
.. [1] R. Fayat, V. Delgado Betancourt, T. Goyallon, M. Petremann, P. Liaudet,
   V. Descossy, L. Reveret, G. P. Dugué, "Inertial measurement of head tilt in rodents:
   principles and applications to vestibular research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
.. [2] A. Van Oosterom, J. Strackee, "The solid angle of a plane triangle", IEEE Trans.
   Biomed. Eng. BME-30(2):125–126, 1983. doi:10.1109/TBME.1983.325207
.. [3] Á. González, "Measurement of areas on a sphere using Fibonacci and
   latitude–longitude lattices", Math. Geosci. 42:49–64, 2010.
   doi:10.1007/s11004-009-9257-x
.. [4] O. Devillers, S. Pion, M. Teillaud, "Walking in a triangulation", Int. J. Found.
   Comput. Sci. 13(2):181–199, 2002. doi:10.1142/S0129054102001047

Inputs
------
Every function of :mod:`tiltlab.sphere` that takes a series of directions accepts

* a labelled :class:`xarray.DataArray` with dims ``(time, axis)`` — e.g. the output of
  :func:`tiltlab.filters.gravity` — whose ``attrs["fs"]`` and ``time`` coordinate are used
  where a function needs time;
* a Recording (:class:`xarray.Dataset`): its ``gravity`` variable (compute it with
  ``rec["gravity"] = filters.gravity(filters.estimate(rec, method))``) and its ``fs``;
* a plain array of shape (N, 3), with ``fs=`` (or ``times=``) given where time is needed.

Reading goes through :func:`tiltlab._validate.signal`: an ``fs`` argument that
contradicts the data's attribute, or a time coordinate that contradicts ``fs``, is an
error; so is a missing ``fs`` where a function needs durations.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
import xarray as xr
from numba import njit, prange
from scipy.spatial import ConvexHull

from .._stack import user_stacklevel
from .. import _validate
from .._validate import RecordingError
from ..frames import fibonacci_lattice
from ._mesh_geometry import from_lonlat, spherical_triangle_area, to_lonlat

__all__ = [
    "EDGE_EPS",
    "SphereMesh",
    "fibonacci_lattice",
    "spherical_triangle_area",
    "triangulate",
    "sphere_mesh",
    "locate",
    "histogram",
    "tilt_map",
    "visited",
    "visited_fraction",
    "as_unit_vectors",
    "to_lonlat",
    "from_lonlat",
]

#: tolerance (rad) of the closed-facet test; vectors closer than this to an edge count as on it
EDGE_EPS = 1e-12


# ---------------------------------------------------------------------------
# small helpers
# ---------------------------------------------------------------------------


def as_unit_vectors(v, name: str = "vectors", allow_nan: bool = False) -> np.ndarray:
    """Validate directions and return them as unit vectors, shape (N, 3) (a new array).

    ``v`` is a labelled (time, axis) DataArray, a Recording (its ``gravity`` variable), an
    (N, 3) array or a single (3,) vector; it is read with :func:`tiltlab._validate.signal`.
    Rows must be finite and non-zero; with ``allow_nan`` NaN rows stay NaN.

    Parameters
    ----------
    v : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3) or (3,)
        Directions (any non-zero length).
    name : str
        Name used in error messages.
    allow_nan : bool
        Accept NaN rows (returned as NaN) instead of raising.

    Returns
    -------
    ndarray, shape (N, 3)
        Unit vectors.

    Raises
    ------
    ValueError
        If a row is a zero vector (or NaN/inf when not allowed).
    """
    a = _read(v, name=name, allow_nan=allow_nan).values
    bad = np.isnan(a).any(axis=1)
    n = np.linalg.norm(a, axis=1)
    if np.any((n == 0) & ~bad):
        raise ValueError(f"{name} contains zero vectors (no direction)")
    with np.errstate(invalid="ignore"):
        return a / n[:, None]


_NO_GRAVITY = (
    "the Recording has no 'gravity' variable; compute the tilt first, e.g. "
    "rec['gravity'] = filters.gravity(filters.estimate(rec, method)), or pass that DataArray"
)


def _read(
    vectors,
    *,
    name: str = "vectors",
    fs=None,
    need_fs: bool = False,
    check_time: bool | None = None,
    allow_nan: bool = False,
) -> _validate.Signal:
    """Read one direction series (Recording, labelled DataArray or array) via ``_validate.signal``.

    A Recording must hold a ``gravity`` variable; its ``fs`` is the dataset's (or, when the
    dataset has none, the variable's). A DataArray is put in (time, axis) order; a plain
    (3,) vector counts as one sample.

    ``check_time`` (default ``need_fs``): let ``signal`` check ``fs`` against the time
    coordinate (median step). Functions that use neither time nor ``fs`` skip it, so a
    decimated series (``g[::4]``, whose ``fs`` attribute is stale) can still be fitted or
    smoothed; a series subset by a mask (``g[immobile]``) passes it as long as its
    median step stays ``1 / fs``.
    """
    if check_time is None:
        check_time = need_fs
    data = vectors
    if isinstance(data, xr.Dataset):
        if "gravity" not in data:
            raise RecordingError(f"{name}: {_NO_GRAVITY}")
        if "fs" not in data.attrs and "fs" in data["gravity"].attrs:
            data = data["gravity"]
    time = None
    if isinstance(data, (xr.DataArray, xr.Dataset)):
        da = data["gravity"] if isinstance(data, xr.Dataset) else data
        if "time" in da.coords and da["time"].ndim == 1:
            time = np.asarray(da["time"].values, dtype=float)
            if not check_time:
                data = data.drop_vars("time")
    if isinstance(data, xr.DataArray):
        if "axis" in data.dims and data.dims[-1] != "axis":
            data = data.transpose(..., "axis")
    elif not isinstance(data, xr.Dataset):
        a = np.asarray(data)
        if a.shape == (3,):
            data = a[None, :]
    sig = _validate.signal(
        data, name, var="gravity", fs=fs, need_fs=need_fs, allow_nan=allow_nan
    )
    return sig if sig.time is not None or time is None else replace(sig, time=time)


def _series(vectors, fs, times, name: str = "vectors"):
    """Return unit vectors (N, 3), their times (s) and the Signal read from ``vectors``.

    Times come from ``times`` (strictly increasing, shape (N,)), else from the data's
    ``time`` coordinate, else from ``fs`` (``t = i / fs``). Without ``times`` the sampling
    rate is required (argument or attribute); a ``times`` that contradicts the data's
    time coordinate is an error.
    """
    if (
        fs is None
        and times is None
        and not isinstance(vectors, (xr.DataArray, xr.Dataset))
    ):
        raise RecordingError(
            f"{name}: the sampling rate fs is unknown (pass fs= or times=); "
            "tiltlab never assumes a default"
        )
    sig = _read(vectors, name=name, fs=fs, need_fs=times is None)
    x = as_unit_vectors(sig.values, name)
    n = x.shape[0]
    if times is not None:
        t = np.asarray(times, float)
        if t.shape != (n,) or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
            raise ValueError(
                f"times must be finite and strictly increasing with shape ({n},)"
            )
        if sig.time is not None and not np.allclose(t, sig.time, rtol=0.0, atol=1e-9):
            raise RecordingError(
                f"{name}: times= contradicts the data's time coordinate"
            )
    elif sig.time is not None:
        t = np.asarray(sig.time, float)
        if t.shape != (n,) or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
            raise RecordingError(
                f"{name}: the time coordinate is not strictly increasing"
            )
    else:
        t = np.arange(n) / sig.fs
    return x, t, sig


# ---------------------------------------------------------------------------
# lattice, triangulation, areas
# ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class SphereMesh:
    """A triangulated unit sphere (immutable; arrays are read-only).

    Attributes
    ----------
    vertices : (V, 3) unit vectors.
    faces : (F, 3) int vertex indices, counter-clockwise seen from outside.
    neighbors : (F, 3) facet across the edge opposite to each corner.
    areas : (F,) exact spherical areas (sr); they sum to 4π.
    centroids : (F, 3) normalised planar centroids (unit vectors), used as facet positions.
    edge_normals : (F, 3, 3) unit normals of the edge great circles (row k: edge opposite corner k).
    vf_ptr, vf_idx : CSR list of the facets around each vertex.
    lut : (6·m·m,) start facet of the cube-map look-up cells; ``lut_m`` = m.
    """

    vertices: np.ndarray
    faces: np.ndarray
    neighbors: np.ndarray
    areas: np.ndarray
    centroids: np.ndarray
    edge_normals: np.ndarray
    vf_ptr: np.ndarray
    vf_idx: np.ndarray
    lut: np.ndarray
    lut_m: int

    @property
    def n_vertices(self) -> int:
        """Number of vertices V."""
        return self.vertices.shape[0]

    @property
    def n_faces(self) -> int:
        """Number of facets F."""
        return self.faces.shape[0]

    def area_ratio(self) -> float:
        """Largest over smallest facet area."""
        return float(self.areas.max() / self.areas.min())

    def __repr__(self) -> str:
        """Show the sizes and the area ratio."""
        return f"SphereMesh(n_vertices={self.n_vertices}, n_faces={self.n_faces}, area_ratio={self.area_ratio():.3f})"


def triangulate(vertices, *, lut_m: int | None = None) -> SphereMesh:
    """Spherical Delaunay triangulation (convex hull) of unit vectors, with areas and a locator.

    Parameters
    ----------
    vertices : array_like, shape (V, 3)
        Directions (normalised here); they must not all lie in one hemisphere's boundary
        plane (the hull must contain the origin).
    lut_m : int, optional
        Cube-map resolution of the point-location table (default ≈ √(F/6)).

    Returns
    -------
    SphereMesh
    """
    v = as_unit_vectors(vertices, "vertices")
    if v.shape[0] < 4:
        raise ValueError(f"vertices needs at least 4 directions, got {v.shape[0]}")
    if lut_m is not None:
        lut_m = _validate.integer(lut_m, "lut_m", minimum=1)
        if 6 * lut_m * lut_m > 100_000_000:
            raise ValueError(f"lut_m = {lut_m} gives a table of 6·lut_m² > 1e8 cells")
    hull = ConvexHull(v)
    faces = hull.simplices.astype(np.int64).copy()
    nbr = hull.neighbors.astype(np.int64).copy()
    if len(hull.vertices) != v.shape[0]:
        raise ValueError("some vertices are not on the convex hull (duplicates?)")
    a, b, c = v[faces[:, 0]], v[faces[:, 1]], v[faces[:, 2]]
    flip = np.einsum("ij,ij->i", a, np.cross(b, c)) < 0
    faces[flip, 1], faces[flip, 2] = faces[flip, 2].copy(), faces[flip, 1].copy()
    nbr[flip, 1], nbr[flip, 2] = nbr[flip, 2].copy(), nbr[flip, 1].copy()
    a, b, c = v[faces[:, 0]], v[faces[:, 1]], v[faces[:, 2]]
    if np.any(
        np.einsum("ij,ij->i", hull.equations[:, :3], a) <= 0
    ):  # pragma: no cover - hull sanity
        raise ValueError("the convex hull does not contain the origin")
    areas = spherical_triangle_area(a, b, c)
    cen = a + b + c
    cen /= np.linalg.norm(cen, axis=1, keepdims=True)
    en = np.stack([np.cross(b, c), np.cross(c, a), np.cross(a, b)], axis=1)
    en /= np.linalg.norm(en, axis=2, keepdims=True)
    nf = faces.shape[0]
    order = np.argsort(faces.ravel(), kind="stable")
    vf_idx = (order // 3).astype(np.int64)
    vf_ptr = np.zeros(v.shape[0] + 1, np.int64)
    np.cumsum(np.bincount(faces.ravel(), minlength=v.shape[0]), out=vf_ptr[1:])
    m = int(lut_m) if lut_m is not None else max(4, int(np.ceil(np.sqrt(nf / 6.0))))
    lut = _build_lut(m, en, nbr, faces, vf_ptr, vf_idx)
    arrays = dict(
        vertices=v,
        faces=faces,
        neighbors=nbr,
        areas=areas,
        centroids=cen,
        edge_normals=en,
        vf_ptr=vf_ptr,
        vf_idx=vf_idx,
        lut=lut,
    )
    for x in arrays.values():
        x.flags.writeable = False
    return SphereMesh(**arrays, lut_m=m)


@lru_cache(maxsize=8)
def sphere_mesh(n: int = 5000) -> SphereMesh:
    """Return the (cached) triangulated Fibonacci sphere with ``n`` vertices.

    Fayat et al. used n = 5000.

    Parameters
    ----------
    n : int
        Number of vertices, in [4, 10⁷].

    Returns
    -------
    SphereMesh
        The triangulation (shared between calls: it is immutable).
    """
    n = _validate.integer(n, "n", minimum=4)
    if n > 10_000_000:
        raise ValueError(f"n must be at most 1e7 vertices, got {n}")
    return triangulate(fibonacci_lattice(n))


# ---------------------------------------------------------------------------
# numba point location
# ---------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _cube_cell(p0, p1, p2, m):
    a0, a1, a2 = abs(p0), abs(p1), abs(p2)
    if a0 >= a1 and a0 >= a2:
        k, s, u, w, big = 0, p0 > 0, p1, p2, a0
    elif a1 >= a2:
        k, s, u, w, big = 1, p1 > 0, p2, p0, a1
    else:
        k, s, u, w, big = 2, p2 > 0, p0, p1, a2
    iu = int((u / big + 1.0) * 0.5 * m)
    iw = int((w / big + 1.0) * 0.5 * m)
    iu = min(max(iu, 0), m - 1)
    iw = min(max(iw, 0), m - 1)
    return ((k * 2 + (1 if s else 0)) * m + iu) * m + iw


@njit(cache=True, inline="always")
def _min_test(en, f, p0, p1, p2):
    d = 1e300
    for k in range(3):
        t = en[f, k, 0] * p0 + en[f, k, 1] * p1 + en[f, k, 2] * p2
        if t < d:
            d = t
    return d


@njit(cache=True)
def _walk(en, nbr, faces, vf_ptr, vf_idx, start, p0, p1, p2, eps):
    nf = en.shape[0]
    f = start
    found = -1
    for _ in range(nf + 3):
        worst = -eps
        kk = -1
        for k in range(3):
            t = en[f, k, 0] * p0 + en[f, k, 1] * p1 + en[f, k, 2] * p2
            if t < worst:
                worst = t
                kk = k
        if kk < 0:
            found = f
            break
        f = nbr[f, kk]
    if found < 0:  # pragma: no cover - the walk terminates on Delaunay triangulations
        for g in range(nf):
            if _min_test(en, g, p0, p1, p2) >= -eps:
                found = g
                break
        if found < 0:
            return -1
    # boundary rule: lowest-index closed facet containing p
    if _min_test(en, found, p0, p1, p2) < eps:
        best = found
        for c in range(3):
            vtx = faces[found, c]
            for j in range(vf_ptr[vtx], vf_ptr[vtx + 1]):
                g = vf_idx[j]
                if g < best and _min_test(en, g, p0, p1, p2) >= -eps:
                    best = g
        found = best
    return found


@njit(cache=True)
def _build_lut(m, en, nbr, faces, vf_ptr, vf_idx):
    lut = np.empty(6 * m * m, np.int64)
    f = 0
    for k in range(3):
        for s in range(2):
            sign = 1.0 if s == 1 else -1.0
            for iu in range(m):
                u = -1.0 + (iu + 0.5) * 2.0 / m
                for iw in range(m):
                    w = -1.0 + (iw + 0.5) * 2.0 / m
                    if k == 0:
                        p0, p1, p2 = sign, u, w
                    elif k == 1:
                        p0, p1, p2 = w, sign, u
                    else:
                        p0, p1, p2 = u, w, sign
                    r = np.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
                    p0, p1, p2 = p0 / r, p1 / r, p2 / r
                    f = _walk(en, nbr, faces, vf_ptr, vf_idx, f, p0, p1, p2, 0.0)
                    lut[_cube_cell(p0, p1, p2, m)] = f
    return lut


@njit(cache=True, parallel=True)
def _locate_kernel(x, en, nbr, faces, vf_ptr, vf_idx, lut, m, eps, out):
    for i in prange(x.shape[0]):
        p0, p1, p2 = x[i, 0], x[i, 1], x[i, 2]
        r = np.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
        if not (r > 0.0) or not np.isfinite(r):
            out[i] = -1
            continue
        p0, p1, p2 = p0 / r, p1 / r, p2 / r
        out[i] = _walk(
            en,
            nbr,
            faces,
            vf_ptr,
            vf_idx,
            lut[_cube_cell(p0, p1, p2, m)],
            p0,
            p1,
            p2,
            eps,
        )


def _locate(x: np.ndarray, mesh: SphereMesh) -> np.ndarray:
    x = np.ascontiguousarray(x, dtype=float)
    out = np.empty(x.shape[0], np.int64)
    _locate_kernel(
        x,
        mesh.edge_normals,
        mesh.neighbors,
        mesh.faces,
        mesh.vf_ptr,
        mesh.vf_idx,
        mesh.lut,
        mesh.lut_m,
        EDGE_EPS,
        out,
    )
    return out


def locate(vectors, mesh: SphereMesh | None = None):
    """Index of the facet containing each direction (vectorised numba walk).

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Directions (any non-zero norm): a labelled (time, axis) series, a Recording (its
        ``gravity``) or a plain array. NaN or zero rows give -1; ±inf is an error.
    mesh : SphereMesh, optional
        Default :func:`sphere_mesh` (5000 vertices).

    Returns
    -------
    numpy.ndarray of int64, shape (N,), or xarray.DataArray ``facet`` (dim ``time``) for labelled input
        Facet index; a vector on a shared edge or vertex goes to the lowest-index facet
        containing it (closed facets, tolerance ``EDGE_EPS``), so each sample is counted once.
    """
    mesh = _check_mesh(mesh)
    sig = _read(vectors, allow_nan=True)
    return _validate.labelled(_locate(sig.values, mesh), sig, "facet", dims=("time",))


# ---------------------------------------------------------------------------
# tilt maps
# ---------------------------------------------------------------------------


def _bincount(idx: np.ndarray, mesh: SphereMesh, weights) -> np.ndarray:
    ok = idx >= 0
    if weights is None:
        return np.bincount(idx[ok], minlength=mesh.n_faces)
    w = np.asarray(weights, float)
    if w.shape != idx.shape:
        raise ValueError(f"weights must have shape {idx.shape}, got {w.shape}")
    bad = ~np.isfinite(w[ok]) | (w[ok] < 0)
    if np.any(bad):
        raise ValueError(
            f"weights must be finite and >= 0, got {int(bad.sum())} bad values "
            f"(first: {w[ok][np.argmax(bad)]!r})"
        )
    return np.bincount(idx[ok], weights=w[ok], minlength=mesh.n_faces)


def _no_zero_rows(x: np.ndarray, name: str) -> np.ndarray:
    """Zero rows (no direction) are an error naming ``name``; NaN rows (missing) pass."""
    zero = np.all(x == 0, axis=1)
    if np.any(zero):
        raise ValueError(
            f"{name} contains {int(zero.sum())} zero vectors (no direction; "
            f"first at row {int(np.argmax(zero))}); mark missing samples with NaN"
        )
    return x


def _check_mesh(mesh) -> SphereMesh:
    if mesh is None:
        return sphere_mesh()
    if not isinstance(mesh, SphereMesh):
        raise ValueError(
            f"mesh must be a SphereMesh (sphere_mesh, triangulate), got {type(mesh).__name__}"
        )
    return mesh


def histogram(vectors, mesh: SphereMesh | None = None, *, weights=None) -> np.ndarray:
    """Count the samples (or sum their ``weights``) per facet, shape (F,).

    ``vectors`` is a labelled (time, axis) series, a Recording (its ``gravity``) or an
    (N, 3) array. Rows that are NaN (e.g. masked samples) are ignored; zero rows (no
    direction) and non-finite or negative ``weights`` are errors.

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Directions (any non-zero length).
    mesh : SphereMesh, optional
        Facets to count in; None uses the default :func:`sphere_mesh`.
    weights : array_like, shape (N,), optional
        Non-negative weight of each sample; None counts samples.

    Returns
    -------
    ndarray, shape (F,)
        Count (or summed weight) per facet.
    """
    mesh = _check_mesh(mesh)
    sig = _read(vectors, allow_nan=True)
    x = _no_zero_rows(sig.values, "vectors")
    return _bincount(_locate(x, mesh), mesh, weights)


def tilt_map(
    vectors, *, mesh: SphereMesh | None = None, fs: float | None = None, mask=None
) -> xr.Dataset:
    r"""Map head tilt: counts, time, time fraction and area-normalised density per facet.

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Unit-vector series (tilt :math:`g_s`, heading, posture...): a labelled (time, axis)
        DataArray such as :func:`tiltlab.filters.gravity`'s, a Recording with a
        ``gravity`` variable, or a plain array. NaN rows are skipped.
    mesh : SphereMesh, optional
        Default: the cached 5000-vertex Fibonacci triangulation.
    fs : float, optional
        Sampling rate (Hz) of a plain array; labelled data carry their own (an ``fs``
        that contradicts it, or the time coordinate, is an error; a masked subset such
        as ``g[immobile]`` is fine). When the rate is known, ``time`` (s) per facet is
        added.
    mask : array_like of bool, shape (N,), optional
        Keep only these samples (e.g. immobility; a boolean DataArray works too).

    Returns
    -------
    xarray.Dataset
        dims ``facet`` (and ``axis`` for ``centroid``): ``count``, ``fraction`` (of the
        kept samples), ``density`` = fraction / area (sr⁻¹; integrates to 1), ``time``
        (s, if the sampling rate is known), coords ``area`` (sr) and ``centroid``; attrs
        ``n_samples``, ``n_vertices`` and, copied from labelled input, ``method`` and
        ``axis_labels``. With no valid sample (everything masked out or NaN) the map
        is empty rather than an error: ``count`` 0, ``fraction`` and ``density`` NaN,
        ``attrs["empty_reason"]`` saying why, and a :class:`RuntimeWarning`.

    Examples
    --------
    >>> from tiltlab import sphere
    >>> g = sphere.vmf_sample([0.0, 0.0, 1.0], 50.0, 200, rng=0)
    >>> tmap = sphere.tilt_map(g, mesh=sphere.sphere_mesh(500), fs=100.0)
    >>> int(tmap["count"].sum()), float(tmap["time"].sum())
    (200, 2.0)
    >>> round(float((tmap["density"] * tmap["area"]).sum()), 6)
    1.0
    """
    mesh = _check_mesh(mesh)
    sig = _read(vectors, fs=fs, need_fs=False, check_time=True, allow_nan=True)
    x = sig.values
    if mask is not None:
        mask = np.asarray(mask)
        if mask.dtype != bool:
            if not (
                np.issubdtype(mask.dtype, np.number) and np.isin(mask, (0, 1)).all()
            ):
                raise ValueError(
                    f"mask must be boolean (or 0/1), got dtype {mask.dtype}"
                )
            mask = mask.astype(bool)
        if mask.shape != x.shape[:1]:
            raise ValueError(f"mask must have shape {x.shape[:1]}, got {mask.shape}")
        x = x[mask]
    counts = _bincount(_locate(_no_zero_rows(x, "vectors"), mesh), mesh, None)
    total = counts.sum()
    reason = None
    if total == 0:
        n_all = sig.values.shape[0]
        reason = (
            f"no valid samples to map: {n_all} samples"
            + (f", {x.shape[0]} kept by the mask" if mask is not None else "")
            + ", none finite"
        )
        warnings.warn(
            f"tilt_map: {reason}; the map is empty (count 0, fraction and density NaN)",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = counts / total if total else np.full(counts.shape, np.nan)
    ds = xr.Dataset(
        {
            "count": ("facet", counts, {"units": "1", "long_name": "samples"}),
            "fraction": ("facet", frac, {"units": "1", "long_name": "time fraction"}),
            "density": (
                "facet",
                frac / mesh.areas,
                {"units": "1/sr", "long_name": "density"},
            ),
        },
        coords={
            "area": ("facet", np.array(mesh.areas), {"units": "sr"}),
            "centroid": (("facet", "axis"), np.array(mesh.centroids)),
            "axis": ["x", "y", "z"],
        },
        attrs={"n_samples": int(total), "n_vertices": mesh.n_vertices},
    )
    if reason is not None:
        ds.attrs["empty_reason"] = reason
    if sig.fs is not None:
        ds["time"] = ("facet", counts / sig.fs, {"units": "s", "long_name": "time"})
        ds.attrs["fs"] = sig.fs
    for key in ("method", "axis_labels"):
        if key in sig.attrs:
            ds.attrs[key] = sig.attrs[key]
    return ds


def _counts(m) -> np.ndarray:
    if isinstance(m, xr.Dataset):
        return np.asarray(m["count"].values)
    return np.asarray(m)


def visited(tmap, *, min_count: int = 1) -> np.ndarray:
    """Binarised map: True for facets with at least ``min_count`` samples (Fayat Fig. 3c–d).

    Parameters
    ----------
    tmap : xarray.Dataset or array_like, shape (F,)
        A map from :func:`tilt_map` (its ``count`` variable) or counts per facet.
    min_count : int
        Minimum number of samples (≥ 1) for a facet to count as visited.

    Returns
    -------
    ndarray of bool, shape (F,)
        True for visited facets.
    """
    min_count = _validate.integer(min_count, "min_count", minimum=1)
    return _counts(tmap) >= min_count


def visited_fraction(
    tmap, mesh: SphereMesh | None = None, *, min_count: int = 1, by: str = "area"
) -> float:
    r"""Fraction of the sphere visited (facets with ≥ ``min_count`` samples).

    ``by="area"`` sums the exact facet areas over :math:`4\pi`; ``by="count"`` is the
    fraction of facets (Fayat et al.'s measure, which weights every facet equally even
    though their areas differ by :meth:`SphereMesh.area_ratio`). An empty map (from
    :func:`tilt_map` with no valid sample) gives NaN: nothing was observed.

    Parameters
    ----------
    tmap : xarray.Dataset or array_like, shape (F,)
        A map from :func:`tilt_map` or counts per facet.
    mesh : SphereMesh, optional
        Mesh of the map; None uses the default :func:`sphere_mesh`.
    min_count : int
        Minimum number of samples (≥ 1) for a facet to count as visited.
    by : {"area", "count"}
        Weight facets by their area or equally.

    Returns
    -------
    float
        Visited fraction, in [0, 1]; NaN for an empty map.

    Raises
    ------
    ValueError
        If the map and the mesh have different numbers of facets, or ``by`` is invalid.

    Examples
    --------
    >>> from tiltlab import sphere
    >>> mesh = sphere.sphere_mesh(500)
    >>> g = sphere.vmf_sample([0.0, 0.0, 1.0], 50.0, 200, rng=0)
    >>> tmap = sphere.tilt_map(g, mesh=mesh)
    >>> round(sphere.visited_fraction(tmap, mesh), 3)
    0.04
    """
    mesh = _check_mesh(mesh)
    if isinstance(tmap, xr.Dataset) and tmap.attrs.get("n_samples", 1) == 0:
        return float("nan")
    v = visited(tmap, min_count=min_count)
    if v.shape != (mesh.n_faces,):
        raise ValueError(f"map has {v.shape[0]} facets, mesh has {mesh.n_faces}")
    if by == "area":
        return float(mesh.areas[v].sum() / mesh.areas.sum())
    if by == "count":
        return float(v.mean())
    raise ValueError(f"by must be 'area' or 'count', got {by!r}")
