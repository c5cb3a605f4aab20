r"""Body-rotation trigonometry for bio-logging (Benhamou 2023).

Posture, heading, arcs, rotations, dead reckoning and oscillations.

This package implements, as vectorised numpy functions, the classical-trigonometry
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
* **Gyroscope.** tiltlab's gyroscope vector ω (body frame, right-handed; units read
  from the data and converted to rad/s) maps
  to Benhamou's roll, pitch and yaw speeds as (ρ̇, β̇, α̇) = (ω_x, −ω_y, ω_z): his
  pitch speed is positive nose-up, i.e. clockwise about the sway axis
  (:func:`gyro_to_body_rates`).
* **Magnetometer.** The measured field 𝐌 is the true field expressed in body
  axes (no sign flip). Only directions matter for the azimuth.

Modules
-------
* :mod:`~tiltlab.trig.posture` — posture (Eqs. 2–3), tangential/centripetal
  corrections, magnetic posture (§2–§3);
* :mod:`~tiltlab.trig.heading` — azimuth (Eq. 5), collar azimuth (Eq. 18), full
  heading, declination, App. A azimuth mismatch;
* :mod:`~tiltlab.trig.arcs` — orthodromic arcs, interpolation of heading and bank,
  great-circle apex, posture change (Eqs. 6–9);
* :mod:`~tiltlab.trig.rotations` — gyroscope body rotations (§4), sequential and
  simultaneous rotations, sub-arcs, the exact constant-rate step (Eqs. 10–13), head
  relative to body (App. B), cap passage (App. C);
* :mod:`~tiltlab.trig.deadreckoning` — local coordinates and dead reckoning (§8);
* :mod:`~tiltlab.trig.anchors` — regularly spaced anchors, and dead reckoning anchored
  on a known track (§8);
* :mod:`~tiltlab.trig.oscillations` — crossing times and oscillation statistics (§9).

Benhamou's frames, rotation matrices, sign conventions and angle conversions live in
:mod:`tiltlab.frames` and are re-exported here (the same objects): :func:`wrap_angle`,
:func:`angles_from_quaternion` and :func:`angles_from_matrix` accept labelled input
(DataArrays in, DataArrays out) and refuse non-unit quaternions and matrices that are
not rotations (reflections included). Static acceleration and DBA (§2, §9)
are in :mod:`tiltlab.behavior`; the four-point magnetometer calibration (Eq. 4) in
:mod:`tiltlab.calibration`.

Metadata
--------
Functions that take sensor samples (``acc``, ``mag``, ``gyr`` or a 1-D signal) accept
a Recording, a labelled DataArray or a plain array; ``fs`` and ``units`` are read from
the attributes (a missing or contradictory one is a
:class:`~tiltlab._validate.RecordingError` naming it) and labelled input gives labelled
output (DataArrays with ``time``, ``fs``, ``units``). Per-sample functions of angles
(:func:`arc`, :func:`azimuth_change`, :func:`simultaneous_rotations`, ...) accept
labelled angles too (``units`` "rad" or "deg"; several labelled arguments must share
their ``time`` coordinate) and then return DataArrays with that coordinate.

Undefined quantities
--------------------
Following :mod:`tiltlab._validate`'s policy, quantities that are undefined for some
samples are NaN with a :class:`RuntimeWarning`: the azimuth (heading) where the
magnetic field is zero or parallel to the acceleration, and every posture angle where
the acceleration (or, for :func:`magnetic_posture`, the field) is zero.

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
"""

from __future__ import annotations

from ..frames import (
    R1,
    R2,
    R3,
    Convention,
    Orientation,
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
from ..frames import __all__ as _frames_all
from ._types import Arc, OscillationStats, Posture, Rotations
from .anchors import anchor_steps, dead_reckon_every
from .arcs import *  # noqa: F401,F403
from .arcs import __all__ as _arcs
from .deadreckoning import *  # noqa: F401,F403
from .flight import *  # noqa: F401,F403
from .flight import __all__ as _flight
from .deadreckoning import __all__ as _dr
from .heading import *  # noqa: F401,F403
from .heading import __all__ as _heading
from .oscillations import *  # noqa: F401,F403
from .oscillations import __all__ as _osc
from .posture import *  # noqa: F401,F403
from .posture import __all__ as _posture
from .rotations import *  # noqa: F401,F403
from .rotations import __all__ as _rot

# Benhamou's frames and conventions, re-exported (the same objects as in tiltlab.frames);
# Fayat's tumble stage and marker frame stay there, Orientation is listed below.
_FAYAT = (
    "fibonacci_lattice",
    "stage_angles",
    "stage_quaternion",
    "head_frame_from_markers",
)
_FRAMES = [n for n in _frames_all if n not in (*_FAYAT, "Orientation")]

__all__ = [
    *_FRAMES,
    *_posture,
    *_heading,
    *_arcs,
    *_rot,
    *_dr,
    "anchor_steps",
    "dead_reckon_every",
    *_osc,
    *_flight,
    # result types
    "Orientation",
    "Posture",
    "Arc",
    "Rotations",
    "OscillationStats",
]
