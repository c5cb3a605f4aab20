r"""Changes of heading along orthodromic arcs (Benhamou 2023 §5, Eqs. 6–9).

Angles in radians; azimuth θ counter-clockwise from East, elevation φ above the
horizon. These functions take angles (scalars or arrays that broadcast), not sensor
samples; labelled angles (DataArrays, e.g. from :func:`tiltlab.trig.heading`) give
DataArrays with their ``time`` coordinate.
"""

from __future__ import annotations

import numpy as np

from ..frames import _clip1, acc_from_angles, unit_vector, wrap_angle
from ._common import angle_function
from ._types import Arc

__all__ = [
    "arc",
    "arc_inclination",
    "interpolate_heading",
    "great_circle_apex",
    "interpolate_bank",
    "posture_change",
]


@angle_function(())
def arc(az0, el0, az1, el1) -> Arc:
    r"""Orthodromic arc between headings (θ0, φ0) → (θ1, φ1): size and inclinations, Eq. 7.

    .. math::
        \cos\omega &= \sin\phi_0\sin\phi_1 + \cos\phi_0\cos\phi_1\cos(\theta_1-\theta_0) \quad(7a)\\
        \tilde\delta(q) &= \mathrm{atan2}\big(\cos(q\omega)\sin\phi_1 - \cos((1-q)\omega)\sin\phi_0,\;\cos\phi_0\cos\phi_1\sin(\theta_1-\theta_0)\big)\quad(7b)

    ω is computed as atan2(‖x0×x1‖, x0·x1), equal to Eq. 7a but accurate for small
    arcs. Inclinations are measured counter-clockwise from the horizontal in the
    frontal plane. Degenerate cases (ω = 0, or a heading at φ = ±π/2) give
    atan2(0, 0) = 0 for the undefined inclination.

    Parameters
    ----------
    az0, el0, az1, el1 : float or array_like
        Azimuth θ0 and elevation φ0 of the initial heading, θ1 and φ1 of the final one
        (rad); they broadcast.

    Returns
    -------
    Arc
        Size ω ∈ [0, π] and initial and final inclinations δ^i, δ^f (rad);
        DataArrays (with the first labelled argument's ``time``) for labelled input.
    """
    x0, x1 = unit_vector(az0, el0), unit_vector(az1, el1)
    w = np.arctan2(np.linalg.norm(np.cross(x0, x1), axis=-1), np.sum(x0 * x1, axis=-1))
    return Arc(w, _incl(az0, el0, az1, el1, w, 0.0), _incl(az0, el0, az1, el1, w, 1.0))


def _incl(az0, el0, az1, el1, w, q):
    q = np.asarray(q, float)
    num = np.cos(q * w) * np.sin(el1) - np.cos((1 - q) * w) * np.sin(el0)
    den = np.cos(el0) * np.cos(el1) * np.sin(np.asarray(az1, float) - az0)
    return np.arctan2(num, den)


@angle_function("inclination")
def arc_inclination(az0, el0, az1, el1, q) -> np.ndarray:
    """Local inclination δ̃(q), q ∈ [0, 1], of the arc (θ0, φ0) → (θ1, φ1), Eq. 7b.

    Parameters
    ----------
    az0, el0, az1, el1 : float or array_like
        The initial and final headings (rad), as for :func:`arc`.
    q : float or array_like
        Fraction of the arc, in [0, 1] (0: start, 1: end).

    Returns
    -------
    ndarray
        Local inclination δ̃(q) (rad).
    """
    return _incl(az0, el0, az1, el1, arc(az0, el0, az1, el1).size, q)


@angle_function(("azimuth", "elevation"))
def interpolate_heading(
    az0, el0, initial_inclination, size, q
) -> tuple[np.ndarray, np.ndarray]:
    r"""Heading at fraction q of the arc, Eq. 6 (:math:`[\tilde\theta\bullet\tilde\phi]^\top=R_3(\theta_0)R_2(\phi_0)R_1(\delta^i)[q\omega\bullet0]^\top`).

    .. math::
        \tilde\theta(q) &= \theta_0 + \mathrm{atan2}\big(\cos\delta^i\sin q\omega,\;\cos\phi_0\cos q\omega - \sin\delta^i\sin\phi_0\sin q\omega\big)\\
        \tilde\phi(q) &= \sin^{-1}(\sin q\omega\,\sin\delta^i\cos\phi_0 + \cos q\omega\,\sin\phi_0)

    Eq. 6a's printed form divides by tan(qω); both atan2 arguments are multiplied
    here by sin(qω) ≥ 0, which gives the same angle and is defined at q = 0.

    Parameters
    ----------
    az0, el0 : float or array_like
        Azimuth θ0 and elevation φ0 (rad) of the initial heading.
    initial_inclination : float or array_like
        Initial inclination δ^i (rad) of the arc.
    size : float or array_like
        Arc size ω (rad).
    q : float or array_like
        Fraction of the arc, in [0, 1].

    Returns
    -------
    azimuth : ndarray
        Azimuth θ̃(q) (rad), wrapped to (−π, π].
    elevation : ndarray
        Elevation φ̃(q) (rad).
    """
    s = np.asarray(q, float) * np.asarray(size, float)
    d = np.asarray(initial_inclination, float)
    el0 = np.asarray(el0, float)
    th = np.asarray(az0, float) + np.arctan2(
        np.cos(d) * np.sin(s),
        np.cos(el0) * np.cos(s) - np.sin(d) * np.sin(el0) * np.sin(s),
    )
    ph = np.arcsin(
        _clip1(np.sin(s) * np.sin(d) * np.cos(el0) + np.cos(s) * np.sin(el0))
    )
    return wrap_angle(th), ph


@angle_function(("apex_elevation", "apex_azimuth"))
def great_circle_apex(az, el, inclination) -> tuple[np.ndarray, np.ndarray]:
    r"""Apex (highest point) of the great circle through heading (θ, φ) with local inclination δ (§5).

    :math:`\hat\phi=\cos^{-1}|\cos\phi\cos\delta|` (constant along the arc) and
    :math:`\hat\theta=\theta+\mathrm{sgn}(\tan\delta)\cos^{-1}(\tan\phi/\tan\hat\phi)`.
    Returns (φ̂, θ̂). Fallback: when the great circle is the horizon (φ̂ = 0) every
    point is an apex and θ̂ = θ is returned.

    Parameters
    ----------
    az, el : float or array_like
        Azimuth θ and elevation φ (rad) of a heading on the great circle.
    inclination : float or array_like
        Local inclination δ (rad) of the great circle at that heading.

    Returns
    -------
    apex_elevation : ndarray
        Elevation φ̂ (rad) of the apex, in [0, π/2].
    apex_azimuth : ndarray
        Azimuth θ̂ (rad) of the apex, wrapped to (−π, π].
    """
    az, el, d = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (az, el, inclination))
    )
    p = np.cos(el) * np.cos(d)
    ph = np.arccos(_clip1(np.abs(p)))
    t = np.tan(ph)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(t > 0, np.tan(el) / np.where(t > 0, t, 1.0), 1.0)
    sg = np.sign(np.sin(d) * np.cos(d))
    th = np.where(ph > 1e-12, az + sg * np.arccos(_clip1(r)), az)
    return ph, wrap_angle(th)


@angle_function("bank")
def interpolate_bank(az0, el0, bank0, az1, el1, bank1, q) -> np.ndarray:
    r"""Bank angle at fraction q of a step, Eq. 8 (constant roll speed).

    :math:`\tilde\lambda(q)=\lambda_0+\tilde\delta(q)-\delta^i+q(\eta^i-\eta^f)` with
    :math:`\eta^i=\delta^i-\lambda_0`, :math:`\eta^f=\delta^f-\lambda_1` and the roll
    :math:`\rho=\eta^i-\eta^f` wrapped to (−π, π]. Ends at λ1 (mod 2π) for q = 1.

    Parameters
    ----------
    az0, el0, bank0 : float or array_like
        Azimuth, elevation and bank (rad) at the start of the step.
    az1, el1, bank1 : float or array_like
        Azimuth, elevation and bank (rad) at the end of the step.
    q : float or array_like
        Fraction of the step, in [0, 1].

    Returns
    -------
    ndarray
        Bank λ̃(q) (rad), wrapped to (−π, π].
    """
    a = arc(az0, el0, az1, el1)
    rho = wrap_angle((a.initial - bank0) - (a.final - bank1))
    dq = _incl(az0, el0, az1, el1, a.size, q)
    return wrap_angle(
        np.asarray(bank0, float) + dq - a.initial + np.asarray(q, float) * rho
    )


@angle_function("posture_change")
def posture_change(el0, bank0, el1, bank1) -> np.ndarray:
    r"""Size :math:`\bar\omega` of a change of posture, Eq. 9: :math:`\cos\bar\omega=[\lambda_0\bullet\phi_0]\cdot[\lambda_1\bullet\phi_1]`.

    Equal to the angle between the two static acceleration vectors. Computed with atan2.

    Parameters
    ----------
    el0, bank0, el1, bank1 : float or array_like
        Elevation φ and bank λ (rad) of the initial (0) and final (1) postures; all
        four broadcast.

    Returns
    -------
    ndarray
        Size ω̄ (rad) of the change of posture, in [0, π].
    """
    u, v = acc_from_angles(el0, bank0), acc_from_angles(el1, bank1)
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1))
