"""Numba kernel of Mahony's explicit complementary filter (:func:`~tiltlab.filters.mahony`)."""

from __future__ import annotations

import numpy as np
from numba import njit

from ..quaternion import rotate_scalar
from ._shared_kernel import _attitude_step, _gravity_error, _unit_sample


@njit(cache=True, nogil=True)
def _mahony_kernel(acc, gyr, mag, use_mag, dt, kp, ki, q0, b0, out, bias):
    w, x, y, z = q0[0], q0[1], q0[2], q0[3]
    bx_, by_, bz_ = b0[0], b0[1], b0[2]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = w, x, y, z
    bias[0, 0], bias[0, 1], bias[0, 2] = bx_, by_, bz_
    for k in range(1, acc.shape[0]):
        ox, oy, oz = gyr[k, 0], gyr[k, 1], gyr[k, 2]
        ax, ay, az, an = _unit_sample(acc, k)
        ex, ey, ez = 0.0, 0.0, 0.0
        have = False
        if an > 0.0:
            # against the estimated gravity-up in the sensor frame, R(q)^T e_z
            cx, cy, cz = _gravity_error(w, x, y, z, ax, ay, az)
            ex += cx
            ey += cy
            ez += cz
            have = True
        if use_mag:
            mx, my, mz, mn = _unit_sample(mag, k)
            if mn > 0.0:
                hx, hy, hz = rotate_scalar(w, x, y, z, mx, my, mz)
                # expected field in the sensor frame: R^T (0, |h_xy|, h_z) (ENU: y north)
                hn = np.sqrt(hx * hx + hy * hy)
                wx, wy, wz = rotate_scalar(w, -x, -y, -z, 0.0, hn, hz)
                wn = np.sqrt(wx * wx + wy * wy + wz * wz)
                wx, wy, wz = wx / wn, wy / wn, wz / wn
                ex += my * wz - mz * wy
                ey += mz * wx - mx * wz
                ez += mx * wy - my * wx
                have = True
        if have:
            bx_ -= ki * ex * dt
            by_ -= ki * ey * dt
            bz_ -= ki * ez * dt
            ox = ox - bx_ + kp * ex
            oy = oy - by_ + kp * ey
            oz = oz - bz_ + kp * ez
        else:
            ox, oy, oz = ox - bx_, oy - by_, oz - bz_
        w, x, y, z = _attitude_step(w, x, y, z, ox, oy, oz, 0.5 * dt)
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z
        bias[k, 0], bias[k, 1], bias[k, 2] = bx_, by_, bz_
