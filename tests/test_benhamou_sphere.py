"""Benhamou 2023 §7 and App. C on the sphere: biased random bridges, residence maps,
and kernel densities of changes of heading (invariants and bad inputs)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs
from scipy.stats import vonmises

from tiltlab import sphere


def _arc_path(n, lon_span, fs=1.0, lat=0.0):
    lon = np.linspace(0.0, lon_span, n)
    x = np.column_stack(
        [np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.full(n, np.sin(lat))]
    )
    return x, fs


def _l1(a, b):
    return sphere.kde_distance(a, b)


# --- the bridge's kernel width ------------------------------------------------------


@settings(max_examples=40, deadline=None)
@given(
    alpha=hs.floats(0.0, 1.0),
    dt=hs.floats(0.0, 1e3),
    h_min=hs.floats(1e-4, 1.0),
    d=hs.floats(0.0, 10.0),
)
def test_bridge_width_bounds_and_symmetry(alpha, dt, h_min, d):
    h = sphere.bridge_bandwidth(alpha, dt, h_min, d)
    top = np.sqrt(h_min**2 + d * dt / 2)  # Brownian-bridge variance 2DΔt·¼ at α = ½
    assert h_min * (1 - 1e-12) <= h <= top * (1 + 1e-12)
    assert np.isclose(h, sphere.bridge_bandwidth(1 - alpha, dt, h_min, d), rtol=1e-12)


def test_bridge_width_is_h_min_at_the_fixes_and_largest_in_the_middle():
    a = np.linspace(0, 1, 101)
    h = sphere.bridge_bandwidth(a, 4.0, 0.1, 0.02)
    assert h[0] == h[-1] == 0.1
    assert np.argmax(h) == 50
    assert np.isclose(h[50] ** 2, 0.1**2 + 0.02 * 4.0 / 2)


@pytest.mark.parametrize(
    "kw, word",
    [
        ({"alpha": 1.5}, "alpha"),
        ({"alpha": -0.1}, "alpha"),
        ({"dt": -1.0}, "dt"),
        ({"h_min": 0.0}, "h_min"),
        ({"diffusion": -1.0}, "diffusion"),
    ],
)
def test_bridge_width_bad_inputs_name_the_problem(kw, word):
    args = {"alpha": 0.5, "dt": 1.0, "h_min": 0.1, "diffusion": 0.1, **kw}
    with pytest.raises(ValueError, match=word):
        sphere.bridge_bandwidth(**args)


# --- the diffusion coefficient --------------------------------------------------------


def test_brb_diffusion_recovers_a_simulated_random_walk():
    # an isotropic random walk on the sphere: per-axis variance 2D per second in the
    # tangent plane of the current direction
    rng = np.random.default_rng(3)
    d_true, n = 2e-4, 6001
    x = np.empty((n, 3))
    x[0] = [0.0, 0.0, 1.0]
    for i in range(1, n):
        v = rng.normal(0.0, np.sqrt(2 * d_true), 3)
        v -= (v @ x[i - 1]) * x[i - 1]
        y = x[i - 1] + v
        x[i] = y / np.linalg.norm(y)
    est = sphere.brb_diffusion(x, fs=1.0, h_min=1e-5)
    # 3000 independent triplets: the ML estimate's relative SE is about 1/sqrt(3000)
    assert abs(est / d_true - 1) < 0.1


def test_brb_diffusion_of_a_uniform_arc_is_at_the_lower_bound():
    x, fs = _arc_path(101, 1.0)
    assert sphere.brb_diffusion(x, fs=fs, h_min=0.01) <= 1e-8


# --- the movement-based KDE -----------------------------------------------------------


@pytest.mark.parametrize("weighting", ["time", "residence", "visits"])
def test_brb_integrates_to_one(weighting):
    rng = np.random.default_rng(0)
    x = sphere.vmf_sample([0.0, 0.0, 1.0], 30.0, 60, rng)
    u = sphere.brb(
        x,
        fs=2.0,
        h_min=0.08,
        diffusion=0.01,
        cell_deg=3.0,
        weighting=weighting,
        caps=(0.2, 1.0),
    )
    assert abs(u.integral() - 1) < 1e-9
    assert np.all(u.density >= 0)


def test_brb_reduces_to_the_location_kde_when_steps_vanish():
    # steps of h/100: the kernels along the arcs are the sample kernels, shifted by
    # a fraction of a step, so the two densities agree to about step/h
    h = 0.1
    x, fs = _arc_path(2001, 2.0)  # 1e-3 rad per step
    lk = sphere.kde(x, h=h, cell_deg=2.0)
    mk = sphere.brb(x, fs=fs, h_min=h, diffusion=0.0, grid=lk.grid)
    assert _l1(mk, lk) < 5e-3
    # with steps of 2h the fixes alone leave gaps that the bridges fill
    xs = x[::200]
    lk_s = sphere.kde(xs, h=h, grid=lk.grid)
    mk_s = sphere.brb(xs, fs=fs / 200, h_min=h, diffusion=0.0, grid=lk.grid)
    assert _l1(lk_s, lk) > 10 * _l1(mk_s, lk)


def test_brb_static_track_is_the_kernel_of_the_fix():
    x = np.tile([0.3, -0.2, 0.9], (20, 1))
    lk = sphere.kde(x[:1], h=0.1, cell_deg=2.0)
    for w in ("time", "residence", "visits"):
        mk = sphere.brb(
            x,
            fs=1.0,
            h_min=0.1,
            diffusion=0.5,
            l_min=1e-6,
            grid=lk.grid,
            weighting=w,
            caps=(0.2, 1.0),
        )
        assert _l1(mk, lk) < 1e-9  # steps below l_min: no bridge spread, one visit
    spread = sphere.brb(x, fs=1.0, h_min=0.1, diffusion=0.5, grid=lk.grid)
    assert spread.density.max() < lk.density.max()  # l_min = 0: bridges may wander


def test_brb_diffusion_widens_only_moving_steps():
    x, fs = _arc_path(11, 1.0)
    grid = sphere.kde(x, h=0.05, cell_deg=2.0).grid
    still = sphere.brb(x, fs=fs, h_min=0.05, diffusion=0.0, grid=grid)
    wide = sphere.brb(x, fs=fs, h_min=0.05, diffusion=0.01, grid=grid)
    short = sphere.brb(x, fs=fs, h_min=0.05, diffusion=0.01, l_min=0.2, grid=grid)
    assert wide.density.max() < still.density.max()
    assert _l1(short, still) < 1e-12  # every step (0.1 rad) is below l_min


def test_brb_rotation_about_the_grid_pole_rolls_the_density():
    grid = sphere.equal_area_grid(4.0)
    rng = np.random.default_rng(1)
    x = sphere.vmf_sample(sphere.from_lonlat(0.4, 0.3), 20.0, 40, rng)
    dlon = 2 * np.pi / grid.n_lon
    c, s = np.cos(dlon), np.sin(dlon)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    kw = dict(fs=1.0, h_min=0.1, diffusion=0.02, grid=grid, caps=(0.3, 2.0))
    for w in ("time", "visits"):
        a = sphere.brb(x, weighting=w, **kw).density
        b = sphere.brb(x @ R.T, weighting=w, **kw).density
        np.testing.assert_allclose(np.roll(a, 1, axis=1), b, rtol=1e-9, atol=1e-12)


def test_residence_weighting_is_time_for_single_visits():
    # a monotone arc visits every cap once: the ID equals the UD
    x, fs = _arc_path(41, 2.0)
    grid = sphere.kde(x, h=0.1, cell_deg=3.0).grid
    kw = dict(fs=fs, h_min=0.1, diffusion=0.0, grid=grid, caps=(0.15, 1.0))
    ud = sphere.brb(x, **kw)
    idd = sphere.brb(x, weighting="residence", **kw)
    assert _l1(idd, ud) < 1e-9


def test_visits_weighting_favours_the_revisited_direction():
    # alternate A (1 s) and B (5 s) three times: B holds more time, A as many visits
    a, b = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    x = np.vstack([np.tile(a, (2, 1)), np.tile(b, (6, 1))] * 3)
    grid = sphere.equal_area_grid(3.0)
    kw = dict(fs=1.0, h_min=0.1, diffusion=0.0, grid=grid, caps=(0.2, 0.5))
    cells = [
        np.unravel_index(
            np.argmin(np.linalg.norm(grid.centres() - v, axis=-1)), grid.shape
        )
        for v in (a, b)
    ]
    ud = sphere.brb(x, **kw).density
    rd = sphere.brb(x, weighting="visits", **kw).density
    assert ud[cells[1]] > 2 * ud[cells[0]]
    assert rd[cells[1]] / rd[cells[0]] < ud[cells[1]] / ud[cells[0]] / 2


@pytest.mark.parametrize(
    "kw, err, word",
    [
        ({"weighting": "space"}, ValueError, "weighting"),
        ({"weighting": "visits"}, ValueError, "caps"),
        ({"h_min": -1.0}, ValueError, "h_min"),
        ({"diffusion": -1.0}, ValueError, "diffusion"),
        ({"l_min": -1.0}, ValueError, "l_min"),
        ({"t_max": 0.0}, ValueError, "t_max"),
        ({"t_max": 0.5}, ValueError, "max_gap"),
        ({"bogus": 1}, TypeError, "bogus"),
    ],
)
def test_brb_bad_inputs_name_the_problem(kw, err, word):
    x, fs = _arc_path(5, 0.5)
    args = {"fs": fs, "h_min": 0.1, "diffusion": 0.0, "cell_deg": 10.0, **kw}
    with pytest.raises(err, match=word):
        sphere.brb(x, **args)


def test_brb_diffusion_bad_inputs():
    x, fs = _arc_path(5, 0.5)
    with pytest.raises(ValueError, match="at least 3"):
        sphere.brb_diffusion(x[:2], fs=fs, h_min=0.1)
    with pytest.raises(ValueError, match="bounds"):
        sphere.brb_diffusion(x, fs=fs, h_min=0.1, bounds=(1.0, 0.1))
    with pytest.raises(ValueError, match="t_max"):
        sphere.brb_diffusion(x, fs=fs, h_min=0.1, t_max=1.0)


# --- residence per grid node ----------------------------------------------------------


def test_residence_map_of_a_static_track_is_its_duration_within_r():
    x = np.tile([0.0, 0.0, 1.0], (31, 1))  # 30 s at the pole
    grid = sphere.equal_area_grid(10.0)
    r = 0.5
    m = sphere.residence_map(x, grid, r, 1.0, fs=1.0)
    inside = grid.centres()[..., 2] >= np.cos(r)
    assert np.all(m.total[inside] == 30.0) and np.all(m.total[~inside] == 0.0)
    assert np.all(m.n_visits[inside] == 1) and np.all(m.n_visits[~inside] == 0)
    assert np.all(np.isnan(m.mean_residence[~inside]))


@pytest.mark.parametrize("t_out, visits", [(0.5, 4), (10.0, 1)])
def test_residence_map_counts_re_entries(t_out, visits):
    # four stays at the pole separated by 2-s excursions to the equator
    up, side = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    x = np.vstack(
        [np.tile(up, (3, 1)), np.tile(side, (3, 1))] * 3 + [np.tile(up, (3, 1))]
    )
    grid = sphere.equal_area_grid(10.0)
    m = sphere.residence_map(x, grid, 0.5, t_out, fs=1.0)
    top = grid.centres()[..., 2].argmax(axis=0)[0]
    assert m.n_visits[top, 0] == visits


def test_residence_map_is_rotation_invariant():
    rng = np.random.default_rng(2)
    x = sphere.vmf_sample([0.0, 0.0, 1.0], 5.0, 200, rng)
    grid = sphere.equal_area_grid(15.0)
    dlon = 2 * np.pi / grid.n_lon
    c, s = np.cos(dlon), np.sin(dlon)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    a = sphere.residence_map(x, grid, 0.3, 2.0, fs=10.0)
    b = sphere.residence_map(x @ R.T, grid, 0.3, 2.0, fs=10.0)
    np.testing.assert_array_equal(np.roll(a.n_visits, 1, axis=1), b.n_visits)
    np.testing.assert_allclose(np.roll(a.total, 1, axis=1), b.total, atol=1e-9)


def test_residence_map_refuses_a_mesh():
    with pytest.raises(ValueError, match="grid"):
        sphere.residence_map(np.eye(3), np.eye(3), 0.3, 1.0, fs=1.0)


# --- changes of heading -----------------------------------------------------------------


@settings(max_examples=30, deadline=None)
@given(d=hs.floats(-10.0, 10.0), w=hs.floats(0.0, np.pi))
def test_heading_change_vector_is_unit_with_size_as_colatitude(d, w):
    u = sphere.heading_change_vectors([d], [w])[0]
    assert np.isclose(np.linalg.norm(u), 1.0)
    assert np.isclose(np.arccos(np.clip(u[2], -1, 1)), w, atol=1e-7)


def test_heading_change_vector_inverts_an_arc():
    # the arc from the pole to a point: size = its colatitude, direction = its longitude
    rng = np.random.default_rng(5)
    d, w = rng.uniform(-np.pi, np.pi, 50), rng.uniform(0.01, 3.1, 50)
    u = sphere.heading_change_vectors(d, w)
    np.testing.assert_allclose(sphere.angle(u, [0.0, 0.0, 1.0]), w, atol=1e-12)
    lon, _ = sphere.to_lonlat(u)
    np.testing.assert_allclose(np.angle(np.exp(1j * (lon - d))), 0.0, atol=1e-12)


def test_heading_change_kde_integrates_to_one():
    rng = np.random.default_rng(0)
    k = sphere.heading_change_kde(
        rng.uniform(-np.pi, np.pi, 300), rng.uniform(0, 0.5, 300), h=0.1, cell_deg=3.0
    )
    assert abs(k.integral() - 1) < 1e-9


@pytest.mark.parametrize(
    "d, w, word",
    [
        ([0.0, 1.0], [0.1], "same shape"),
        ([0.0], [4.0], "size"),
        ([0.0], [-0.1], "size"),
    ],
)
def test_heading_change_bad_inputs(d, w, word):
    with pytest.raises(ValueError, match=word):
        sphere.heading_change_vectors(d, w)


@settings(max_examples=20, deadline=None)
@given(h=hs.floats(0.05, 2.0), mu=hs.floats(-np.pi, np.pi))
def test_circular_kde_of_one_angle_is_the_von_mises_density(h, mu):
    g, f = sphere.circular_kde([mu], h=h, n_grid=720)
    np.testing.assert_allclose(f, vonmises.pdf(g, 1 / h**2, loc=mu), rtol=1e-9)
    assert abs(f.sum() * (g[1] - g[0]) - 1) < 1e-6


def test_circular_kde_weights_and_rotation():
    rng = np.random.default_rng(0)
    a = rng.vonmises(0.5, 4.0, 500)
    w = rng.uniform(0, 1, 500)
    g, f = sphere.circular_kde(a, h=0.3, weights=w)
    step = g[1] - g[0]
    g2, f2 = sphere.circular_kde(a + step, h=0.3, weights=w)
    np.testing.assert_allclose(np.roll(f, 1), f2, rtol=1e-9, atol=1e-12)
    _, fw = sphere.circular_kde(np.r_[a, a], h=0.3, weights=np.r_[w, 0 * w])
    np.testing.assert_allclose(f, fw, rtol=1e-12)


@pytest.mark.parametrize(
    "kw, word",
    [
        ({"h": 0.0}, "h"),
        ({"n_grid": 2}, "n_grid"),
        ({"weights": [1.0, -1.0]}, "weights"),
        ({"weights": [1.0]}, "weights"),
    ],
)
def test_circular_kde_bad_inputs(kw, word):
    args = {"h": 0.3, **kw}
    with pytest.raises(ValueError, match=word):
        sphere.circular_kde([0.0, 1.0], **args)


def test_kde_distance_bounds_and_grid_check():
    rng = np.random.default_rng(0)
    g = sphere.equal_area_grid(5.0)
    a = sphere.kde(sphere.vmf_sample([0.0, 0.0, 1.0], 50.0, 50, rng), h=0.1, grid=g)
    b = sphere.kde(sphere.vmf_sample([0.0, 0.0, -1.0], 50.0, 50, rng), h=0.1, grid=g)
    assert sphere.kde_distance(a, a) == 0.0
    assert abs(sphere.kde_distance(a, b) - 2.0) < 1e-6  # no overlap
    other = sphere.kde(np.eye(3), h=0.3, cell_deg=10.0)
    with pytest.raises(ValueError, match="same grid"):
        sphere.kde_distance(a, other)
