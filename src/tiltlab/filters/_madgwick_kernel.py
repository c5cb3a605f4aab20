"""Numba kernels of Madgwick's filter: 6D and 9D loops and a parallel gain batch.

The loop is latency-bound on the per-sample chain q -> gradient s -> |s| -> step ->
|q| -> q (about 32 ns per sample written plainly), so each step keeps that chain short
(about 16 ns per 6D sample, 30 ns per 9D sample):

* the gyroscope half-step ``u = q + dt/2 q (x) (0, w)``, ``|u|^2`` and ``u . s`` run
  beside the gradient; the norm of ``v = u - g s``, ``g = beta dt / |s|``, is then
  ``|v|^2 = |u|^2 - 2 g (u . s) + (beta dt)^2`` (as ``g^2 |s|^2 = (beta dt)^2``): one
  product and one sum after the square root of ``|s|^2`` instead of a dot product of v;
* ``1/|v|`` (and ``1/|v|^2``) are polynomials in ``eps = |v|^2 - 1`` when
  ``|eps| < _EPS_POLY`` (``_inv_sqrt_1p``, ``_inv_1p``), the exact expression otherwise;
* the gradient uses ``|q| = 1``: ``J^T f / 4 = rho q - J^T a / 4`` with
  ``rho = x^2 + y^2`` for gravity, and the analogous closed form for the magnetic
  field (``_marg_gradient``), fewer dependent products;
* 6D: the state is kept as ``q = r v`` (v and ``r^2``), so the next gradient starts
  from v and waits only for ``r^2``; the accelerometer sample is used as it is, the
  gradient scaled by ``|a|`` (a square root, no division per sample).

The results equal the plain formulation to rounding (tests/test_madgwick_speed_*.py).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..quaternion import qmul_scalar, rotate_scalar
from ._shared_kernel import _unit_sample

_C = 0.7071067811865476  # cos 45° = sin 45°

#: |eps| below which 1/sqrt(1 + eps) is its degree-5 Taylor polynomial. The series
#: sum_k c_k eps^k, c_k = binom(-1/2, k) = (-1)^k (2k-1)!!/(2k)!!, has
#: |c_{k+1}/c_k| = (2k+1)/(2k+2) < 1. For eps > 0 it alternates with decreasing terms,
#: so the error after the eps^5 term is at most |c_6| eps^6 = 231/1024 eps^6; for
#: eps < 0 all terms are positive and the tail is at most
#: |c_6| |eps|^6 sum_j |eps|^j = 231/1024 |eps|^6/(1 - |eps|). With |eps| < 2e-3 both
#: are < 231/1024 * 6.4e-17 / 0.998 < 1.5e-17, 0.07 units in the last place of 1.
_EPS_POLY = 2e-3

#: |a|^2 range in which the 6D gradient uses the raw sample a (times |a|): its
#: square stays far from overflow and underflow
_A2_MIN = 1e-100
_A2_MAX = 1e100

#: |s|^2 above which g = sqrt(|s|^2) * (beta dt / |s|^2) cannot overflow (below it,
#: g = beta dt / sqrt(|s|^2), the plain way)
_S2_MIN = 1e-150


@njit(cache=True, nogil=True, inline="always")
def _inv_sqrt_1p(eps):
    # 1/sqrt(1 + eps) = 1 - eps/2 + 3/8 eps^2 - 5/16 eps^3 + 35/128 eps^4 - 63/256 eps^5
    # (+ error < 1.5e-17 for |eps| < _EPS_POLY), as a + (e^2 b + e^4 c) (Estrin's
    # scheme: 5 dependent operations instead of Horner's 10)
    e2 = eps * eps
    a = 1.0 - 0.5 * eps
    b = 0.375 - 0.3125 * eps
    c = 0.2734375 - 0.24609375 * eps
    return a + (e2 * b + (e2 * e2) * c)


@njit(cache=True, nogil=True, inline="always")
def _inv_1p(eps):
    # 1/(1 + eps) = sum_{i<8} (-eps)^i + eps^8/(1 + eps)
    #             = (1 - eps)(1 + eps^2)(1 + eps^4) + error < 2.6e-22 (|eps| < _EPS_POLY)
    e2 = eps * eps
    return ((1.0 - eps) * (1.0 + e2)) * (1.0 + e2 * e2)


@njit(cache=True, nogil=True, inline="always")
def _half_step(w, x, y, z, gyr, k, hd):
    # u = q + dt/2 q (x) (0, w): the gyroscope part of the step (hd = dt/2)
    gx, gy, gz = hd * gyr[k, 0], hd * gyr[k, 1], hd * gyr[k, 2]
    return (
        w - (x * gx + y * gy + z * gz),
        x + (w * gx + y * gz - z * gy),
        y + (w * gy - x * gz + z * gx),
        z + (w * gz + x * gy - y * gx),
    )


@njit(cache=True, nogil=True, inline="always")
def _advance(uw, ux, uy, uz, s0, s1, s2, s3, h):
    # v = u - h s/|s| (v = u when s = 0), h = beta dt, and r = 1/|v|, r2 = r^2: the
    # next orientation is q_k = r v
    uu = (uw * uw + ux * ux) + (uy * uy + uz * uz)
    s2n = (s0 * s0 + s1 * s1) + (s2 * s2 + s3 * s3)
    us = (uw * s0 + ux * s1) + (uy * s2 + uz * s3)
    # |v|^2 - 1 = (|u|^2 - 1) + h^2 - 2 g (u . s)
    if s2n > _S2_MIN:
        # g = h/|s| = |s| (h/|s|^2): the division needs only |s|^2, and eps is one
        # product and one sum after the square root
        sn = np.sqrt(s2n)
        hs = h / s2n
        g = sn * hs
        eps = ((uu - 1.0) + h * h) + sn * (-(us + us) * hs)
    elif s2n > 0.0:
        g = h / np.sqrt(s2n)
        eps = ((uu - 1.0) + h * h) - (us + us) * g
    else:
        g = 0.0
        eps = uu - 1.0
    vw, vx, vy, vz = uw - g * s0, ux - g * s1, uy - g * s2, uz - g * s3
    if abs(eps) < _EPS_POLY:
        r = _inv_sqrt_1p(eps)
        r2 = _inv_1p(eps)
    else:
        r = 1.0 / np.sqrt((vw * vw + vx * vx) + (vy * vy + vz * vz))
        r2 = r * r
    return vw, vx, vy, vz, r, r2


@njit(cache=True, nogil=True, inline="always")
def _gravity_gradient(w, x, y, z, ax, ay, az, r2, an):
    # Madgwick's J^T f / 4 for f = R(q)^T e_z - a (unit q, unit a): with
    # rho = x^2 + y^2, J^T R^T e_z = 4 rho q, and J^T a is linear in q. For q = r v
    # given as v and r2 = r^2, and a given as an * (unit a), the same times an/r:
    # r2 an rho(v) v - J^T(v) a / 4 (r2 multiplies last: v is known before r2)
    rho = an * (x * x + y * y)
    ha, hb = 0.5 * ax, 0.5 * ay
    return (
        r2 * (rho * w) - (x * hb - y * ha),
        r2 * (rho * x) - ((z * ha + w * hb) - x * az),
        r2 * (rho * y) - ((z * hb - w * ha) - y * az),
        r2 * (rho * z) - (x * ha + y * hb),
    )


@njit(cache=True, nogil=True, inline="always")
def _scaled_sample(a, k):
    # row k of a as (x, y, z, n) = n * (unit vector), with n = |a_k| and the row as it
    # is, so that a gradient computed with it is n times the one with the unit vector
    # (only the direction of the gradient matters): a square root but no division per
    # sample. A unit vector and n = 1 when |a_k|^2 is outside (_A2_MIN, _A2_MAX), the
    # zero row and n = 0 when it is zero.
    x, y, z = a[k, 0], a[k, 1], a[k, 2]
    a2 = x * x + y * y + z * z
    n = np.sqrt(a2)
    if not (_A2_MIN < a2 < _A2_MAX) and a2 > 0.0:
        r = 1.0 / n
        return x * r, y * r, z * r, 1.0
    return x, y, z, n


@njit(cache=True, nogil=True)
def _madgwick6_kernel(acc, gyr, dt, beta, q0, out):
    # the state is q = r v, kept as v and r, r2 = r^2: the next gradient (s/r) and
    # half-step (u/r) start from v, and r2 comes from eps as soon as r
    vw, vx, vy, vz = q0[0], q0[1], q0[2], q0[3]
    r, r2 = 1.0, 1.0
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = vw, vx, vy, vz
    hd = 0.5 * dt
    h = beta * dt
    for k in range(1, acc.shape[0]):
        tw, tx, ty, tz = _half_step(vw, vx, vy, vz, gyr, k, hd)
        ax, ay, az, an = _scaled_sample(acc, k)
        s0, s1, s2, s3 = 0.0, 0.0, 0.0, 0.0
        if an > 0.0:
            s0, s1, s2, s3 = _gravity_gradient(vw, vx, vy, vz, ax, ay, az, r2, an)
        vw, vx, vy, vz, r, r2 = _advance(
            r * tw, r * tx, r * ty, r * tz, s0, s1, s2, s3, h
        )
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = vw * r, vx * r, vy * r, vz * r


@njit(cache=True, nogil=True, inline="always")
def _marg_gradient(w, x, y, z, ax, ay, az, mx, my, mz):
    # Madgwick's (J^T f + J_b^T f_b) / 4, f_b = R(q)^T b - m, b = (b_x, 0, b_z) =
    # (|h_xy|, 0, h_z), h = R(q) m (unit q, a, m). As for gravity,
    # J_b^T R^T b = 2 (|b|^2 - b . R^T b) q = 4 (b_x^2 (y^2 + z^2) - 2 b_x b_z x z
    # + b_z^2 rho) q, and J_b^T m = b_x A + b_z B is linear in q. Only the terms in b_x
    # (not b_x^2 = h_x^2 + h_y^2) wait for the square root:
    # s = [(rho + k0) q - J^T a/4 - b_z B/2] - b_x [2 b_z x z q + A/2]
    hx, hy, hz = rotate_scalar(w, x, y, z, mx, my, mz)
    bx2 = hx * hx + hy * hy
    bx = np.sqrt(bx2)
    bz = hz
    ha, hb = 0.5 * ax, 0.5 * ay
    ma, mb, mc = 0.5 * mx, 0.5 * my, 0.5 * mz
    rho = x * x + y * y
    k = rho + (bx2 * (y * y + z * z) + (bz * bz) * rho)
    c = (bz + bz) * (x * z)
    w0 = k * w - ((x * hb - y * ha) + bz * (x * mb - y * ma))
    w1 = k * x - (((z * ha + w * hb) - x * az) + bz * ((z * ma + w * mb) - x * mz))
    w2 = k * y - (((z * hb - w * ha) - y * az) + bz * ((z * mb - w * ma) - y * mz))
    w3 = k * z - ((x * ha + y * hb) + bz * (x * ma + y * mb))
    v0 = c * w + (y * mc - z * mb)
    v1 = c * x + (y * mb + z * mc)
    v2 = c * y + ((x * mb + w * mc) - y * mx)
    v3 = c * z + ((x * mc - w * mb) - z * mx)
    return w0 - bx * v0, w1 - bx * v1, w2 - bx * v2, w3 - bx * v3


@njit(cache=True, nogil=True)
def _madgwick9_kernel(acc, gyr, mag, dt, beta, q0, out):
    # q0 and out in ENU; the update runs in Madgwick's NWU earth frame:
    # q_nwu = Rz(-90°) (x) q_enu, q_enu = Rz(+90°) (x) q_nwu
    c = _C
    w, x, y, z = qmul_scalar(c, 0.0, 0.0, -c, q0[0], q0[1], q0[2], q0[3])
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = q0[0], q0[1], q0[2], q0[3]
    hd = 0.5 * dt
    h = beta * dt
    for k in range(1, acc.shape[0]):
        uw, ux, uy, uz = _half_step(w, x, y, z, gyr, k, hd)
        ax, ay, az, an = _unit_sample(acc, k)
        s0, s1, s2, s3 = 0.0, 0.0, 0.0, 0.0
        if an > 0.0:
            mx, my, mz, mn = _unit_sample(mag, k)
            if mn > 0.0:
                s0, s1, s2, s3 = _marg_gradient(w, x, y, z, ax, ay, az, mx, my, mz)
            else:
                s0, s1, s2, s3 = _gravity_gradient(w, x, y, z, ax, ay, az, 1.0, 1.0)
        w, x, y, z, r, _ = _advance(uw, ux, uy, uz, s0, s1, s2, s3, h)
        w, x, y, z = w * r, x * r, y * r, z * r
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = qmul_scalar(
            c, 0.0, 0.0, c, w, x, y, z
        )


@njit(cache=True, nogil=True)
def _madgwick_kernel(acc, gyr, mag, use_mag, dt, beta, q0, out):
    # one sequence into out (N, 4): the 9D loop with use_mag, else the 6D one
    if use_mag:
        _madgwick9_kernel(acc, gyr, mag, dt, beta, q0, out)
    else:
        _madgwick6_kernel(acc, gyr, dt, beta, q0, out)


@njit(cache=True, nogil=True, parallel=True)
def _madgwick_batch_kernel(acc, gyr, mag, use_mag, dt, betas, q0, out):
    for p in prange(betas.shape[0]):
        _madgwick_kernel(acc, gyr, mag, use_mag, dt, betas[p], q0, out[p])
