"""Numba helpers that the filters' kernels share: reading a unit sample."""

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
        return x / n, y / n, z / n, n
    return x, y, z, n
