r"""Geomagnetic field, tumble stage, Fibonacci lattice and marker head frame.

The private part of :mod:`tiltlab.frames`.

Everything here is re-exported by :mod:`tiltlab.frames`, where it is documented and
imported from; this module imports nothing from it (the dependency runs one way). It
also holds the small input checks and labelling helpers that :mod:`tiltlab.frames` and
:mod:`tiltlab.trig` share.

References
----------
.. [2] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
.. [3] R. Swinbank and R. J. Purser, "Fibonacci grids: A novel approach to global
   modelling", Q. J. R. Meteorol. Soc. 132:1769–1793, 2006. doi:10.1256/qj.05.235
"""

from __future__ import annotations

import numpy as np
import xarray as xr

import tiltlab._validate as _v
import tiltlab.quaternion as _quat

__all__ = [
    "geomagnetic_field",
    "fibonacci_lattice",
    "stage_angles",
    "stage_quaternion",
    "head_frame_from_markers",
]

_GOLDEN = (1.0 + 5.0**0.5) / 2.0


def _vec3(a, name: str) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    if a.ndim == 0 or a.shape[-1] != 3:
        raise ValueError(
            f"{name} must have a last dimension of size 3, got shape {a.shape}"
        )
    return a


def _angle(a, name: str) -> np.ndarray:
    """Angles (rad) as a float copy; NaN (undefined) passes, ±inf or complex raise."""
    return _v.vectors(a, name, width=None, ndim=None, allow_nan=True)


RAD_UNITS = ("rad", "radian", "radians", "1", "")  # SI: rad = 1
DEG_UNITS = ("deg", "degree", "degrees", "°")


def _angle_units(da: xr.DataArray, name: str) -> str:
    """``"rad"`` or ``"deg"``: the angle units of ``da`` (none means rad), else raise."""
    units = da.attrs.get("units")
    key = "rad" if units is None else str(units).strip().lower()
    if key in RAD_UNITS:
        return "rad"
    if key in DEG_UNITS:
        return "deg"
    raise ValueError(f"{name} must be an angle in rad (or deg), got units {units!r}")


def _label_attrs(da: xr.DataArray, units, attrs=None) -> dict:
    """Return the attributes of an output derived from ``da``: its ``fs``, ``method``, ``units``."""
    a = {k: da.attrs[k] for k in ("fs", "method") if k in da.attrs}
    if units is not None:
        a["units"] = units
    a.update(attrs or {})
    return a


def _label_as(values, da: xr.DataArray, name: str, units, attrs=None) -> xr.DataArray:
    """``values`` (shaped like ``da``) with its dims and coords, ``fs`` and ``method``."""
    a = _label_attrs(da, units, attrs)
    return xr.DataArray(values, dims=da.dims, coords=da.coords, name=name, attrs=a)


def _nonzero(a: np.ndarray, name: str, what: str = "vector") -> np.ndarray:
    """Return ``a`` (…, 3) unchanged; raise on a zero (finite) vector, which has no direction."""
    n = np.linalg.norm(a, axis=-1)
    if np.any(n == 0):
        k = int(np.sum(n == 0))
        raise ValueError(
            f"{name} has {k} zero {what}{'s' if k > 1 else ''}: its direction is undefined"
        )
    return a


# ---------------------------------------------------------------------------
# the Earth's magnetic field (Benhamou §1)
# ---------------------------------------------------------------------------


def geomagnetic_field(
    intensity: float = 48.0,
    inclination: float = np.radians(64.0),
    declination: float = 0.0,
) -> np.ndarray:
    r"""Geomagnetic field in ENU coordinates.

    ``inclination`` is the dip angle, positive *downwards* (northern hemisphere),
    ``declination`` is positive East of true North:
    :math:`B(\cos I\sin D, \cos I\cos D, -\sin I)`.

    Parameters
    ----------
    intensity : float, optional
        Total field intensity (> 0), in the unit wanted for the output; default 48.0
        (µT).
    inclination : float, optional
        Dip angle I in rad, positive downwards; default 64° (in rad).
    declination : float, optional
        Declination D in rad, positive East of true North; default 0.

    Returns
    -------
    numpy.ndarray, shape (3,)
        Field (East, North, Up) in the unit of ``intensity``.
    """
    intensity = _v.positive(intensity, "intensity")
    inclination = _v.finite(inclination, "inclination")
    declination = _v.finite(declination, "declination")
    return intensity * np.array(
        [
            np.cos(inclination) * np.sin(declination),
            np.cos(inclination) * np.cos(declination),
            -np.sin(inclination),
        ]
    )


# ---------------------------------------------------------------------------
# tumble stage and the Fibonacci lattice (Fayat App. A.1)
# ---------------------------------------------------------------------------


def fibonacci_lattice(n: int = 5000) -> np.ndarray:
    r"""Spherical Fibonacci lattice of ``n`` nearly uniform unit vectors, shape (n, 3).

    Point :math:`i = 0,\dots,n-1` has :math:`z_i = 1 - (2i+1)/n` (equal-area latitude
    bands) and longitude :math:`2\pi i/\Phi` with the golden ratio :math:`\Phi` [3]_.

    Parameters
    ----------
    n : int, optional
        Number of points (≥ 1); default 5000.

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        Unit vectors (dimensionless), from near the north pole (z ≈ 1) southwards.
    """
    if isinstance(n, bool) or int(n) != n or n < 1:
        raise ValueError(f"n must be a positive integer, got {n!r}")
    i = np.arange(int(n), dtype=float)
    z = 1.0 - (2.0 * i + 1.0) / n
    r = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
    lon = 2.0 * np.pi * ((i / _GOLDEN) % 1.0)
    return np.column_stack([r * np.cos(lon), r * np.sin(lon), z])


def stage_angles(g) -> tuple[np.ndarray, np.ndarray]:
    r"""Stage pitch β and roll γ (rad) bringing gravity-up to ``g`` in the sensor frame.

    With the stage :math:`R = R_y(\beta) R_x(\gamma)`, the tilt is
    :math:`g = R^\top e_z = (-\sin\beta, \sin\gamma\cos\beta, \cos\gamma\cos\beta)`,
    so :math:`\beta = -\arcsin g_x` and :math:`\gamma = \operatorname{atan2}(g_y, g_z)`.

    Parameters
    ----------
    g : array_like, shape (..., 3)
        Target gravity-up directions in the sensor frame; non-zero, need not be unit
        (any unit).

    Returns
    -------
    pitch : numpy.ndarray, shape (...)
        Stage pitch β in rad, in [−π/2, π/2].
    roll : numpy.ndarray, shape (...)
        Stage roll γ in rad, in (−π, π].
    """
    g = _nonzero(_vec3(g, "g"), "g")
    g = g / np.linalg.norm(g, axis=-1, keepdims=True)
    # atan2 form of beta = -asin(g_x): accurate near the poles too
    return np.arctan2(-g[..., 0], np.hypot(g[..., 1], g[..., 2])), np.arctan2(
        g[..., 1], g[..., 2]
    )


def stage_quaternion(pitch, roll) -> np.ndarray:
    """Orientation ``R_y(pitch) R_x(roll)`` (sensor → world) of the two-axis stage.

    Parameters
    ----------
    pitch : array_like
        Stage pitch β in rad (rotation about y).
    roll : array_like
        Stage roll γ in rad (rotation about x). ``pitch`` and ``roll`` broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit sensor → world quaternions (w, x, y, z).
    """
    pitch, roll = np.broadcast_arrays(_angle(pitch, "pitch"), _angle(roll, "roll"))
    z = np.zeros_like(pitch)
    return _quat.mul(
        _quat.from_rotvec(np.stack([z, pitch, z], -1)),
        _quat.from_rotvec(np.stack([roll, z, z], -1)),
    )


# ---------------------------------------------------------------------------
# marker head frame (Fayat §2.6.4)
# ---------------------------------------------------------------------------


def head_frame_from_markers(m1, m2, m3) -> np.ndarray:
    r"""Compute the head frame of Fayat §2.6.4 from markers 1–3.

    The head frame is given as rotation matrices (..., 3, 3) whose columns are
    :math:`h_x, h_y, h_z` in mocap (world) coordinates.

    :math:`h_y = (m_1 - m_2)/\|\cdot\|`, :math:`h_z = (m_3 - m_2) \times h_y / \|\cdot\|`,
    :math:`h_x = h_y \times h_z`.

    Parameters
    ----------
    m1, m2, m3 : array_like, shape (..., 3)
        Positions of markers 1, 2 and 3 in mocap (world) coordinates, in any length
        unit; not coincident or collinear. They broadcast; NaN (missing marker)
        propagates.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Head → world rotation matrices with columns ``h_x``, ``h_y``, ``h_z``.
    """
    m1, m2, m3 = (_vec3(v, n) for v, n in ((m1, "m1"), (m2, "m2"), (m3, "m3")))
    v21, v23 = m1 - m2, m3 - m2
    n21 = np.linalg.norm(v21, axis=-1)
    ncz = np.linalg.norm(np.cross(v23, v21), axis=-1)
    # frames with a missing (NaN) marker give NaN; NaN compares False here
    bad = (n21 == 0) | (ncz <= 1e-9 * n21 * np.linalg.norm(v23, axis=-1))
    if np.any(bad):
        raise ValueError(
            f"markers m1, m2, m3 are coincident or collinear in {int(bad.sum())} "
            "frame(s): the head frame is undefined"
        )
    hy = m1 - m2
    hy = hy / np.linalg.norm(hy, axis=-1, keepdims=True)
    hz = np.cross(m3 - m2, hy)
    hz = hz / np.linalg.norm(hz, axis=-1, keepdims=True)
    hx = np.cross(hy, hz)
    return np.stack([hx, hy, hz], axis=-1)
