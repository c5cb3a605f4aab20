"""The reorganised Madgwick kernels against the plain formulation they replace.

The kernels in ``tiltlab.filters._madgwick_kernel`` reorder the arithmetic of each step
(closed-form gradient for unit q, the norm of the step computed algebraically, a
polynomial for 1/sqrt(1 + eps)); here a plain loop, written as Madgwick's equations
read, is the reference.
"""

from __future__ import annotations

import importlib
import math

import numpy as np
import pytest

from tiltlab import filters

K = importlib.import_module("tiltlab.filters._madgwick_kernel")

_C = math.sqrt(0.5)


def _qmul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def _unit(v):
    n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return (v[0] / n, v[1] / n, v[2] / n) if n > 0.0 else None


def _mag_terms(w, x, y, z, m):
    # f_b and J_b^T f_b (Madgwick 2010, eqs. 29-32) for b from h = q m q*
    hw, hx, hy, hz = _qmul(_qmul((w, x, y, z), (0.0, *m)), (w, -x, -y, -z))
    bx, bz = math.sqrt(hx * hx + hy * hy), hz
    mx, my, mz = m
    f4 = 2 * bx * (0.5 - y * y - z * z) + 2 * bz * (x * z - w * y) - mx
    f5 = 2 * bx * (x * y - w * z) + 2 * bz * (w * x + y * z) - my
    f6 = 2 * bx * (w * y + x * z) + 2 * bz * (0.5 - x * x - y * y) - mz
    jt = (
        (-2 * bz * y, -2 * bx * z + 2 * bz * x, 2 * bx * y),
        (2 * bz * z, 2 * bx * y + 2 * bz * w, 2 * bx * z - 4 * bz * x),
        (-4 * bx * y - 2 * bz * w, 2 * bx * x + 2 * bz * z, 2 * bx * w - 4 * bz * y),
        (-4 * bx * z + 2 * bz * x, -2 * bx * w + 2 * bz * y, 2 * bx * x),
    )
    return [r[0] * f4 + r[1] * f5 + r[2] * f6 for r in jt]


def _gradient(q, a, m):
    # J^T f stacked over gravity and (with m) the magnetic field
    w, x, y, z = q
    f1 = 2 * (x * z - w * y) - a[0]
    f2 = 2 * (w * x + y * z) - a[1]
    f3 = 2 * (0.5 - x * x - y * y) - a[2]
    s = [
        -2 * y * f1 + 2 * x * f2,
        2 * z * f1 + 2 * w * f2 - 4 * x * f3,
        -2 * w * f1 + 2 * z * f2 - 4 * y * f3,
        2 * x * f1 + 2 * y * f2,
    ]
    if m is not None:
        s = [si + ti for si, ti in zip(s, _mag_terms(w, x, y, z, m), strict=True)]
    return s


def reference(acc, gyr, mag, fs, beta, q0):
    """Madgwick's update as written: q += (q (x) w / 2 - beta s/|s|) dt, normalised.

    Also returns, per sample, |v|^2 - 1 for the unnormalised v (the kernel's ``eps``).
    """
    dt = 1.0 / fs
    q = tuple(q0)
    if mag is not None:  # to Madgwick's NWU frame
        q = _qmul((_C, 0.0, 0.0, -_C), q)
    out = np.empty((len(acc), 4))
    eps = np.zeros(len(acc))
    out[0] = q0
    for k in range(1, len(acc)):
        dq = [0.5 * c for c in _qmul(q, (0.0, *gyr[k]))]
        a = _unit(acc[k])
        if a is not None:
            m = None if mag is None else _unit(mag[k])
            s = _gradient(q, a, m)
            sn = math.sqrt(sum(c * c for c in s))
            if sn > 0.0:
                dq = [d - beta * c / sn for d, c in zip(dq, s, strict=True)]
        v = [c + d * dt for c, d in zip(q, dq, strict=True)]
        n2 = sum(c * c for c in v)
        eps[k] = n2 - 1.0
        q = tuple(c / math.sqrt(n2) for c in v)
        out[k] = q if mag is None else _qmul((_C, 0.0, 0.0, _C), q)
    return out, eps


def _inputs(n, seed, *, fast=False):
    """Random sensors: zero acc and zero mag samples, and bursts of fast rotation."""
    rng = np.random.default_rng(seed)
    acc = rng.normal(size=(n, 3)) * 9.81 + [0.0, 0.0, 9.81]
    gyr = rng.normal(size=(n, 3)) * 2.0
    mag = rng.normal(size=(n, 3)) * 20.0 + [0.0, 20.0, -40.0]
    acc[rng.random(n) < 0.02] = 0.0
    mag[rng.random(n) < 0.02] = 0.0
    burst = rng.random(n) < (0.3 if fast else 0.05)
    gyr[burst] *= 15.0  # |w| ~ 50 rad/s: |v|^2 - 1 beyond the polynomial's range
    return acc, gyr, mag


def _q0(seed):
    q = np.random.default_rng(seed).normal(size=4)
    return q / np.linalg.norm(q)


@pytest.mark.parametrize("use_mag", [False, True])
@pytest.mark.parametrize(
    ("fs", "beta", "seed"), [(100.0, 0.1, 1), (300.0, 0.05, 2), (50.0, 5.0, 3)]
)
def test_kernel_matches_plain_formulation(use_mag, fs, beta, seed):
    # (a gradient step beta/fs much above 0.1 rad makes the update chaotic: rounding
    # differences then grow even between two orderings of the plain formulation)
    n = 20_000
    acc, gyr, mag = _inputs(n, seed)
    q0 = _q0(seed)
    m = mag if use_mag else None
    expected, eps = reference(acc, gyr, m, fs, beta, q0)
    # both ways of normalising are exercised: the polynomial and the exact one
    small = np.abs(eps[1:]) < K._EPS_POLY
    assert small.sum() > 100
    assert (~small).sum() > 100
    got = filters.madgwick(acc, gyr, fs, mag=m, beta=beta, q0=q0)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("use_mag", [False, True])
def test_kernel_matches_plain_formulation_long_smooth(use_mag):
    # a long sequence that stays on the polynomial path (slow motion, small gain), where
    # rounding differences would accumulate if they did not stay bounded
    n = 100_000
    fs = 200.0
    rng = np.random.default_rng(7)
    t = np.arange(n) / fs
    gyr = np.column_stack(
        [np.sin(0.7 * t), np.cos(0.4 * t + 1.0), 0.8 * np.sin(0.9 * t + 2.0)]
    )
    acc = [0.0, 0.0, 9.81] + 3.0 * rng.normal(size=(n, 3))
    mag = [0.0, 20.0, -40.0] + 10.0 * rng.normal(size=(n, 3))
    q0 = _q0(8)
    m = mag if use_mag else None
    expected, eps = reference(acc, gyr, m, fs, 0.05, q0)
    assert np.abs(eps[1:]).max() < K._EPS_POLY
    got = filters.madgwick(acc, gyr, fs, mag=m, beta=0.05, q0=q0)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)
    # no drift of the norm over the whole run
    assert np.abs(np.linalg.norm(got, axis=1) - 1.0).max() < 1e-15


def test_batch_equals_single_runs():
    acc, gyr, mag = _inputs(3000, 11, fast=True)
    betas = [0.0, 0.05, 3.0]
    for m in (None, mag):
        batch = filters.madgwick_batch(acc, gyr, 100.0, betas=betas, mag=m)
        for p, b in enumerate(betas):
            np.testing.assert_array_equal(
                batch[p], filters.madgwick(acc, gyr, 100.0, mag=m, beta=b)
            )


def test_inv_sqrt_polynomial_within_its_bound():
    # 1/sqrt(1 + eps) in extended precision against the float64 polynomial: the
    # truncation bound (231/1024 eps^6 / (1 - |eps|), < 1.5e-17) plus the rounding of
    # its last two operations (one unit in the last place of 1 at most)
    lim = K._EPS_POLY
    eps = np.concatenate(
        [np.linspace(-lim, lim, 20_001)[1:-1], np.geomspace(1e-18, lim, 2001)[:-1]]
    )
    eps = np.concatenate([eps, -eps, [0.0]])
    got = np.array([K._inv_sqrt_1p(e) for e in eps])
    exact = 1.0 / np.sqrt(np.longdouble(1.0) + eps.astype(np.longdouble))
    trunc = 231.0 / 1024.0 * eps**6 / (1.0 - np.abs(eps))
    assert trunc.max() < 1.5e-17
    err = np.abs(got.astype(np.longdouble) - exact)
    assert float(err.max()) <= 2.0**-52 + 1.5e-17
    # and it is as good as the plain float64 expression on average
    plain = 1.0 / np.sqrt(1.0 + eps)
    plain_err = np.abs(plain.astype(np.longdouble) - exact)
    assert float(err.mean()) <= float(plain_err.mean()) * 1.5 + 1e-20


def test_inv_polynomial_within_its_bound():
    # 1/(1 + eps) = (1 - eps)(1 + eps^2)(1 + eps^4) + eps^8/(1 + eps): the truncation is
    # negligible (< 2.6e-22); five rounded operations near 1 (half a unit in the last
    # place each) give at most 2.5 units, 2.5 * 2^-52 (as 1/(1 + eps) < 2)
    lim = K._EPS_POLY
    eps = np.linspace(-lim, lim, 40_001)[1:-1]
    got = np.array([K._inv_1p(e) for e in eps])
    exact = 1.0 / (np.longdouble(1.0) + eps.astype(np.longdouble))
    assert float(np.abs(got.astype(np.longdouble) - exact).max()) <= 2.5 * 2.0**-52


@pytest.mark.parametrize("use_mag", [False, True])
def test_any_accelerometer_scale(use_mag):
    # the 6D gradient uses |a| times the unit sample, except for tiny or huge |a|
    # (normalised first): samples at 1e-60, 1, 1e60 times their size give the same
    # orientations as the reference, which normalises each sample
    n = 5000
    acc, gyr, mag = _inputs(n, 21)
    scale = np.random.default_rng(22).choice([1e-60, 1e-45, 1.0, 1e45, 1e60], size=n)
    acc_scaled = acc * scale[:, None]
    assert (np.sum(acc_scaled**2, axis=1) > K._A2_MAX).any()
    assert ((np.sum(acc_scaled**2, axis=1) < K._A2_MIN) & (scale < 1)).any()
    m = mag if use_mag else None
    q0 = _q0(21)
    expected, _ = reference(acc_scaled, gyr, m, 100.0, 0.1, q0)
    got = filters.madgwick(acc_scaled, gyr, 100.0, mag=m, beta=0.1, q0=q0)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)
    unscaled = filters.madgwick(acc, gyr, 100.0, mag=m, beta=0.1, q0=q0)
    np.testing.assert_allclose(got, unscaled, rtol=0, atol=1e-12)


def test_repeated_normalisation_does_not_drift():
    # renormalise after small perturbations many times, as the filter does: the norm
    # (measured in extended precision) stays within two units in the last place of 1,
    # without a systematic drift, as with the exact expression
    rng = np.random.default_rng(5)
    q = _q0(5)
    dev = []
    for d in rng.normal(scale=1e-4, size=(100_000, 4)):
        v = q + d
        eps = float(v @ v) - 1.0
        assert abs(eps) < K._EPS_POLY
        q = v * K._inv_sqrt_1p(eps)
        dev.append(np.sqrt(np.sum(q.astype(np.longdouble) ** 2)) - 1)
    dev = np.array(dev, dtype=np.longdouble)
    assert float(np.abs(dev).max()) < 2 * 2.0**-52
    assert abs(float(dev.mean())) < 2e-17
    assert abs(float(dev[-10_000:].mean())) < 2e-17
