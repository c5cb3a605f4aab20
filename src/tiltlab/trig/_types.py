"""Result types of :mod:`tiltlab.trig` (named tuples; angles in radians).

With labelled input (a Recording or a DataArray) the fields are DataArrays carrying
``time``, ``fs`` and ``units``; with plain arrays they are numpy arrays.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..frames import Orientation

__all__ = ["Orientation", "Posture", "Arc", "Rotations", "OscillationStats"]


class Posture(NamedTuple):
    """Elevation φ, bank λ (Eq. 3), inclination ζ and postural orientation χ (Eq. 2), rad."""

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
    """Body rotations over a step: yaw α, pitch β (+ nose up), roll ρ (rad).

    Yaw is about the heave axis, pitch about the sway axis, roll about the surge axis.
    """

    yaw: np.ndarray
    pitch: np.ndarray
    roll: np.ndarray


class OscillationStats(NamedTuple):
    """Per-window crossing statistics.

    Window centre time (s), mean delay d̄ (s), CV, period 2d̄ (s), number of intervals.
    """

    time: np.ndarray
    mean_delay: np.ndarray
    cv: np.ndarray
    period: np.ndarray
    n_intervals: np.ndarray
