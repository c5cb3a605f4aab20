"""Numba kernel of :mod:`tiltlab.simulate.kinematics`: the per-sample head-motion loop.

One nopython loop over samples keeps the generator's whole state (orientation,
low-passed angular velocity, Ornstein–Uhlenbeck noises, oscillator phases, neck
position and velocity) in local variables; :func:`tiltlab.simulate.head_kinematics`
prepares its inputs and documents the model.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..quaternion import zoh_step_scalar

__all__ = ["kinematics_kernel"]


@njit(cache=True)
def kinematics_kernel(
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
    """Fill ``out_q``, ``out_w``, ``out_a`` and ``out_pos`` with ``n`` samples of head motion.

    Parameters
    ----------
    n : int
        Number of samples.
    dt : float
        Sampling interval (s).
    b_start : numpy.ndarray of int64, shape (B,)
        First sample of each behavioural bout (increasing, first 0).
    table : numpy.ndarray, shape (B, 16)
        Per-bout kinematic parameters (columns of :mod:`tiltlab.simulate.kinematics`).
    q0 : numpy.ndarray, shape (4,)
        Initial orientation, sensor to world.
    d : numpy.ndarray, shape (3,)
        Sensor position relative to the neck pivot, sensor frame (m).
    k_tilt, tau_w, tau_p, arena_r : float
        Tilt gain (1/s), angular-velocity and posture time constants (s), arena
        radius (m).
    seed : int
        Seed of numba's random generator.
    out_q, out_w, out_a, out_pos : numpy.ndarray, shape (n, 4) or (n, 3)
        Outputs: orientation, angular velocity (rad/s, sensor frame), linear
        acceleration (m/s², world frame) and sensor position (m, world frame).
    """
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
