"""Numba helpers that the filters share.

Reading a unit sample, Mahony's gravity error and attitude step, scanning inputs once.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..quaternion import qmul_scalar, rotate_scalar


@njit(cache=True, nogil=True, inline="always")
def _unit_sample(a, k):
    # row k of the (N, 3) array a divided by its norm, and the norm; the row as it is
    # when its norm is zero
    x, y, z = a[k, 0], a[k, 1], a[k, 2]
    n = np.sqrt(x * x + y * y + z * z)
    if n > 0.0:
        r = 1.0 / n  # one division, three products (the loops are latency-bound)
        return x * r, y * r, z * r, n
    return x, y, z, n


@njit(cache=True, nogil=True, inline="always")
def _gravity_error(w, x, y, z, ax, ay, az):
    # a × v for the unit measured direction a and the estimated gravity-up in the
    # sensor frame v = R(q)^T e_z: the correction of Mahony's explicit filter
    vx, vy, vz = rotate_scalar(w, -x, -y, -z, 0.0, 0.0, 1.0)
    return ay * vz - az * vy, az * vx - ax * vz, ax * vy - ay * vx


@njit(cache=True, nogil=True, inline="always")
def _attitude_step(w, x, y, z, ox, oy, oz, h):
    # q <- (q + h q ⊗ (0, Ω)) / ‖·‖ with h = Δt/2 (first-order integration)
    dw, dx, dy, dz = qmul_scalar(w, x, y, z, 0.0, ox, oy, oz)
    nw, nx, ny, nz = w + h * dw, x + h * dx, y + h * dy, z + h * dz
    n = np.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
    return nw / n, nx / n, ny / n, nz / n


@njit(cache=True, nogil=True)
def _scan_samples(x):
    # one pass over an (N, 3) array: NaN count, ±inf count, whether any value is
    # non-zero, largest absolute finite value
    n_nan = 0
    n_inf = 0
    nonzero = False
    peak = 0.0
    for k in range(x.shape[0]):
        for j in range(x.shape[1]):
            v = x[k, j]
            if v != v:
                n_nan += 1
            elif v == np.inf or v == -np.inf:
                n_inf += 1
            else:
                if v != 0.0:
                    nonzero = True
                a = abs(v)
                if a > peak:
                    peak = a
    return n_nan, n_inf, nonzero, peak
