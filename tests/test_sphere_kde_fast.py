"""The vectorised spherical-KDE kernel sum against a direct evaluation of the same sum.

The mass-quadrature kernel sum (:func:`tiltlab.sphere.kde`) evaluates exp with its own
branch-free routine (``_exp_nonpos``) and sums each kernel's values in vectorised order,
so its arithmetic differs from a plain loop by rounding only: these tests bound the
routine against ``numpy.exp`` (2 ulp) and the whole KDE against a brute-force evaluation
of the same truncated, mass-normalised kernels over every cell of the grid (1e-13).
"""

import math

import numpy as np
import pytest

from tiltlab import sphere as S
from tiltlab.sphere._kde_kernel import _cell_tables, _exp_nonpos
from tiltlab.sphere.mesh import to_lonlat

ULP = np.finfo(float).eps  # 2^-52


def test_exp_nonpos_is_exp_within_two_ulp():
    rng = np.random.default_rng(0)
    x = np.concatenate(
        [
            -rng.random(200_000) * 746.0,
            -rng.random(50_000) * 30.0,
            -rng.random(10_000) * 1e-6,
            [0.0, -0.0, -5e-324, -1e-300, -0.5 * np.log(2), -np.log(2), -708.39],
            [-708.4, -709.0, -744.4, -745.1, -745.13],
        ]
    )
    got = np.array([_exp_nonpos(v) for v in x])
    ref = np.exp(x)
    normal = ref >= np.finfo(float).tiny
    rel = np.abs(got[normal] - ref[normal]) / ref[normal]
    assert rel.max() <= 2 * ULP
    # subnormal results: within one unit of the last (subnormal) place
    assert np.abs(got[~normal] - ref[~normal]).max() <= 5e-324
    assert _exp_nonpos(0.0) == 1.0


def test_exp_nonpos_underflows_to_zero_and_ignores_nan():
    for v in (-746.0, -800.0, -1e300, -np.inf, np.nan):
        assert _exp_nonpos(v) == 0.0


def _brute_mass_kde(x, w, h, grid, kernel="vmf", tol=1e-10):
    """Evaluate the mass quadrature of ``kde`` cell by cell, kernel by kernel.

    Each kernel: the cosine of its distance to every cell centre (the kernel's own
    arithmetic and tables), the largest, values exp(κ(cos - largest)) truncated where
    below ``tol`` (inside the cap of the module's notes, whose margin keeps every
    non-zero value), divided by their sum times the cell area.
    """
    n_lon, n_lat = grid.n_lon, grid.n_lat
    clon, slon, sc, cc = _cell_tables(n_lon, n_lat)
    area = (2.0 * np.pi / n_lon) * (2.0 / n_lat)
    g = grid.to_grid_frame(x)
    lon, _ = to_lonlat(g)
    s = np.clip(g[:, 2], -1.0, 1.0)
    log_tol = math.log(tol)
    acc = np.zeros((n_lat, n_lon))
    for i in range(x.shape[0]):
        k = 1.0 / h**2
        si, ci = s[i], math.sqrt(max(1.0 - s[i] * s[i], 0.0))
        cl, sl = math.cos(lon[i]), math.sin(lon[i])
        cosd = si * sc[:, None] + (ci * cc)[:, None] * (clon * cl + slon * sl)[None, :]
        r_own = min(max(int((si + 1.0) / (2.0 / n_lat)), 0), n_lat - 1)
        j_own = min(max(int((lon[i] + np.pi) / (2.0 * np.pi / n_lon)), 0), n_lon - 1)
        c_own = si * sc[r_own] + ci * cc[r_own] * (clon[j_own] * cl + slon[j_own] * sl)
        cos_cut = min(c_own, 1.0) - 1e-12 + log_tol / k
        cap = cosd >= cos_cut
        d = np.where(cap, cosd - cosd[cap].max(), -np.inf)
        with np.errstate(invalid="ignore", over="ignore"):
            xx = np.where(d < 0, k * d, 0.0)
        e = np.where(xx >= log_tol, np.exp(xx), 0.0)
        m = w[i] if kernel == "vmf" else w[i] * -np.expm1(-2.0 * k)
        acc += m / (e.sum() * area) * e
    return acc / w.sum()


def _samples(where, rng, n, grid):
    if where == "seam":  # longitude ±180° of the grid: rows wrap
        lon = np.pi + rng.normal(size=n) * 0.05
        lat = rng.normal(size=n) * 0.1
        return S.from_lonlat(lon, lat) @ grid.rotation.T
    if where == "pole":  # caps around the grid's pole: whole rows
        return S.vmf_sample([0.0, 0.0, 1.0], 400.0, n, rng)
    return S.vmf_sample(rng.normal(size=3), 20.0, n, rng)


@pytest.mark.parametrize("kernel", ["vmf", "gauss"])
@pytest.mark.parametrize("h", [0.004, 0.03, 0.15, 0.7, 3.0])
@pytest.mark.parametrize("where", ["seam", "pole", "random"])
def test_mass_kde_equals_brute_force_sum(where, h, kernel):
    rng = np.random.default_rng(11)
    grid = S.equal_area_grid(4.0)  # pole along z
    x = _samples(where, rng, 30, grid)
    w = rng.random(30) + 0.1
    got = S.kde(x, grid=grid, h=h, weights=w, kernel=kernel).density
    ref = _brute_mass_kde(x, w, h, grid, kernel)
    np.testing.assert_allclose(got, ref, rtol=1e-13, atol=1e-13 * ref.max())
    assert np.array_equal(got > 0, ref > 0)


@pytest.mark.parametrize("tol", [1e-3, 1e-10, 1e-200])
def test_mass_kde_equals_brute_force_sum_tilted_grid_and_tol(tol):
    rng = np.random.default_rng(12)
    grid = S.equal_area_grid(3.0, pole=[0.3, -0.2, 1.0])
    x = _samples("random", rng, 40, grid)
    w = np.ones(40)
    got = S.kde(x, grid=grid, h=0.08, tol=tol).density
    ref = _brute_mass_kde(x, w, 0.08, grid, tol=tol)
    np.testing.assert_allclose(got, ref, rtol=1e-13, atol=1e-13 * ref.max())
    assert np.array_equal(got > 0, ref > 0)


def test_kde_does_not_depend_on_the_number_of_threads():
    """The chunking of the kernel sum is fixed, so the density is bit-identical with
    one thread (a cohort worker) and with several."""
    import numba

    from tiltlab import sphere

    rng = np.random.default_rng(7)
    x = rng.normal(size=(5000, 3)) + [0.0, 0.0, 2.0]
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = sphere.kde(x, cell_deg=2.0)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = sphere.kde(x, cell_deg=2.0)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one.density, many.density)
    assert one.h == many.h
