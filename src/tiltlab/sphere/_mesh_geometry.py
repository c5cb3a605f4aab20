r"""Convert longitude/latitude and compute exact spherical-triangle areas, without a mesh.

The private part of :mod:`tiltlab.sphere.mesh`.

Everything here is re-exported by :mod:`tiltlab.sphere.mesh` (and :mod:`tiltlab.sphere`),
where it is documented and imported from; this module imports nothing from it (the
dependency runs one way).

References
----------
.. [2] A. Van Oosterom, J. Strackee, "The solid angle of a plane triangle", IEEE Trans.
   Biomed. Eng. BME-30(2):125–126, 1983. doi:10.1109/TBME.1983.325207
"""

from __future__ import annotations

import numpy as np

from .. import _validate

__all__ = [
    "spherical_triangle_area",
    "to_lonlat",
    "from_lonlat",
]


def to_lonlat(v) -> tuple[np.ndarray, np.ndarray]:
    r"""Longitude :math:`\xi=\mathrm{atan2}(v_y, v_x)` and latitude :math:`\psi=\mathrm{atan2}(v_z,\sqrt{v_x^2+v_y^2})` (rad).

    In the rodent sensor frame (x nose, y left, z up) longitude 0 is the nose, +π/2 the
    left ear, and latitude +π/2 the dorsal axis.

    Parameters
    ----------
    v : array_like, shape (..., 3)
        Directions (need not be unit length).

    Returns
    -------
    lon : ndarray, shape (...)
        Longitude ξ (rad), in (−π, π].
    lat : ndarray, shape (...)
        Latitude ψ (rad), in [−π/2, π/2].
    """
    v = np.asarray(v, float)
    if v.shape[-1] != 3:
        raise ValueError(f"vectors must have a last axis of length 3, got {v.shape}")
    return np.arctan2(v[..., 1], v[..., 0]), np.arctan2(
        v[..., 2], np.hypot(v[..., 0], v[..., 1])
    )


def from_lonlat(lon, lat) -> np.ndarray:
    """Return unit vectors from longitude and latitude (rad), shape (..., 3).

    The inverse of :func:`to_lonlat`.

    Parameters
    ----------
    lon : float or array_like
        Longitude ξ (rad).
    lat : float or array_like
        Latitude ψ (rad); broadcasts with ``lon``.

    Returns
    -------
    ndarray, shape (..., 3)
        Unit vectors (x, y, z).
    """
    lon, lat = np.broadcast_arrays(np.asarray(lon, float), np.asarray(lat, float))
    c = np.cos(lat)
    return np.stack([c * np.cos(lon), c * np.sin(lon), np.sin(lat)], axis=-1)


def spherical_triangle_area(a, b, c) -> np.ndarray:
    r"""Exact area (spherical excess, sr) of the spherical triangles with unit-vector corners a, b, c.

    Van Oosterom–Strackee [2]_:
    :math:`E = 2\,\mathrm{atan2}\big(|a\cdot(b\times c)|,\;1 + a\cdot b + b\cdot c + c\cdot a\big)`,
    valid for any triangle (the atan2 keeps the right quadrant when the denominator is
    negative). Inputs broadcast over leading axes; they are normalised first.

    Parameters
    ----------
    a, b, c : array_like, shape (..., 3)
        Corners of the triangles (normalised here; no zero vectors).

    Returns
    -------
    ndarray, shape (...)
        Area (sr) of each triangle.
    """
    a, b, c = (
        _validate.vectors(x, name, width=3, ndim=None, allow_nan=True)
        for x, name in ((a, "a"), (b, "b"), (c, "c"))
    )
    for name, x in zip("abc", (a, b, c)):
        if np.any(np.all(x == 0, axis=-1)):
            raise ValueError(f"{name} contains zero vectors (no direction)")
    a, b, c = (x / np.linalg.norm(x, axis=-1, keepdims=True) for x in (a, b, c))
    num = np.abs(np.einsum("...i,...i->...", a, np.cross(b, c)))
    den = (
        1.0
        + np.einsum("...i,...i->...", a, b)
        + np.einsum("...i,...i->...", b, c)
        + np.einsum("...i,...i->...", c, a)
    )
    return 2.0 * np.arctan2(num, den)
