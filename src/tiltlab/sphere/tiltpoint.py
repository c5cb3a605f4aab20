r"""Summarise a tilt map: mean tilt point, sagittal angle, rotation to the pole.

The mean tilt point is the vMF fit of the facet centroids weighted by their counts
(Fayat et al. 2021, §2.8, §3.3); its angle to the sagittal plane and the rotation of a
baseline to the pole (Fig. 3e) follow.

References
----------
.. [1] R. Fayat et al., Sensors 21(18):6318, 2021, §2.8. doi:10.3390/s21186318
"""

from __future__ import annotations


import numpy as np
import xarray as xr

from .. import _validate
from .mesh import SphereMesh, _read, as_unit_vectors, sphere_mesh
from .vmf import VMFFit, _direction, _weights, vmf_fit

__all__ = [
    "mean_tilt_point",
    "sagittal_angle",
    "rotation_to_pole",
    "rotate_to_pole",
]


# ---------------------------------------------------------------------------
# mean tilt point, sagittal angle, rotation to the pole
# ---------------------------------------------------------------------------


def _facet_radius(mesh: SphereMesh) -> np.ndarray:
    """Per facet, the largest chord from its (unit) centroid to its corners."""
    c = mesh.centroids / np.linalg.norm(mesh.centroids, axis=1, keepdims=True)
    corners = mesh.vertices[mesh.faces]  # (F, 3, 3)
    return np.linalg.norm(corners - c[:, None, :], axis=2).max(axis=1)


def _map_mesh(tmap: xr.Dataset, mesh: SphereMesh | None) -> SphereMesh | None:
    """Return the mesh a tilt-map Dataset was counted on, or None when unknown.

    The mesh is ``mesh`` if given, else rebuilt from the ``n_vertices`` attribute.
    """
    n_faces = tmap.sizes.get("facet")
    if mesh is None and "n_vertices" in tmap.attrs:
        try:
            mesh = sphere_mesh(int(tmap.attrs["n_vertices"]))
        except (TypeError, ValueError):
            return None
    if mesh is not None and mesh.n_faces == n_faces:
        return mesh
    return None


def mean_tilt_point(tmap, mesh: SphereMesh | None = None) -> VMFFit:
    r"""Average tilt point of a map (Fayat et al. §2.8): vMF fit of the facet centroids weighted by their counts.

    Parameters
    ----------
    tmap : xarray.Dataset (from :func:`~tiltlab.sphere.tilt_map`) or array (F,)
        Samples (or time) per facet.
    mesh : SphereMesh, optional
        Needed when ``tmap`` is an array (default the 5000-vertex mesh). For a Dataset
        it defaults to the mesh named by its ``n_vertices`` attribute.

    Returns
    -------
    VMFFit
        Mean direction, concentration, mean resultant length and total weight.

    Raises
    ------
    ValueError
        As :func:`vmf_fit` when the map has no mean direction: a map symmetric enough
        that its mean resultant length :math:`\bar R` is within the facets' size. A
        count stands for samples anywhere in its facet, so replacing them by the
        centroid moves each by at most the facet radius :math:`\rho_i` (largest chord
        from the centroid to a corner); the resultant of the samples themselves may
        then be anywhere within :math:`\bar\rho = \sum_i w_i\rho_i / \sum_i w_i` of the
        map's. When :math:`\bar R \le \bar\rho` even its direction is not determined
        by the map (e.g. a uniform map, whose :math:`\bar R` of about 10⁻⁶ only
        reflects the mesh's irregularity): an error, as :func:`vmf_fit` gives for a
        zero resultant, rather than an arbitrary direction. For a Dataset whose mesh
        is unknown, :math:`\rho_i` is estimated from the facet area :math:`A_i` as the
        circumradius of an equilateral triangle, :math:`\sqrt{4A_i/(3\sqrt3)}`.
    """
    if isinstance(tmap, xr.Dataset):
        c, w = tmap["centroid"].values, tmap["count"].values
        used = _map_mesh(tmap, mesh)
        if used is not None:
            radius = _facet_radius(used)
        elif "area" in tmap.coords:
            radius = np.sqrt(
                4.0 * np.asarray(tmap["area"].values, float) / (3 * np.sqrt(3))
            )
        else:
            radius = None
    else:
        mesh = sphere_mesh() if mesh is None else mesh
        c, w = mesh.centroids, np.asarray(tmap, float)
        if w.shape != (mesh.n_faces,):
            raise ValueError(
                f"tmap has shape {w.shape}, mesh has {mesh.n_faces} facets"
            )
        radius = _facet_radius(mesh)
    w = _weights(w, c.shape[0], "tmap")
    if radius is not None:
        x = as_unit_vectors(c, "centroid")
        rbar = float(np.linalg.norm(w @ x)) / float(w.sum())
        rho = float(w @ radius) / float(w.sum())
        if rbar <= rho:
            raise ValueError(
                f"tmap: the map has no mean direction: its mean resultant length "
                f"R̄ = {rbar:.3g} is within the facets' size ({rho:.3g}, the mean facet "
                "radius), so the direction of its resultant is set by the mesh, not by "
                "the data (a map symmetric about the centre of the sphere, e.g. "
                "uniform); vmf_fit raises likewise for a zero resultant"
            )
    return vmf_fit(c, w)


def sagittal_angle(mu, lesion_side: str = "left") -> np.ndarray:
    r"""Signed angle (rad) of the tilt direction :math:`\mu` to the sagittal (xz) plane; positive = head tilted toward the lesion side.

    Sensor frame: x nose, y left, z up; :math:`\mu` is the gravity-up direction in that
    frame. When the head rolls so that its **left** ear goes down, the up direction
    seen from the head moves toward **−y** (:math:`\mu_y<0`): a tilt toward the lesion
    side shows as a deviation of the gravity vector *away* from it (Fayat et al. §3.3).
    Hence

    .. math:: \alpha = \arcsin(-s\,\mu_y),\qquad s = +1 \text{ (left lesion)},\ -1 \text{ (right)},

    so α > 0 means the head is tilted toward the lesioned side. :math:`|\alpha|` is
    Fayat et al.'s "angular distance to the sagittal plane" (Fig. 4c).

    Parameters
    ----------
    mu : array_like, shape (..., 3)
        Tilt (gravity-up) direction(s) in the sensor frame (normalised here).
    lesion_side : {"left", "right"}
        Side of the lesion; sets the sign s.

    Returns
    -------
    ndarray, shape (...)
        Signed angle α (rad), in [−π/2, π/2].

    Raises
    ------
    ValueError
        If ``lesion_side`` is not 'left' or 'right', or ``mu`` has a zero vector.
    """
    mu = _validate.vectors(mu, "mu", width=3, ndim=None, allow_nan=True)
    s = {"left": 1.0, "right": -1.0}.get(lesion_side)
    if s is None:
        raise ValueError(f"lesion_side must be 'left' or 'right', got {lesion_side!r}")
    n = np.linalg.norm(mu, axis=-1, keepdims=True)
    if np.any(n == 0):
        raise ValueError("mu contains zero vectors (no direction)")
    mu = mu / n
    return np.arcsin(np.clip(-s * mu[..., 1], -1, 1))


def rotation_to_pole(point) -> np.ndarray:
    r"""Return the minimal rotation matrix R (3×3) with :math:`R\,p = e_z`.

    The rotation is about the axis :math:`p\times e_z`.

    Rodrigues' formula; for :math:`p=-e_z` a half-turn about x. ``point`` must be a
    finite non-zero 3-vector.

    Parameters
    ----------
    point : array_like, shape (3,)
        Direction p to bring to the pole (normalised here).

    Returns
    -------
    ndarray, shape (3, 3)
        Rotation matrix R.
    """
    p = _direction(point, "point")
    ez = np.array([0.0, 0.0, 1.0])
    c = float(p @ ez)
    if c < -1 + 1e-15:
        return np.diag([1.0, -1.0, -1.0])
    v = np.cross(p, ez)
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1.0 + c)


def rotate_to_pole(vectors, baseline):
    """Rotate directions so that ``baseline`` sits at the north pole (Fayat et al. Fig. 3e).

    Angles between directions are preserved; a point's distance to the pole afterwards
    is its distance to the baseline point. ``vectors`` of shape (..., 3), or a labelled
    (time, axis) series / a Recording (its ``gravity``), which gives a DataArray back
    with the same coordinates and attributes.

    Parameters
    ----------
    vectors : array_like (..., 3), xarray.DataArray or xarray.Dataset
        Directions to rotate (NaN rows stay NaN).
    baseline : array_like, shape (3,)
        Direction brought to the north pole (normalised here).

    Returns
    -------
    ndarray, shape (..., 3), or xarray.DataArray
        Rotated directions; a (time, axis) DataArray for labelled input.
    """
    R = rotation_to_pole(_direction(baseline, "baseline"))
    if isinstance(vectors, (xr.DataArray, xr.Dataset)):
        sig = _read(vectors, allow_nan=True)
        out = sig.values @ R.T
        attrs = {"units": "1", "long_name": "direction, baseline at the pole"}
        if "method" in sig.attrs:
            attrs["method"] = sig.attrs["method"]
        return _validate.labelled(
            out, sig, "rotated", dims=("time", "axis"), attrs=attrs
        )
    v = _validate.vectors(vectors, "vectors", width=3, ndim=None, allow_nan=True)
    return v @ R.T
