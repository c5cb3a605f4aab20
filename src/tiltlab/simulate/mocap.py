r"""Optical motion capture of head markers, synchronised to the IMU by TTL pulses.

Geometry. Markers sit on a rigid head-borne support (after Fayat et al. [1]_,
Fig. A2; the exact dimensions of the figure are not reproduced): markers 1 and 2
left and right (32 mm apart, the value implied by Fayat's
:math:`\arctan(\sigma_{d_{12}}/d_{12}) = 0.38°` with :math:`\sigma_{d_{12}} = 0.21` mm),
marker 3 in front of marker 2 and marker 4 raised. The head frame of §2.6.4,
:math:`h_y = v_{21}/\|v_{21}\|`, :math:`h_z \propto v_{23} \times h_y`,
:math:`h_x = h_y \times h_z`, then coincides with the sensor frame up to the small
support misalignment ``true_support_q`` (the rotation taking head-frame coordinates
to sensor coordinates), which Fayat removed with a Kabsch fit.

Timing (Fayat App. A.2). Video and IMU run on separate 300 Hz clocks; the video
sync unit emits a TTL every 6th frame, registered on the first IMU sample at or
after it. The clock phase drifts slowly (with a little jitter), so that rarely
(≈ 0.07 % of cycles) an interval between TTLs holds 5 or 7 IMU samples.

Errors. Gaussian coordinate noise (default 0.15 mm, giving
:math:`\sigma_{d_{12}} \approx 0.21` mm), short occlusions (NaN) and spurious
reflections that displace a marker by 2–5 mm for a few frames.

References
----------
.. [1] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from .. import quaternion as _quat
from ..frames import head_frame_from_markers
from .kinematics import BehaviourParams, Lesion, TrueMotion, head_kinematics
from .sensor import SensorModel, recording_from_motion

__all__ = [
    "MarkerSupport",
    "mocap_markers",
    "simulate_mocap_session",
    "head_frame_from_markers",
]


@dataclass(frozen=True)
class MarkerSupport:
    """Rigid marker support of a motion-capture session.

    Rigid marker support. ``markers_mm``: nominal marker positions in the head
    (= sensor) frame, mm, rows = markers 1..4; ``misalign_deg``: standard deviation of
    the random rotation between the marker frame and the IMU axes.
    """

    markers_mm: tuple = (
        (0.0, 16.0, 30.0),
        (0.0, -16.0, 30.0),
        (35.0, -16.0, 30.0),
        (18.0, 4.0, 48.0),
    )
    misalign_deg: float = 2.0

    def __post_init__(self):
        """Check the marker layout."""
        m = np.asarray(self.markers_mm, float)
        if m.ndim != 2 or m.shape[1] != 3 or m.shape[0] < 3:
            raise ValueError(f"markers_mm must be (M >= 3, 3), got {m.shape}")


def _nlerp(q, u):
    i = np.clip(np.floor(u).astype(np.int64), 0, q.shape[0] - 2)
    f = (u - i)[:, None]
    a, b = q[i], q[i + 1]
    b = np.where(np.sum(a * b, axis=1, keepdims=True) < 0, -b, b)
    return _quat.normalize((1 - f) * a + f * b), i, f


def mocap_markers(
    motion: TrueMotion,
    *,
    rng: np.random.Generator,
    support: MarkerSupport | None = None,
    noise_mm: float = 0.15,
    occlusion_rate: float = 1e-3,
    reflection_rate: float = 1e-3,
    slip_fraction: float = 7e-4,
    ttl_every: int = 6,
    clock_jitter: float = 2e-4,
) -> tuple[xr.Dataset, np.ndarray]:
    """Marker trajectories seen by a motion-capture system running at the IMU rate.

    Parameters
    ----------
    motion : TrueMotion
        True head motion (``q``, ``pos``) at the IMU rate ``motion.fs``.
    rng : numpy.random.Generator
        Random source of the support misalignment, noise, occlusions and clock.
    support : MarkerSupport, optional
        Marker layout (default ``MarkerSupport()``).
    noise_mm : float
        Per-coordinate Gaussian noise (mm).
    occlusion_rate, reflection_rate : float
        Per-frame, per-marker probability that an occlusion (1–2 frames of NaN) or a
        spurious reflection (1–10 frames displaced by 2–5 mm) starts.
    slip_fraction : float
        Clock drift in IMU samples per TTL cycle: about this fraction of the cycles hold
        5 or 7 IMU samples (Fayat: 0.07 %).
    clock_jitter : float
        Standard deviation (IMU samples) of the white jitter of the clock phase, which
        occasionally makes a slip come back (a 7 followed by a 5 or vice versa).
    ttl_every : int
        A TTL pulse every this many video frames.

    Returns
    -------
    mocap : xarray.Dataset
        dims ``frame``, ``marker``, ``axis``: ``markers`` (mm, mocap/world frame, NaN when
        occluded), ``gross_error`` (bool), ``t_true`` (s, IMU time base), ``q_ref`` (true
        head orientation at the frame), ``ttl`` (bool, frames emitting a TTL); coordinate
        ``frame_time`` (s, video clock); attrs ``fs``, the support geometry, the true
        misalignment ``true_support_q`` and the realised number of clock slips.
    sync : numpy.ndarray of bool, shape (N,)
        IMU samples that registered a TTL.
    """
    sup = support or MarkerSupport()
    fs = motion.fs
    n = len(motion)
    if ttl_every < 2:
        raise ValueError("ttl_every must be >= 2")
    # clock phase (IMU samples): a constant drift of ±slip_fraction samples per TTL cycle plus
    # white jitter; each crossing of an integer moves a TTL one IMU sample (5 or 7 per cycle)
    n_cyc = n // ttl_every + 2
    drift = slip_fraction * (1.0 if rng.random() < 0.5 else -1.0)
    phase_c = (
        rng.uniform(0.0, 1.0)
        + drift * np.arange(n_cyc)
        + clock_jitter * rng.standard_normal(n_cyc)
    )
    j = np.arange(n)
    phase = np.interp(j / ttl_every, np.arange(n_cyc), phase_c)
    u = j + phase  # fractional IMU sample index of each frame
    keep = (u >= 0.0) & (u <= n - 1.0)
    j, u = j[keep], u[keep]
    j = j - j[0]
    n_frames = j.size
    ttl = (j % ttl_every) == 0
    idx = np.ceil(u[ttl] - 1e-12).astype(np.int64)
    ok = idx < n
    sync = np.zeros(n, bool)
    sync[idx[ok]] = True
    gaps = np.diff(idx[ok])
    # true pose at frame times
    q, i0, f = _nlerp(motion.q, u)
    pos = (1 - f) * motion.pos[i0] + f * motion.pos[i0 + 1]
    mis = _quat.from_rotvec(np.radians(sup.misalign_deg) * rng.standard_normal(3))
    m_s = _quat.rotate(
        mis, np.asarray(sup.markers_mm, float)
    )  # marker coordinates in the sensor frame
    nm = m_s.shape[0]
    mk = pos[:, None, :] * 1000.0 + _quat.rotate(q[:, None, :], m_s[None, :, :])
    mk = mk + noise_mm * rng.standard_normal(mk.shape)
    gross = np.zeros((n_frames, nm), bool)
    occl = np.zeros((n_frames, nm), bool)
    for k in range(nm):
        for s in np.flatnonzero(rng.random(n_frames) < reflection_rate):
            L = int(rng.integers(1, 11))
            v = rng.standard_normal(3)
            mk[s : s + L, k] += rng.uniform(2.0, 5.0) * v / np.linalg.norm(v)
            gross[s : s + L, k] = True
        for s in np.flatnonzero(rng.random(n_frames) < occlusion_rate):
            L = int(rng.integers(1, 3))
            occl[s : s + L, k] = True
    mk[occl] = np.nan
    gross |= occl
    ds = xr.Dataset(
        {
            "markers": (
                ("frame", "marker", "axis"),
                mk,
                {"units": "mm", "frame": "mocap (world, z up)"},
            ),
            "gross_error": (
                ("frame", "marker"),
                gross,
                {"long_name": "reflection or occlusion (ground truth)"},
            ),
            "occluded": (("frame", "marker"), occl),
            "t_true": (
                ("frame",),
                u / fs,
                {"units": "s", "long_name": "true frame time in the IMU time base"},
            ),
            "q_ref": (("frame", "quat"), q, {"units": "1", "frame": "sensor->world"}),
            "ttl": (("frame",), ttl, {"long_name": "frame emitting a TTL pulse"}),
        },
        coords={
            "frame_time": ("frame", j / fs, {"units": "s"}),
            "marker": np.arange(1, nm + 1),
            "axis": ["x", "y", "z"],
            "quat": ["w", "x", "y", "z"],
        },
        attrs={
            "fs": float(fs),
            "source": "tiltlab.simulate.mocap_markers",
            "markers_nominal_mm": np.asarray(sup.markers_mm, float).tolist(),
            "markers_sensor_mm": m_s.tolist(),
            "true_support_q": mis.tolist(),
            "noise_mm": float(noise_mm),
            "ttl_every": int(ttl_every),
            "n_slips": int(np.count_nonzero(gaps != ttl_every)),
            "n_cycles": int(gaps.size),
        },
    )
    return ds, sync


def simulate_mocap_session(
    duration_s: float,
    fs: float = 300.0,
    *,
    seed: int | np.random.SeedSequence | None,
    behaviour: BehaviourParams | None = None,
    sensor: SensorModel | None = None,
    lesion: Lesion | None = None,
    support: MarkerSupport | None = None,
    **mocap_kwargs,
) -> tuple[xr.Dataset, xr.Dataset]:
    """Simulate a concurrent IMU + motion-capture session (Fayat §2.6).

    A concurrent IMU + motion-capture session (Fayat §2.6): returns the IMU
    Recording (with a boolean ``sync`` variable marking TTL-bearing samples) and the
    mocap Dataset of :func:`mocap_markers`.

    Parameters
    ----------
    duration_s : float
        Session duration (s).
    fs : float, default 300.0
        IMU sampling rate (Hz).
    seed : int, SeedSequence or None
        Seed of the single random generator of the session (None: fresh entropy).
    behaviour : BehaviourParams, optional
        Behaviour of the simulated rat; default ``BehaviourParams()``.
    sensor : SensorModel, optional
        IMU model; its ``None`` errors are drawn.
    lesion : Lesion, optional
        Unilateral vestibular deficit; default none.
    support : MarkerSupport, optional
        Rigid marker support geometry.
    **mocap_kwargs
        Passed to :func:`mocap_markers` (``noise_mm``, ``occlusion_rate``,
        ``reflection_rate``, ``slip_fraction``, ``clock_jitter``, ``ttl_every`` ...).

    Returns
    -------
    rec : xarray.Dataset
        IMU Recording (``acc`` g, ``gyr`` °/s, ``mag`` µT, truth ``q_ref`` ...) with
        the boolean ``sync`` variable.
    mocap : xarray.Dataset
        Motion-capture Dataset of :func:`mocap_markers` (markers in mm).
    """
    rng = np.random.default_rng(seed)
    motion = head_kinematics(
        duration_s, fs, behaviour=behaviour, lesion=lesion, rng=rng
    )
    mocap, sync = mocap_markers(motion, rng=rng, support=support, **mocap_kwargs)
    rec = recording_from_motion(
        motion,
        rng=rng,
        sensor=sensor,
        keep_true=True,
        attrs={"session": "imu + motion capture"},
    )
    rec["sync"] = ("time", sync, {"long_name": "IMU sample registering a video TTL"})
    return rec, mocap
