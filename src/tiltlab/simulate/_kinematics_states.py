r"""Behaviour parameters of the head-kinematics generator (private part of its module).

The lesion, the generator's parameters and the tilt of a posture. Everything here is
re-exported by :mod:`tiltlab.simulate.kinematics` (and :mod:`tiltlab.simulate`), where
it is documented (with its references) and imported from; this module imports nothing
from it (the dependency runs one way).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

__all__ = [
    "BehaviourParams",
    "Lesion",
    "target_tilt",
]


@dataclass(frozen=True)
class Lesion:
    """A unilateral vestibular deficit expressed as changes of behaviour.

    Parameters
    ----------
    tilt_deg : float
        Angle (deg) between the baseline tilt point and the sagittal (xz) plane,
        toward the lesion side (the head rolls so that the lesioned ear goes down).
    pitch_deg : float
        Additional nose-down pitch of the baseline tilt point (deg).
    circling_cpm : float
        Mean azimuthal rotation toward the lesion side during active states, in
        circles per minute (counter-clockwise for a left lesion).
    immobility_fraction : float or None
        Expected fraction of time immobile (replaces the behaviour's value when given).
    mobility : float
        Multiplier of the amplitude of active head movements (1 = normal).
    side : {"left", "right"}
        Lesioned side.
    """

    tilt_deg: float = 0.0
    pitch_deg: float = 0.0
    circling_cpm: float = 0.0
    immobility_fraction: float | None = None
    mobility: float = 1.0
    side: str = "left"

    def __post_init__(self):
        if self.side not in ("left", "right"):
            raise ValueError(f"side must be 'left' or 'right', got {self.side!r}")
        if not 0 <= abs(self.tilt_deg) < 90:
            raise ValueError(f"tilt_deg must be in (-90, 90), got {self.tilt_deg}")
        if self.mobility <= 0:
            raise ValueError(f"mobility must be > 0, got {self.mobility}")


@dataclass(frozen=True)
class BehaviourParams:
    """Parameters of the behavioural-state head-motion generator.

    Angles in degrees, durations in seconds, lengths in metres (names say so).
    Defaults give a healthy rat exploring a small box in the dark, tuned so that the
    angular-speed distribution is bimodal, with a still mode near 4–5 °/s, a moving mode
    near 80–120 °/s and a valley at 10–13 °/s (the 12 °/s threshold of Fayat et al.
    2021, doi:10.3390/s21186318, Fig. A3; checked over 30 seeds of 10-min sessions).

    Parameters
    ----------
    immobility_fraction : float
        Expected fraction of time spent in the immobile state.
    active_bout_s : float
        Mean duration of an active episode (a run of non-immobile states); immobile
        episodes last ``f / (1 - f)`` times as long on average.
    state_weights : tuple of 5 floats
        Share of active time spent exploring, in locomotion, rearing, grooming and
        circling (normalised; circling is normally 0 and set by a lesion).
    state_mean_s : tuple of 5 floats
        Mean bout durations of those active states.
    baseline_pitch_deg, baseline_roll_deg : float
        Baseline tilt point: nose-down pitch and right-ear-down roll of the head at
        rest (the tilt is ``g = (-sin β, sin γ cos β, cos γ cos β)``).
    immobile_scatter_deg : float
        Standard deviation of the posture of each immobile bout around the baseline
        (a von Mises–Fisher-like scatter, κ ≈ 1/σ²).
    mobility : float
        Multiplier of active movement amplitudes (postures, scanning, oscillations).
    circling_cpm : float
        Mean azimuthal rotation during active states (circles/min, counter-clockwise
        positive).
    still_jitter_dps : float
        Per-axis standard deviation of the micro-movements during immobility (°/s).
    active_jitter_dps : float
        Per-axis standard deviation of the fast jitter during exploration (°/s).
    vigour_sd : float
        Standard deviation of the log of a per-bout factor scaling the scanning, yaw and
        jitter amplitudes of exploration, locomotion and rearing bouts (slow, quiet bouts
        and brisk ones).
    tilt_gain : float
        Gain ``k`` (1/s) of the attraction of the tilt toward its target.
    omega_tau_s : float
        Time constant of the low-pass on the commanded angular velocity.
    posture_tau_s : float
        Time constant with which the target posture follows bout changes.
    sensor_from_pivot_m : tuple of 3 floats
        Position of the sensor relative to the neck pivot, sensor frame (m).
    arena_radius_m : float
        The neck is steered back toward the centre beyond this distance.
    """

    immobility_fraction: float = 0.32
    active_bout_s: float = 12.0
    state_weights: tuple[float, float, float, float, float] = (
        0.55,
        0.20,
        0.12,
        0.13,
        0.0,
    )
    state_mean_s: tuple[float, float, float, float, float] = (2.0, 1.5, 2.0, 4.0, 3.0)
    baseline_pitch_deg: float = 25.0
    baseline_roll_deg: float = 0.0
    immobile_scatter_deg: float = 6.0
    mobility: float = 1.0
    circling_cpm: float = 0.0
    still_jitter_dps: float = 2.8
    active_jitter_dps: float = 9.0
    vigour_sd: float = 0.3
    tilt_gain: float = 5.0
    omega_tau_s: float = 0.015
    posture_tau_s: float = 0.15
    sensor_from_pivot_m: tuple[float, float, float] = (0.025, 0.0, 0.015)
    arena_radius_m: float = 0.15

    def __post_init__(self):
        if not 0.0 <= self.immobility_fraction < 1.0:
            raise ValueError(
                f"immobility_fraction must be in [0, 1), got {self.immobility_fraction}"
            )
        if self.active_bout_s <= 0 or min(self.state_mean_s) <= 0:
            raise ValueError("bout durations must be positive")
        if len(self.state_weights) != 5 or len(self.state_mean_s) != 5:
            raise ValueError(
                "state_weights and state_mean_s need 5 values (explore, locomotion, rearing, grooming, circling)"
            )
        if min(self.state_weights) < 0 or sum(self.state_weights) <= 0:
            raise ValueError("state_weights must be non-negative and not all zero")
        if self.mobility <= 0:
            raise ValueError(f"mobility must be > 0, got {self.mobility}")
        if self.tilt_gain <= 0 or self.omega_tau_s <= 0 or self.posture_tau_s <= 0:
            raise ValueError(
                "tilt_gain, omega_tau_s and posture_tau_s must be positive"
            )
        if abs(self.baseline_pitch_deg) >= 90:
            raise ValueError("baseline_pitch_deg must be within (-90, 90)")

    def with_lesion(self, lesion: Lesion | None) -> "BehaviourParams":
        """Apply a :class:`Lesion` to these parameters (``None`` returns ``self``).

        The roll is solved so that the baseline tilt point lies ``lesion.tilt_deg``
        from the sagittal plane on the lesion side.
        """
        if lesion is None:
            return self
        sgn = 1.0 if lesion.side == "left" else -1.0
        pitch = self.baseline_pitch_deg + lesion.pitch_deg
        g0 = target_tilt(math.radians(pitch), math.radians(self.baseline_roll_deg))
        # angle to the xz plane toward the lesion side adds to the animal's own
        tilt = (
            math.degrees(math.asin(max(-1.0, min(1.0, -sgn * g0[1])))) + lesion.tilt_deg
        )
        s = -sgn * math.sin(math.radians(tilt)) / math.cos(math.radians(pitch))
        if abs(s) > 1:
            raise ValueError(
                f"tilt {tilt:.1f}° is not reachable with pitch {pitch:.1f}°"
            )
        roll = math.degrees(math.asin(s))
        return replace(
            self,
            baseline_pitch_deg=pitch,
            baseline_roll_deg=roll,
            circling_cpm=self.circling_cpm + sgn * lesion.circling_cpm,
            mobility=self.mobility * lesion.mobility,
            immobility_fraction=self.immobility_fraction
            if lesion.immobility_fraction is None
            else lesion.immobility_fraction,
        )

    def baseline_tilt(self) -> np.ndarray:
        """Return the baseline tilt point ``g0`` (unit vector, sensor frame)."""
        return target_tilt(
            math.radians(self.baseline_pitch_deg), math.radians(self.baseline_roll_deg)
        )

    def to_dict(self) -> dict:
        """Return the parameters as a JSON-serialisable dict."""
        return {
            k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()
        }


def target_tilt(pitch, roll) -> np.ndarray:
    r"""Tilt vector of a posture: :math:`g = (-\sin\beta,\ \sin\gamma\cos\beta,\ \cos\gamma\cos\beta)`.

    ``pitch`` β (rad) is nose-down, ``roll`` γ (rad) right-ear-down. This is the gravity-up
    direction in the sensor frame after a pitch about world y then a roll about sensor x,
    ``R = R_y(β) R_x(γ)``.

    Parameters
    ----------
    pitch : float or array_like
        Pitch β (rad), nose-down positive.
    roll : float or array_like
        Roll γ (rad), right-ear-down positive; broadcast with ``pitch``.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Unit tilt vectors (sensor frame), one per broadcast (pitch, roll) pair.
    """
    pitch, roll = np.asarray(pitch, float), np.asarray(roll, float)
    return np.stack(
        [-np.sin(pitch), np.sin(roll) * np.cos(pitch), np.cos(roll) * np.cos(pitch)],
        axis=-1,
    )
