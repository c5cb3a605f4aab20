r"""Posture from static acceleration and from the magnetic field (Benhamou 2023 §2–§3).

Every function taking an acceleration accepts a Recording (variable ``acc``), a
labelled DataArray or a plain array (shape (..., 3)); labelled input gives labelled
output. Units do not matter (only directions do).
"""

from __future__ import annotations

import warnings

import numpy as np

from .._stack import user_stacklevel
import tiltlab._validate as _v
from ..frames import Convention, _as_benhamou, _clip1, _elev_bank, acc_from_angles
from ._common import angle_function, label, read_input
from ._types import Posture

__all__ = [
    "posture",
    "inclination_from_angles",
    "angles_from_inclination",
    "correct_tangential",
    "correct_centripetal",
    "magnetic_posture",
    "posture_from_magnetic_loop",
]


def posture(acc, *, convention: Convention = "tiltlab") -> Posture:
    r"""Body posture from (static, body-frame) acceleration, Eqs. 2–3.

    .. math::
        \phi &= \sin^{-1}(-A_U/\|\mathbf A\|)
               = \tan^{-1}\!\big(-A_U/(A_V^2+A_W^2)^{1/2}\big) \quad(3a)\\
        \lambda &= \mathrm{atan2}(-A_V, -A_W) \quad(3b)\\
        \zeta &= \cos^{-1}(-A_W/\|\mathbf A\|) \quad(2a)\\
        \chi &= \mathrm{atan2}(-A_V, -A_U) \quad(2b)

    with Benhamou's sign 𝐀 (−𝐟 for tiltlab specific force). φ is evaluated in its
    atan form and ζ as atan2 (accurate near 0 and ±π/2). Singular cases: λ is
    undefined at φ = ±π/2 (returned as atan2(0, 0) = 0, the pseudo-bank of §3); χ is
    undefined at ζ = 0 (returned as 0). A zero acceleration (free fall, a dropped
    sample written as 0) has no posture: all four angles are NaN, with a
    :class:`RuntimeWarning`.

    Parameters
    ----------
    acc : xarray.Dataset, xarray.DataArray or array_like (..., 3)
        Static acceleration in the body frame (a Recording: its ``acc``). Low-pass it
        first (:func:`tiltlab.behavior.static_acceleration`) for a moving animal.
    convention : {"tiltlab", "benhamou"}
        Sign of ``acc``: specific force (tiltlab) or gravity (Benhamou).

    Returns
    -------
    Posture
        Angles in radians (DataArrays with ``time``/``fs`` for labelled input).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import trig
    >>> acc = trig.acc_from_angles(np.radians(20.0), np.radians(-10.0))
    >>> p = trig.posture(acc)
    >>> p._fields
    ('elevation', 'bank', 'inclination', 'orientation')
    >>> [float(np.round(np.degrees(v), 1)) for v in p]
    [20.0, -10.0, 22.3, -25.5]
    """
    s = read_input(acc, "acc")
    A = _as_benhamou(s.values, convention)
    el, bk = _elev_bank(A)
    zeta = np.arctan2(np.hypot(A[..., 0], A[..., 1]), -A[..., 2])
    chi = np.arctan2(-A[..., 1], -A[..., 0])
    el, bk, zeta, chi = _nan_where_zero(A, "posture", "acc", el, bk, zeta, chi)
    return Posture(
        label(el, s, "elevation", "rad"),
        label(bk, s, "bank", "rad"),
        label(zeta, s, "inclination", "rad"),
        label(chi, s, "orientation", "rad"),
    )


def _nan_where_zero(V, where: str, name: str, *angles):
    """Return the angles, NaN (with a RuntimeWarning) where the vector ``V`` is zero."""
    zero = np.all(V == 0, axis=-1)
    if not np.any(zero):
        return angles
    warnings.warn(
        f"{where}: {int(np.sum(zero))} of {zero.size} samples of {name} are zero "
        "vectors, whose direction (hence every angle) is undefined; set to NaN",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
    return tuple(np.where(zero, np.nan, a) for a in angles)


@angle_function(("inclination", "orientation"))
def inclination_from_angles(elevation, bank) -> tuple[np.ndarray, np.ndarray]:
    r"""Convert (φ, λ) to (ζ, χ).

    :math:`[\chi\bullet(\pi/2-\zeta)] = (\sin\phi, \cos\phi\sin\lambda,
    \cos\phi\cos\lambda)`.

    In particular :math:`\cos\zeta=\cos\phi\cos\lambda`.

    Parameters
    ----------
    elevation : float or array_like
        Elevation φ (rad).
    bank : float or array_like
        Bank λ (rad).

    Returns
    -------
    inclination : ndarray
        Overall inclination ζ (rad), in [0, π].
    orientation : ndarray
        Postural orientation χ (rad), in (−π, π].
    """
    v = acc_from_angles(elevation, bank)
    zeta = np.arctan2(np.hypot(v[..., 0], v[..., 1]), v[..., 2])
    return zeta, np.arctan2(v[..., 1], v[..., 0])


@angle_function(("elevation", "bank"))
def angles_from_inclination(inclination, orientation) -> tuple[np.ndarray, np.ndarray]:
    r"""Convert (ζ, χ) to (φ, λ).

    :math:`\phi=\sin^{-1}(\sin\zeta\cos\chi)`,
    :math:`\lambda=\mathrm{atan2}(\sin\zeta\sin\chi,\cos\zeta)`.

    Parameters
    ----------
    inclination : float or array_like
        Overall inclination ζ (rad).
    orientation : float or array_like
        Postural orientation χ (rad).

    Returns
    -------
    elevation : ndarray
        Elevation φ (rad), in [−π/2, π/2].
    bank : ndarray
        Bank λ (rad), in (−π, π].
    """
    z, c = np.broadcast_arrays(
        np.asarray(inclination, float), np.asarray(orientation, float)
    )
    elevation = np.arcsin(_clip1(np.sin(z) * np.cos(c)))
    return elevation, np.arctan2(np.sin(z) * np.sin(c), np.cos(z))


@angle_function("elevation", angles=("elevation",))
def correct_tangential(elevation, tangential_acc, *, g: float = 9.81) -> np.ndarray:
    r"""Correct the elevation for a sustained forward acceleration h = Δv/Δt (§2).

    :math:`\phi - \tan^{-1}(h/g)`.

    ``tangential_acc`` and ``g`` in the same units; h < 0 for a deceleration.

    Parameters
    ----------
    elevation : float or array_like
        Elevation φ (rad) from the acceleration.
    tangential_acc : float or array_like
        Forward acceleration h = Δv/Δt (e.g. m/s²), negative for a deceleration.
    g : float
        Gravity in the units of ``tangential_acc`` (default 9.81, m/s²), > 0.

    Returns
    -------
    ndarray
        Corrected elevation (rad).
    """
    g = _v.positive(g, "g")
    return np.asarray(elevation, float) - np.arctan2(
        np.asarray(tangential_acc, float), g
    )


@angle_function("bank", angles=("bank",))
def correct_centripetal(bank, speed, curvature, *, g: float = 9.81) -> np.ndarray:
    r"""Correct the bank for a sustained horizontal turn (§2).

    :math:`\lambda - \tan^{-1}(v^2\kappa/g)`.

    ``curvature`` κ = 1/r is signed, positive for a left (counter-clockwise) turn,
    which reproduces Benhamou's "− for a left turn, + for a right turn". κ = 0 is a
    straight path (no NaN). ``speed`` and ``g`` in consistent units (m/s, m/s²).

    Parameters
    ----------
    bank : float or array_like
        Bank λ (rad) from the acceleration.
    speed : float or array_like
        Horizontal speed v (e.g. m/s).
    curvature : float or array_like
        Signed path curvature κ = 1/r (e.g. 1/m), positive for a left turn.
    g : float
        Gravity in units consistent with v²κ (default 9.81, m/s²), > 0.

    Returns
    -------
    ndarray
        Corrected bank (rad).
    """
    g = _v.positive(g, "g")
    v = np.asarray(speed, float)
    return np.asarray(bank, float) - np.arctan2(v**2 * np.asarray(curvature, float), g)


def magnetic_posture(mag) -> tuple[np.ndarray, np.ndarray]:
    r"""Compute the magnetic 'elevation' and 'bank' (§3).

    :math:`\sin^{-1}(-M_U/\|\mathbf M\|)`, :math:`\mathrm{atan2}(-M_V,-M_W)`.

    Insensitive to dynamic acceleration, but measured against the plane orthogonal
    to the (dipping) field, hence hard to interpret on its own. ``mag``: a Recording
    (its ``mag``), a labelled DataArray or an array (..., 3). Zero field vectors give
    NaN with a :class:`RuntimeWarning`.

    Parameters
    ----------
    mag : xarray.Dataset, xarray.DataArray or array_like (..., 3)
        Body-frame magnetic field (any unit; a Recording: its ``mag``).

    Returns
    -------
    magnetic_elevation : ndarray or xarray.DataArray
        Magnetic 'elevation' (rad).
    magnetic_bank : ndarray or xarray.DataArray
        Magnetic 'bank' (rad).
    """
    s = read_input(mag, "mag")
    el, bk = _elev_bank(s.values)
    el, bk = _nan_where_zero(s.values, "magnetic_posture", "mag", el, bk)
    return label(el, s, "magnetic_elevation", "rad"), label(
        bk, s, "magnetic_bank", "rad"
    )


def posture_from_magnetic_loop(
    mag_loop, inclination: float
) -> tuple[float, float, float]:
    r"""Compute the posture of a bird looping in a thermal (§3).

    From magnetic vectors sampled evenly over one loop.

    With :math:`\Sigma\mathbf M` the sum of the body-frame field vectors and I the
    geomagnetic dip (rad, positive downward):
    :math:`\zeta=\cos^{-1}(|\Sigma M_W|/\|\Sigma\mathbf M\|)`,
    :math:`\phi=\sin^{-1}(-\mathrm{sgn}(I)\Sigma M_U/\|\Sigma\mathbf M\|)`,
    :math:`\lambda=\tan^{-1}(-\mathrm{sgn}(I)\Sigma M_V/|\Sigma M_W|)`.
    Returns (ζ, φ, λ); valid for |λ| < π/2. A zero sum (e.g. a field that cancels
    over the loop) has no direction: an error naming ``mag_loop``.

    Parameters
    ----------
    mag_loop : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        Body-frame magnetic vectors sampled evenly over one loop (any unit; no NaN).
    inclination : float
        Geomagnetic dip I (rad), positive downward.

    Returns
    -------
    zeta : float
        Overall inclination ζ (rad).
    phi : float
        Elevation φ (rad).
    lam : float
        Bank λ (rad).

    Raises
    ------
    ValueError
        If the field vectors sum to zero.
    """
    inclination = _v.finite(inclination, "inclination")
    m = read_input(mag_loop, "mag_loop", var="mag", allow_nan=False).values
    s = m.reshape(-1, 3).sum(axis=0)
    n = np.linalg.norm(s)
    if n == 0:
        raise ValueError(
            f"mag_loop: the {m.reshape(-1, 3).shape[0]} field vectors sum to zero; "
            "the posture is undefined"
        )
    sg = np.sign(inclination) if inclination != 0 else 1.0
    zeta = float(np.arctan2(np.hypot(s[0], s[1]), abs(s[2])))
    phi = float(np.arcsin(np.clip(-sg * s[0] / n, -1, 1)))
    lam = float(np.arctan2(-sg * s[1], abs(s[2])))
    return zeta, phi, lam
