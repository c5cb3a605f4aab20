"""Numba kernel of LaCanna's per-axis complementary filter (roll and pitch angles)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def complementary_angles_kernel(acc, gyr, dt, a, out):
    """Run ``angle_i = a (angle_{i-1} + gyro_i dt) + (1 - a) acc_angle_i`` per axis.

    Parameters
    ----------
    acc : ndarray (N, 3)
        Specific force, any unit.
    gyr : ndarray (N, 3)
        Angular velocity (rad/s).
    dt : float
        Sampling interval (s).
    a : float
        Weight of the gyroscope path, in [0, 1].
    out : ndarray (N, 2)
        Written in place: roll (about x, from ``atan2(a_y, a_z)``) and pitch (about y,
        from ``atan2(-a_x, sqrt(a_y² + a_z²))``) in rad; the first sample holds the
        accelerometer's angles.
    """
    for k in range(acc.shape[0]):
        ax, ay, az = acc[k, 0], acc[k, 1], acc[k, 2]
        roll_acc = np.arctan2(ay, az)
        pitch_acc = np.arctan2(-ax, np.sqrt(ay * ay + az * az))
        if k == 0:
            out[0, 0], out[0, 1] = roll_acc, pitch_acc
        else:
            out[k, 0] = a * (out[k - 1, 0] + gyr[k, 0] * dt) + (1.0 - a) * roll_acc
            out[k, 1] = a * (out[k - 1, 1] + gyr[k, 1] * dt) + (1.0 - a) * pitch_acc
