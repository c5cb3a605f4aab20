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
.. [1] R. Fayat, V. Delgado Betancourt, T. Goyallon, M. Petremann, P. Liaudet,
   V. Descossy, L. Reveret, G. P. Dugué, "Inertial measurement of head tilt in
   rodents: principles and applications to vestibular research", Sensors 21(18):6318,
   2021. doi:10.3390/s21186318
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from .. import quaternion as _quat
from ..quaternion import zoh_step_scalar
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
        return self.q.shape[0]


# ------------------------------------------------------------------ bouts


def _gamma_dur(rng: np.random.Generator, mean: float, minimum: float) -> float:
    # gamma(shape 2) durations above a floor, with the requested mean
    return minimum + rng.gamma(2.0, max(mean - minimum, 1e-3) / 2.0)


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
    m = p.mobility
    d_act = p.active_bout_s
    d_imm = f / (1.0 - f) * d_act
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
    pick = pick / pick.sum()

    b0, g0 = p.baseline_pitch_deg * _D2R, p.baseline_roll_deg * _D2R
    sc = p.immobile_scatter_deg * _D2R
    starts: list[float] = []
    states: list[int] = []
    rows: list[np.ndarray] = []

    def row(state: int) -> np.ndarray:
        r = np.zeros(_NFIELDS)
        r[_POS_TAU], r[_YAW_TAU] = 0.5, 0.4
        if state == IMMOBILE:
            r[_PITCH], r[_ROLL] = b0 + rng.normal(0, sc), g0 + rng.normal(0, sc)
            r[_POS_SD], r[_POS_TAU] = 1.0 * _D2R, 3.0
            r[_YAW_SD], r[_YAW_TAU] = 0.5 * _D2R, 1.0
            r[_JIT_SD] = p.still_jitter_dps * _D2R
            r[_ACC_SD] = 0.08
            return r
        r[_YAW_BIAS] = bias
        r[_JIT_SD] = p.active_jitter_dps * _D2R * math.sqrt(m)
        # vigour of the bout: slow, quiet bouts and brisk ones (log-normal, median 1)
        vig = math.exp(p.vigour_sd * rng.standard_normal()) if p.vigour_sd > 0 else 1.0
        if state == EXPLORE:
            r[_PITCH], r[_ROLL] = (
                b0 + m * rng.normal(-8.0, 12.0) * _D2R,
                g0 + m * rng.normal(0, 10.0) * _D2R,
            )
            r[_POS_SD], r[_YAW_SD] = m * 24.0 * _D2R, m * 140.0 * _D2R
            r[_SPEED] = 0.04
        elif state in (LOCOMOTION, CIRCLING):
            r[_PITCH], r[_ROLL] = (
                b0 + m * rng.normal(0, 6.0) * _D2R,
                g0 + m * rng.normal(0, 4.0) * _D2R,
            )
            r[_POS_SD], r[_YAW_SD] = m * 6.0 * _D2R, m * 40.0 * _D2R
            r[_SPEED] = rng.uniform(0.12, 0.28) * math.sqrt(m)
            r[_GAIT_F], r[_GAIT_AMP], r[_BOB] = (
                rng.uniform(3.0, 5.0),
                m * 2.5 * _D2R,
                0.004,
            )
            r[_JIT_SD] *= 0.7
            if state == CIRCLING:
                r[_YAW_BIAS] = bias + sgn_c * CIRCLING_SPEED_DPS * _D2R
                r[_SPEED] = 0.10
        elif state == REARING:
            r[_PITCH], r[_ROLL] = (
                b0 + m * rng.normal(-60.0, 10.0) * _D2R,
                g0 + m * rng.normal(0, 8.0) * _D2R,
            )
            r[_POS_SD], r[_YAW_SD] = m * 8.0 * _D2R, m * 35.0 * _D2R
            r[_HEIGHT] = m * rng.uniform(0.06, 0.12)
            r[_JIT_SD] *= 0.7
        elif state == GROOMING:
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
        if state in (EXPLORE, LOCOMOTION, REARING):
            r[_POS_SD] *= vig
            r[_YAW_SD] *= vig
            r[_JIT_SD] *= vig
        r[_ACC_SD] = _ACC_PER_JIT * r[_JIT_SD]
        return r

    t = 0.0
    immobile = rng.random() < f
    while t < duration_s:
        if immobile:
            dur = _gamma_dur(rng, d_imm, min(0.5, 0.5 * d_imm)) if f > 0 else 0.0
            if dur > 0:
                starts.append(t)
                states.append(IMMOBILE)
                rows.append(row(IMMOBILE))
                t += dur
        else:
            end = t + _gamma_dur(rng, d_act, min(1.0, 0.5 * d_act))
            while t < end and t < duration_s:
                s = 1 + int(rng.choice(5, p=pick))
                dur = _gamma_dur(rng, means[s - 1], min(0.2, 0.5 * means[s - 1]))
                if end - (t + dur) < 0.2:
                    dur = end - t
                starts.append(t)
                states.append(s)
                rows.append(row(s))
                t += dur
        immobile = not immobile
    return (
        np.array(starts),
        np.array(states, dtype=np.int64),
        np.array(rows).reshape(-1, _NFIELDS),
    )


# ------------------------------------------------------------------ kernel


@njit(cache=True)
def _kinematics_kernel(
    n,
    dt,
    b_start,
    table,
    q0,
    d,
    k_tilt,
    tau_w,
    tau_p,
    arena_r,
    seed,
    out_q,
    out_w,
    out_a,
    out_pos,
):
    np.random.seed(seed)
    nb = b_start.shape[0]
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    wf0 = 0.0
    wf1 = 0.0
    wf2 = 0.0
    ou_p = np.random.standard_normal()
    ou_r = np.random.standard_normal()
    ou_y = np.random.standard_normal()
    j0 = np.random.standard_normal()
    j1 = np.random.standard_normal()
    j2 = np.random.standard_normal()
    px = 0.0
    py = 0.0
    pz = 0.0
    vx = 0.0
    vy = 0.0
    vz = 0.0
    ph_g = 0.0
    ph_m = 0.0
    bi = -1
    beta_s = table[0, 0]
    gam_s = table[0, 1]
    e_w = math.exp(-dt / tau_w)
    e_p = math.exp(-dt / tau_p)
    tau_j = 0.04
    e_j = math.exp(-dt / tau_j)
    s_j = math.sqrt(1.0 - e_j * e_j)
    wn = (
        2.0 * math.pi * 1.0
    )  # neck height follows its target as a critically damped 1 Hz system
    tau_v = 0.15
    ramp = 0.15
    e_pos = 0.0
    s_pos = 0.0
    e_yaw = 0.0
    s_yaw = 0.0
    k_start = 0
    k_end = 0
    for k in range(n):
        # ---- bout bookkeeping
        while bi + 1 < nb and k >= b_start[bi + 1]:
            bi += 1
            k_start = b_start[bi]
            k_end = b_start[bi + 1] if bi + 1 < nb else n
            e_pos = math.exp(-dt / table[bi, 3])
            s_pos = math.sqrt(1.0 - e_pos * e_pos)
            e_yaw = math.exp(-dt / table[bi, 5])
            s_yaw = math.sqrt(1.0 - e_yaw * e_yaw)
        if bi < 0:
            bi = 0
            k_start = 0
            k_end = b_start[1] if nb > 1 else n
            e_pos = math.exp(-dt / table[0, 3])
            s_pos = math.sqrt(1.0 - e_pos * e_pos)
            e_yaw = math.exp(-dt / table[0, 5])
            s_yaw = math.sqrt(1.0 - e_yaw * e_yaw)
        row = table[bi]
        # envelope of oscillations (linear ramps at bout edges)
        t_in = (k - k_start) * dt
        t_left = (k_end - k) * dt
        env = 1.0
        denv = 0.0
        if t_in < ramp and t_in <= t_left:
            env = t_in / ramp
            denv = 1.0 / ramp
        elif t_left < ramp:
            env = t_left / ramp
            denv = -1.0 / ramp
        # ---- target posture (smoothed) and current tilt
        beta_t = row[0] + row[2] * ou_p
        gam_t = row[1] + row[2] * ou_r
        beta_s = beta_t + (beta_s - beta_t) * e_p
        gam_s = gam_t + (gam_s - gam_t) * e_p
        cb = math.cos(beta_s)
        gtx = -math.sin(beta_s)
        gty = math.sin(gam_s) * cb
        gtz = math.cos(gam_s) * cb
        gx = 2.0 * (x * z - w * y)
        gy = 2.0 * (y * z + w * x)
        gz = w * w - x * x - y * y + z * z
        # heading of the nose and steering back from the walls
        hx = 1.0 - 2.0 * (y * y + z * z)
        hy = 2.0 * (x * y + w * z)
        hn = math.sqrt(hx * hx + hy * hy) + 1e-12
        hx /= hn
        hy /= hn
        r = row[4] * ou_y + row[6]
        rr = math.sqrt(px * px + py * py)
        if rr > arena_r:
            fw = min(1.0, (rr - arena_r) / 0.03)
            cx = -px / rr
            cy = -py / rr
            r += 6.0 * fw * (hx * cy - hy * cx)
        # ---- commanded angular velocity (sensor frame) and its low-pass
        c0 = k_tilt * (gty * gz - gtz * gy) + r * gx + row[7] * j0
        c1 = k_tilt * (gtz * gx - gtx * gz) + r * gy + row[7] * j1
        c2 = k_tilt * (gtx * gy - gty * gx) + r * gz + row[7] * j2
        af0 = (c0 - wf0) / tau_w
        af1 = (c1 - wf1) / tau_w
        af2 = (c2 - wf2) / tau_w
        # ---- oscillations: angle env*A*sin(phase) on sensor axes
        o0 = 0.0
        o1 = 0.0
        o2 = 0.0
        a0 = 0.0
        a1 = 0.0
        a2 = 0.0
        bob = 0.0
        if row[10] > 0.0:
            om = 2.0 * math.pi * row[10]
            amp = row[11]
            # pitch at the stride frequency, roll and yaw at half of it
            sp, cp = math.sin(ph_g), math.cos(ph_g)
            sh, ch = math.sin(0.5 * ph_g), math.cos(0.5 * ph_g)
            o1 += amp * (denv * sp + env * om * cp)
            a1 += amp * (2.0 * denv * om * cp - env * om * om * sp)
            o0 += 1.2 * amp * (denv * sh + env * 0.5 * om * ch)
            a0 += 1.2 * amp * (2.0 * denv * 0.5 * om * ch - env * 0.25 * om * om * sh)
            o2 += 0.8 * amp * (denv * ch - env * 0.5 * om * sh)
            a2 += 0.8 * amp * (-2.0 * denv * 0.5 * om * sh - env * 0.25 * om * om * ch)
            bob = -env * row[12] * om * om * sp
            ph_g += om * dt
        if row[13] > 0.0:
            om = 2.0 * math.pi * row[13]
            amp = row[14]
            sp, cp = math.sin(ph_m), math.cos(ph_m)
            sq, cq = math.sin(ph_m + 1.3), math.cos(ph_m + 1.3)
            o1 += amp * (denv * sp + env * om * cp)
            a1 += amp * (2.0 * denv * om * cp - env * om * om * sp)
            o0 += 0.7 * amp * (denv * sq + env * om * cq)
            a0 += 0.7 * amp * (2.0 * denv * om * cq - env * om * om * sq)
            o2 += 0.3 * amp * (denv * cq - env * om * sq)
            a2 += 0.3 * amp * (-2.0 * denv * om * sq - env * om * om * cq)
            ph_m += om * dt
        w0 = wf0 + o0
        w1 = wf1 + o1
        w2 = wf2 + o2
        al0 = af0 + a0
        al1 = af1 + a1
        al2 = af2 + a2
        out_w[k, 0] = w0
        out_w[k, 1] = w1
        out_w[k, 2] = w2
        out_q[k, 0] = w
        out_q[k, 1] = x
        out_q[k, 2] = y
        out_q[k, 3] = z
        # ---- neck (pivot) acceleration, world frame
        # translational jitter shares the rotational jitter's noise (head movements are coupled)
        sa = row[15]
        spd = row[8]
        if rr > arena_r and hx * px + hy * py > 0.0:
            spd *= max(0.0, 1.0 - (rr - arena_r) / 0.05)
        ax = (spd * hx - vx) / tau_v + sa * j0
        ay = (spd * hy - vy) / tau_v + sa * j1
        az = wn * wn * (row[9] - pz) - 2.0 * wn * vz + bob + sa * j2
        # ---- rotational acceleration of the sensor about the pivot: alpha x d + w x (w x d)
        t0 = al1 * d[2] - al2 * d[1]
        t1 = al2 * d[0] - al0 * d[2]
        t2 = al0 * d[1] - al1 * d[0]
        u0 = w1 * d[2] - w2 * d[1]
        u1 = w2 * d[0] - w0 * d[2]
        u2 = w0 * d[1] - w1 * d[0]
        t0 += w1 * u2 - w2 * u1
        t1 += w2 * u0 - w0 * u2
        t2 += w0 * u1 - w1 * u0
        # rotate t and d to the world frame with R(q)
        rx = 2.0 * (y * t2 - z * t1)
        ry = 2.0 * (z * t0 - x * t2)
        rz = 2.0 * (x * t1 - y * t0)
        out_a[k, 0] = ax + t0 + w * rx + (y * rz - z * ry)
        out_a[k, 1] = ay + t1 + w * ry + (z * rx - x * rz)
        out_a[k, 2] = az + t2 + w * rz + (x * ry - y * rx)
        rx = 2.0 * (y * d[2] - z * d[1])
        ry = 2.0 * (z * d[0] - x * d[2])
        rz = 2.0 * (x * d[1] - y * d[0])
        out_pos[k, 0] = px + d[0] + w * rx + (y * rz - z * ry)
        out_pos[k, 1] = py + d[1] + w * ry + (z * rx - x * rz)
        out_pos[k, 2] = pz + d[2] + w * rz + (x * ry - y * rx)
        # ---- integrate: neck with constant acceleration over the step
        px += vx * dt + 0.5 * ax * dt * dt
        py += vy * dt + 0.5 * ay * dt * dt
        pz += vz * dt + 0.5 * az * dt * dt
        vx += ax * dt
        vy += ay * dt
        vz += az * dt
        # ---- orientation: q <- q ⊗ exp(ω dt / 2), the same operations as integrate_gyro
        nw, nx, ny, nz = zoh_step_scalar(w, x, y, z, w0 * dt, w1 * dt, w2 * dt)
        nn = np.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
        w, x, y, z = nw / nn, nx / nn, ny / nn, nz / nn
        # ---- filters and noises
        wf0 = c0 + (wf0 - c0) * e_w
        wf1 = c1 + (wf1 - c1) * e_w
        wf2 = c2 + (wf2 - c2) * e_w
        ou_p = ou_p * e_pos + s_pos * np.random.standard_normal()
        ou_r = ou_r * e_pos + s_pos * np.random.standard_normal()
        ou_y = ou_y * e_yaw + s_yaw * np.random.standard_normal()
        j0 = j0 * e_j + s_j * np.random.standard_normal()
        j1 = j1 * e_j + s_j * np.random.standard_normal()
        j2 = j2 * e_j + s_j * np.random.standard_normal()


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
    _kinematics_kernel(
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
