r"""Heading: azimuth from acceleration and magnetic field.

Benhamou 2023 §3, Eqs. 5, 18 and App. A.

:func:`azimuth`, :func:`collar_azimuth` and :func:`heading` take ``acc`` and ``mag`` as
Recordings, labelled DataArrays or plain arrays (..., 3); pass a Recording alone
(``heading(rec)``) to read both its ``acc`` and its ``mag``. Labelled input gives
labelled output. Magnetometer calibration (Eq. 4) lives in
:mod:`tiltlab.calibration` (:func:`~tiltlab.calibration.four_point_mag_calibration`,
:func:`~tiltlab.calibration.apply_mag_calibration`).
"""

from __future__ import annotations

import warnings

import numpy as np

from .._stack import user_stacklevel
import tiltlab._validate as _v
from ..frames import (
    R1,
    R2,
    Convention,
    Orientation,
    _as_benhamou,
    _elev_bank,
    unit_vector,
    wrap_angle,
)
from ._common import angle_function, first_labelled, label, pair, read_input

__all__ = [
    "mounting_azimuth_offset",
    "azimuth",
    "collar_azimuth",
    "heading",
    "body_azimuth_from_device",
    "apply_declination",
]


def _declination(declination) -> np.ndarray:
    return _v.vectors(declination, "declination", width=None, ndim=None)


def _undefined(A, M, singular_tol: float) -> np.ndarray:
    """Flag the samples whose azimuth is undefined.

    Undefined: zero acceleration or field, or a field parallel to the acceleration
    (‖A×M‖ ≤ singular_tol·‖A‖‖M‖: no horizontal field).
    """
    A, M = np.broadcast_arrays(A, M)
    na = np.linalg.norm(A, axis=-1)
    nm = np.linalg.norm(M, axis=-1)
    cross = np.linalg.norm(np.cross(A, M), axis=-1)
    return (na == 0) | (nm == 0) | (cross <= singular_tol * na * nm)


def _warn_undefined(where: str, bad: np.ndarray, total: int, why: str) -> None:
    warnings.warn(
        f"{where}: {int(np.sum(bad))} of {total} samples set to NaN: {why}",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def _azimuth(A, M, declination, singular_tol: float, where: str) -> np.ndarray:
    """Eq. 5 on arrays (A in Benhamou's sign); NaN (with a warning) where undefined."""
    A, M = np.broadcast_arrays(A, M)
    AU, AV, AW = A[..., 0], A[..., 1], A[..., 2]
    MU, MV, MW = M[..., 0], M[..., 1], M[..., 2]
    s2 = AV**2 + AW**2
    n = np.sqrt(AU**2 + s2)
    th = np.arctan2(s2 * MU - AU * (AV * MV + AW * MW), (AV * MW - AW * MV) * n)
    sing = np.sqrt(s2) < singular_tol * n
    sg = np.where(AU >= 0, 1.0, -1.0)
    pseudo = np.arctan2(MV, -sg * MW) - np.pi / 2
    th = np.where(sing, pseudo, th)
    bad = _undefined(A, M, singular_tol)
    if np.any(bad):
        _warn_undefined(
            where,
            bad,
            bad.size,
            "the azimuth is undefined where mag (or acc) is a zero vector or mag is "
            "parallel to acc (no horizontal field, e.g. at a magnetic pole); a zero "
            "acc also leaves elevation and bank undefined",
        )
        th = np.where(bad, np.nan, th)
    return wrap_angle(th - declination)


def _read_azimuth(acc, mag, convention, declination, singular_tol, where: str):
    """Read ``acc`` and ``mag`` and compute Eq. 5: the first step of azimuth and heading.

    Returns the azimuth (rad), the acceleration in Benhamou's sign, the signal to label
    the outputs like, and the checked ``singular_tol``.
    """
    singular_tol = _v.positive(singular_tol, "singular_tol")
    decl = _declination(declination)
    sa = read_input(acc, "acc")
    sm = read_input(pair(acc, mag), "mag")
    try:
        np.broadcast_shapes(sa.values.shape, sm.values.shape)
    except ValueError:
        raise ValueError(
            f"acc and mag must have the same number of samples (or broadcast), got "
            f"shapes {sa.values.shape} and {sm.values.shape}"
        ) from None
    A = _as_benhamou(sa.values, convention)
    th = _azimuth(A, sm.values, decl, singular_tol, where)
    return th, A, first_labelled(sa, sm), singular_tol


def mounting_azimuth_offset(
    acc_rest, mag_rest, observed_bearing, *, convention: Convention = "tiltlab"
) -> np.ndarray:
    r"""App. A azimuth mismatch :math:`\theta^* - \pi/2 + \theta^{obs}` (rad).

    θ* is the device azimuth at rest (Eq. 5 on the device vectors, ccw from East)
    and ``observed_bearing`` the visually assessed body bearing θ^obs (clockwise from
    North, radians, as read on a compass). Pass the result as ``dtheta`` to
    :func:`~tiltlab.frames.mounting_matrix` / :func:`~tiltlab.frames.device_to_body`.

    Parameters
    ----------
    acc_rest : xarray.Dataset, xarray.DataArray or array_like (..., 3)
        Device-frame static acceleration at rest (a Recording: its ``acc`` and ``mag``).
    mag_rest : xarray.DataArray or array_like (..., 3), optional
        Device-frame magnetic field at rest (any unit); None to read it from a
        Recording.
    observed_bearing : float or array_like
        Observed body bearing θ^obs (rad, clockwise from North).
    convention : {"tiltlab", "benhamou"}
        Sign of ``acc_rest``: specific force (tiltlab) or gravity (Benhamou).

    Returns
    -------
    ndarray
        Azimuth mismatch Δθ (rad), wrapped to (−π, π].
    """
    theta_star = azimuth(acc_rest, mag_rest, convention=convention)
    bearing = _v.vectors(observed_bearing, "observed_bearing", width=None, ndim=None)
    return wrap_angle(np.asarray(theta_star) - np.pi / 2 + bearing)


def azimuth(
    acc,
    mag=None,
    *,
    convention: Convention = "tiltlab",
    declination=0.0,
    singular_tol: float = 1e-9,
) -> np.ndarray:
    r"""Compute the body azimuth θ (ccw from East, rad) by Eq. 5.

    From body-frame static acceleration and magnetic field:

    .. math::
        \theta = \mathrm{atan2}\big((A_V^2+A_W^2)M_U - A_U(A_V M_V + A_W M_W),\;
        (A_V M_W - A_W M_V)\|\mathbf A\|\big)

    (𝐀 in Benhamou's sign; the second argument changes sign with the convention,
    which is why ``convention`` matters). This is atan2 of the levelled field
    :math:`\underline M_U, \underline M_V`,
    :math:`\underline{\mathbf M}^\top=R_2(\phi)R_1(\lambda)\mathbf M^\top`.

    With magnetic vectors the result is magnetic azimuth; ``declination`` (rad,
    positive East) is subtracted to get the true azimuth (:func:`apply_declination`).

    Singular case (φ ≈ ±π/2, :math:`(A_V^2+A_W^2)^{1/2} <` ``singular_tol``·‖𝐀‖):
    the pseudo-azimuth θ = θ' − π/2 with θ' = atan2(M_V, −sgn(A_U) M_W), the
    direction of the sway axis (§3), consistent with pseudo-bank λ = 0.

    Undefined azimuth — a zero field or acceleration, or a field parallel to the
    acceleration (:math:`\|\mathbf A\times\mathbf M\| \le` ``singular_tol``
    ·‖𝐀‖‖𝐌‖, e.g. at a magnetic pole): NaN with a :class:`RuntimeWarning`.

    Parameters
    ----------
    acc : xarray.Dataset, xarray.DataArray or array_like (..., 3)
        Static acceleration (a Recording: its ``acc``, and its ``mag`` if ``mag`` is
        None).
    mag : xarray.DataArray or array_like (..., 3), optional
        Calibrated magnetic field in the same frame (any unit).
    convention : {"tiltlab", "benhamou"}, optional
        Sign convention of ``acc``: specific force (``"tiltlab"``, default) or
        Benhamou's acceleration.
    declination : float or array_like, optional
        Magnetic declination (rad, positive East) subtracted from the result
        (default 0: magnetic azimuth).
    singular_tol : float, optional
        Relative threshold (> 0) for the singular (surge vertical) and undefined
        cases (default 1e-9).

    Returns
    -------
    numpy.ndarray or xarray.DataArray
        Azimuth θ in rad, in (−π, π], one per sample; a DataArray named ``azimuth``
        for labelled input.
    """
    th, _, like, _ = _read_azimuth(
        acc, mag, convention, declination, singular_tol, "azimuth"
    )
    return label(th, like, "azimuth", "rad")


def collar_azimuth(
    acc, mag=None, *, convention: Convention = "tiltlab", declination=0.0
) -> np.ndarray:
    r"""Compute the azimuth of a collar-mounted device (Eq. 18).

    From *device* static acceleration and mean field.

    Same expression as Eq. 5 applied to :math:`\bar{\mathbf a}, \bar{\mathbf m}`
    (device frame): valid for the body when the animal moves unbanked and the device
    surge axis is orthogonal to the collar plane, whatever the collar roll.

    Parameters
    ----------
    acc : xarray.Dataset, xarray.DataArray or array_like (..., 3)
        Device-frame static acceleration (a Recording: its ``acc``, and its ``mag`` if
        ``mag`` is None).
    mag : xarray.DataArray or array_like (..., 3), optional
        Device-frame mean magnetic field (any unit).
    convention : {"tiltlab", "benhamou"}
        Sign of ``acc``: specific force (tiltlab) or gravity (Benhamou).
    declination : float or array_like
        Magnetic declination (rad, positive East) subtracted; 0 gives magnetic azimuth.

    Returns
    -------
    ndarray or xarray.DataArray
        Azimuth (rad, ccw from East), wrapped to (−π, π]; NaN where undefined.
    """
    return azimuth(acc, mag, convention=convention, declination=declination)


def heading(
    acc,
    mag=None,
    *,
    convention: Convention = "tiltlab",
    declination=0.0,
    singular_tol: float = 1e-9,
) -> Orientation:
    """Compute the full 3-D orientation (θ Eq. 5, φ Eq. 3a, λ Eq. 3b).

    With the §3 fallback (pseudo-bank 0) at φ = ±π/2.

    Inputs as for :func:`azimuth` (``heading(rec)`` reads a Recording's ``acc`` and
    ``mag``). Returns an :class:`~tiltlab.frames.Orientation` in radians (DataArrays
    for labelled input). Undefined angles are NaN with a :class:`RuntimeWarning`: the
    azimuth as in :func:`azimuth`, and all three where the acceleration is zero.

    Parameters
    ----------
    acc : xarray.Dataset, xarray.DataArray or array_like (..., 3)
        Body-frame static acceleration (a Recording: its ``acc``, and its ``mag`` if
        ``mag`` is None).
    mag : xarray.DataArray or array_like (..., 3), optional
        Calibrated body-frame magnetic field (any unit).
    convention : {"tiltlab", "benhamou"}
        Sign of ``acc``: specific force (tiltlab) or gravity (Benhamou).
    declination : float or array_like
        Magnetic declination (rad, positive East) subtracted from the azimuth.
    singular_tol : float
        Relative tolerance (> 0) for the singular (φ ≈ ±π/2) and undefined cases.

    Returns
    -------
    Orientation
        Azimuth θ, elevation φ and bank λ (rad).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import trig
    >>> th, ph, la = np.radians([40.0, 20.0, -10.0])
    >>> acc = trig.acc_from_angles(ph, la)  # a body at rest
    >>> mag = trig.mag_from_angles(th, ph, la)  # in the default geomagnetic field
    >>> o = trig.heading(acc, mag)
    >>> [float(np.round(np.degrees(v), 1)) for v in o]
    [40.0, 20.0, -10.0]
    """
    th, A, like, singular_tol = _read_azimuth(
        acc, mag, convention, declination, singular_tol, "heading"
    )
    el, bk = _elev_bank(A)
    sing = np.hypot(A[..., 1], A[..., 2]) < singular_tol * np.linalg.norm(A, axis=-1)
    el = np.where(sing, np.where(A[..., 0] >= 0, -np.pi / 2, np.pi / 2), el)
    bk = np.where(sing, 0.0, bk)
    zero = np.linalg.norm(A, axis=-1) == 0  # (already warned about by _azimuth)
    el = np.where(zero, np.nan, el)
    bk = np.where(zero, np.nan, bk)
    return Orientation(
        label(th, like, "azimuth", "rad"),
        label(el, like, "elevation", "rad"),
        label(bk, like, "bank", "rad"),
    )


@angle_function("azimuth")
def body_azimuth_from_device(device_azimuth, elevation, bank, phi_star) -> np.ndarray:
    r"""Compute the azimuth by the §3 alternative to Eq. 5.

    :math:`\theta=\theta^d-\mathrm{atan2}(c_2,c_1)`,
    :math:`(c_1,c_2,c_3)^\top=R_2(\phi)R_1(\lambda)[0\bullet\phi^*]^\top`.

    θ^d is the device azimuth (Eq. 18 on device vectors), φ, λ the body posture and
    φ* the longitudinal mounting tilt (device surge axis in the sagittal plane).

    Parameters
    ----------
    device_azimuth : float or array_like
        Device azimuth θ^d (rad).
    elevation : float or array_like
        Body elevation φ (rad).
    bank : float or array_like
        Body bank λ (rad).
    phi_star : float or array_like
        Longitudinal mounting tilt φ* (rad).

    Returns
    -------
    ndarray
        Body azimuth θ (rad), wrapped to (−π, π].
    """
    c = np.einsum(
        "...ij,...j->...i", R2(elevation) @ R1(bank), unit_vector(0.0, phi_star)
    )
    return wrap_angle(
        np.asarray(device_azimuth, float) - np.arctan2(c[..., 1], c[..., 0])
    )


@angle_function("azimuth")
def apply_declination(magnetic_azimuth, declination) -> np.ndarray:
    """Convert a magnetic azimuth to a true azimuth (rad), wrapped to (−π, π].

    True azimuth = magnetic azimuth − declination (declination positive East).

    Parameters
    ----------
    magnetic_azimuth : float or array_like
        Magnetic azimuth (rad).
    declination : float or array_like
        Magnetic declination (rad, positive East).

    Returns
    -------
    ndarray
        True azimuth (rad).
    """
    return wrap_angle(np.asarray(magnetic_azimuth, float) - _declination(declination))
