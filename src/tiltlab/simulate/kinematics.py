r"""Head kinematics of a freely moving rat, driven by behavioural states.

The generator is a semi-Markov sequence of behavioural bouts (immobility,
exploration, locomotion, rearing, grooming, circling) feeding a per-sample
``@njit`` kernel that turns each bout's posture, scanning and oscillation
parameters into a sensor-frame angular velocity :math:`\omega_k`, integrates the
orientation with the same zero-order hold as :func:`tiltlab.quaternion.integrate_gyro`,

.. math:: q_{k+1} = q_k \otimes \exp\!\left(\tfrac12\,\omega_k\,\Delta t\right),

and computes the linear acceleration of the sensor, which sits at a fixed offset
:math:`d` from a neck pivot:

.. math:: a_{lin} = a_{neck} + R(q)\,\big(\alpha \times d + \omega \times (\omega \times d)\big).

Posture control. The tilt :math:`g_s = R(q)^\top e_z` is attracted to a target tilt
:math:`g_t` by the angular velocity :math:`k\,(g_t \times g_s)`, since
:math:`\dot g_s = g_s \times \omega` gives
:math:`\dot g_s = k\,(g_t - g_s\,(g_s\cdot g_t))`: a geodesic approach to
:math:`g_t`. Heading changes are rotations about the vertical,
:math:`r\,g_s` (sensor frame), with :math:`r > 0` counter-clockwise seen from above
(toward the animal's left). The commanded angular velocity is low-passed with a
time constant :math:`\tau_\omega`; stride-locked and grooming oscillations are added
analytically on the sensor axes. The target tilt of each bout is drawn around a
baseline tilt point (a von Mises–Fisher-like scatter during immobility) that a
lesion can rotate toward one side.

References
----------
.. [1] Fayat et al. 2021, Sensors 21(18):6318, doi:10.3390/s21186318 (full entry in
   :mod:`tiltlab.evaluate` and the book's bibliography).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from .. import quaternion as _quat
from ._kinematics_kernel import kinematics_kernel
from ._kinematics_states import BehaviourParams, Lesion, target_tilt

__all__ = [
    "STATES",
    "BehaviourParams",
    "Lesion",
    "TrueMotion",
    "behaviour_bouts",
    "head_kinematics",
    "target_tilt",
]

#: Behavioural state codes (index = code stored in the ``state`` variable).
STATES: tuple[str, ...] = (
    "immobile",
    "explore",
    "locomotion",
    "rearing",
    "grooming",
    "circling",
)
IMMOBILE, EXPLORE, LOCOMOTION, REARING, GROOMING, CIRCLING = range(6)

# columns of the per-bout parameter table passed to the kernel
(
    _PITCH,
    _ROLL,
    _POS_SD,
    _POS_TAU,
    _YAW_SD,
    _YAW_TAU,
    _YAW_BIAS,
    _JIT_SD,
    _SPEED,
    _HEIGHT,
    _GAIT_F,
    _GAIT_AMP,
    _BOB,
    _GROOM_F,
    _GROOM_AMP,
    _ACC_SD,
) = range(16)
_NFIELDS = 16
_D2R = math.pi / 180.0
#: angular speed (deg/s) of the head during a circling bout (15 circles per minute)
CIRCLING_SPEED_DPS = 90.0
# translational jitter of the neck (m/s²) per rad/s of rotational jitter
_ACC_PER_JIT = 6.0


@dataclass
class TrueMotion:
    """Ground-truth motion sampled at ``fs``.

    Attributes
    ----------
    q : (N, 4) orientation, sensor → world.
    omega : (N, 3) angular velocity, sensor frame, rad/s (zero-order hold: ``q`` is its
        exact integral with :func:`tiltlab.quaternion.integrate_gyro`).
    a_lin : (N, 3) linear acceleration of the sensor, world frame, m/s².
    pos : (N, 3) position of the sensor, world frame, m.
    state : (N,) int8 behavioural state codes (:data:`STATES`).
    fs : sampling rate (Hz).
    params : dict of generator parameters and bout statistics.
    """

    q: np.ndarray
    omega: np.ndarray
    a_lin: np.ndarray
    pos: np.ndarray
    state: np.ndarray
    fs: float
    params: dict = field(default_factory=dict)

    def __len__(self) -> int:
        """Return the number of samples."""
        return self.q.shape[0]


# ------------------------------------------------------------------ bouts


def _gamma_dur(rng: np.random.Generator, mean: float, minimum: float) -> float:
    # gamma(shape 2) durations above a floor, with the requested mean
    return minimum + rng.gamma(2.0, max(mean - minimum, 1e-3) / 2.0)


class _BoutSetting(NamedTuple):
    # what every bout row needs: the behaviour, its baseline posture (rad) and scatter,
    # the mobility, and the circling yaw bias (rad/s) and direction
    params: BehaviourParams
    b0: float
    g0: float
    scatter: float
    mobility: float
    bias: float
    sgn_c: float


def _state_choice(p: BehaviourParams) -> tuple[np.ndarray, np.ndarray, float, float]:
    # probabilities of picking each active state, their mean durations, the yaw bias
    # (rad/s) of active states and the circling direction
    m = p.mobility
    w = np.array(p.state_weights, float)
    # circling set by circling_cpm: circling bouts take up to 30% of active time, a yaw bias the rest
    c_cpm = p.circling_cpm
    share_c = (
        min(0.3, 0.6 * abs(c_cpm) / (CIRCLING_SPEED_DPS / 6.0))
        if c_cpm
        else w[4] / w.sum()
    )
    w = w / w.sum()
    if c_cpm:
        w[:4] = w[:4] / max(w[:4].sum(), 1e-12) * (1.0 - share_c)
        w[4] = share_c
    w[2] *= (
        m  # rearing and grooming scale with mobility (loss and recovery of repertoire)
    )
    w[3] *= m
    w = w / w.sum()
    share_c = w[4]
    sgn_c = 1.0 if c_cpm >= 0 else -1.0
    bias = (
        (abs(c_cpm) - share_c * CIRCLING_SPEED_DPS / 6.0) * 2.0 * math.pi / 60.0 * sgn_c
        if c_cpm
        else 0.0
    )
    means = np.array(p.state_mean_s, float)
    pick = w / means
    return pick / pick.sum(), means, bias, sgn_c


def _immobile_row(r: np.ndarray, c: _BoutSetting, rng: np.random.Generator) -> None:
    r[_PITCH], r[_ROLL] = (
        c.b0 + rng.normal(0, c.scatter),
        c.g0 + rng.normal(0, c.scatter),
    )
    r[_POS_SD], r[_POS_TAU] = 1.0 * _D2R, 3.0
    r[_YAW_SD], r[_YAW_TAU] = 0.5 * _D2R, 1.0
    r[_JIT_SD] = c.params.still_jitter_dps * _D2R
    r[_ACC_SD] = 0.08


def _draw_posture(r, c: _BoutSetting, rng, pitch: tuple, roll: tuple) -> None:
    # bout posture: baseline plus mobility times normal (mean, sd) draws in degrees
    r[_PITCH] = c.b0 + c.mobility * rng.normal(*pitch) * _D2R
    r[_ROLL] = c.g0 + c.mobility * rng.normal(*roll) * _D2R


def _explore_row(r, c: _BoutSetting, rng, state: int) -> None:
    m = c.mobility
    _draw_posture(r, c, rng, (-8.0, 12.0), (0, 10.0))
    r[_POS_SD], r[_YAW_SD] = m * 24.0 * _D2R, m * 140.0 * _D2R
    r[_SPEED] = 0.04


def _locomotion_row(r, c: _BoutSetting, rng, state: int) -> None:
    m = c.mobility
    _draw_posture(r, c, rng, (0, 6.0), (0, 4.0))
    r[_POS_SD], r[_YAW_SD] = m * 6.0 * _D2R, m * 40.0 * _D2R
    r[_SPEED] = rng.uniform(0.12, 0.28) * math.sqrt(m)
    r[_GAIT_F], r[_GAIT_AMP], r[_BOB] = (
        rng.uniform(3.0, 5.0),
        m * 2.5 * _D2R,
        0.004,
    )
    r[_JIT_SD] *= 0.7
    if state == CIRCLING:
        r[_YAW_BIAS] = c.bias + c.sgn_c * CIRCLING_SPEED_DPS * _D2R
        r[_SPEED] = 0.10


def _rearing_row(r, c: _BoutSetting, rng, state: int) -> None:
    m = c.mobility
    _draw_posture(r, c, rng, (-60.0, 10.0), (0, 8.0))
    r[_POS_SD], r[_YAW_SD] = m * 8.0 * _D2R, m * 35.0 * _D2R
    r[_HEIGHT] = m * rng.uniform(0.06, 0.12)
    r[_JIT_SD] *= 0.7


def _grooming_row(r, c: _BoutSetting, rng, state: int) -> None:
    b0, g0, m = c.b0, c.g0, c.mobility
    side = 1.0 if rng.random() < 0.5 else -1.0
    r[_PITCH] = b0 + m * rng.normal(50.0, 10.0) * _D2R
    r[_ROLL] = g0 + m * side * rng.uniform(10.0, 35.0) * _D2R
    r[_POS_SD], r[_POS_TAU] = m * 10.0 * _D2R, 0.3
    r[_YAW_SD] = m * 20.0 * _D2R
    r[_GROOM_F], r[_GROOM_AMP] = (
        rng.uniform(5.0, 8.0),
        m * rng.uniform(5.0, 8.0) * _D2R,
    )
    r[_JIT_SD] *= 1.2


_ACTIVE_ROWS = {
    EXPLORE: _explore_row,
    LOCOMOTION: _locomotion_row,
    CIRCLING: _locomotion_row,
    REARING: _rearing_row,
    GROOMING: _grooming_row,
}


def _bout_row(state: int, c: _BoutSetting, rng: np.random.Generator) -> np.ndarray:
    # the kinematic parameters of one bout (a row of the kernel's table)
    r = np.zeros(_NFIELDS)
    r[_POS_TAU], r[_YAW_TAU] = 0.5, 0.4
    if state == IMMOBILE:
        _immobile_row(r, c, rng)
        return r
    p = c.params
    r[_YAW_BIAS] = c.bias
    r[_JIT_SD] = p.active_jitter_dps * _D2R * math.sqrt(c.mobility)
    # vigour of the bout: slow, quiet bouts and brisk ones (log-normal, median 1)
    vig = math.exp(p.vigour_sd * rng.standard_normal()) if p.vigour_sd > 0 else 1.0
    _ACTIVE_ROWS[state](r, c, rng, state)
    if state in (EXPLORE, LOCOMOTION, REARING):
        r[_POS_SD] *= vig
        r[_YAW_SD] *= vig
        r[_JIT_SD] *= vig
    r[_ACC_SD] = _ACC_PER_JIT * r[_JIT_SD]
    return r


def behaviour_bouts(
    duration_s: float, params: BehaviourParams, rng: np.random.Generator
):
    """Draw the sequence of behavioural bouts and the parameters of each.

    Immobile and active episodes alternate; an active episode (mean
    ``params.active_bout_s``) is cut into active states chosen with probabilities
    proportional to ``state_weights / state_mean_s`` so that their shares of active
    time follow ``state_weights``; the last state is truncated at the episode end.
    The expected fraction of immobile time is therefore ``params.immobility_fraction``.

    Parameters
    ----------
    duration_s : float
        Duration (s) to fill with bouts.
    params : BehaviourParams
        Behaviour parameters (immobility fraction, mobility, bout durations, state
        weights, circling rate ...).
    rng : numpy.random.Generator
        Random source.

    Returns
    -------
    starts : (B,) float, bout start times (s)
    states : (B,) int64
    table : (B, 16) float, per-bout kinematic parameters (radians, m, Hz)
    """
    p = params
    f = p.immobility_fraction
    d_act = p.active_bout_s
    d_imm = f / (1.0 - f) * d_act
    pick, means, bias, sgn_c = _state_choice(p)
    c = _BoutSetting(
        p,
        p.baseline_pitch_deg * _D2R,
        p.baseline_roll_deg * _D2R,
        p.immobile_scatter_deg * _D2R,
        p.mobility,
        bias,
        sgn_c,
    )
    starts: list[float] = []
    states: list[int] = []
    rows: list[np.ndarray] = []

    def add(t: float, s: int) -> None:
        starts.append(t)
        states.append(s)
        rows.append(_bout_row(s, c, rng))

    t = 0.0
    immobile = rng.random() < f
    while t < duration_s:
        if immobile:
            dur = _gamma_dur(rng, d_imm, min(0.5, 0.5 * d_imm)) if f > 0 else 0.0
            if dur > 0:
                add(t, IMMOBILE)
                t += dur
        else:
            end = t + _gamma_dur(rng, d_act, min(1.0, 0.5 * d_act))
            while t < end and t < duration_s:
                s = 1 + int(rng.choice(5, p=pick))
                dur = _gamma_dur(rng, means[s - 1], min(0.2, 0.5 * means[s - 1]))
                if end - (t + dur) < 0.2:
                    dur = end - t
                add(t, s)
                t += dur
        immobile = not immobile
    return (
        np.array(starts),
        np.array(states, dtype=np.int64),
        np.array(rows).reshape(-1, _NFIELDS),
    )


def head_kinematics(
    duration_s: float,
    fs: float,
    *,
    seed: int | np.random.SeedSequence | None = None,
    behaviour: BehaviourParams | None = None,
    lesion: Lesion | None = None,
    rng: np.random.Generator | None = None,
) -> TrueMotion:
    """Simulate the true head motion of a freely moving rat.

    Parameters
    ----------
    duration_s : float
        Duration (s).
    fs : float
        Sampling rate (Hz); mandatory.
    seed : int or SeedSequence, optional
        Seed (used when ``rng`` is not given). Same seed → bit-identical output.
    behaviour : BehaviourParams, optional
        Generator parameters (default :class:`BehaviourParams()`).
    lesion : Lesion, optional
        Applied with :meth:`BehaviourParams.with_lesion`.
    rng : numpy.random.Generator, optional
        Random generator to draw from (overrides ``seed``).

    Returns
    -------
    TrueMotion
        ``q`` is produced by the zero-order-hold integration of ``omega``, exactly as
        :func:`tiltlab.quaternion.integrate_gyro` does it.
    """
    if fs is None or not np.isfinite(fs) or fs <= 0:
        raise ValueError(f"fs must be a positive number of Hz, got {fs!r}")
    if not np.isfinite(duration_s) or duration_s <= 0:
        raise ValueError(f"duration_s must be positive, got {duration_s!r}")
    n = int(round(duration_s * fs))
    if n < 2:
        raise ValueError(f"duration_s * fs gives {n} samples; need at least 2")
    params = (behaviour or BehaviourParams()).with_lesion(lesion)
    rng = rng if rng is not None else np.random.default_rng(seed)
    starts, states, table = behaviour_bouts(n / fs, params, rng)
    b_start = np.round(starts * fs).astype(np.int64)
    keep = np.r_[True, np.diff(b_start) > 0] & (b_start < n)
    b_start, states, table = (
        b_start[keep],
        states[keep],
        np.ascontiguousarray(table[keep]),
    )
    heading = rng.uniform(-np.pi, np.pi)
    b0, g0 = (
        math.radians(params.baseline_pitch_deg),
        math.radians(params.baseline_roll_deg),
    )
    # q0 = R_z(heading) R_y(pitch) R_x(roll): the baseline posture with a random heading
    q0 = _quat.mul(
        _quat.from_rotvec([0.0, 0.0, heading]),
        _quat.mul(_quat.from_rotvec([0.0, b0, 0.0]), _quat.from_rotvec([g0, 0.0, 0.0])),
    )
    kseed = int(rng.integers(0, 2**31 - 1))
    q = np.empty((n, 4))
    w = np.empty((n, 3))
    a = np.empty((n, 3))
    pos = np.empty((n, 3))
    d = np.asarray(params.sensor_from_pivot_m, float)
    kinematics_kernel(
        n,
        1.0 / fs,
        b_start,
        table,
        q0,
        d,
        params.tilt_gain,
        params.omega_tau_s,
        params.posture_tau_s,
        params.arena_radius_m,
        kseed,
        q,
        w,
        a,
        pos,
    )
    lengths = np.diff(np.r_[b_start, n])
    state = np.repeat(states.astype(np.int8), lengths)
    info = {
        "behaviour": params.to_dict(),
        "baseline_tilt": params.baseline_tilt().tolist(),
        "n_bouts": int(len(b_start)),
    }
    return TrueMotion(
        q=q, omega=w, a_lin=a, pos=pos, state=state, fs=float(fs), params=info
    )
