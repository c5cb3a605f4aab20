r"""Named frames and their geometry, in one place.

Layer 3 of the package (beside :mod:`tiltlab.quaternion`): the conventions that several
modules share and that must not be implemented twice.

* **Sensor frame** — the IMU's own axes; tiltlab's quaternions rotate sensor → world
  (world z up), and tilt is the gravity-up direction in the sensor frame.
* **Benhamou body frame** — surge, sway, heave (forward, left, up) in an ENU world
  (Benhamou 2023 [1]_ §1): rotation matrices :func:`R1`, :func:`R2` (clockwise, so that a
  positive elevation is nose up), :func:`R3`; the orientation matrix
  :math:`C = R_3(\theta) R_2(\phi) R_1(\lambda)` (:func:`angles_to_matrix`); the sign
  conventions between tiltlab's specific force and Benhamou's acceleration
  (:func:`to_benhamou_acc`) and between the gyroscope and Benhamou's roll/pitch/yaw speeds
  (:func:`gyro_to_body_rates`); the device → body mounting correction (Eq. 1, App. A:
  :func:`mounting_angles`, :func:`mounting_matrix`, :func:`device_to_body`).
* **Tumble stage** — the two-axis (pitch, roll) stage of Fayat et al. [2]_ App. A.1:
  :func:`stage_angles`, :func:`stage_quaternion`, and the spherical Fibonacci lattice of
  target orientations (:func:`fibonacci_lattice`).
* **Marker head frame** — the head frame defined by three motion-capture markers
  (Fayat §2.6.4, :func:`head_frame_from_markers`).

Inputs are checked (:class:`ValueError` naming the argument): NaN angles and vectors
(missing samples) propagate, but infinite angles, zero vectors where a direction is
needed (``acc_rest``, ``g``), coincident or collinear markers, non-unit quaternions and
matrices that are not rotations (reflections included) are errors.
:func:`wrap_angle`, :func:`angles_from_quaternion` and :func:`angles_from_matrix`
also take labelled DataArrays (e.g. the ``q`` of :func:`tiltlab.filters.estimate`) and
then return DataArrays with their ``time`` coordinate and ``fs``; :mod:`tiltlab.trig`
re-exports them (the same objects).

References
----------
.. [1] S. Benhamou, "Inferring the 3D orientation of a body from its acceleration and
   magnetic field", Movement Ecology (2023).
.. [2] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
.. [3] R. Swinbank and R. J. Purser, "Fibonacci grids: A novel approach to global
   modelling", Q. J. R. Meteorol. Soc. 132:1769–1793, 2006. doi:10.1256/qj.05.235
"""

from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np
import xarray as xr

import tiltlab._validate as _v
import tiltlab.quaternion as _quat

from ._frames_lab import (
    _angle,
    _angle_units,
    _label_as,
    _nonzero,
    _vec3,
    fibonacci_lattice,
    geomagnetic_field,
    head_frame_from_markers,
    stage_angles,
    stage_quaternion,
)

__all__ = [
    "Convention",
    "Orientation",
    "wrap_angle",
    "R1",
    "R2",
    "R3",
    "unit_vector",
    "spherical_coords",
    "to_benhamou_acc",
    "from_benhamou_acc",
    "gyro_to_body_rates",
    "body_rates_to_gyro",
    "angles_to_matrix",
    "angles_from_matrix",
    "angles_to_quaternion",
    "angles_from_quaternion",
    "acc_from_angles",
    "geomagnetic_field",
    "mag_from_angles",
    "mounting_angles",
    "mounting_matrix",
    "device_to_body",
    "device_to_body_eq1",
    "fibonacci_lattice",
    "stage_angles",
    "stage_quaternion",
    "head_frame_from_markers",
]

Convention = Literal["tiltlab", "benhamou"]


class Orientation(NamedTuple):
    """Azimuth θ, elevation φ and bank λ (rad)."""

    azimuth: np.ndarray
    elevation: np.ndarray
    bank: np.ndarray


def _convention(convention) -> str:
    if convention not in ("tiltlab", "benhamou"):
        raise ValueError(
            f"convention must be 'tiltlab' or 'benhamou', got {convention!r}"
        )
    return convention


def _as_benhamou(acc, convention: Convention, name: str = "acc") -> np.ndarray:
    acc = _vec3(acc, name)
    if _convention(convention) == "tiltlab":
        return -acc
    return acc.copy()


def _clip1(x):
    return np.clip(x, -1.0, 1.0)


def _wrap(a: np.ndarray) -> np.ndarray:
    w = np.mod(a + np.pi, 2 * np.pi) - np.pi
    return np.where(w == -np.pi, np.pi, w)


def wrap_angle(angle):
    """Wrap angles (rad) to (−π, π].

    A DataArray gives a DataArray with the same dims, coordinates, attributes and name;
    one in degrees (``attrs["units"] == "deg"``) is wrapped to (−180, 180]. Anything
    else gives an ndarray. NaN (a missing sample) stays NaN.

    Parameters
    ----------
    angle : float, array_like or xarray.DataArray
        Angles in rad, any shape (a DataArray may be in degrees).

    Returns
    -------
    numpy.ndarray or xarray.DataArray
        The equivalent angles in (−π, π] (or (−180°, 180°]), in the input's units and
        shape.

    Raises
    ------
    ValueError
        If ``angle`` is not numeric, holds ±inf, or is a DataArray with units other
        than rad or deg.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import trig
    >>> np.round(trig.wrap_angle([3 * np.pi / 2, -np.pi, 0.5]), 3)
    array([-1.571,  3.142,  0.5  ])
    """
    if not isinstance(angle, xr.DataArray):
        return _wrap(_angle(angle, "angle"))
    v = _angle(angle.values, "angle")
    w = (
        _wrap(v)
        if _angle_units(angle, "angle") == "rad"
        else np.degrees(_wrap(np.radians(v)))
    )
    return angle.copy(data=w)


# ---------------------------------------------------------------------------
# Benhamou's notation and the body frame (§1)
# ---------------------------------------------------------------------------


def _rot(angle, i: int, j: int, sign: float) -> np.ndarray:
    a = _angle(angle, "angle")
    c, s = np.cos(a), np.sin(a)
    m = np.zeros(a.shape + (3, 3))
    k = 3 - i - j
    m[..., k, k] = 1.0
    m[..., i, i] = c
    m[..., j, j] = c
    m[..., i, j] = -sign * s
    m[..., j, i] = sign * s
    return m


def R1(angle) -> np.ndarray:
    r"""Benhamou's rotation about the first axis (X or U), counter-clockwise: shape (..., 3, 3).

    :math:`R_1(\varphi) = \begin{pmatrix}1&0&0\\0&\cos\varphi&-\sin\varphi\\0&\sin\varphi&\cos\varphi\end{pmatrix}`.

    Parameters
    ----------
    angle : array_like, shape (...)
        Rotation angles in rad; finite (NaN propagates).

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Rotation matrices, one per angle.
    """
    return _rot(angle, 1, 2, 1.0)


def R2(angle) -> np.ndarray:
    r"""Benhamou's rotation about the second axis (Y or V), measured *clockwise*: shape (..., 3, 3).

    :math:`R_2(\varphi) = \begin{pmatrix}\cos\varphi&0&-\sin\varphi\\0&1&0\\\sin\varphi&0&\cos\varphi\end{pmatrix}`,
    i.e. the usual right-handed :math:`R_y(-\varphi)`, so that a positive angle raises
    the first axis (positive elevation = nose up).

    Parameters
    ----------
    angle : array_like, shape (...)
        Elevation-like angles in rad (positive raises the first axis), as for :func:`R1`.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Clockwise rotations about the second axis, one per angle.
    """
    return _rot(angle, 0, 2, 1.0)


def R3(angle) -> np.ndarray:
    r"""Benhamou's rotation about the third axis (Z or W), counter-clockwise: shape (..., 3, 3).

    Parameters
    ----------
    angle : array_like, shape (...)
        Azimuth-like angles in rad (counter-clockwise seen from above), as for :func:`R1`.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Counter-clockwise rotations about the third axis, one per angle.
    """
    return _rot(angle, 0, 1, 1.0)


def unit_vector(xi, psi) -> np.ndarray:
    r"""Benhamou's :math:`[\xi\bullet\psi] = (\cos\xi\cos\psi, \sin\xi\cos\psi, \sin\psi)`, shape (..., 3).

    Parameters
    ----------
    xi : array_like
        Azimuth-like angle ξ in rad, measured from the first axis towards the second.
    psi : array_like
        Elevation-like angle ψ in rad, above the plane of the first two axes. ``xi``
        and ``psi`` broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Unit vectors, with the broadcast shape of ``xi`` and ``psi`` plus a last axis.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import trig
    >>> np.round(trig.unit_vector(0.0, np.radians(45)), 3)
    array([0.707, 0.   , 0.707])
    """
    xi, psi = np.broadcast_arrays(_angle(xi, "xi"), _angle(psi, "psi"))
    return np.stack(
        [np.cos(xi) * np.cos(psi), np.sin(xi) * np.cos(psi), np.sin(psi)], axis=-1
    )


def spherical_coords(v) -> tuple[np.ndarray, np.ndarray]:
    r"""Inverse of :func:`unit_vector`: (ξ, ψ) of (not necessarily unit) vectors.

    ψ is computed as :math:`\mathrm{atan2}(v_z, \sqrt{v_x^2+v_y^2})` (accurate near ±π/2);
    ξ = atan2(v_y, v_x) is 0 on the poles (documented fallback).

    Parameters
    ----------
    v : array_like, shape (..., 3)
        Vectors (any length and unit).

    Returns
    -------
    xi : numpy.ndarray, shape (...)
        Azimuth-like angles ξ in rad, in (−π, π].
    psi : numpy.ndarray, shape (...)
        Elevation-like angles ψ in rad, in [−π/2, π/2].
    """
    v = _vec3(v, "v")
    return np.arctan2(v[..., 1], v[..., 0]), np.arctan2(
        v[..., 2], np.hypot(v[..., 0], v[..., 1])
    )


def to_benhamou_acc(acc) -> np.ndarray:
    """Specific force (tiltlab, +1 g on the up axis) → Benhamou's acceleration sign (−g on the up axis).

    Parameters
    ----------
    acc : array_like, shape (..., 3)
        Specific force in tiltlab's sign, in any unit (g or m/s², kept).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        The acceleration in Benhamou's sign (``−acc``), same unit.
    """
    return -_vec3(acc, "acc")


def from_benhamou_acc(acc) -> np.ndarray:
    """Benhamou's acceleration sign (−g on the up axis) → specific force (tiltlab).

    Parameters
    ----------
    acc : array_like, shape (..., 3)
        Acceleration in Benhamou's sign, in any unit (g or m/s², kept).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        The specific force in tiltlab's sign (``−acc``), same unit.
    """
    return -_vec3(acc, "acc")


def gyro_to_body_rates(gyr) -> np.ndarray:
    r"""Tiltlab angular velocity (ω_x, ω_y, ω_z) → Benhamou's (roll, pitch, yaw) speeds (ρ̇, β̇, α̇).

    :math:`\dot\rho=\omega_x`, :math:`\dot\beta=-\omega_y` (positive nose-up),
    :math:`\dot\alpha=\omega_z`. Units are kept (pass rad/s for radians).

    Parameters
    ----------
    gyr : array_like, shape (..., 3)
        Sensor-frame angular velocity (ω_x, ω_y, ω_z), in rad/s or °/s (kept).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Roll, pitch and yaw speeds (ρ̇, β̇, α̇), in the unit of ``gyr``.
    """
    g = _vec3(gyr, "gyr")
    return np.stack([g[..., 0], -g[..., 1], g[..., 2]], axis=-1)


def body_rates_to_gyro(rates) -> np.ndarray:
    """Inverse of :func:`gyro_to_body_rates`: (ρ̇, β̇, α̇) → (ω_x, ω_y, ω_z).

    Parameters
    ----------
    rates : array_like, shape (..., 3)
        Benhamou's roll, pitch and yaw speeds (ρ̇, β̇, α̇), in rad/s or °/s (kept).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Sensor-frame angular velocity (ω_x, ω_y, ω_z), in the unit of ``rates``.
    """
    return gyro_to_body_rates(rates)


def angles_to_matrix(azimuth, elevation, bank) -> np.ndarray:
    r"""Body→world (ENU) rotation matrices :math:`C = R_3(\theta)R_2(\phi)R_1(\lambda)`, shape (..., 3, 3).

    Column k is body axis k (surge, sway, heave) in world coordinates; column 0 is
    :math:`[\theta\bullet\phi]`.

    Parameters
    ----------
    azimuth : array_like
        Azimuth θ in rad (heading of the surge axis, counter-clockwise from East).
    elevation : array_like
        Elevation φ in rad (positive nose up).
    bank : array_like
        Bank λ in rad (roll about the surge axis). The three angles broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Body → world (ENU) rotation matrices ``C``.
    """
    return R3(azimuth) @ R2(elevation) @ R1(bank)


def _orientation(C: np.ndarray, singular_tol: float) -> Orientation:
    """Azimuth, elevation and bank of checked rotation matrices ``C`` (..., 3, 3)."""
    h = np.hypot(C[..., 0, 0], C[..., 1, 0])
    el = np.arctan2(C[..., 2, 0], h)
    az = np.arctan2(C[..., 1, 0], C[..., 0, 0])
    bk = np.arctan2(C[..., 2, 1], C[..., 2, 2])
    with np.errstate(invalid="ignore"):  # NaN matrices (missing samples)
        sing = h < singular_tol
    az = np.where(sing, _wrap(np.arctan2(C[..., 1, 1], C[..., 0, 1]) - np.pi / 2), az)
    return Orientation(az, el, np.where(sing, 0.0, bk))


def _labelled_orientation(o: Orientation, da, drop) -> Orientation:
    """``o`` as DataArrays labelled like ``da`` without its ``drop`` dimensions."""
    if da is None:
        return o
    tmpl = da.isel({d: 0 for d in drop}, drop=True)
    return Orientation(
        *(_label_as(v, tmpl, n, "rad") for v, n in zip(o, o._fields, strict=True))
    )


def angles_from_matrix(matrix, singular_tol: float = 1e-9) -> Orientation:
    r"""Compute azimuth, elevation and bank (rad) from body→world rotation matrices.

    :math:`\theta=\mathrm{atan2}(C_{10},C_{00})`, :math:`\phi=\mathrm{atan2}(C_{20},\sqrt{C_{00}^2+C_{10}^2})`,
    :math:`\lambda=\mathrm{atan2}(C_{21},C_{22})`.

    Singular configuration (surge vertical, :math:`\cos\phi <` ``singular_tol``):
    θ and λ are then not separately defined; following Benhamou (§3, App. B) the
    pseudo-bank is λ = 0 and the pseudo-azimuth θ = θ' − π/2 with θ' the azimuth of
    the sway axis, which represents the same rotation exactly.

    ``matrix`` must hold proper rotations: reflections (det −1), non-orthonormal
    matrices and ±inf are errors naming it; NaN matrices (missing samples) give NaN. A
    DataArray whose last two dims are the 3 × 3 matrix gives DataArrays with its other
    coordinates (``time``) and ``fs``.

    Parameters
    ----------
    matrix : array_like, shape (..., 3, 3), or xarray.DataArray
        Body → world rotation matrices (orthonormal within 1e-6, determinant +1).
    singular_tol : float, optional
        Threshold (≥ 0) on cos φ below which the configuration is treated as singular
        (default 1e-9).

    Returns
    -------
    Orientation
        Named tuple ``(azimuth, elevation, bank)`` of arrays of shape (...), in rad:
        azimuth θ and bank λ in (−π, π], elevation φ in [−π/2, π/2]; DataArrays for
        DataArray input.

    Raises
    ------
    ValueError
        If ``matrix`` has a wrong shape, is not numeric, holds ±inf or is not a proper
        rotation, or ``singular_tol`` is negative or NaN.
    """
    singular_tol = _v.nonnegative(singular_tol, "singular_tol")
    da = None
    if isinstance(matrix, xr.DataArray):
        if matrix.ndim < 2:
            raise ValueError(
                f"matrix must have shape (..., 3, 3), got dims {matrix.dims}"
            )
        da = matrix.transpose("time", ...) if "time" in matrix.dims else matrix
        matrix = da.values
    C = _v.vectors(matrix, "matrix", width=None, ndim=None, allow_nan=True)
    if C.ndim < 2 or C.shape[-2:] != (3, 3):
        raise ValueError(f"matrix must have shape (..., 3, 3), got {C.shape}")
    _quat.check_rotation(C, "matrix")
    return _labelled_orientation(
        _orientation(C, singular_tol), da, () if da is None else da.dims[-2:]
    )


def angles_to_quaternion(azimuth, elevation, bank) -> np.ndarray:
    r"""Sensor(body)→world quaternions (w, x, y, z) of :math:`R_3(\theta)R_2(\phi)R_1(\lambda)`, w ≥ 0.

    Closed form :math:`q = q_z(\theta)\otimes q_y(-\phi)\otimes q_x(\lambda)`.

    Parameters
    ----------
    azimuth, elevation, bank : array_like
        Azimuth θ, elevation φ and bank λ in rad, as for :func:`angles_to_matrix`;
        they broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions (w, x, y, z), w ≥ 0, rotating body (sensor) to world.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import trig
    >>> np.round(trig.angles_to_quaternion(np.pi / 2, 0.0, 0.0), 3)  # facing North
    array([0.707, 0.   , 0.   , 0.707])
    >>> np.round(trig.angles_to_quaternion(0.0, np.radians(30), 0.0), 3)  # nose up
    array([ 0.966,  0.   , -0.259,  0.   ])
    """
    t, p, lam = np.broadcast_arrays(
        *(
            _angle(a, n) / 2
            for a, n in ((azimuth, "azimuth"), (elevation, "elevation"), (bank, "bank"))
        )
    )
    ct, st = np.cos(t), np.sin(t)
    cp, sp = np.cos(p), -np.sin(p)  # rotation by -phi about y
    cl, sl = np.cos(lam), np.sin(lam)
    w = ct * cp * cl + st * sp * sl
    x = ct * cp * sl - st * sp * cl
    y = ct * sp * cl + st * cp * sl
    z = st * cp * cl - ct * sp * sl
    q = np.stack([w, x, y, z], axis=-1)
    return np.where(q[..., :1] < 0, -q, q)


def angles_from_quaternion(q, singular_tol: float = 1e-9) -> Orientation:
    """Compute azimuth, elevation and bank (rad) of sensor(body)→world quaternions.

    See :func:`angles_from_matrix` for the formulas and the singular (surge vertical)
    fallback. A DataArray with a ``quat`` dimension (e.g. the output of
    :func:`tiltlab.filters.estimate`) gives DataArrays with its ``time`` coordinate and
    ``fs``. Non-unit quaternions are refused (normalise them first with
    :func:`tiltlab.quaternion.normalize`); NaN rows (missing samples) give NaN angles.

    Parameters
    ----------
    q : array_like, shape (..., 4), or xarray.DataArray
        Unit body (sensor) → world quaternions (w, x, y, z), norm 1 within 1e-6; a
        DataArray has a ``quat`` dimension (else its last dimension holds the
        components).
    singular_tol : float, optional
        Threshold (≥ 0) on cos φ below which the configuration is treated as singular
        (default 1e-9); see :func:`angles_from_matrix`.

    Returns
    -------
    Orientation
        The angles of each quaternion, as :func:`angles_from_matrix` returns them.

    Raises
    ------
    ValueError
        If ``q`` has a wrong shape, holds ±inf or quaternions whose norm is not 1
        (zero ones included), or ``singular_tol`` is negative or NaN.
    """
    singular_tol = _v.nonnegative(singular_tol, "singular_tol")
    da, qd = None, ()
    if isinstance(q, xr.DataArray):
        qd = ("quat" if "quat" in q.dims else q.dims[-1],)
        da = q.transpose(..., *qd)
        da = da.transpose("time", ...) if "time" in da.dims else da
        q = da.values
    qv = _v.vectors(q, "q", width=4, ndim=None, allow_nan=True)
    _quat.check_unit(qv, "q")
    qv = qv / np.linalg.norm(qv, axis=-1, keepdims=True)  # exact within the tolerance
    return _labelled_orientation(
        _orientation(_quat.to_matrix(qv), singular_tol), da, qd
    )


def acc_from_angles(
    elevation, bank, g: float = 1.0, convention: Convention = "tiltlab"
) -> np.ndarray:
    r"""Compute the static accelerometer reading of a body at rest with elevation φ and bank λ.

    Specific force (``"tiltlab"``): :math:`g\,C^\top e_z = g(\sin\phi, \cos\phi\sin\lambda, \cos\phi\cos\lambda)`;
    ``"benhamou"`` returns its negative.

    Parameters
    ----------
    elevation : array_like
        Elevation φ in rad (positive nose up).
    bank : array_like
        Bank λ in rad. ``elevation`` and ``bank`` broadcast.
    g : float, optional
        Magnitude of gravity (> 0) in the output unit: 1.0 (default) gives g units,
        9.81 gives m/s².
    convention : {"tiltlab", "benhamou"}, optional
        Sign of the output: specific force (``"tiltlab"``, default, +g on the up axis)
        or Benhamou's acceleration (−g on the up axis).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Accelerometer readings in body axes, in the unit of ``g``.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import trig
    >>> np.round(trig.acc_from_angles(np.radians(30), 0.0), 3)  # nose 30° up
    array([0.5  , 0.   , 0.866])
    >>> np.round(trig.acc_from_angles(0.0, np.radians(90), g=9.81), 3)  # on its side
    array([0.  , 9.81, 0.  ])
    """
    g = _v.positive(g, "g")
    convention = _convention(convention)
    p, lam = np.broadcast_arrays(_angle(elevation, "elevation"), _angle(bank, "bank"))
    f = g * np.stack(
        [np.sin(p), np.cos(p) * np.sin(lam), np.cos(p) * np.cos(lam)], axis=-1
    )
    return f if convention == "tiltlab" else _as_benhamou(f, "tiltlab")


def mag_from_angles(azimuth, elevation, bank, field=None) -> np.ndarray:
    """Magnetometer reading (field in body axes, :math:`C^T m_{ENU}`) for orientations θ, φ, λ, shape (..., 3).

    Parameters
    ----------
    azimuth, elevation, bank : array_like
        Azimuth θ, elevation φ and bank λ in rad, as for :func:`angles_to_matrix`;
        they broadcast.
    field : array_like, shape (3,), optional
        Earth magnetic field in ENU world coordinates, any unit (kept); the default,
        ``None``, is ``geomagnetic_field()`` (48 µT, dip 64°).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        The field in body axes, in the unit of ``field``.
    """
    m = geomagnetic_field() if field is None else _vec3(field, "field")
    C = angles_to_matrix(azimuth, elevation, bank)
    return np.einsum("...ji,j->...i", C, m)


# ---------------------------------------------------------------------------
# device -> body (Eq. 1, App. A)
# ---------------------------------------------------------------------------


def mounting_angles(
    acc_rest, convention: Convention = "tiltlab"
) -> tuple[np.ndarray, np.ndarray]:
    r"""Device mounting angles φ*, λ* from the acceleration recorded with the animal at rest and level.

    :math:`\phi^*=\sin^{-1}(-a^*_U/\|\mathbf a^*\|)`, :math:`\lambda^*=\mathrm{atan2}(-a^*_V,-a^*_W)` (§1),
    with Benhamou's sign (converted from ``convention``). ``acc_rest`` may be a
    single vector or many (then average them first for a single mounting).

    Parameters
    ----------
    acc_rest : array_like, shape (3,) or (..., 3)
        Device-frame acceleration recorded with the animal at rest and level, in any
        unit (g or m/s²); non-zero.
    convention : {"tiltlab", "benhamou"}, optional
        Sign convention of ``acc_rest``: specific force (``"tiltlab"``, default) or
        Benhamou's acceleration.

    Returns
    -------
    phi_star : numpy.ndarray, shape (...)
        Mounting elevation φ* in rad, in [−π/2, π/2].
    lambda_star : numpy.ndarray, shape (...)
        Mounting bank λ* in rad, in (−π, π].
    """
    a = _as_benhamou(acc_rest, convention, "acc_rest")
    return _elev_bank(_nonzero(a, "acc_rest"))


def _elev_bank(A):
    el = np.arctan2(-A[..., 0], np.hypot(A[..., 1], A[..., 2]))
    bk = np.arctan2(-A[..., 1], -A[..., 2])
    return el, bk


def mounting_matrix(phi_star, lambda_star, dtheta=0.0) -> np.ndarray:
    r"""Device→body matrix :math:`R_3(\Delta\theta)R_2(\phi^*)R_1(\lambda^*)` (App. A; Δθ = 0 gives Eq. 1).

    Parameters
    ----------
    phi_star : array_like
        Mounting elevation φ* in rad.
    lambda_star : array_like
        Mounting bank λ* in rad.
    dtheta : array_like, optional
        Mounting azimuth offset Δθ in rad (default 0, Eq. 1). The angles broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Device → body rotation matrices.
    """
    return R3(dtheta) @ R2(phi_star) @ R1(lambda_star)


def device_to_body(
    vectors, phi_star, lambda_star, dtheta=0.0, rates: bool = False
) -> np.ndarray:
    r"""Express device-frame vectors in the body frame: :math:`\mathbf B^\top = R_3(\Delta\theta)R_2(\phi^*)R_1(\lambda^*)\mathbf D^\top`.

    Applies to (static) acceleration in either sign convention, calibrated magnetic
    field, and tiltlab gyroscope vectors ω, which are ordinary vectors. If
    ``rates=True`` the columns are Benhamou's (ρ̇, β̇, α̇); the pitch-rate sign is
    flipped before and after the rotation (App. A: :math:`B_V=-\dot\beta`, :math:`D_V=-\dot\beta^d`).

    Parameters
    ----------
    vectors : array_like, shape (..., 3)
        Vectors in device coordinates, in any unit (kept).
    phi_star : array_like
        Mounting elevation φ* in rad (see :func:`mounting_angles`).
    lambda_star : array_like
        Mounting bank λ* in rad.
    dtheta : array_like, optional
        Mounting azimuth offset Δθ in rad (default 0).
    rates : bool, optional
        If True, ``vectors`` are Benhamou's (ρ̇, β̇, α̇) rates rather than ordinary
        vectors (default False).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        The vectors in body coordinates (surge, sway, heave), in the unit of
        ``vectors``.
    """
    D = _vec3(vectors, "vectors")
    if rates:
        D = gyro_to_body_rates(D)
    M = mounting_matrix(phi_star, lambda_star, dtheta)
    B = np.einsum("...ij,...j->...i", M, D)
    return gyro_to_body_rates(B) if rates else B


def device_to_body_eq1(
    vectors, acc_rest, convention: Convention = "tiltlab"
) -> np.ndarray:
    r"""Eq. 1a–1c: explicit (matrix-free) device→body correction from the level-rest acceleration a*.

    .. math::
        B_U &= \big(D_U\,s - a^*_U (D_V a^*_V + D_W a^*_W)/s\big)/\|\mathbf a^*\|,\quad s=(a^{*2}_V+a^{*2}_W)^{1/2}\\
        B_V &= (D_W a^*_V - D_V a^*_W)/s\\
        B_W &= -(D_U a^*_U + D_V a^*_V + D_W a^*_W)/\|\mathbf a^*\|

    with a* in Benhamou's sign (converted from ``convention``). Identical to
    :func:`device_to_body` with :func:`mounting_angles`. Requires s > 0 (device not
    mounted vertically).

    Parameters
    ----------
    vectors : array_like, shape (..., 3)
        Vectors D in device coordinates, in any unit (kept).
    acc_rest : array_like, shape (3,) or (..., 3)
        Device-frame acceleration a* recorded at rest and level, in any unit, with a
        non-zero sway/heave part; broadcasts with ``vectors``.
    convention : {"tiltlab", "benhamou"}, optional
        Sign convention of ``acc_rest``: specific force (``"tiltlab"``, default) or
        Benhamou's acceleration.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        The vectors B in body coordinates (surge, sway, heave), in the unit of
        ``vectors``.
    """
    D = _vec3(vectors, "vectors")
    a = _as_benhamou(acc_rest, convention, "acc_rest")
    aU, aV, aW = a[..., 0], a[..., 1], a[..., 2]
    s = np.hypot(aV, aW)
    if np.any(s == 0):
        raise ValueError(
            "acc_rest has no sway/heave component: the mounting bank angle is undefined"
        )
    n = np.sqrt(aU**2 + s**2)
    DU, DV, DW = D[..., 0], D[..., 1], D[..., 2]
    BU = (DU * s - aU * (DV * aV + DW * aW) / s) / n
    BV = (DW * aV - DV * aW) / s
    BW = -(DU * aU + DV * aV + DW * aW) / n
    return np.stack(np.broadcast_arrays(BU, BV, BW), axis=-1)
