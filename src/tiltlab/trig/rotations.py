r"""Body rotations from the gyroscope and their relation to changes of orientation.

Benhamou 2023 §4, §6, Eqs. 10–13; App. B head relative to body; App. C cap passage.

:func:`body_rotations` takes per-sample angular velocity: a Recording (variable
``gyr``), a labelled DataArray or a plain array with ``fs`` and ``units``; units are
read from the attributes and converted to rad/s. The other functions take angles
(radians).
"""

from __future__ import annotations

from typing import Literal

import numpy as np

import tiltlab._validate as _v
from ..dsp import window_samples
from ..frames import (
    R1,
    R2,
    R3,
    Orientation,
    _clip1,
    angles_to_matrix,
    spherical_coords,
    unit_vector,
    wrap_angle,
)
from ._common import angle_function, read_input, windowed
from ._types import Rotations
from .arcs import arc, interpolate_heading

__all__ = [
    "body_rotations",
    "sequential_yaw_pitch",
    "sequential_arc_from_yaw_pitch",
    "heading_in_body_frame",
    "simultaneous_rotations",
    "rotations_from_orientations",
    "arc_from_rotations",
    "azimuth_change",
    "sub_arc_rotations",
    "compose_sub_arcs",
    "exact_step",
    "step_body_rates",
    "head_relative_to_body",
    "cap_passage",
]


def body_rotations(
    gyr, fs=None, *, window_s: float, units: str | None = None
) -> Rotations:
    r"""Compute yaw, pitch and roll per Δt step (§4).

    :math:`\alpha_i=\sum_j\dot\alpha_{i,j}/f` etc. over k = round(fΔt) samples.

    With (ρ̇, β̇, α̇) = (ω_x, −ω_y, ω_z) from tiltlab's body-frame angular velocity ω.
    Non-overlapping blocks; a trailing incomplete block is dropped.

    Parameters
    ----------
    gyr : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        Body-frame angular velocity: a Recording (its ``gyr``), a labelled DataArray, or
        a plain array with ``fs`` and ``units``.
    fs : float, optional
        Sampling rate (Hz); read from the attributes of labelled input.
    window_s : float
        Step duration Δt (s).
    units : str, optional
        Units of a plain ``gyr`` ('deg/s' or 'rad/s'); read from the attributes of
        labelled input.

    Returns
    -------
    Rotations
        Radians per step; for labelled input, DataArrays over the step-centre times
        with ``fs`` = steps per second.
    """
    s = read_input(
        gyr, "gyr", fs=fs, units=units, to_units="rad/s", need_fs=True, ndim=2
    )
    k = window_samples(window_s, s.fs)
    g = s.values
    nb = g.shape[0] // k
    r = g[: nb * k].reshape(nb, k, 3).sum(axis=1) / s.fs
    centre = (np.arange(nb) * k + k / 2) / s.fs
    out = [r[:, 2], -r[:, 1], r[:, 0]]
    return Rotations(
        *(
            windowed(x, s, name, centre_s=centre, fs_out=s.fs / k, units="rad")
            for x, name in zip(out, Rotations._fields, strict=True)
        )
    )


@angle_function(("yaw", "pitch"))
def sequential_yaw_pitch(size, eta) -> tuple[np.ndarray, np.ndarray]:
    r"""Eq. 10: yaw then pitch decomposition of an arc of size ω at constant body-relative inclination η.

    :math:`\alpha=\mathrm{atan2}(\cos\eta, \cot\omega)` (evaluated as
    atan2(cos η sin ω, cos ω)) and :math:`\beta=\sin^{-1}(\sin\eta\sin\omega)`, i.e.
    :math:`[\alpha\bullet\beta]^\top=R_1(\eta)[\omega\bullet0]^\top`. Accurate for the
    simultaneous rotations only for small ω (see :func:`simultaneous_rotations`).

    Parameters
    ----------
    size : float or array_like
        Arc size ω (rad).
    eta : float or array_like
        Body-relative inclination η of the arc (rad); broadcasts with ``size``.

    Returns
    -------
    yaw : ndarray
        Yaw α (rad), rotation about the heave axis applied first.
    pitch : ndarray
        Pitch β (rad), rotation about the sway axis applied second.
    """
    w, e = np.broadcast_arrays(np.asarray(size, float), np.asarray(eta, float))
    return np.arctan2(np.cos(e) * np.sin(w), np.cos(w)), np.arcsin(
        _clip1(np.sin(e) * np.sin(w))
    )


@angle_function(("size", "eta"))
def sequential_arc_from_yaw_pitch(yaw, pitch) -> tuple[np.ndarray, np.ndarray]:
    r"""Inverse of Eq. 10: arc size ω and body-relative inclination η of sequential yaw α then pitch β.

    From :math:`[\alpha\bullet\beta]=(\cos\omega, \sin\omega\cos\eta, \sin\omega\sin\eta)`:
    :math:`\omega=\mathrm{atan2}\big((\sin^2\alpha\cos^2\beta+\sin^2\beta)^{1/2}, \cos\alpha\cos\beta\big)`,
    :math:`\eta=\mathrm{atan2}(\sin\beta, \sin\alpha\cos\beta)` (0 when ω = 0). Returns (ω, η).

    Parameters
    ----------
    yaw : float or array_like
        Yaw α (rad), applied first.
    pitch : float or array_like
        Pitch β (rad), applied second; broadcasts with ``yaw``.

    Returns
    -------
    size : ndarray
        Arc size ω (rad), in [0, π].
    eta : ndarray
        Body-relative inclination η (rad), in (−π, π].
    """
    v = unit_vector(yaw, pitch)
    return np.arctan2(np.hypot(v[..., 1], v[..., 2]), v[..., 0]), np.arctan2(
        v[..., 2], v[..., 1]
    )


@angle_function(("yaw", "pitch"))
def heading_in_body_frame(az0, el0, bank0, az1, el1) -> tuple[np.ndarray, np.ndarray]:
    r"""§6: heading at step i in the body frame of step i−1: :math:`[\alpha\bullet\beta]^\top=R_1(-\lambda_0)R_2(-\phi_0)R_3(-\theta_0)[\theta_1\bullet\phi_1]^\top`.

    Returns (α, β) of the sequential decomposition; equals Eq. 10 with η = δ^i − λ0.

    Parameters
    ----------
    az0, el0, bank0 : float or array_like
        Azimuth θ0, elevation φ0 and bank λ0 (rad) of the orientation at step i−1.
    az1, el1 : float or array_like
        Azimuth θ1 and elevation φ1 (rad) of the heading at step i.

    Returns
    -------
    yaw : ndarray
        Azimuth α (rad) of the new heading in the previous body frame.
    pitch : ndarray
        Elevation β (rad) of the new heading in the previous body frame.
    """
    C0 = angles_to_matrix(az0, el0, bank0)
    v = np.einsum("...ji,...j->...i", C0, unit_vector(az1, el1))
    return spherical_coords(v)


@angle_function(())
def simultaneous_rotations(size, eta_initial, eta_final) -> Rotations:
    r"""Eq. 11 (corrected): yaw, pitch and roll of simultaneous rotations producing an arc of size ω.

    .. math::
        \rho &= \eta^i - \eta^f \ (\text{wrapped to } (-\pi,\pi])\\
        \alpha &= (\sin\eta^i - \sin\eta^f)\,\omega/\rho = 2\cos\bar\eta\,\sin(\rho/2)\,\omega/\rho\\
        \beta &= (\cos\eta^f - \cos\eta^i)\,\omega/\rho = 2\sin\bar\eta\,\sin(\rho/2)\,\omega/\rho,\qquad \bar\eta=\eta^i-\rho/2

    The seed text prints "sin(η^i) − sin(η^i)" and "ρ = η^f − η^f" (typos). The
    second (half-angle) forms are used; :math:`2\sin(\rho/2)/\rho` is evaluated as a
    sinc so ρ = 0 (no roll: α = ω cos η, β = ω sin η) is handled without NaN.
    These are the exact integrals of the gyroscope for the constant-rate model of
    :func:`exact_step`.

    Parameters
    ----------
    size : float or array_like
        Arc size ω (rad).
    eta_initial : float or array_like
        Initial body-relative inclination η^i = δ^i − λ0 (rad).
    eta_final : float or array_like
        Final body-relative inclination η^f = δ^f − λ1 (rad).

    Returns
    -------
    Rotations
        Yaw α, pitch β and roll ρ (rad) integrated over the step.
    """
    w, ei, ef = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (size, eta_initial, eta_final))
    )
    rho = wrap_angle(ei - ef)
    eb = ei - rho / 2
    f = np.sinc(rho / (2 * np.pi)) * w
    return Rotations(np.cos(eb) * f, np.sin(eb) * f, rho)


@angle_function(())
def rotations_from_orientations(
    az0,
    el0,
    bank0,
    az1,
    el1,
    bank1,
    *,
    method: Literal["simultaneous", "sequential"] = "simultaneous",
) -> Rotations:
    """Yaw, pitch, roll between two orientations: Eq. 11 (``"simultaneous"``) or Eq. 10 (``"sequential"``, roll = η^i − η^f).

    Parameters
    ----------
    az0, el0, bank0, az1, el1, bank1 : float or array_like
        Azimuth, elevation and bank (rad) at the start (0) and the end (1) of the step;
        they broadcast.
    method : {"simultaneous", "sequential"}
        Eq. 11 simultaneous rotations (default) or Eq. 10 yaw-then-pitch decomposition.

    Returns
    -------
    Rotations
        Yaw α, pitch β and roll ρ (rad); roll wrapped to (−π, π].

    Raises
    ------
    ValueError
        If ``method`` is not one of the two choices.
    """
    a = arc(az0, el0, az1, el1)
    ei = a.initial - np.asarray(bank0, float)
    ef = a.final - np.asarray(bank1, float)
    if method == "simultaneous":
        return simultaneous_rotations(a.size, ei, ef)
    if method == "sequential":
        al, be = sequential_yaw_pitch(a.size, ei)
        return Rotations(al, be, wrap_angle(ei - ef))
    raise ValueError(f"method must be 'simultaneous' or 'sequential', got {method!r}")


@angle_function(("size", "eta"))
def arc_from_rotations(yaw, pitch, roll) -> tuple[np.ndarray, np.ndarray]:
    r"""Eq. 12: arc size and mean body-relative inclination from gyroscope rotations.

    :math:`\omega=\tfrac12\rho(\alpha^2+\beta^2)^{1/2}/\sin(\rho/2)` (sinc form, finite at
    ρ = 0) and :math:`\bar\eta=\mathrm{atan2}(\beta,\alpha)` (0 when ω = 0, where it
    is undefined). Valid for |ρ| ≤ π. Returns (ω, η̄).

    Parameters
    ----------
    yaw : float or array_like
        Yaw α (rad) summed over the step (rotation about the heave axis).
    pitch : float or array_like
        Pitch β (rad) summed over the step (rotation about the sway axis).
    roll : float or array_like
        Roll ρ (rad) summed over the step (rotation about the surge axis).

    Returns
    -------
    size : ndarray
        Arc size ω (rad).
    eta : ndarray
        Mean body-relative inclination η̄ (rad).
    """
    al, be, ro = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (yaw, pitch, roll))
    )
    return np.hypot(al, be) / np.sinc(ro / (2 * np.pi)), np.arctan2(be, al)


@angle_function("azimuth_change")
def azimuth_change(el0, bank0, el1, bank1, yaw, pitch, roll) -> np.ndarray:
    r"""Eq. 13: change of azimuth over a step from postures and gyroscope rotations.

    .. math::
        \Delta\theta=\mathrm{atan2}\big(\sin\omega(\cos\phi_0\cos\delta^i+\cos\phi_1\cos\delta^f)/2,\;\cos\omega-\sin\phi_0\sin\phi_1\big)

    with :math:`\delta^i=\lambda_0+\bar\eta+\rho/2`, :math:`\delta^f=\lambda_1+\bar\eta-\rho/2` and ω, η̄
    from Eq. 12.

    Parameters
    ----------
    el0, bank0 : float or array_like
        Elevation φ0 and bank λ0 (rad) at the start of the step.
    el1, bank1 : float or array_like
        Elevation φ1 and bank λ1 (rad) at the end of the step.
    yaw, pitch, roll : float or array_like
        Gyroscope rotations α, β, ρ (rad) over the step (:func:`body_rotations`).

    Returns
    -------
    ndarray
        Change of azimuth Δθ (rad) over the step, in (−π, π].
    """
    w, eb = arc_from_rotations(yaw, pitch, roll)
    ro = np.asarray(roll, float)
    el0, el1 = np.asarray(el0, float), np.asarray(el1, float)
    di = np.asarray(bank0, float) + eb + ro / 2
    df = np.asarray(bank1, float) + eb - ro / 2
    return np.arctan2(
        np.sin(w) * (np.cos(el0) * np.cos(di) + np.cos(el1) * np.cos(df)) / 2,
        np.cos(w) - np.sin(el0) * np.sin(el1),
    )


def sub_arc_rotations(
    size: float, eta_initial: float, roll: float, k: int
) -> tuple[np.ndarray, np.ndarray]:
    r"""§6 k-sub-arc construction: per-block yaw and pitch (α_{i,j}, β_{i,j}), j = 1..k.

    :math:`\alpha_{i,j}=\tan^{-1}(\cos\tilde\eta(q)\tan(\omega/k))`,
    :math:`\beta_{i,j}=\sin^{-1}(\sin\tilde\eta(q)\sin(\omega/k))`, :math:`\tilde\eta(q)=\eta^i-q\rho`, q = j/k
    (as printed). Each block also rolls by ρ/k. Their sums converge to Eq. 11 as k → ∞.

    Parameters
    ----------
    size : float
        Arc size ω (rad).
    eta_initial : float
        Initial body-relative inclination η^i (rad).
    roll : float
        Total roll ρ (rad) over the step.
    k : int
        Number of sub-arcs (blocks), ≥ 1.

    Returns
    -------
    yaw : ndarray, shape (k,)
        Per-block yaw α_{i,j} (rad).
    pitch : ndarray, shape (k,)
        Per-block pitch β_{i,j} (rad).
    """
    k = _v.integer(k, "k", minimum=1)
    q = np.arange(1, k + 1) / k
    e = eta_initial - q * roll
    s = size / k
    return np.arctan2(np.cos(e) * np.sin(s), np.cos(s)), np.arcsin(
        _clip1(np.sin(e) * np.sin(s))
    )


def compose_sub_arcs(
    az0: float,
    el0: float,
    bank0: float,
    size: float,
    eta_initial: float,
    roll: float,
    k: int,
) -> np.ndarray:
    r"""Compute the final body→world matrix after k blocks of sub-arc rotations.

    Each block is a roll ρ/k about surge, a yaw α_{i,j} about heave and a pitch
    β_{i,j} about sway.

    Rotations are intrinsic (body axes): :math:`C \leftarrow C\,R_1(\rho/k)\,R_3(\alpha_{i,j})\,R_2(\beta_{i,j})`
    (Benhamou's :math:`R_2` makes a positive pitch raise the nose).

    Parameters
    ----------
    az0, el0, bank0 : float
        Azimuth, elevation and bank (rad) at the start of the step.
    size, eta_initial, roll, k
        The step and its number of sub-arcs, as for :func:`sub_arc_rotations`.

    Returns
    -------
    ndarray, shape (3, 3)
        Body→world rotation matrix at the end of the step.
    """
    k = _v.integer(k, "k", minimum=1)
    al, be = sub_arc_rotations(size, eta_initial, roll, k)
    C = angles_to_matrix(az0, el0, bank0)
    r = R1(roll / k)
    for a, b in zip(R3(al), R2(be), strict=True):
        C = C @ r @ a @ b
    return C


def _axis_angle_matrix(axis, angle):
    axis = np.asarray(axis, float)
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    K = np.zeros(axis.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = (
        -axis[..., 2],
        axis[..., 1],
        -axis[..., 0],
    )
    K = K - np.swapaxes(K, -1, -2)
    a = np.asarray(angle, float)[..., None, None]
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * (K @ K)


def exact_step(az0, el0, bank0, initial_inclination, size, roll) -> np.ndarray:
    r"""Exact end orientation of the §6 constant-rate step (reference for Eqs. 8, 11–13).

    The surge axis moves at constant speed along the great circle leaving heading
    (θ0, φ0) with inclination δ^i over an arc ω, while the body rolls at constant
    speed by ρ about the surge axis: :math:`C_1 = \mathrm{Rot}(\mathbf n,\omega)\,C_0\,R_1(\rho)`
    with n the unit normal of the reorientation plane. Returns (..., 3, 3).

    Parameters
    ----------
    az0, el0, bank0 : float or array_like
        Azimuth θ0, elevation φ0 and bank λ0 (rad) at the start of the step.
    initial_inclination : float or array_like
        Initial inclination δ^i (rad) of the arc in the frontal plane.
    size : float or array_like
        Arc size ω (rad).
    roll : float or array_like
        Roll ρ (rad) about the surge axis over the step.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Body→world rotation matrix C1 at the end of the step.
    """
    C0 = angles_to_matrix(az0, el0, bank0)
    d = np.asarray(initial_inclination, float)
    # normal in world = C0 * (0, -sin eta, cos eta) with eta = delta - bank0
    eta = d - np.asarray(bank0, float)
    nb = np.stack(
        np.broadcast_arrays(np.zeros_like(eta), -np.sin(eta), np.cos(eta)), axis=-1
    )
    n = np.einsum("...ij,...j->...i", C0, nb)
    return _axis_angle_matrix(n, size) @ C0 @ R1(roll)


def step_body_rates(
    size: float, eta_initial: float, roll: float, duration_s: float, n: int
) -> np.ndarray:
    r"""Body-frame angular velocity (tiltlab ω, rad/s) of :func:`exact_step`, sampled at n midpoints, shape (n, 3).

    :math:`\omega_x=\rho/\Delta t`, :math:`-\omega_y=\dot\beta=\sin\tilde\eta(t)\,\omega/\Delta t`,
    :math:`\omega_z=\dot\alpha=\cos\tilde\eta(t)\,\omega/\Delta t`, :math:`\tilde\eta(t)=\eta^i-\rho t/\Delta t`.
    Feeding it to :func:`tiltlab.quaternion.integrate_gyro` reproduces the step (to the
    zero-order-hold error of the integrator).

    Parameters
    ----------
    size, eta_initial, roll : float
        Arc size ω, initial body-relative inclination η^i and total roll ρ (rad) of
        the step (see :func:`exact_step`).
    duration_s : float
        Step duration Δt (s), > 0.
    n : int
        Number of samples (midpoints), ≥ 1.

    Returns
    -------
    ndarray, shape (n, 3)
        Body-frame angular velocity (ω_x, ω_y, ω_z) in rad/s.
    """
    n = _v.integer(n, "n", minimum=1)
    duration_s = _v.positive(duration_s, "duration_s")
    q = (np.arange(n) + 0.5) / n
    e = eta_initial - q * roll
    r = size / duration_s
    return np.column_stack(
        [np.full(n, roll / duration_s), -np.sin(e) * r, np.cos(e) * r]
    )


@angle_function(())
def head_relative_to_body(
    az_b, el_b, bank_b, az_h, el_h, bank_h, *, singular_tol: float = 1e-9
) -> Orientation:
    r"""App. B: orientation of the head expressed in the body frame, from two absolute orientations.

    :math:`\mathbf x_{h/b}^\top = R_1(-\lambda_b)R_2(-\phi_b)R_3(-\theta_b)\mathbf x_h^\top` for the head
    surge :math:`\mathbf x_h=[\theta_h\bullet\phi_h]` and sway :math:`\mathbf x'_h`; then
    :math:`\theta_{h/b}=\mathrm{atan2}(y,x)`, :math:`\phi_{h/b}=\sin^{-1}z`,
    :math:`\lambda_{h/b}=\mathrm{atan2}(z', z'')` with :math:`z''=xy'-yx'`. Singular
    case (head surge orthogonal to the body coronal plane): θ = θ' − π/2, φ = sgn(z)π/2, λ = 0.

    Parameters
    ----------
    az_b, el_b, bank_b : float or array_like
        Azimuth, elevation and bank (rad) of the body.
    az_h, el_h, bank_h : float or array_like
        Azimuth, elevation and bank (rad) of the head.
    singular_tol : float
        Threshold (> 0) on the horizontal norm of the head surge axis in the body frame
        below which the singular fallback is used.

    Returns
    -------
    Orientation
        Azimuth, elevation and bank (rad) of the head in the body frame.
    """
    singular_tol = _v.positive(singular_tol, "singular_tol")
    Cb = angles_to_matrix(az_b, el_b, bank_b)
    Ch = angles_to_matrix(az_h, el_h, bank_h)
    x = np.einsum("...ji,...j->...i", Cb, Ch[..., :, 0])
    xp = np.einsum("...ji,...j->...i", Cb, Ch[..., :, 1])
    zpp = x[..., 0] * xp[..., 1] - x[..., 1] * xp[..., 0]
    h = np.hypot(x[..., 0], x[..., 1])
    sing = h < singular_tol
    th = np.where(
        sing,
        wrap_angle(np.arctan2(xp[..., 1], xp[..., 0]) - np.pi / 2),
        np.arctan2(x[..., 1], x[..., 0]),
    )
    ph = np.where(sing, np.sign(x[..., 2]) * np.pi / 2, np.arctan2(x[..., 2], h))
    lam = np.where(sing, 0.0, np.arctan2(xp[..., 2], zpp))
    return Orientation(th, ph, lam)


@angle_function(
    ("arc_to_passage", "fraction", "longitude", "latitude"),
    units=("rad", "1", "rad", "rad"),
)
def cap_passage(
    xi_in, psi_in, xi_out, psi_out, xi_mu, psi_mu, radius
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    r"""App. C: where the arc from an inside location I to an outside location O crosses a cap boundary.

    The cap is centred on μ = (ξ_μ, ψ_μ) with angular radius ω_Pμ (< π/2); I must be
    inside and O outside. Returns (ω_IP, ω_IP/ω_IO, ξ_P, ψ_P); the passage time is
    :math:`t_P=t_I+(t_O-t_I)\,\omega_{IP}/\omega_{IO}`.

    .. math::
        \omega_{IP} &= \tan^{-1}(b/a)+\cos^{-1}\big(\cos\omega_{P\mu}/(a^2+b^2)^{1/2}\big)\\
        a &= \sin\psi_I\sin\psi_\mu+\cos\psi_I\cos\psi_\mu\cos(\xi_\mu-\xi_I)\\
        b &= \cos\delta^i_{IO}\cos\psi_\mu\sin(\xi_\mu-\xi_I)+\sin\delta^i_{IO}(\sin\psi_\mu-a\sin\psi_I)/\cos\psi_I

    (:math:`a=\cos\omega_{I\mu}`, b = tangent·μ). The last term of b is evaluated as
    :math:`\sin\psi_\mu\cos\psi_I-\sin\psi_I\cos\psi_\mu\cos(\xi_\mu-\xi_I)` (algebraically
    identical, finite at the poles). P from Eq. 6 with δ^i_IO and ω_IP.

    Parameters
    ----------
    xi_in, psi_in : float or array_like
        Longitude ξ_I and latitude ψ_I (rad) of the inside location I.
    xi_out, psi_out : float or array_like
        Longitude ξ_O and latitude ψ_O (rad) of the outside location O.
    xi_mu, psi_mu : float or array_like
        Longitude ξ_μ and latitude ψ_μ (rad) of the cap centre μ.
    radius : float or array_like
        Angular radius ω_Pμ of the cap (rad), in (0, π/2).

    Returns
    -------
    arc_to_passage : ndarray
        Arc ω_IP (rad) from I to the passage point P.
    fraction : ndarray
        ω_IP/ω_IO, the fraction of the arc I → O at which P lies (0 if I = O).
    longitude, latitude : ndarray
        Longitude ξ_P and latitude ψ_P (rad) of P.

    Raises
    ------
    ValueError
        If ``radius`` is not in (0, π/2).
    """
    r = np.asarray(radius, float)
    bad = ~np.isfinite(r) | (r <= 0) | (r >= np.pi / 2)
    if np.any(bad):
        raise ValueError(f"radius must be in (0, π/2) rad, got {r[bad].ravel()[0]!r}")
    a_io = arc(xi_in, psi_in, xi_out, psi_out)
    d = a_io.initial
    psi_in, psi_mu = np.asarray(psi_in, float), np.asarray(psi_mu, float)
    dx = np.asarray(xi_mu, float) - xi_in
    a = np.sin(psi_in) * np.sin(psi_mu) + np.cos(psi_in) * np.cos(psi_mu) * np.cos(dx)
    b = np.cos(d) * np.cos(psi_mu) * np.sin(dx) + np.sin(d) * (
        np.sin(psi_mu) * np.cos(psi_in) - np.sin(psi_in) * np.cos(psi_mu) * np.cos(dx)
    )
    w_ip = np.arctan2(b, a) + np.arccos(_clip1(np.cos(radius) / np.hypot(a, b)))
    xp, pp = interpolate_heading(xi_in, psi_in, d, w_ip, 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = np.where(
            a_io.size > 0, w_ip / np.where(a_io.size > 0, a_io.size, 1.0), 0.0
        )
    return w_ip, frac, xp, pp
