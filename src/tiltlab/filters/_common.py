"""Shared pieces of the orientation filters: input checks, the initial orientation,
the minimal tilt quaternion and ``q0`` handling.

Every filter function reads its arrays through :func:`sensor_inputs` and its numeric
parameters through :mod:`tiltlab._validate`, so that the same mistake gives the same
message in every method.
"""

from __future__ import annotations

import numpy as np

from .. import _validate as _v
from .. import quaternion as quat

__all__ = [
    "initial_orientation",
    "tilt_quaternion",
    "samples",
    "sensor_inputs",
    "start_orientation",
]


def samples(
    a, name: str, n: int | None = None, *, nonzero: bool | None = None
) -> np.ndarray:
    """A contiguous float (N, 3) copy of ``a``; bad samples raise a ValueError naming
    ``name``.

    Refused: a wrong shape, no samples at all, NaN or infinite values (the filters need
    finite samples: interpolate or split the recording, e.g. with
    ``estimate(..., gaps="segments")``), a length other than ``n`` and, with
    ``nonzero`` (default: for ``acc``), samples that are all zero (an accelerometer
    that reads exactly zero throughout has no gravity direction: a disconnected sensor
    or a zero-filled dropout).
    """
    x = _v.vectors(a, name, width=3, ndim=2, allow_nan=True)
    if x.shape[0] == 0:
        raise ValueError(
            f"{name} is empty (0 samples); the filters need at least one sample"
        )
    k = int(np.isnan(x).sum())
    if k:
        raise ValueError(
            f"{name} has {k} NaN values; the filters need finite samples "
            "(interpolate or split the recording)"
        )
    if n is not None and x.shape[0] != n:
        raise ValueError(f"{name} has {x.shape[0]} samples, expected {n}")
    if (name == "acc" if nonzero is None else nonzero) and not np.any(x):
        what = "; no gravity direction can be defined" if name == "acc" else ""
        raise ValueError(
            f"{name} is zero in all {x.shape[0]} samples (a disconnected or "
            f"zero-filled sensor?){what}"
        )
    return np.ascontiguousarray(x)


#: Angular rates (rad/s) above this are refused: about 100 times the range of MEMS
#: gyroscopes (±2000–4000 °/s), far below where the kernels' arithmetic would overflow.
MAX_GYR_RAD_S = 1.0e4


def sensor_inputs(acc, gyr, mag=None):
    """``(acc, gyr, mag_or_dummy, use_mag)`` as contiguous (N, 3) arrays for the kernels.

    Every filter and adapter reads its arrays here (or through :func:`samples`), so
    that they all refuse the same inputs: empty arrays, non-finite samples, mismatched
    lengths, an ``acc`` (or a given ``mag``) that is zero in every sample, and angular
    rates above :data:`MAX_GYR_RAD_S`.
    Without a magnetometer, a (1, 3) zero array stands in for ``mag`` (the kernels take
    an array in every case) and ``use_mag`` is False.
    """
    acc = samples(acc, "acc", nonzero=True)
    gyr = samples(gyr, "gyr", acc.shape[0])
    peak = float(np.abs(gyr).max())
    if peak > MAX_GYR_RAD_S:
        raise ValueError(
            f"gyr reaches {peak:.3g} rad/s ({np.degrees(peak):.3g} deg/s), beyond any "
            f"gyroscope (limit {MAX_GYR_RAD_S:g} rad/s): check its units or scale"
        )
    if mag is None:
        return acc, gyr, np.zeros((1, 3)), False
    return acc, gyr, samples(mag, "mag", acc.shape[0], nonzero=True), True


def init_samples(init_window_s: float, fs: float) -> int:
    """Number of samples (at least 1) in the initialisation window of ``init_window_s``."""
    init_window_s = _v.nonnegative(init_window_s, "init_window_s")
    return max(1, int(round(init_window_s * fs)))


def start_orientation(q0, acc, mag, fs: float, init_window_s: float) -> np.ndarray:
    """The initial orientation: ``q0`` normalised, or :func:`initial_orientation` of the
    first ``init_window_s`` seconds of ``acc`` (and ``mag``)."""
    n = init_samples(init_window_s, fs)
    if q0 is None:
        return initial_orientation(acc[:n], None if mag is None else mag[:n])
    q = np.asarray(q0, dtype=np.float64).reshape(-1)
    if q.shape != (4,) or not np.all(np.isfinite(q)) or np.linalg.norm(q) == 0:
        raise ValueError(
            f"q0 must be a finite non-zero quaternion (w, x, y, z), got {q0!r}"
        )
    return q / np.linalg.norm(q)


def tilt_quaternion(g) -> np.ndarray:
    """Minimal rotations (zero heading part) taking unit vectors ``g`` (sensor) to e_z
    (world); ``g = -e_z`` gives the half turn about x."""
    g = np.asarray(g, float)
    q = np.stack(
        [1.0 + g[..., 2], g[..., 1], -g[..., 0], np.zeros(g.shape[:-1])], axis=-1
    )
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    flip = n[..., 0] < 1e-9
    return np.where(
        flip[..., None],
        np.array([0.0, 1.0, 0.0, 0.0]),
        q / np.where(n == 0, 1.0, n),
    )


def initial_orientation(acc, mag=None) -> np.ndarray:
    r"""Orientation from a few (quasi-static) samples, TRIAD-style.

    The mean specific force :math:`\bar a` defines world up. Without magnetometer the
    quaternion is the minimal rotation taking :math:`\hat a` to :math:`e_z` (its heading
    part is zero: :math:`q_z = 0`). With magnetometer, TRIAD (Shuster & Oh 1981) with
    the gravity as the primary vector: east :math:`e = \bar m \times \hat a / \|\cdot\|`,
    north :math:`n = \hat a \times e`, and :math:`R = [e; n; \hat a]` (rows: the world
    axes in sensor coordinates, ENU).

    Parameters
    ----------
    acc : array_like, shape (N, 3) or (3,)
        Accelerometer samples (any unit).
    mag : array_like, shape (N, 3) or (3,), optional
        Magnetometer samples (any unit).

    Returns
    -------
    numpy.ndarray, shape (4,)
        Unit quaternion, sensor → world.
    """
    a = np.atleast_2d(np.asarray(acc, float)).mean(axis=0)
    an = np.linalg.norm(a)
    if not np.isfinite(an) or an == 0:
        raise ValueError(
            "cannot initialise: the mean accelerometer sample is zero or not finite"
        )
    up = a / an
    if mag is None:
        return tilt_quaternion(up)
    m = np.atleast_2d(np.asarray(mag, float)).mean(axis=0)
    east = np.cross(m, up)
    en = np.linalg.norm(east)
    if not np.isfinite(en) or en < 1e-12 * max(np.linalg.norm(m), 1e-300):
        raise ValueError(
            "cannot initialise: magnetometer is zero or parallel to gravity"
        )
    east /= en
    north = np.cross(up, east)
    return quat.from_matrix(np.stack([east, north, up]))
