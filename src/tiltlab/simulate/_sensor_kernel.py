"""Numba kernel of :mod:`tiltlab.simulate.sensor`: the per-sample measurement loop.

:func:`tiltlab.simulate.apply_sensor_model` prepares its inputs and documents the
error model.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["measure_kernel"]


@njit(cache=True)
def measure_kernel(
    x,
    T,
    offset,
    temp_coef,
    dtemp,
    noise_sd,
    walk_sd,
    lo,
    hi,
    lsb,
    quantize,
    seed,
    out,
    bias_mean,
):
    """Fill ``out`` with the measured 3-axis signal and return the saturated count.

    ``y = Q(sat(T x + o + c dT + b + n))`` with ``b`` a random walk started at 0.

    Parameters
    ----------
    x : numpy.ndarray, shape (N, 3)
        True values.
    T : numpy.ndarray, shape (3, 3)
        Scale and misalignment matrix.
    offset, temp_coef : numpy.ndarray, shape (3,)
        Offset at the reference temperature and its temperature coefficients.
    dtemp : numpy.ndarray, shape (N,)
        Temperature minus the reference temperature.
    noise_sd, walk_sd : float
        White-noise standard deviation and bias random-walk step.
    lo, hi, lsb : float
        Saturation limits and quantisation step.
    quantize : bool
        Round to multiples of ``lsb``.
    seed : int
        Seed of numba's random generator.
    out : numpy.ndarray, shape (N, 3)
        Output: the measured signal.
    bias_mean : numpy.ndarray, shape (3,)
        Output: the mean of the random-walk bias.

    Returns
    -------
    int
        Number of saturated values.
    """
    np.random.seed(seed)
    n = x.shape[0]
    b0 = 0.0
    b1 = 0.0
    b2 = 0.0
    s0 = 0.0
    s1 = 0.0
    s2 = 0.0
    n_sat = 0
    for k in range(n):
        x0, x1, x2 = x[k, 0], x[k, 1], x[k, 2]
        for i in range(3):
            v = (
                T[i, 0] * x0
                + T[i, 1] * x1
                + T[i, 2] * x2
                + offset[i]
                + temp_coef[i] * dtemp[k]
            )
            if i == 0:
                v += b0
            elif i == 1:
                v += b1
            else:
                v += b2
            if noise_sd > 0.0:
                v += noise_sd * np.random.standard_normal()
            if v < lo:
                v = lo
                n_sat += 1
            elif v > hi:
                v = hi
                n_sat += 1
            if quantize:
                v = np.round(v / lsb) * lsb
            out[k, i] = v
        s0 += b0
        s1 += b1
        s2 += b2
        if walk_sd > 0.0:
            b0 += walk_sd * np.random.standard_normal()
            b1 += walk_sd * np.random.standard_normal()
            b2 += walk_sd * np.random.standard_normal()
    bias_mean[0] = s0 / n
    bias_mean[1] = s1 / n
    bias_mean[2] = s2 / n
    return n_sat
