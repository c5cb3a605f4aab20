r"""Body-rotation trigonometry for bio-logging (Benhamou 2023): posture, heading, arcs, dead reckoning.

This module implements, as vectorised numpy functions, the classical-trigonometry
formulas of Benhamou (2023) [1]_ (§1–§9 and Appendices A–C) for tri-axial
accelerometers, magnetometers and gyroscopes carried by an animal.

Frames and conventions
----------------------
* **World**: East-North-Up (ENU), axes X (east), Y (north), Z (up).
* **Body**: surge U (tail → head, forward), sway V (right → left), heave W
  (belly → back, up). This is exactly tiltlab's rodent sensor frame (x nose, y left,
  z up), so a tiltlab sensor→world quaternion ``q`` is the body→world rotation
  when the sensor is aligned with the body.
* **Orientation angles** (radians): azimuth θ ∈ (−π, π] (counter-clockwise from
  East; the surge axis points North at θ = π/2), elevation φ ∈ [−π/2, π/2]
  (surge axis above the horizon for φ > 0) and bank λ ∈ (−π, π] (sway axis
  above the horizon for λ > 0). The body→world matrix is
  :math:`C = R_3(\theta) R_2(\phi) R_1(\lambda)` with Benhamou's matrices
  (:func:`R1`, :func:`R2`, :func:`R3`; note :math:`R_2(\phi)` rotates *clockwise*
  about Y, i.e. it is the usual :math:`R_y(-\phi)`). In scipy terms,
  ``Rotation.from_euler("ZYX", [θ, -φ, λ])``.
* **Accelerometer sign.** Benhamou's accelerometer reads −g on an axis pointing
  *up* (his "acceleration" is the gravity vector, 𝐀 = −𝐟). tiltlab Recordings store
  the *specific force* 𝐟, which reads +1 g on the up axis. Every function taking an
  acceleration has a ``convention`` argument: ``"tiltlab"`` (default; specific
  force) or ``"benhamou"`` (gravity sign). :func:`to_benhamou_acc` and
  :func:`from_benhamou_acc` convert explicitly.
* **Gyroscope.** tiltlab's gyroscope vector ω (rad/s, body frame, right-handed) maps
  to Benhamou's roll, pitch and yaw speeds as (ρ̇, β̇, α̇) = (ω_x, −ω_y, ω_z): his
  pitch speed is positive nose-up, i.e. clockwise about the sway axis
  (:func:`gyro_to_body_rates`).
* **Magnetometer.** The measured field 𝐌 is the true field expressed in body
  axes (no sign flip). Only directions matter for the azimuth.

Corrections to the seed text
----------------------------
The arXiv text of [1]_ contains typographical errors; the forms implemented here
are derived (and checked against quaternion algebra in ``tests/test_trig.py``):

* Eq. 11: the first forms read "sin(η^i) − sin(η^i)" and "ρ = η^f − η^f"; the
  correct expressions are :math:`\alpha = (\sin\eta^i - \sin\eta^f)\,\omega/\rho`,
  :math:`\beta = (\cos\eta^f - \cos\eta^i)\,\omega/\rho` with :math:`\rho = \eta^i-\eta^f`,
  and :math:`\tilde\eta(0)=\eta^i=\bar\eta+\rho/2`.
* §5: :math:`\eta^i = \delta^i - \lambda_{i-1}` and :math:`\eta^f = \delta^f - \lambda_i`
  (minus signs lost).
* App. A: the second argument of θ* is :math:`(a_V m_W - a_W m_V)\|\mathbf a\|`
  (printed as ":math:`a_W m_W - a_W m_V`"); it is Eq. 5 applied to the device vectors.
* §8: the dead-reckoning rotations by :math:`-\hat\Theta` and :math:`\Theta` are about
  the Z (vertical) axis, not "the X axis"; the rescaling factor is :math:`L/\tilde V`
  with :math:`\tilde V = \|\sum_i \tilde{\mathbf v}_i\|` (Δt cancels).
* Fig. 2's caption omits :math:`\phi_{i-1}`; :math:`\phi_{i-1}=\pi/6` reproduces all
  printed values.

References
----------
.. [1] S. Benhamou, "Of heading, posture and body rotations derived from data acquired
   by animal-borne accelerometers, magnetometers and gyrometers, kernel density
   estimation of the corresponding spherical distributions, and fine-scale movement
   reconstruction", arXiv:2310.05820, 2023. doi:10.48550/arXiv.2310.05820
.. [2] L. Qasem et al., "Tri-axial dynamic acceleration as a proxy for animal energy
   expenditure; should we be summing values or calculating the vector?", PLoS ONE
   7:e31187, 2012. doi:10.1371/journal.pone.0031187
"""

from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np

from .units import check_fs as _check_fs
from .frames import (  # noqa: F401  (Benhamou's frames live in tiltlab.frames; re-exported)
    Convention,
    Orientation,
    R1,
    R2,
    R3,
    _as_benhamou,
    _clip1,
    _elev_bank,
    _vec3,
    acc_from_angles,
    angles_from_matrix,
    angles_from_quaternion,
    angles_to_matrix,
    angles_to_quaternion,
    body_rates_to_gyro,
    device_to_body,
    device_to_body_eq1,
    from_benhamou_acc,
    geomagnetic_field,
    gyro_to_body_rates,
    mag_from_angles,
    mounting_angles,
    mounting_matrix,
    spherical_coords,
    to_benhamou_acc,
    unit_vector,
    wrap_angle,
)

__all__ = [
    # notation and frames
    "R1",
    "R2",
    "R3",
    "unit_vector",
    "spherical_coords",
    "wrap_angle",
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
    # device -> body
    "mounting_angles",
    "mounting_azimuth_offset",
    "mounting_matrix",
    "device_to_body",
    "device_to_body_eq1",
    # static / dynamic acceleration
    "window_length",
    "static_acceleration",
    "dba",
    "odba",
    "step_summary",
    # posture
    "posture",
    "inclination_from_angles",
    "angles_from_inclination",
    "correct_tangential",
    "correct_centripetal",
    "magnetic_posture",
    "posture_from_magnetic_loop",
    # heading
    "four_point_mag_calibration",
    "calibrate_magnetometer",
    "azimuth",
    "collar_azimuth",
    "heading",
    "body_azimuth_from_device",
    "apply_declination",
    # gyroscope
    "body_rotations",
    # arcs
    "arc",
    "arc_inclination",
    "interpolate_heading",
    "great_circle_apex",
    "interpolate_bank",
    "posture_change",
    # rotations <-> changes of orientation
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
    # head/body, caps
    "head_relative_to_body",
    "cap_passage",
    # dead reckoning
    "EARTH_RADIUS",
    "lonlat_to_local",
    "local_to_lonlat",
    "velocity_components",
    "dead_reckon",
    "dead_reckon_2d",
    "simulate_track",
    "anchored_errors",
    # oscillations
    "crossing_times",
    "oscillation_stats",
    "simulate_heave",
    # result types
    "Orientation",
    "Posture",
    "Arc",
    "Rotations",
    "StepSummary",
    "Track",
    "OscillationStats",
]

EARTH_RADIUS = 6_371_000.0
"""Mean Earth radius (m) used by Benhamou (2023) §8."""



class Posture(NamedTuple):
    """Elevation φ, bank λ (Eq. 3), overall inclination ζ and postural orientation χ (Eq. 2), rad."""

    elevation: np.ndarray
    bank: np.ndarray
    inclination: np.ndarray
    orientation: np.ndarray


class Arc(NamedTuple):
    """Orthodromic arc: size ω ∈ [0, π], initial and final inclinations δ^i, δ^f (rad)."""

    size: np.ndarray
    initial: np.ndarray
    final: np.ndarray


class Rotations(NamedTuple):
    """Body rotations over a step: yaw α (heave axis), pitch β (sway axis, + nose up), roll ρ (surge axis), rad."""

    yaw: np.ndarray
    pitch: np.ndarray
    roll: np.ndarray


class StepSummary(NamedTuple):
    """One value per Δt step (§9): centre time (s), static acceleration (n, 3), mean DBA."""

    time: np.ndarray
    static: np.ndarray
    dba: np.ndarray


class Track(NamedTuple):
    """A simulated 3-D path: positions (n+1, 3) in m, per-step speed (m/s), azimuth and elevation (rad), dt (s)."""

    positions: np.ndarray
    speed: np.ndarray
    azimuth: np.ndarray
    elevation: np.ndarray
    dt: float


class OscillationStats(NamedTuple):
    """Per-window crossing statistics: window centre time, mean delay d̄ (s), CV, period 2d̄ (s), number of intervals."""

    time: np.ndarray
    mean_delay: np.ndarray
    cv: np.ndarray
    period: np.ndarray
    n_intervals: np.ndarray


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------



# 2. device -> body (Eq. 1, App. A)
# ---------------------------------------------------------------------------


def mounting_azimuth_offset(acc_rest, mag_rest, observed_bearing, convention: Convention = "tiltlab") -> np.ndarray:
    r"""App. A azimuth mismatch :math:`\theta^* - \pi/2 + \theta^{obs}` (rad).

    θ* is the device azimuth at rest (Eq. 5 on the device vectors, ccw from East)
    and ``observed_bearing`` the visually assessed body bearing θ^obs (clockwise from
    North, radians, as read on a compass). Pass the result as ``dtheta`` to
    :func:`mounting_matrix` / :func:`device_to_body`.
    """
    theta_star = azimuth(acc_rest, mag_rest, convention=convention)
    return wrap_angle(theta_star - np.pi / 2 + np.asarray(observed_bearing, float))


# ---------------------------------------------------------------------------
# 3. static / dynamic acceleration (§2, §9)
# ---------------------------------------------------------------------------


def window_length(fs: float, window_s: float) -> int:
    """Number of samples k = round(f Δt) of a Δt window (at least 1)."""
    fs = _check_fs(fs)
    if window_s is None or not np.isfinite(window_s) or window_s <= 0:
        raise ValueError(f"window_s must be a positive number of seconds, got {window_s!r}")
    return max(1, int(round(fs * window_s)))


def static_acceleration(acc, fs: float, window_s: float, mode: Literal["sliding", "jumping"] = "sliding") -> np.ndarray:
    r"""Static acceleration :math:`\bar{\mathbf a}`: per-axis mean over a Δt window (§2).

    ``"sliding"``: centred window of k = round(fΔt) samples attributed to its centre
    ((k−1)/2 samples either side for odd k; k/2 before and (k−2)/2 after for even k);
    near the ends the window is truncated to the available samples (no NaN). Output
    shape = input shape (N, 3).

    ``"jumping"``: means of consecutive non-overlapping blocks of k samples; a
    trailing incomplete block is dropped. Output shape (N // k, 3).
    """
    a = _vec3(acc, "acc")
    if a.ndim != 2:
        raise ValueError(f"acc must have shape (N, 3), got {a.shape}")
    k = window_length(fs, window_s)
    n = a.shape[0]
    if mode == "jumping":
        nb = n // k
        return a[: nb * k].reshape(nb, k, 3).mean(axis=1)
    if mode != "sliding":
        raise ValueError(f"mode must be 'sliding' or 'jumping', got {mode!r}")
    before = k // 2
    after = k - 1 - before
    c = np.vstack([np.zeros((1, 3)), np.cumsum(a, axis=0)])
    i = np.arange(n)
    lo = np.maximum(0, i - before)
    hi = np.minimum(n, i + after + 1)
    return (c[hi] - c[lo]) / (hi - lo)[:, None]


def dba(acc, fs: float, window_s: float) -> np.ndarray:
    r"""Dynamic body acceleration :math:`\|\mathbf a - \bar{\mathbf a}\|` per sample (vectorial DBA, VeDBA [2]_).

    Posture-independent: it is invariant to any rotation of the device. Same units as ``acc``.
    """
    a = _vec3(acc, "acc")
    return np.linalg.norm(a - static_acceleration(a, fs, window_s), axis=-1)


def odba(acc, fs: float, window_s: float) -> np.ndarray:
    r"""Overall DBA :math:`|d_U|+|d_V|+|d_W|` per sample (Wilson et al. 2006).

    Shown for comparison only: it depends on the device orientation (it is not
    rotation invariant), unlike :func:`dba`.
    """
    a = _vec3(acc, "acc")
    return np.abs(a - static_acceleration(a, fs, window_s)).sum(axis=-1)


def step_summary(acc, fs: float, window_s: float) -> StepSummary:
    r"""Keep one value per Δt step (§9): subsampled static acceleration and averaged DBA.

    The sliding-window :math:`\bar{\mathbf a}` is subsampled at the centre sample of each
    consecutive block of k = round(fΔt) samples, and the per-sample DBA is averaged
    over the block. Trailing incomplete block dropped.
    """
    a = _vec3(acc, "acc")
    fs = _check_fs(fs)
    k = window_length(fs, window_s)
    stat = static_acceleration(a, fs, window_s)
    d = np.linalg.norm(a - stat, axis=-1)
    nb = a.shape[0] // k
    centre = np.arange(nb) * k + k // 2
    return StepSummary(centre / fs, stat[centre], d[: nb * k].reshape(nb, k).mean(axis=1))


# ---------------------------------------------------------------------------
# 4. posture (§2)
# ---------------------------------------------------------------------------


def posture(acc, convention: Convention = "tiltlab") -> Posture:
    r"""Body posture from (static, body-frame) acceleration, Eqs. 2–3.

    .. math::
        \phi &= \sin^{-1}(-A_U/\|\mathbf A\|) = \tan^{-1}\!\big(-A_U/(A_V^2+A_W^2)^{1/2}\big) \quad(3a)\\
        \lambda &= \mathrm{atan2}(-A_V, -A_W) \quad(3b)\\
        \zeta &= \cos^{-1}(-A_W/\|\mathbf A\|) \quad(2a)\\
        \chi &= \mathrm{atan2}(-A_V, -A_U) \quad(2b)

    with Benhamou's sign 𝐀 (−𝐟 for tiltlab specific force). φ is evaluated in its
    atan form and ζ as atan2 (accurate near 0 and ±π/2). Singular cases: λ is
    undefined at φ = ±π/2 (returned as atan2(0, 0) = 0, the pseudo-bank of §3); χ is
    undefined at ζ = 0 (returned as 0).
    """
    A = _as_benhamou(acc, convention)
    el, bk = _elev_bank(A)
    zeta = np.arctan2(np.hypot(A[..., 0], A[..., 1]), -A[..., 2])
    chi = np.arctan2(-A[..., 1], -A[..., 0])
    return Posture(el, bk, zeta, chi)


def inclination_from_angles(elevation, bank) -> tuple[np.ndarray, np.ndarray]:
    r"""(ζ, χ) from (φ, λ): :math:`[\chi\bullet(\pi/2-\zeta)] = (\sin\phi, \cos\phi\sin\lambda, \cos\phi\cos\lambda)`.

    In particular :math:`\cos\zeta=\cos\phi\cos\lambda`.
    """
    v = acc_from_angles(elevation, bank)
    return np.arctan2(np.hypot(v[..., 0], v[..., 1]), v[..., 2]), np.arctan2(v[..., 1], v[..., 0])


def angles_from_inclination(inclination, orientation) -> tuple[np.ndarray, np.ndarray]:
    r"""(φ, λ) from (ζ, χ): :math:`\phi=\sin^{-1}(\sin\zeta\cos\chi)`, :math:`\lambda=\mathrm{atan2}(\sin\zeta\sin\chi,\cos\zeta)`."""
    z, c = np.broadcast_arrays(np.asarray(inclination, float), np.asarray(orientation, float))
    return np.arcsin(_clip1(np.sin(z) * np.cos(c))), np.arctan2(np.sin(z) * np.sin(c), np.cos(z))


def correct_tangential(elevation, tangential_acc, g: float = 9.81) -> np.ndarray:
    r"""Elevation corrected for a sustained forward acceleration h = Δv/Δt (§2): :math:`\phi - \tan^{-1}(h/g)`.

    ``tangential_acc`` and ``g`` in the same units; h < 0 for a deceleration.
    """
    return np.asarray(elevation, float) - np.arctan2(np.asarray(tangential_acc, float), g)


def correct_centripetal(bank, speed, curvature, g: float = 9.81) -> np.ndarray:
    r"""Bank corrected for a sustained horizontal turn (§2): :math:`\lambda - \tan^{-1}(v^2\kappa/g)`.

    ``curvature`` κ = 1/r is signed, positive for a left (counter-clockwise) turn,
    which reproduces Benhamou's "− for a left turn, + for a right turn". κ = 0 is a
    straight path (no NaN).
    """
    v = np.asarray(speed, float)
    return np.asarray(bank, float) - np.arctan2(v**2 * np.asarray(curvature, float), g)


def magnetic_posture(mag) -> tuple[np.ndarray, np.ndarray]:
    r"""Magnetic 'elevation' and 'bank' :math:`\sin^{-1}(-M_U/\|\mathbf M\|)`, :math:`\mathrm{atan2}(-M_V,-M_W)` (§3).

    Insensitive to dynamic acceleration, but measured against the plane orthogonal
    to the (dipping) field, hence hard to interpret on its own.
    """
    return _elev_bank(_vec3(mag, "mag"))


def posture_from_magnetic_loop(mag_loop, inclination: float) -> tuple[float, float, float]:
    r"""Posture of a bird looping in a thermal from magnetic vectors sampled evenly over one loop (§3).

    With :math:`\Sigma\mathbf M` the sum of the body-frame field vectors and I the
    geomagnetic dip (positive downward):
    :math:`\zeta=\cos^{-1}(|\Sigma M_W|/\|\Sigma\mathbf M\|)`,
    :math:`\phi=\sin^{-1}(-\mathrm{sgn}(I)\Sigma M_U/\|\Sigma\mathbf M\|)`,
    :math:`\lambda=\tan^{-1}(-\mathrm{sgn}(I)\Sigma M_V/|\Sigma M_W|)`.
    Returns (ζ, φ, λ); valid for |λ| < π/2.
    """
    m = _vec3(mag_loop, "mag_loop")
    s = m.reshape(-1, 3).sum(axis=0)
    n = np.linalg.norm(s)
    sg = np.sign(inclination) if inclination != 0 else 1.0
    zeta = float(np.arctan2(np.hypot(s[0], s[1]), abs(s[2])))
    phi = float(np.arcsin(np.clip(-sg * s[0] / n, -1, 1)))
    lam = float(np.arctan2(-sg * s[1], abs(s[2])))
    return zeta, phi, lam


# ---------------------------------------------------------------------------
# 5. heading (§3, Eqs. 4, 5, 18)
# ---------------------------------------------------------------------------


def four_point_mag_calibration(bottom, flank, flank_on: Literal["left", "right"] = "left") -> tuple[np.ndarray, np.ndarray]:
    r"""Eq. 4 four-point magnetometer calibration, as a hard-iron offset and a diagonal scale matrix.

    Parameters
    ----------
    bottom, flank : array_like, shape (4, 3)
        Raw readings (U, V, W) with the surge axis horizontal pointing magnetic North,
        East, South, West (rows in that order), device resting on its bottom
        ("bottom rotation") and on a flank ("flank rotation").
    flank_on : {"left", "right"}
        The flank the device rests on during the flank rotation (left flank on the
        ground: sway axis down, Benhamou's :math:`a_V>0`, sgn = +1).

    Returns
    -------
    offset : ndarray (3,)
        :math:`((N_U+S_U)/2, (E_V+W_V)/2, (E_W+W_W)/2)` from the relevant rotation.
    soft_iron : ndarray (3, 3)
        ``diag(2/(N_U−S_U), 2/(E_V−W_V), sgn(a_V)·2/(E_W−W_W))``.

    Notes
    -----
    With :func:`calibrate_magnetometer` this reproduces Eqs. 4a–c: each axis reads
    +1 pointing horizontally North and −1 pointing South.
    """
    b = np.asarray(bottom, float)
    f = np.asarray(flank, float)
    if b.shape != (4, 3) or f.shape != (4, 3):
        raise ValueError("bottom and flank must have shape (4, 3): rows N, E, S, W; columns U, V, W")
    if flank_on not in ("left", "right"):
        raise ValueError(f"flank_on must be 'left' or 'right', got {flank_on!r}")
    N, E, S, W = range(4)
    s = 1.0 if flank_on == "left" else -1.0
    den = np.array([b[N, 0] - b[S, 0], b[E, 1] - b[W, 1], f[E, 2] - f[W, 2]])
    if np.any(den == 0):
        raise ValueError("degenerate calibration readings (zero range on an axis)")
    offset = np.array([(b[N, 0] + b[S, 0]) / 2, (b[E, 1] + b[W, 1]) / 2, (f[E, 2] + f[W, 2]) / 2])
    return offset, np.diag(2.0 / den * np.array([1.0, 1.0, s]))


def calibrate_magnetometer(raw, offset, soft_iron=None) -> np.ndarray:
    r"""Calibrated magnetic vectors :math:`\mathbf m = S(\mathbf r - \mathbf b)` (hard-iron offset b, soft-iron matrix S)."""
    r = _vec3(raw, "raw")
    b = _vec3(offset, "offset")
    d = r - b
    if soft_iron is None:
        return d
    S = np.asarray(soft_iron, float)
    if S.shape != (3, 3):
        raise ValueError(f"soft_iron must be a (3, 3) matrix, got {S.shape}")
    return d @ S.T


def azimuth(acc, mag, convention: Convention = "tiltlab", declination=0.0, singular_tol: float = 1e-9) -> np.ndarray:
    r"""Body azimuth θ (ccw from East, rad) from body-frame static acceleration and magnetic field, Eq. 5.

    .. math::
        \theta = \mathrm{atan2}\big((A_V^2+A_W^2)M_U - A_U(A_V M_V + A_W M_W),\;(A_V M_W - A_W M_V)\|\mathbf A\|\big)

    (𝐀 in Benhamou's sign; the second argument changes sign with the convention,
    which is why ``convention`` matters). This is atan2 of the levelled field
    :math:`\underline M_U, \underline M_V`, :math:`\underline{\mathbf M}^\top=R_2(\phi)R_1(\lambda)\mathbf M^\top`.

    With magnetic vectors the result is magnetic azimuth; ``declination`` (positive
    East) is subtracted to get the true azimuth (:func:`apply_declination`).

    Singular case (φ ≈ ±π/2, :math:`(A_V^2+A_W^2)^{1/2} <` ``singular_tol``·‖𝐀‖): the
    pseudo-azimuth θ = θ' − π/2 with θ' = atan2(M_V, −sgn(A_U) M_W), the direction of
    the sway axis (§3), consistent with pseudo-bank λ = 0.
    """
    A = _as_benhamou(acc, convention)
    M = _vec3(mag, "mag")
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
    return wrap_angle(th - np.asarray(declination, float))


def collar_azimuth(acc, mag, convention: Convention = "tiltlab", declination=0.0) -> np.ndarray:
    r"""Eq. 18: azimuth of a collar-mounted device from *device* static acceleration and mean field.

    Same expression as Eq. 5 applied to :math:`\bar{\mathbf a}, \bar{\mathbf m}` (device frame):
    valid for the body when the animal moves unbanked and the device surge axis is
    orthogonal to the collar plane, whatever the collar roll.
    """
    return azimuth(acc, mag, convention=convention, declination=declination)


def heading(acc, mag, convention: Convention = "tiltlab", declination=0.0, singular_tol: float = 1e-9) -> Orientation:
    """Full 3-D orientation (θ Eq. 5, φ Eq. 3a, λ Eq. 3b) with the §3 fallback (pseudo-bank 0) at φ = ±π/2."""
    A = _as_benhamou(acc, convention)
    th = azimuth(A, mag, convention="benhamou", declination=declination, singular_tol=singular_tol)
    el, bk = _elev_bank(A)
    sing = np.hypot(A[..., 1], A[..., 2]) < singular_tol * np.linalg.norm(A, axis=-1)
    el = np.where(sing, np.where(A[..., 0] >= 0, -np.pi / 2, np.pi / 2), el)
    return Orientation(th, el, np.where(sing, 0.0, bk))


def body_azimuth_from_device(device_azimuth, elevation, bank, phi_star) -> np.ndarray:
    r"""§3 alternative to Eq. 5: :math:`\theta=\theta^d-\mathrm{atan2}(c_2,c_1)`, :math:`(c_1,c_2,c_3)^\top=R_2(\phi)R_1(\lambda)[0\bullet\phi^*]^\top`.

    θ^d is the device azimuth (Eq. 18 on device vectors), φ, λ the body posture and
    φ* the longitudinal mounting tilt (device surge axis in the sagittal plane).
    """
    c = np.einsum("...ij,...j->...i", R2(elevation) @ R1(bank), unit_vector(0.0, phi_star))
    return wrap_angle(np.asarray(device_azimuth, float) - np.arctan2(c[..., 1], c[..., 0]))


def apply_declination(magnetic_azimuth, declination) -> np.ndarray:
    """True azimuth = magnetic azimuth − declination (declination positive East), wrapped to (−π, π]."""
    return wrap_angle(np.asarray(magnetic_azimuth, float) - np.asarray(declination, float))


# ---------------------------------------------------------------------------
# 6. gyroscope rotations (§4)
# ---------------------------------------------------------------------------


def body_rotations(gyr, fs: float, window_s: float) -> Rotations:
    r"""Yaw, pitch, roll per Δt step: :math:`\alpha_i=\sum_j\dot\alpha_{i,j}/f` etc. over k = round(fΔt) samples (§4).

    ``gyr`` is tiltlab's body-frame angular velocity in rad/s, shape (N, 3); with
    (ρ̇, β̇, α̇) = (ω_x, −ω_y, ω_z). Non-overlapping blocks; trailing incomplete block dropped.
    """
    g = _vec3(gyr, "gyr")
    if g.ndim != 2:
        raise ValueError(f"gyr must have shape (N, 3), got {g.shape}")
    fs = _check_fs(fs)
    k = window_length(fs, window_s)
    nb = g.shape[0] // k
    s = g[: nb * k].reshape(nb, k, 3).sum(axis=1) / fs
    return Rotations(s[:, 2], -s[:, 1], s[:, 0])


# ---------------------------------------------------------------------------
# 7. changes of heading (§5, Eqs. 6-9)
# ---------------------------------------------------------------------------


def arc(az0, el0, az1, el1) -> Arc:
    r"""Orthodromic arc between headings (θ0, φ0) → (θ1, φ1): size and inclinations, Eq. 7.

    .. math::
        \cos\omega &= \sin\phi_0\sin\phi_1 + \cos\phi_0\cos\phi_1\cos(\theta_1-\theta_0) \quad(7a)\\
        \tilde\delta(q) &= \mathrm{atan2}\big(\cos(q\omega)\sin\phi_1 - \cos((1-q)\omega)\sin\phi_0,\;\cos\phi_0\cos\phi_1\sin(\theta_1-\theta_0)\big)\quad(7b)

    ω is computed as atan2(‖x0×x1‖, x0·x1), equal to Eq. 7a but accurate for small
    arcs. Inclinations are measured counter-clockwise from the horizontal in the
    frontal plane. Degenerate cases (ω = 0, or a heading at φ = ±π/2) give
    atan2(0, 0) = 0 for the undefined inclination.
    """
    x0, x1 = unit_vector(az0, el0), unit_vector(az1, el1)
    w = np.arctan2(np.linalg.norm(np.cross(x0, x1), axis=-1), np.sum(x0 * x1, axis=-1))
    return Arc(w, _incl(az0, el0, az1, el1, w, 0.0), _incl(az0, el0, az1, el1, w, 1.0))


def _incl(az0, el0, az1, el1, w, q):
    q = np.asarray(q, float)
    num = np.cos(q * w) * np.sin(el1) - np.cos((1 - q) * w) * np.sin(el0)
    den = np.cos(el0) * np.cos(el1) * np.sin(np.asarray(az1, float) - az0)
    return np.arctan2(num, den)


def arc_inclination(az0, el0, az1, el1, q) -> np.ndarray:
    """Local inclination δ̃(q), q ∈ [0, 1], of the arc (θ0, φ0) → (θ1, φ1), Eq. 7b."""
    return _incl(az0, el0, az1, el1, arc(az0, el0, az1, el1).size, q)


def interpolate_heading(az0, el0, initial_inclination, size, q) -> tuple[np.ndarray, np.ndarray]:
    r"""Heading at fraction q of the arc, Eq. 6 (:math:`[\tilde\theta\bullet\tilde\phi]^\top=R_3(\theta_0)R_2(\phi_0)R_1(\delta^i)[q\omega\bullet0]^\top`).

    .. math::
        \tilde\theta(q) &= \theta_0 + \mathrm{atan2}\big(\cos\delta^i\sin q\omega,\;\cos\phi_0\cos q\omega - \sin\delta^i\sin\phi_0\sin q\omega\big)\\
        \tilde\phi(q) &= \sin^{-1}(\sin q\omega\,\sin\delta^i\cos\phi_0 + \cos q\omega\,\sin\phi_0)

    Eq. 6a's printed form divides by tan(qω); both atan2 arguments are multiplied
    here by sin(qω) ≥ 0, which gives the same angle and is defined at q = 0.
    """
    s = np.asarray(q, float) * np.asarray(size, float)
    d = np.asarray(initial_inclination, float)
    el0 = np.asarray(el0, float)
    th = np.asarray(az0, float) + np.arctan2(np.cos(d) * np.sin(s), np.cos(el0) * np.cos(s) - np.sin(d) * np.sin(el0) * np.sin(s))
    ph = np.arcsin(_clip1(np.sin(s) * np.sin(d) * np.cos(el0) + np.cos(s) * np.sin(el0)))
    return wrap_angle(th), ph


def great_circle_apex(az, el, inclination) -> tuple[np.ndarray, np.ndarray]:
    r"""Apex (highest point) of the great circle through heading (θ, φ) with local inclination δ (§5).

    :math:`\hat\phi=\cos^{-1}|\cos\phi\cos\delta|` (constant along the arc) and
    :math:`\hat\theta=\theta+\mathrm{sgn}(\tan\delta)\cos^{-1}(\tan\phi/\tan\hat\phi)`.
    Returns (φ̂, θ̂). Fallback: when the great circle is the horizon (φ̂ = 0) every
    point is an apex and θ̂ = θ is returned.
    """
    az, el, d = np.broadcast_arrays(*(np.asarray(a, float) for a in (az, el, inclination)))
    p = np.cos(el) * np.cos(d)
    ph = np.arccos(_clip1(np.abs(p)))
    t = np.tan(ph)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(t > 0, np.tan(el) / np.where(t > 0, t, 1.0), 1.0)
    sg = np.sign(np.sin(d) * np.cos(d))
    th = np.where(ph > 1e-12, az + sg * np.arccos(_clip1(r)), az)
    return ph, wrap_angle(th)


def interpolate_bank(az0, el0, bank0, az1, el1, bank1, q) -> np.ndarray:
    r"""Bank angle at fraction q of a step, Eq. 8 (constant roll speed).

    :math:`\tilde\lambda(q)=\lambda_0+\tilde\delta(q)-\delta^i+q(\eta^i-\eta^f)` with
    :math:`\eta^i=\delta^i-\lambda_0`, :math:`\eta^f=\delta^f-\lambda_1` and the roll
    :math:`\rho=\eta^i-\eta^f` wrapped to (−π, π]. Ends at λ1 (mod 2π) for q = 1.
    """
    a = arc(az0, el0, az1, el1)
    rho = wrap_angle((a.initial - bank0) - (a.final - bank1))
    dq = _incl(az0, el0, az1, el1, a.size, q)
    return wrap_angle(np.asarray(bank0, float) + dq - a.initial + np.asarray(q, float) * rho)


def posture_change(el0, bank0, el1, bank1) -> np.ndarray:
    r"""Size :math:`\bar\omega` of a change of posture, Eq. 9: :math:`\cos\bar\omega=[\lambda_0\bullet\phi_0]\cdot[\lambda_1\bullet\phi_1]`.

    Equal to the angle between the two static acceleration vectors. Computed with atan2.
    """
    u, v = acc_from_angles(el0, bank0), acc_from_angles(el1, bank1)
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1))


# ---------------------------------------------------------------------------
# 8. rotations <-> changes of orientation (§6, Eqs. 10-13)
# ---------------------------------------------------------------------------


def sequential_yaw_pitch(size, eta) -> tuple[np.ndarray, np.ndarray]:
    r"""Eq. 10: yaw then pitch decomposition of an arc of size ω at constant body-relative inclination η.

    :math:`\alpha=\mathrm{atan2}(\cos\eta, \cot\omega)` (evaluated as
    atan2(cos η sin ω, cos ω)) and :math:`\beta=\sin^{-1}(\sin\eta\sin\omega)`, i.e.
    :math:`[\alpha\bullet\beta]^\top=R_1(\eta)[\omega\bullet0]^\top`. Accurate for the
    simultaneous rotations only for small ω (see :func:`simultaneous_rotations`).
    """
    w, e = np.broadcast_arrays(np.asarray(size, float), np.asarray(eta, float))
    return np.arctan2(np.cos(e) * np.sin(w), np.cos(w)), np.arcsin(_clip1(np.sin(e) * np.sin(w)))


def sequential_arc_from_yaw_pitch(yaw, pitch) -> tuple[np.ndarray, np.ndarray]:
    r"""Inverse of Eq. 10: arc size ω and body-relative inclination η of sequential yaw α then pitch β.

    From :math:`[\alpha\bullet\beta]=(\cos\omega, \sin\omega\cos\eta, \sin\omega\sin\eta)`:
    :math:`\omega=\mathrm{atan2}\big((\sin^2\alpha\cos^2\beta+\sin^2\beta)^{1/2}, \cos\alpha\cos\beta\big)`,
    :math:`\eta=\mathrm{atan2}(\sin\beta, \sin\alpha\cos\beta)` (0 when ω = 0). Returns (ω, η).
    """
    v = unit_vector(yaw, pitch)
    return np.arctan2(np.hypot(v[..., 1], v[..., 2]), v[..., 0]), np.arctan2(v[..., 2], v[..., 1])


def heading_in_body_frame(az0, el0, bank0, az1, el1) -> tuple[np.ndarray, np.ndarray]:
    r"""§6: heading at step i in the body frame of step i−1: :math:`[\alpha\bullet\beta]^\top=R_1(-\lambda_0)R_2(-\phi_0)R_3(-\theta_0)[\theta_1\bullet\phi_1]^\top`.

    Returns (α, β) of the sequential decomposition; equals Eq. 10 with η = δ^i − λ0.
    """
    C0 = angles_to_matrix(az0, el0, bank0)
    v = np.einsum("...ji,...j->...i", C0, unit_vector(az1, el1))
    return spherical_coords(v)


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
    """
    w, ei, ef = np.broadcast_arrays(*(np.asarray(a, float) for a in (size, eta_initial, eta_final)))
    rho = wrap_angle(ei - ef)
    eb = ei - rho / 2
    f = np.sinc(rho / (2 * np.pi)) * w
    return Rotations(np.cos(eb) * f, np.sin(eb) * f, rho)


def rotations_from_orientations(
    az0, el0, bank0, az1, el1, bank1, method: Literal["simultaneous", "sequential"] = "simultaneous"
) -> Rotations:
    """Yaw, pitch, roll between two orientations: Eq. 11 (``"simultaneous"``) or Eq. 10 (``"sequential"``, roll = η^i − η^f)."""
    a = arc(az0, el0, az1, el1)
    ei = a.initial - np.asarray(bank0, float)
    ef = a.final - np.asarray(bank1, float)
    if method == "simultaneous":
        return simultaneous_rotations(a.size, ei, ef)
    if method == "sequential":
        al, be = sequential_yaw_pitch(a.size, ei)
        return Rotations(al, be, wrap_angle(ei - ef))
    raise ValueError(f"method must be 'simultaneous' or 'sequential', got {method!r}")


def arc_from_rotations(yaw, pitch, roll) -> tuple[np.ndarray, np.ndarray]:
    r"""Eq. 12: arc size and mean body-relative inclination from gyroscope rotations.

    :math:`\omega=\tfrac12\rho(\alpha^2+\beta^2)^{1/2}/\sin(\rho/2)` (sinc form, finite at
    ρ = 0) and :math:`\bar\eta=\mathrm{atan2}(\beta,\alpha)` (0 when ω = 0, where it
    is undefined). Valid for |ρ| ≤ π. Returns (ω, η̄).
    """
    al, be, ro = np.broadcast_arrays(*(np.asarray(a, float) for a in (yaw, pitch, roll)))
    return np.hypot(al, be) / np.sinc(ro / (2 * np.pi)), np.arctan2(be, al)


def azimuth_change(el0, bank0, el1, bank1, yaw, pitch, roll) -> np.ndarray:
    r"""Eq. 13: change of azimuth over a step from postures and gyroscope rotations.

    .. math::
        \Delta\theta=\mathrm{atan2}\big(\sin\omega(\cos\phi_0\cos\delta^i+\cos\phi_1\cos\delta^f)/2,\;\cos\omega-\sin\phi_0\sin\phi_1\big)

    with :math:`\delta^i=\lambda_0+\bar\eta+\rho/2`, :math:`\delta^f=\lambda_1+\bar\eta-\rho/2` and ω, η̄
    from Eq. 12.
    """
    w, eb = arc_from_rotations(yaw, pitch, roll)
    ro = np.asarray(roll, float)
    el0, el1 = np.asarray(el0, float), np.asarray(el1, float)
    di = np.asarray(bank0, float) + eb + ro / 2
    df = np.asarray(bank1, float) + eb - ro / 2
    return np.arctan2(
        np.sin(w) * (np.cos(el0) * np.cos(di) + np.cos(el1) * np.cos(df)) / 2, np.cos(w) - np.sin(el0) * np.sin(el1)
    )


def sub_arc_rotations(size: float, eta_initial: float, roll: float, k: int) -> tuple[np.ndarray, np.ndarray]:
    r"""§6 k-sub-arc construction: per-block yaw and pitch (α_{i,j}, β_{i,j}), j = 1..k.

    :math:`\alpha_{i,j}=\tan^{-1}(\cos\tilde\eta(q)\tan(\omega/k))`,
    :math:`\beta_{i,j}=\sin^{-1}(\sin\tilde\eta(q)\sin(\omega/k))`, :math:`\tilde\eta(q)=\eta^i-q\rho`, q = j/k
    (as printed). Each block also rolls by ρ/k. Their sums converge to Eq. 11 as k → ∞.
    """
    if int(k) < 1:
        raise ValueError(f"k must be a positive integer, got {k!r}")
    q = np.arange(1, int(k) + 1) / int(k)
    e = eta_initial - q * roll
    s = size / k
    return np.arctan2(np.cos(e) * np.sin(s), np.cos(s)), np.arcsin(_clip1(np.sin(e) * np.sin(s)))


def compose_sub_arcs(az0: float, el0: float, bank0: float, size: float, eta_initial: float, roll: float, k: int) -> np.ndarray:
    r"""Final body→world matrix after k blocks of (roll ρ/k about surge, yaw α_{i,j} about heave, pitch β_{i,j} about sway).

    Rotations are intrinsic (body axes): :math:`C \leftarrow C\,R_1(\rho/k)\,R_3(\alpha_{i,j})\,R_2(\beta_{i,j})`
    (Benhamou's :math:`R_2` makes a positive pitch raise the nose).
    """
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
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -axis[..., 2], axis[..., 1], -axis[..., 0]
    K = K - np.swapaxes(K, -1, -2)
    a = np.asarray(angle, float)[..., None, None]
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * (K @ K)


def exact_step(az0, el0, bank0, initial_inclination, size, roll) -> np.ndarray:
    r"""Exact end orientation of the §6 constant-rate step (reference for Eqs. 8, 11–13).

    The surge axis moves at constant speed along the great circle leaving heading
    (θ0, φ0) with inclination δ^i over an arc ω, while the body rolls at constant
    speed by ρ about the surge axis: :math:`C_1 = \mathrm{Rot}(\mathbf n,\omega)\,C_0\,R_1(\rho)`
    with n the unit normal of the reorientation plane. Returns (..., 3, 3).
    """
    C0 = angles_to_matrix(az0, el0, bank0)
    d = np.asarray(initial_inclination, float)
    # normal in world = C0 * (0, -sin eta, cos eta) with eta = delta - bank0
    eta = d - np.asarray(bank0, float)
    nb = np.stack(np.broadcast_arrays(np.zeros_like(eta), -np.sin(eta), np.cos(eta)), axis=-1)
    n = np.einsum("...ij,...j->...i", C0, nb)
    return _axis_angle_matrix(n, size) @ C0 @ R1(roll)


def step_body_rates(size: float, eta_initial: float, roll: float, duration: float, n: int) -> np.ndarray:
    r"""Body-frame angular velocity (tiltlab ω, rad/s) of :func:`exact_step`, sampled at n midpoints, shape (n, 3).

    :math:`\omega_x=\rho/\Delta t`, :math:`-\omega_y=\dot\beta=\sin\tilde\eta(t)\,\omega/\Delta t`,
    :math:`\omega_z=\dot\alpha=\cos\tilde\eta(t)\,\omega/\Delta t`, :math:`\tilde\eta(t)=\eta^i-\rho t/\Delta t`.
    Feeding it to :func:`tiltlab.quaternion.integrate_gyro` reproduces the step (to the
    zero-order-hold error of the integrator).
    """
    if n < 1 or duration <= 0:
        raise ValueError("n must be >= 1 and duration > 0")
    q = (np.arange(n) + 0.5) / n
    e = eta_initial - q * roll
    r = size / duration
    return np.column_stack([np.full(n, roll / duration), -np.sin(e) * r, np.cos(e) * r])


# ---------------------------------------------------------------------------
# 9. head relative to body (App. B)
# ---------------------------------------------------------------------------


def head_relative_to_body(az_b, el_b, bank_b, az_h, el_h, bank_h, singular_tol: float = 1e-9) -> Orientation:
    r"""App. B: orientation of the head expressed in the body frame, from two absolute orientations.

    :math:`\mathbf x_{h/b}^\top = R_1(-\lambda_b)R_2(-\phi_b)R_3(-\theta_b)\mathbf x_h^\top` for the head
    surge :math:`\mathbf x_h=[\theta_h\bullet\phi_h]` and sway :math:`\mathbf x'_h`; then
    :math:`\theta_{h/b}=\mathrm{atan2}(y,x)`, :math:`\phi_{h/b}=\sin^{-1}z`,
    :math:`\lambda_{h/b}=\mathrm{atan2}(z', z'')` with :math:`z''=xy'-yx'`. Singular
    case (head surge orthogonal to the body coronal plane): θ = θ' − π/2, φ = sgn(z)π/2, λ = 0.
    """
    Cb = angles_to_matrix(az_b, el_b, bank_b)
    Ch = angles_to_matrix(az_h, el_h, bank_h)
    x = np.einsum("...ji,...j->...i", Cb, Ch[..., :, 0])
    xp = np.einsum("...ji,...j->...i", Cb, Ch[..., :, 1])
    zpp = x[..., 0] * xp[..., 1] - x[..., 1] * xp[..., 0]
    h = np.hypot(x[..., 0], x[..., 1])
    sing = h < singular_tol
    th = np.where(sing, wrap_angle(np.arctan2(xp[..., 1], xp[..., 0]) - np.pi / 2), np.arctan2(x[..., 1], x[..., 0]))
    ph = np.where(sing, np.sign(x[..., 2]) * np.pi / 2, np.arctan2(x[..., 2], h))
    lam = np.where(sing, 0.0, np.arctan2(xp[..., 2], zpp))
    return Orientation(th, ph, lam)


# ---------------------------------------------------------------------------
# App. C: passage through a cap boundary
# ---------------------------------------------------------------------------


def cap_passage(xi_in, psi_in, xi_out, psi_out, xi_mu, psi_mu, radius) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
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
    """
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
        frac = np.where(a_io.size > 0, w_ip / np.where(a_io.size > 0, a_io.size, 1.0), 0.0)
    return w_ip, frac, xp, pp


# ---------------------------------------------------------------------------
# 10. dead reckoning (§8, Eqs. 17, 19)
# ---------------------------------------------------------------------------


def lonlat_to_local(lon0, lat0, lon1, lat1, radius: float = EARTH_RADIUS) -> tuple[np.ndarray, np.ndarray]:
    r"""§8 local flat-Earth step between two fixes (radians): :math:`X=R(\Xi_1-\Xi_0)\cos((\Psi_0+\Psi_1)/2)`, :math:`Y=R(\Psi_1-\Psi_0)` (m).

    The longitude difference is wrapped to (−π, π].
    """
    lat0, lat1 = np.asarray(lat0, float), np.asarray(lat1, float)
    dlon = wrap_angle(np.asarray(lon1, float) - lon0)
    return radius * dlon * np.cos((lat0 + lat1) / 2), radius * (lat1 - lat0)


def local_to_lonlat(x, y, lon0, lat0, lat1, radius: float = EARTH_RADIUS) -> tuple[np.ndarray, np.ndarray]:
    r"""Inverse of :func:`lonlat_to_local` for in-between points: :math:`\xi=\Xi_0+x/(R\cos((\Psi_0+\Psi_1)/2))`, :math:`\psi=\Psi_0+y/R`."""
    c = np.cos((np.asarray(lat0, float) + np.asarray(lat1, float)) / 2)
    return wrap_angle(np.asarray(lon0, float) + np.asarray(x, float) / (radius * c)), np.asarray(lat0, float) + np.asarray(y, float) / radius


def velocity_components(speed, az, el=None) -> np.ndarray:
    r"""Velocity (proxy) vectors :math:`\tilde v_i[\theta_i\bullet\phi_i]`, shape (N, 3) (elevation 0 if ``el`` is None)."""
    el = np.zeros_like(np.asarray(az, float)) if el is None else el
    return np.asarray(speed, float)[..., None] * unit_vector(az, el)


def _check_anchors(anchors, anchor_steps, n, dim):
    X = np.asarray(anchors, float)
    idx = np.asarray(anchor_steps)
    if X.ndim != 2 or X.shape[1] != dim:
        raise ValueError(f"anchors must have shape (M, {dim}), got {X.shape}")
    if idx.shape != (X.shape[0],) or X.shape[0] < 2:
        raise ValueError("anchor_steps must have one index per anchor and at least two anchors")
    if not np.issubdtype(idx.dtype, np.integer) or idx[0] != 0 or idx[-1] != n or np.any(np.diff(idx) <= 0):
        raise ValueError(f"anchor_steps must be strictly increasing integers from 0 to the number of steps ({n})")
    return X, idx


def dead_reckon(
    speed, az, el, anchors, anchor_steps, dt: float | None = None, current=None, return_water: bool = False
) -> np.ndarray:
    r"""3-D dead reckoning between GNSS anchors with rotation and rescaling, Eq. 17.

    For each interval I (steps ``anchor_steps[I-1]`` … ``anchor_steps[I]``), the
    dead-reckoned vector :math:`\sum_i\tilde{\mathbf v}_i` (azimuth :math:`\hat\Theta`,
    elevation :math:`\hat\Phi`, norm :math:`\tilde V`) is rotated onto the ground-truth
    step (L, Θ, Φ) by :math:`R_3(\Theta)R_2(\Phi-\hat\Phi)R_3(-\hat\Theta)` and rescaled by
    :math:`L/\tilde V`; each step uses Eqs. 17a–c with the intermediate p, q, r.

    Parameters
    ----------
    speed, az, el : array_like, shape (N,)
        Speed proxy ṽ_i (any positive scale), azimuth and elevation of each step.
    anchors : array_like, shape (M, 3)
        Anchor positions (m, local ENU) at step indices ``anchor_steps``.
    anchor_steps : array_like of int, shape (M,)
        Strictly increasing, from 0 to N.
    dt : float, optional
        Step duration (s); needed only with ``current``.
    current : array_like, shape (M-1, 2), optional
        Mean (East, North) current velocity (m/s) over each interval: the swimming
        path is reconstructed with :math:`\Delta X-\Delta T E`, :math:`\Delta Y-\Delta T N`
        and drifted back, :math:`x^g_i=x_i+i\Delta t E` (§8).
    return_water : bool
        With ``current``, return the water-relative path instead of the geographic one.

    Returns
    -------
    ndarray, shape (N+1, 3)
        Positions; row ``anchor_steps[I]`` equals ``anchors[I]`` up to rounding.

    Notes
    -----
    Fallbacks: if :math:`\tilde V=0` over an interval (no movement in the proxy), the
    interval is filled by constant-velocity straight-line interpolation; if L = 0,
    the reconstructed bout collapses on the anchor (scale 0).
    """
    v = velocity_components(speed, az, el)
    n = v.shape[0]
    X, idx = _check_anchors(anchors, anchor_steps, n, 3)
    dX = np.diff(X, axis=0)
    nI = np.diff(idx)
    if current is not None:
        if dt is None or dt <= 0:
            raise ValueError("dt (s) is required with current")
        cur = np.asarray(current, float)
        if cur.shape != (X.shape[0] - 1, 2):
            raise ValueError(f"current must have shape ({X.shape[0] - 1}, 2), got {cur.shape}")
        drift = np.column_stack([cur * (nI * dt)[:, None], np.zeros(len(nI))])
        dX = dX - drift
    L = np.linalg.norm(dX, axis=1)
    Th = np.arctan2(dX[:, 1], dX[:, 0])
    Ph = np.arctan2(dX[:, 2], np.hypot(dX[:, 0], dX[:, 1]))
    S = np.add.reduceat(v, idx[:-1], axis=0)
    Vt = np.linalg.norm(S, axis=1)
    Thh = np.arctan2(S[:, 1], S[:, 0])
    Phh = np.arctan2(S[:, 2], np.hypot(S[:, 0], S[:, 1]))
    seg = np.repeat(np.arange(len(nI)), nI)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(Vt > 0, L / np.where(Vt > 0, Vt, 1.0), 0.0)
    ct, st = np.cos(Thh[seg]), np.sin(Thh[seg])
    cd, sd = np.cos(Ph[seg] - Phh[seg]), np.sin(Ph[seg] - Phh[seg])
    cT, sT = np.cos(Th[seg]), np.sin(Th[seg])
    p = v[:, 0] * ct + v[:, 1] * st
    q = v[:, 1] * ct - v[:, 0] * st
    r = p * cd - v[:, 2] * sd
    k = scale[seg]
    inc = np.column_stack([(r * cT - q * sT) * k, (q * cT + r * sT) * k, (v[:, 2] * cd + p * sd) * k])
    still = (Vt == 0)[seg]
    if np.any(still):
        inc[still] = (dX / nI[:, None])[seg[still]]
    if current is not None and not return_water:
        inc = inc + np.column_stack([cur[seg] * dt, np.zeros(n)])
    out = np.empty((n + 1, 3))
    out[idx[:-1]] = X[:-1]
    # cumulative sum restarted at each anchor
    cs = np.cumsum(inc, axis=0)
    start = np.concatenate([np.zeros((1, 3)), cs])[idx[:-1]]
    out[1:] = X[:-1][seg] + cs - start[seg]
    return out


def dead_reckon_2d(speed, az, anchors, anchor_steps) -> np.ndarray:
    r"""2-D dead reckoning for collar-mounted loggers, Eq. 19 (trigonometry-free form).

    .. math::
        x_i &= x_{i-1}+\big((\Delta X\Sigma\tilde v_x+\Delta Y\Sigma\tilde v_y)\tilde v_{xi}-(\Delta Y\Sigma\tilde v_x-\Delta X\Sigma\tilde v_y)\tilde v_{yi}\big)/\big((\Sigma\tilde v_x)^2+(\Sigma\tilde v_y)^2\big)\\
        y_i &= y_{i-1}+\big((\Delta X\Sigma\tilde v_x+\Delta Y\Sigma\tilde v_y)\tilde v_{yi}+(\Delta Y\Sigma\tilde v_x-\Delta X\Sigma\tilde v_y)\tilde v_{xi}\big)/\big((\Sigma\tilde v_x)^2+(\Sigma\tilde v_y)^2\big)

    Equal to :func:`dead_reckon` with zero elevations. ``anchors`` shape (M, 2);
    returns (N+1, 2). Same fallback for a null proxy sum.
    """
    v = velocity_components(speed, az)[:, :2]
    n = v.shape[0]
    X, idx = _check_anchors(anchors, anchor_steps, n, 2)
    dX = np.diff(X, axis=0)
    nI = np.diff(idx)
    S = np.add.reduceat(v, idx[:-1], axis=0)
    den = (S**2).sum(axis=1)
    seg = np.repeat(np.arange(len(nI)), nI)
    c = dX[:, 0] * S[:, 0] + dX[:, 1] * S[:, 1]
    s = dX[:, 1] * S[:, 0] - dX[:, 0] * S[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(den > 0, c / np.where(den > 0, den, 1.0), 0.0)
        s = np.where(den > 0, s / np.where(den > 0, den, 1.0), 0.0)
    inc = np.column_stack([c[seg] * v[:, 0] - s[seg] * v[:, 1], c[seg] * v[:, 1] + s[seg] * v[:, 0]])
    still = (den == 0)[seg]
    if np.any(still):
        inc[still] = (dX / nI[:, None])[seg[still]]
    cs = np.cumsum(inc, axis=0)
    start = np.concatenate([np.zeros((1, 2)), cs])[idx[:-1]]
    out = np.empty((n + 1, 2))
    out[0] = X[0]
    out[1:] = X[:-1][seg] + cs - start[seg]
    return out


def simulate_track(
    n_steps: int,
    dt: float = 1.0,
    *,
    mean_speed: float = 1.0,
    turn_sd: float = 0.15,
    pitch_sd: float = 0.05,
    max_elevation: float = 0.6,
    rng: np.random.Generator | int | None = None,
) -> Track:
    """A smooth correlated random walk in 3-D (truth for dead-reckoning demonstrations).

    Azimuth performs a random walk (increments N(0, turn_sd²) per step), elevation a
    mean-reverting walk bounded by ``max_elevation``, speed a positive log-normal AR(1)
    around ``mean_speed``. Self-contained (does not use :mod:`tiltlab.simulate`).
    """
    if n_steps < 1 or dt <= 0:
        raise ValueError("n_steps must be >= 1 and dt > 0")
    rng = np.random.default_rng(rng)
    from scipy.signal import lfilter

    az = wrap_angle(rng.uniform(-np.pi, np.pi) + np.cumsum(rng.normal(0, turn_sd, n_steps)))
    e = lfilter([1.0], [1.0, -0.9], rng.normal(0, pitch_sd, n_steps))  # AR(1)
    el = max_elevation * np.tanh(e / max_elevation)
    speed = mean_speed * np.exp(lfilter([1.0], [1.0, -0.95], rng.normal(0, 0.1, n_steps)))
    pos = np.vstack([np.zeros((1, 3)), np.cumsum(velocity_components(speed, az, el) * dt, axis=0)])
    return Track(pos, speed, az, el, float(dt))


def anchored_errors(truth, speed, az, el, intervals) -> tuple[np.ndarray, np.ndarray]:
    """Mean and max position error of :func:`dead_reckon` against true positions, for several anchor intervals.

    ``truth`` (N+1, 3) gives both the anchors (every ``interval`` steps, plus the
    last position) and the reference; ``speed``, ``az``, ``el`` are the (noisy)
    per-step inputs. Returns two arrays (mean, max) with one value per interval (m).
    """
    truth = _vec3(truth, "truth")
    n = truth.shape[0] - 1
    means, maxs = [], []
    for every in intervals:  # one vectorised reconstruction per interval
        if int(every) < 1:
            raise ValueError("anchor intervals must be positive integers")
        idx = np.unique(np.r_[np.arange(0, n, int(every)), n])
        e = np.linalg.norm(dead_reckon(speed, az, el, truth[idx], idx) - truth, axis=1)
        means.append(e.mean())
        maxs.append(e.max())
    return np.array(means), np.array(maxs)


# ---------------------------------------------------------------------------
# 11. oscillations (§9)
# ---------------------------------------------------------------------------


def crossing_times(signal, fs: float, level: float = 0.0) -> np.ndarray:
    """Times (s) at which ``signal`` crosses ``level`` (either direction), linearly interpolated between samples."""
    x = np.asarray(signal, float) - level
    if x.ndim != 1:
        raise ValueError("signal must be one-dimensional")
    fs = _check_fs(fs)
    s = np.sign(x)
    # treat exact zeros as belonging to the previous sign to avoid double counting
    for _ in range(2):
        z = s == 0
        if not np.any(z):
            break
        s[z] = np.concatenate([[1.0], s[:-1]])[z]
    i = np.nonzero(s[:-1] * s[1:] < 0)[0]
    frac = x[i] / (x[i] - x[i + 1])
    return (i + frac) / fs


def oscillation_stats(signal, fs: float, level: float, window_s: float, smooth_s: float | None = None) -> OscillationStats:
    r"""Per Δt window: mean delay d̄ between successive crossings of a balance level, its CV, and period T = 2d̄ (§9).

    For a regular oscillation CV ≪ 1; for random fluctuations the delays are close
    to exponential (CV ≈ 1). The balance level is the static value of the signal,
    e.g. +g on the heave axis for tiltlab specific force (−g in Benhamou's sign).
    Windows with fewer than two intervals give NaN (no statistic can be formed).
    Each interval is assigned to the window containing its midpoint.

    ``smooth_s`` (optional, not in [1]_) applies a centred moving average of that
    duration before detecting crossings, to suppress the spurious extra crossings
    that sensor noise creates near the balance level.
    """
    fs = _check_fs(fs)
    x = np.asarray(signal, float)
    if x.ndim != 1:
        raise ValueError("signal must be one-dimensional")
    if smooth_s is not None:
        x = static_acceleration(np.repeat(x[:, None], 3, axis=1), fs, smooth_s)[:, 0]
    k = window_length(fs, window_s)
    nb = x.shape[0] // k
    t = crossing_times(x, fs, level)
    d = np.diff(t)
    mid = (t[1:] + t[:-1]) / 2
    w = np.floor(mid * fs / k).astype(int)
    keep = w < nb
    w, d = w[keep], d[keep]
    cnt = np.bincount(w, minlength=nb).astype(float)
    s1 = np.bincount(w, weights=d, minlength=nb)
    s2 = np.bincount(w, weights=d**2, minlength=nb)
    with np.errstate(invalid="ignore", divide="ignore"):
        m = np.where(cnt >= 2, s1 / cnt, np.nan)
        var = np.where(cnt >= 2, s2 / cnt - m**2, np.nan)
        cv = np.sqrt(np.maximum(var, 0)) / m
    centre = (np.arange(nb) * k + k / 2) / fs
    return OscillationStats(centre, m, cv, 2 * m, cnt.astype(int))


def simulate_heave(
    fs: float,
    duration: float,
    flapping: np.ndarray | None = None,
    *,
    period: float = 0.18,
    amplitude: float = 0.8,
    noise_sd: float = 0.05,
    glide_sd: float = 0.3,
    g: float = 1.0,
    rng: np.random.Generator | int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Heave specific force (tiltlab sign, units of g) of a bird alternating flapping and gliding.

    While ``flapping`` (boolean per sample; default first half) the signal is
    g + amplitude·sin(2πt/period) + white sensor noise (SD ``noise_sd``); while
    gliding it is g + turbulence, an AR(1) process (coefficient 0.8 per sample,
    marginal SD ``glide_sd``) plus the same sensor noise. Returns (time, signal).
    """
    fs = _check_fs(fs)
    rng = np.random.default_rng(rng)
    n = int(round(duration * fs))
    t = np.arange(n) / fs
    if flapping is None:
        flapping = t < duration / 2
    flapping = np.asarray(flapping, bool)
    if flapping.shape != (n,):
        raise ValueError(f"flapping must have shape ({n},)")
    from scipy.signal import lfilter

    e = rng.normal(0, noise_sd, n)
    ar = lfilter([np.sqrt(1 - 0.8**2)], [1, -0.8], rng.normal(0, glide_sd, n))
    phase = 2 * np.pi * rng.random()
    sig = np.where(flapping, amplitude * np.sin(2 * np.pi * t / period + phase), ar) + e
    return t, g + sig
