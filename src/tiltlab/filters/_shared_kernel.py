"""Numba helpers that the filters share: reading a unit sample, scanning inputs once."""

from __future__ import annotations

import numpy as np
from numba import njit


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
