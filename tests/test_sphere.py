"""Tests of tiltlab.sphere (triangulated sphere, vMF, spherical KDE, residence) and the sphere maps of tiltlab.plot
(the LAEA projection, now in tiltlab.plot.maps)."""

import numpy as np
import pytest
import scipy.stats as st
from hypothesis import given, settings
from hypothesis import strategies as hs

from tiltlab import quaternion as Q
from tiltlab import sphere as S
from tiltlab import trig


def unit(rng, n):
    x = rng.normal(size=(n, 3))
    return x / np.linalg.norm(x, axis=1, keepdims=True)


def brute_locate(mesh, X, tol=1e-9, chunk=4096):
    """Independent reference: barycentric coordinates of every point in every facet.

    A facet (a, b, c) contains p when p = λa·a + λb·b + λc·c with all λ ≥ -tol; the lowest
    such facet index is returned, together with how many facets contain each point.
    Every facet is tested for every point; a float32 dot product with the facet centroid
    only skips pairs that cannot pass (a triangle lies in the convex cap around its
    centroid that holds its corners; margin far above float32 rounding).
    """
    V, F = mesh.vertices, mesh.faces
    M = np.stack([V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]], axis=2)
    Minv = np.linalg.inv(M)
    C = M.sum(axis=2)
    C /= np.linalg.norm(C, axis=1, keepdims=True)
    cos_r = np.min(np.einsum("fi,fik->fk", C, M)) - 1e-4
    if cos_r <= 0:  # a cap wider than a hemisphere is not convex: no pruning
        cos_r = -2.0
    C32 = C.astype(np.float32)
    out = np.full(len(X), len(F))
    cnt = np.zeros(len(X), int)
    for i in range(0, len(X), chunk):
        xs = X[i : i + chunk]
        ii, ff = np.nonzero(xs.astype(np.float32) @ C32.T >= cos_r)
        ok = np.einsum("nij,nj->ni", Minv[ff], xs[ii]).min(axis=1) >= -tol
        np.minimum.at(out, i + ii[ok], ff[ok])
        np.add.at(cnt, i + ii[ok], 1)
    return out, cnt


# ---------------------------------------------------------------------------
# lattice, triangulation, areas
# ---------------------------------------------------------------------------


def test_fibonacci_lattice_is_unit_and_equal_area_in_z():
    v = S.fibonacci_lattice(1000)
    assert v.shape == (1000, 3)
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), 1, atol=1e-14)
    # one point per equal-area band of height 2/n in z
    bands = np.floor((1 - v[:, 2]) / (2 / 1000)).astype(int)
    assert np.array_equal(np.sort(bands), np.arange(1000))


def test_default_mesh_areas_sum_to_4pi_and_topology():
    m = S.sphere_mesh()
    assert m.n_vertices == 5000 and m.n_faces == 2 * 5000 - 4  # Euler: F = 2V - 4
    assert abs(m.areas.sum() - 4 * np.pi) < 1e-9
    assert np.all(m.areas > 0)
    a, b, c = (m.vertices[m.faces[:, k]] for k in range(3))
    assert np.all(np.einsum("ij,ij->i", a, np.cross(b, c)) > 0)  # outward orientation
    assert 1.4 < m.area_ratio() < 1.8  # Fibonacci facets differ by ~1.6x
    # each neighbour shares the edge opposite the corner
    for k in range(3):
        nb = m.neighbors[:, k]
        edge = np.stack([m.faces[:, (k + 1) % 3], m.faces[:, (k + 2) % 3]], 1)
        shared = (edge[:, :, None] == m.faces[nb][:, None, :]).any(axis=2).all(axis=1)
        assert shared.all() and not np.any(nb == np.arange(m.n_faces))
    assert S.sphere_mesh() is m  # cached


def test_spherical_triangle_area_known_cases():
    assert S.spherical_triangle_area([1, 0, 0], [0, 1, 0], [0, 0, 1]) == pytest.approx(
        np.pi / 2, abs=1e-15
    )
    rng = np.random.default_rng(0)
    a, b, c = unit(rng, 200), unit(rng, 200), unit(rng, 200)

    def corner(p, q, r):  # angle at p of the spherical triangle pqr
        t1, t2 = np.cross(p, q), np.cross(p, r)
        return np.arccos(
            np.clip(
                np.sum(t1 * t2, 1)
                / np.linalg.norm(t1, axis=1)
                / np.linalg.norm(t2, axis=1),
                -1,
                1,
            )
        )

    girard = corner(a, b, c) + corner(b, c, a) + corner(c, a, b) - np.pi
    np.testing.assert_allclose(S.spherical_triangle_area(a, b, c), girard, atol=1e-9)


@settings(max_examples=15, deadline=None)
@given(n=hs.integers(0, 300), seed=hs.integers(0, 2**31 - 1))
def test_random_triangulations_areas_and_location(n, seed):
    rng = np.random.default_rng(seed)
    octa = np.vstack([np.eye(3), -np.eye(3)])  # ensures the hull contains the origin
    mesh = S.triangulate(
        np.vstack([octa + 1e-3 * rng.normal(size=(6, 3)), unit(rng, n)])
    )
    assert abs(mesh.areas.sum() - 4 * np.pi) < 1e-9
    X = unit(rng, 3000)
    ref, cnt = brute_locate(mesh, X)
    assert np.all(cnt >= 1)
    np.testing.assert_array_equal(S.locate(X, mesh), ref)


# ---------------------------------------------------------------------------
# point location
# ---------------------------------------------------------------------------


def test_locate_matches_brute_force_on_1e5_vectors_with_edges_and_vertices():
    m = S.sphere_mesh()
    rng = np.random.default_rng(1)
    X = unit(rng, 100_000)
    # 20 000 on edges (great-circle arcs between two corners), 5000 exactly on vertices
    f = rng.integers(0, m.n_faces, 20_000)
    k = rng.integers(0, 3, 20_000)
    a, b = m.vertices[m.faces[f, k]], m.vertices[m.faces[f, (k + 1) % 3]]
    X[:20_000] = S.slerp_vectors(a, b, rng.random(20_000))
    X[20_000:25_000] = m.vertices[rng.integers(0, m.n_vertices, 5000)]
    got = S.locate(X, m)
    ref, cnt = brute_locate(m, X)
    np.testing.assert_array_equal(got, ref)
    assert (
        np.all(cnt[25_000:] == 1)
        and np.all(cnt[:20_000] >= 2)
        and np.all(cnt[20_000:25_000] >= 3)
    )
    # every sample counted exactly once
    assert S.histogram(X, m).sum() == len(X)
    # vertices go to the lowest-index facet around them
    vtx = rng.integers(0, m.n_vertices, 300)
    lowest = [m.vf_idx[m.vf_ptr[v] : m.vf_ptr[v + 1]].min() for v in vtx]
    np.testing.assert_array_equal(S.locate(m.vertices[vtx], m), lowest)


def test_locate_scale_invariant_and_invalid_rows():
    m = S.sphere_mesh()
    rng = np.random.default_rng(2)
    X = unit(rng, 1000)
    np.testing.assert_array_equal(S.locate(3.7 * X, m), S.locate(X, m))
    X[3] = np.nan
    X[5] = 0
    idx = S.locate(X, m)
    assert idx[3] == -1 and idx[5] == -1 and np.all(np.delete(idx, [3, 5]) >= 0)
    with pytest.raises(ValueError):
        S.locate(np.zeros((4, 2)), m)


# ---------------------------------------------------------------------------
# tilt maps
# ---------------------------------------------------------------------------


def test_tilt_map_counts_time_density():
    m = S.sphere_mesh()
    rng = np.random.default_rng(3)
    g = S.vmf_sample([0.1, 0.2, 1.0], 20, 5000, rng)
    g[10] = np.nan
    tm = S.tilt_map(g, fs=100.0)
    assert int(tm["count"].sum()) == 4999 == tm.attrs["n_samples"]
    np.testing.assert_allclose(tm["time"].values, tm["count"].values / 100.0)
    assert float((tm["density"] * tm["area"]).sum()) == pytest.approx(1.0, abs=1e-12)
    mask = np.arange(5000) < 2500
    tm2 = S.tilt_map(g, mask=mask)
    assert int(tm2["count"].sum()) == 2500 - 1
    assert S.visited(tm).sum() == np.count_nonzero(tm["count"].values)
    with pytest.raises(ValueError):
        S.visited_fraction(tm, m, by="volume")


def test_visited_fraction_area_vs_count():
    m = S.sphere_mesh()
    rng = np.random.default_rng(4)
    everywhere = S.histogram(unit(rng, 400_000), m)
    assert (
        S.visited_fraction(everywhere, m)
        == 1.0
        == S.visited_fraction(everywhere, m, by="count")
    )
    # a cap of known area: the area measure is within the boundary facets' share of the truth
    x = unit(rng, 400_000)
    cap = x[x[:, 2] > 0.5]  # cap area 2π(1-0.5) = π -> 1/4 of the sphere
    frac = S.visited_fraction(S.histogram(cap, m), m)
    boundary = m.areas[np.abs(m.centroids[:, 2] - 0.5) < 0.04].sum() / (4 * np.pi)
    assert abs(frac - 0.25) < boundary


# ---------------------------------------------------------------------------
# von Mises-Fisher
# ---------------------------------------------------------------------------


@settings(max_examples=12, deadline=None)
@given(kappa=hs.floats(0.05, 2000), seed=hs.integers(0, 2**31 - 1))
def test_vmf_fit_equals_scipy(kappa, seed):
    rng = np.random.default_rng(seed)
    mu = unit(rng, 1)[0]
    x = S.vmf_sample(mu, kappa, 3000, rng)
    fit = S.vmf_fit(x)
    mu_s, kappa_s = st.vonmises_fisher.fit(x)
    np.testing.assert_allclose(fit.mu, mu_s, atol=1e-6)
    assert fit.kappa == pytest.approx(kappa_s, rel=1e-3)


def test_a3_inverse_and_weights():
    r = np.concatenate([np.geomspace(1e-8, 0.5, 50), 1 - np.geomspace(1e-8, 0.5, 50)])
    np.testing.assert_allclose(S.a3(S.a3_inverse(r)), r, rtol=1e-10, atol=1e-15)
    assert S.a3_inverse(0.0) == 0 and np.isinf(S.a3_inverse(1.0))
    rng = np.random.default_rng(5)
    x = S.vmf_sample([1, 0, 0], 8, 200, rng)
    w = rng.integers(0, 5, 200)
    f1, f2 = S.vmf_fit(x, w), S.vmf_fit(np.repeat(x, w, axis=0))
    np.testing.assert_allclose(f1.mu, f2.mu, atol=1e-12)
    assert f1.kappa == pytest.approx(f2.kappa, rel=1e-10)
    with pytest.raises(ValueError):
        S.vmf_fit([[1, 0, 0], [-1, 0, 0]])


def test_vmf_sampler_and_cap_area():
    rng = np.random.default_rng(6)
    for kappa in (0.5, 6.0, 50.0):
        x = S.vmf_sample([0, 1, 1], kappa, 40_000, rng)
        c = x @ (np.array([0, 1, 1]) / np.sqrt(2))
        assert c.mean() == pytest.approx(S.a3(kappa), abs=4 * c.std() / 200)
        area = S.vmf_cap_area(kappa, 0.8)
        inside = np.mean(c >= 1 - area / (2 * np.pi))
        assert inside == pytest.approx(0.8, abs=0.01)
    # Benhamou §7: the 0.95 isopleth of a vMF with kappa = 6 covers about pi (1/4 of the sphere)
    assert S.vmf_cap_area(6, 0.95) == pytest.approx(np.pi, rel=2e-3)


def test_bootstrap_cone_matches_fisher_and_block_bootstrap_widens():
    rng = np.random.default_rng(7)
    n, kappa = 400, 20.0
    x = S.vmf_sample([0, 0, 1], kappa, n, rng)
    cone = S.vmf_bootstrap(x, n_boot=1000, rng=1)
    R = np.linalg.norm(x.sum(0))
    fisher = np.arccos(
        1 - (n - R) / R * (20 ** (1 / (n - 1)) - 1)
    )  # Fisher (1953) 95 % cone
    assert cone.half_angle == pytest.approx(fisher, rel=0.2)
    assert cone.kappa_low < S.vmf_fit(x).kappa < cone.kappa_high
    # strongly autocorrelated series: repeat each direction 20 times
    xs = np.repeat(x, 20, axis=0)
    iid = S.vmf_bootstrap(xs, n_boot=300, rng=2).half_angle
    blk = S.vmf_bootstrap(xs, n_boot=300, rng=2, block=100).half_angle
    assert blk > 2.5 * iid
    # frequency weights = resampling the underlying samples
    w = rng.integers(1, 4, n)
    cw = S.vmf_bootstrap(x, w, n_boot=500, rng=3).half_angle
    cr = S.vmf_bootstrap(np.repeat(x, w, axis=0), n_boot=500, rng=3).half_angle
    assert cw == pytest.approx(cr, rel=0.2)


def test_mean_tilt_point_from_map_close_to_sample_mean():
    rng = np.random.default_rng(8)
    g = S.vmf_sample([0.3, -0.2, 1.0], 15, 20_000, rng)
    tm = S.tilt_map(g)
    a = S.mean_tilt_point(tm)
    b = S.mean_tilt_point(tm["count"].values)
    np.testing.assert_allclose(a.mu, b.mu)
    assert S.angle(a.mu, S.vmf_fit(g).mu) < np.radians(0.2)


def test_sagittal_angle_sign_left_ear_down_is_positive_for_left_lesion():
    for alpha in (0.1, 0.5):
        q = Q.from_rotvec(
            [-alpha, 0.0, 0.0]
        )  # roll about the nose axis: left ear (+y) goes down
        g = Q.gravity(q)
        assert np.isclose(
            Q.rotate(q, [0, 1, 0])[2], -np.sin(alpha)
        )  # the left ear is below the horizon
        assert S.sagittal_angle(g, "left") == pytest.approx(alpha)
        assert S.sagittal_angle(g, "right") == pytest.approx(-alpha)
    # pitch does not change the angle to the sagittal plane
    assert S.sagittal_angle(
        Q.gravity(Q.from_rotvec([0, 0.4, 0])), "left"
    ) == pytest.approx(0, abs=1e-15)
    with pytest.raises(ValueError):
        S.sagittal_angle([0, 0, 1], "up")


@settings(max_examples=20, deadline=None)
@given(seed=hs.integers(0, 2**31 - 1))
def test_rotate_to_pole_properties(seed):
    rng = np.random.default_rng(seed)
    b, v = unit(rng, 1)[0], unit(rng, 50)
    r = S.rotate_to_pole(v, b)
    np.testing.assert_allclose(S.rotate_to_pole(b, b), [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(
        r[:, 2], v @ b, atol=1e-12
    )  # distance to the pole = distance to baseline
    np.testing.assert_allclose(r @ r.T, v @ v.T, atol=1e-12)
    R = S.rotation_to_pole(b)
    np.testing.assert_allclose(np.linalg.det(R), 1, atol=1e-12)
    np.testing.assert_allclose(S.rotation_to_pole([0, 0, -1]) @ [0, 0, -1], [0, 0, 1])


# ---------------------------------------------------------------------------
# spherical KDE
# ---------------------------------------------------------------------------


def test_kde_equals_direct_sum_of_vmf_kernels():
    rng = np.random.default_rng(9)
    x = S.vmf_sample([1, 1, 0.2], 4, 40, rng)
    w = rng.random(40)
    grid = S.equal_area_grid(5.0, pole=[0.3, -0.2, 1.0])
    h = 0.2
    res = S.kde(x, grid=grid, h=h, weights=w, tol=1e-14, quadrature="point")
    c = grid.centres().reshape(-1, 3)
    kernels = np.array([S.vmf_pdf(c, xi, 1 / h**2) for xi in x]).T
    direct = kernels @ w / w.sum()
    np.testing.assert_allclose(res.density.ravel(), direct, rtol=1e-9, atol=1e-12)
    g = S.kde(
        x, grid=grid, h=h, weights=w, kernel="gauss", tol=1e-14, quadrature="point"
    )
    np.testing.assert_allclose(
        g.density, res.density / (1 - np.exp(-2 / h**2)), rtol=1e-12
    )
    # default quadrature="mass": the same kernels, each rescaled to unit mass on the grid
    mass = S.kde(x, grid=grid, h=h, weights=w, tol=1e-14)
    unit_mass = kernels / (kernels.sum(axis=0) * grid.cell_area)
    np.testing.assert_allclose(
        mass.density.ravel(), unit_mass @ w / w.sum(), rtol=1e-9, atol=1e-12
    )


@settings(max_examples=8, deadline=None)
@given(kappa=hs.floats(2, 400), h=hs.floats(0.03, 0.6), seed=hs.integers(0, 2**31 - 1))
def test_kde_integrates_to_one(kappa, h, seed):
    rng = np.random.default_rng(seed)
    x = S.vmf_sample(unit(rng, 1)[0], kappa, 500, rng)
    res = S.kde(x, h=h, cell_deg=1.0)
    assert res.integral() == pytest.approx(1.0, abs=1e-3)
    assert res.density.min() >= 0


def test_kde_isopleth_area_kappa6_and_reference_bandwidth():
    rng = np.random.default_rng(10)
    x = S.vmf_sample([0.2, 0.5, 0.8], 6.0, 50_000, rng)
    res = S.kde(x)
    assert res.integral() == pytest.approx(1.0, abs=1e-3)
    iso = S.isopleths(res, levels=[0.5, 0.95])
    theory = S.vmf_cap_area(6.0, 0.95)
    assert iso.loc[0.95, "area"] == pytest.approx(theory, rel=0.05)
    assert iso.loc[0.5, "area"] == pytest.approx(S.vmf_cap_area(6.0, 0.5), rel=0.05)
    # Benhamou Fig. 5: n = 3000, kappa = 31.5 -> h_ref = kappa^-1/2 n^-1/6 ~ 0.047 rad
    y = S.vmf_sample(S.from_lonlat(0, np.pi / 6), 31.5, 3000, rng)
    h = S.reference_bandwidth(y)
    assert h == pytest.approx(31.5**-0.5 * 3000 ** (-1 / 6), rel=0.03)
    assert h == pytest.approx(0.047, abs=0.0015)
    assert S.reference_bandwidth(y, method="benhamou") == pytest.approx(h, rel=1e-9)


def test_isopleths_uniform_and_unequal_cells():
    grid = S.equal_area_grid(10.0)
    d = np.full(grid.shape, 1 / (4 * np.pi))
    iso = S.isopleths(d, grid.cell_area, levels=[0.25, 0.95])
    np.testing.assert_allclose(
        iso["area"].to_numpy(), [np.pi, 0.95 * 4 * np.pi], rtol=1e-9
    )
    m = S.sphere_mesh(500)
    dens = 1 + m.centroids[:, 2]  # unnormalised, unequal facet areas
    iso = S.isopleths(dens, m.areas, levels=[0.5])
    # exact: density 1+z, mass above z0 is (1-z0)(3+z0)/4 of the total -> z0 = sqrt(2)-1 ... area 2π(1-z0)
    z0 = -1 + np.sqrt(2.0)
    assert iso["area"].iloc[0] == pytest.approx(2 * np.pi * (1 - z0), rel=0.02)
    mask = S.isopleth_mask(dens, 0.5, m.areas)
    assert (m.areas[mask].sum()) == pytest.approx(iso["area"].iloc[0], rel=0.03)


def test_mkde_mass_along_arcs_and_time_weighting():
    a, b = S.from_lonlat(0.0, 0.0), S.from_lonlat(1.0, 0.0)
    x = np.stack([a, b])
    grid = S.equal_area_grid(1.0, pole=[0, 0, 1])
    mk = S.mkde(x, fs=1.0, grid=grid, h=0.05)
    lk = S.kde(x, grid=grid, h=0.05)
    assert mk.integral() == pytest.approx(1.0, abs=1e-3)
    mid = np.argmin(
        np.linalg.norm(
            grid.centres().reshape(-1, 3) - S.slerp_vectors(a, b, 0.5), axis=1
        )
    )
    assert (
        mk.density.ravel()[mid] > 0.5 / (1.0 * 1.0) and lk.density.ravel()[mid] < 1e-6
    )
    # a series that stays still: MKDE = KDE of that point
    still = np.repeat(a[None], 10, axis=0)
    np.testing.assert_allclose(
        S.mkde(still, fs=5.0, grid=grid, h=0.05).density,
        S.kde(a[None], grid=grid, h=0.05).density,
        rtol=1e-10,
    )
    # the Brownian-bridge variant is wider in the middle of the step
    wide = S.mkde(x, fs=1.0, grid=grid, h=0.05, diffusion=0.05)
    assert (
        wide.integral() == pytest.approx(1.0, abs=1e-3)
        and wide.density.ravel()[mid] < mk.density.ravel()[mid]
    )


def test_stationarity_thirds_detects_a_drift():
    rng = np.random.default_rng(11)
    x = S.vmf_sample([0, 0, 1], 30, 3000, rng)
    df = S.stationarity_thirds(x)
    assert (
        list(df.index) == ["first", "second", "third", "all"]
        and df.attrs["max_angle_deg"] < 2
    )
    drift = np.concatenate([x[:1000], S.vmf_sample([0, 1, 1], 30, 2000, rng)])
    assert S.stationarity_thirds(drift).attrs["max_angle_deg"] > 20


# ---------------------------------------------------------------------------
# residence time and visits
# ---------------------------------------------------------------------------


def test_crossing_matches_trig_cap_passage():
    from tiltlab.sphere.residence import _crossing

    rng = np.random.default_rng(12)
    n_ok = 0
    for _ in range(200):
        mu = unit(rng, 1)[0]
        r = rng.uniform(0.1, 1.2)
        I = S.vmf_sample(mu, 50 / r, 1, rng)[0]
        O = unit(rng, 1)[0]
        if I @ mu < np.cos(r) or O @ mu >= np.cos(r):
            continue
        x = np.stack([I, O])
        tc = _crossing(x, np.array([0.0, 1.0]), 0, 1, *mu, np.cos(r))
        (xi_i, psi_i), (xi_o, psi_o), (xi_m, psi_m) = (
            S.to_lonlat(I),
            S.to_lonlat(O),
            S.to_lonlat(mu),
        )
        _, frac, xp, pp = trig.cap_passage(xi_i, psi_i, xi_o, psi_o, xi_m, psi_m, r)
        assert tc == pytest.approx(float(frac), abs=1e-9)
        assert S.from_lonlat(xp, pp) @ mu == pytest.approx(np.cos(r), abs=1e-9)
        n_ok += 1
    assert n_ok > 50


def test_residence_visits_and_passage_times():
    fs = 50.0
    t = np.arange(0, 20, 1 / fs)
    # oscillation along the equator through the centre (lon 0): inside when |lon| < r
    lon = 0.6 * np.sin(2 * np.pi * t / 4.0)
    x = S.from_lonlat(lon, 0 * lon)
    r, centre = 0.3, S.from_lonlat(0.0, 0.0)
    ent, ext = S.passage_times(x, centre, r, fs=fs)
    # inside while |sin| < 0.5: 1/3 of the time; passages centred on t = 0, 2, ..., 20 s
    # (the first and the last are cut by the ends of the series)
    assert len(ent) == len(ext) == 11 and ent[0] == t[0] and ext[-1] == t[-1]
    np.testing.assert_allclose(ext[1:-1] - ent[1:-1], 2 / 3, rtol=1e-3)
    res = S.residence(x, centre[None], r, t_out=0.1, fs=fs)
    assert (
        res.total[0]
        == pytest.approx(np.sum(ext - ent))
        == pytest.approx((t[-1] - t[0]) / 3, rel=0.01)
    )
    assert res.n_visits[0] == 11
    # excursions last 4/3 s: a longer time-out merges every passage into one visit
    assert S.residence(x, centre[None], r, t_out=2.0, fs=fs).n_visits[0] == 1
    idx, rt, nv = S.residence_series(x, r, t_out=0.1, fs=fs, stride=25)
    assert np.array_equal(idx, np.arange(0, len(t), 25)) and np.all(nv >= 1)
    # sample 0 (t = 0, on the centre) is in the first passage, which starts with the series
    assert ent[0] == 0.0 and rt[0] == pytest.approx(ext[0] - ent[0], rel=1e-9)
    # sample 100 (t = 2 s) is on the centre again: its visit is the 2nd passage, 2/3 s long
    j = np.flatnonzero(idx == 100)[0]
    assert (
        rt[j]
        == pytest.approx(ext[1] - ent[1], rel=1e-9)
        == pytest.approx(2 / 3, rel=0.01)
    )
    still = np.repeat(centre[None], 100, axis=0)
    r2 = S.residence(still, centre[None], r, 1.0, fs=10.0)
    assert r2.n_visits[0] == 1 and r2.total[0] == pytest.approx(9.9)
    with pytest.raises(ValueError):
        S.residence(x, centre[None], 2.0, 1.0, fs=fs)


# ---------------------------------------------------------------------------
# maps
# ---------------------------------------------------------------------------


@pytest.fixture
def no_cartopy_data(monkeypatch, tmp_path):
    """cartopy with empty data directories and no downloaders: any request for Natural
    Earth (or other) data raises instead of reading or downloading it."""
    cartopy = pytest.importorskip("cartopy")
    monkeypatch.setitem(cartopy.config, "data_dir", tmp_path)
    monkeypatch.setitem(cartopy.config, "pre_existing_data_dir", tmp_path)
    monkeypatch.setitem(cartopy.config, "downloaders", {})
    return cartopy


def test_laea_maps_render_without_cartopy_data_and_preserve_area(no_cartopy_data):
    import matplotlib

    matplotlib.use("Agg")
    import cartopy.crs as ccrs
    import matplotlib.pyplot as plt

    from tiltlab import plot as SM

    m = S.sphere_mesh(2000)
    rng = np.random.default_rng(13)
    g = S.vmf_sample([0.2, 0.1, 1.0], 10, 3000, rng)
    tm = S.tilt_map(g, mesh=m)
    k = S.kde(g, cell_deg=3.0)
    fig = plt.figure()
    ax = SM.map_axes(fig, 121)
    SM.plot_facets(ax, tm["fraction"].values, m)
    SM.decorate(ax)
    ax2 = SM.map_axes(fig, 122, centre=[1, 0, 0])
    SM.plot_grid(ax2, k)
    SM.plot_isopleths(ax2, k)
    fig.canvas.draw()
    plt.close(fig)
    # the guard works: a map that asks for Natural Earth coastlines fails under it
    fig = plt.figure()
    bad = fig.add_subplot(projection=ccrs.PlateCarree())
    bad.coastlines()
    with pytest.raises(ValueError, match="natural_earth"):
        fig.canvas.draw()
    plt.close(fig)
    # LAEA on the unit sphere preserves area: projected facet areas sum to their spherical areas
    xy = SM.project(SM.tilt_projection(), m.vertices)
    keep = (
        m.vertices[m.faces].reshape(-1, 9)[:, 2::3].max(axis=1) > -0.5
    )  # away from the antipode
    p, q, s = (xy[m.faces[keep, j]] for j in range(3))
    planar = 0.5 * np.abs((q - p)[:, 0] * (s - p)[:, 1] - (q - p)[:, 1] * (s - p)[:, 0])
    assert planar.sum() == pytest.approx(m.areas[keep].sum(), rel=2e-3)


def test_tilt_map_projection_is_equal_area():
    from tiltlab import quaternion
    from tiltlab import plot as SM

    proj = SM.tilt_projection()
    np.testing.assert_allclose(
        SM.project(proj, np.array([[0.0, 0.0, 1.0]])), [[0.0, 0.0]], atol=1e-9
    )
    eq = SM.project(proj, np.array([[1.0, 0, 0], [0, -1.0, 0]]))
    np.testing.assert_allclose(np.linalg.norm(eq, axis=-1), np.sqrt(2), rtol=1e-9)
    g = quaternion.gravity(
        quaternion.random_quaternions(40000, 1)
    )  # uniform on the sphere
    keep = g[:, 2] > -0.99  # the antipode maps to a circle
    r = np.linalg.norm(SM.project(proj, g[keep]), axis=-1)
    for radius in (0.5, 1.0, 1.5):
        assert np.sum(r < radius) / g.shape[0] == pytest.approx(radius**2 / 4, abs=0.01)


# ---------------------------------------------------------------------------
# labelled inputs: DataArrays (filters.gravity) and Recordings
# ---------------------------------------------------------------------------


def labelled_tilt(g, fs=100.0, t0=0.0, with_fs=True):
    """A tilt series shaped like filters.gravity's output: (time, axis), time coordinate, fs, method."""
    import xarray as xr

    attrs = {"units": "1", "method": "lowpass"} | ({"fs": fs} if with_fs else {})
    return xr.DataArray(
        g,
        dims=("time", "axis"),
        name="gravity",
        attrs=attrs,
        coords={"time": t0 + np.arange(len(g)) / fs, "axis": ["x", "y", "z"]},
    )


def walk(n=2000, fs=50.0):
    t = np.arange(n) / fs
    lon = 0.6 * np.sin(2 * np.pi * t / 4.0)
    return S.from_lonlat(lon, 0.2 + 0 * lon)


def test_labelled_tilt_gives_the_same_results_as_arrays_with_fs():
    rng = np.random.default_rng(20)
    g = S.vmf_sample([0.1, 0.2, 1.0], 20, 3000, rng)
    da = labelled_tilt(g, fs=100.0)
    tm, ref = S.tilt_map(da), S.tilt_map(g, fs=100.0)
    np.testing.assert_array_equal(tm["time"].values, ref["time"].values)
    assert tm.attrs["fs"] == 100.0 and tm.attrs["method"] == "lowpass"
    np.testing.assert_array_equal(S.histogram(da), S.histogram(g))
    idx = S.locate(da)
    assert idx.dims == ("time",) and idx.attrs["fs"] == 100.0
    np.testing.assert_array_equal(idx["time"].values, da["time"].values)
    np.testing.assert_array_equal(idx.values, S.locate(g))
    # a masked subset keeps 1/fs s per sample; a decimated series needs its own fs
    mask = (np.arange(3000) // 200) % 2 == 0  # bouts of 2 s
    np.testing.assert_array_equal(
        S.tilt_map(da[mask])["time"].values,
        S.tilt_map(g, fs=100.0, mask=mask)["time"].values,
    )
    np.testing.assert_array_equal(
        S.tilt_map(da, mask=mask)["count"].values,
        S.tilt_map(g, mask=mask)["count"].values,
    )
    assert (
        S.vmf_fit(da[::4]).kappa == S.vmf_fit(g[::4]).kappa
    )  # no time needed: no check
    with pytest.raises(ValueError, match="fs"):
        S.tilt_map(da[::4])
    assert S.tilt_map(da[::4].assign_attrs(fs=25.0))["time"].sum() == pytest.approx(
        750 / 25.0
    )
    # (axis, time) order is read the same way
    np.testing.assert_array_equal(
        S.histogram(da.transpose("axis", "time")), S.histogram(g)
    )
    assert S.vmf_fit(da).kappa == S.vmf_fit(g).kappa
    assert S.reference_bandwidth(da) == S.reference_bandwidth(g)
    np.testing.assert_array_equal(S.grid_for(da).rotation, S.grid_for(g).rotation)
    np.testing.assert_array_equal(
        S.kde(da, cell_deg=5.0).density, S.kde(g, cell_deg=5.0).density
    )
    assert S.stationarity_thirds(da).equals(S.stationarity_thirds(g))
    rot = S.rotate_to_pole(da, [0.1, 0.2, 1.0])
    assert rot.dims == ("time", "axis")
    np.testing.assert_allclose(rot.values, S.rotate_to_pole(g, [0.1, 0.2, 1.0]))
    # block bootstrap with the block length in seconds, fs from the data
    a = S.vmf_bootstrap(da, n_boot=50, block_s=0.5, rng=1)
    b = S.vmf_bootstrap(g, n_boot=50, block=50, rng=1)
    np.testing.assert_array_equal(a.angles, b.angles)


def test_time_functions_read_fs_and_the_time_coordinate():
    fs = 50.0
    x = walk(fs=fs)
    centre, r = S.from_lonlat(0.0, 0.2), 0.3
    da = labelled_tilt(x, fs=fs)
    grid = S.equal_area_grid(2.0)
    np.testing.assert_array_equal(
        S.mkde(da, grid=grid, h=0.05).density,
        S.mkde(x, fs=fs, grid=grid, h=0.05).density,
    )
    ra, rb = (
        S.residence(da, centre[None], r, 0.1),
        S.residence(x, centre[None], r, 0.1, fs=fs),
    )
    assert ra.total[0] == rb.total[0] and ra.n_visits[0] == rb.n_visits[0]
    ia, rta, nva = S.residence_series(da, r, 0.1, stride=40)
    ib, rtb, nvb = S.residence_series(x, r, 0.1, fs=fs, stride=40)
    np.testing.assert_array_equal(rta, rtb)
    # passage times are on the data's clock
    shifted = labelled_tilt(x, fs=fs, t0=100.0)
    ea, xa = S.passage_times(shifted, centre, r)
    eb, xb = S.passage_times(x, centre, r, fs=fs)
    np.testing.assert_allclose(ea, eb + 100.0, atol=1e-9)
    np.testing.assert_allclose(xa, xb + 100.0, atol=1e-9)
    # a Recording: its gravity variable and its fs
    rec = shifted.copy(deep=True).to_dataset()
    del rec["gravity"].attrs["fs"]
    rec.attrs["fs"] = fs
    np.testing.assert_allclose(S.passage_times(rec, centre, r)[0], ea)
    assert S.tilt_map(rec).attrs["fs"] == fs
    # explicit fs/times agreeing with the data are accepted
    assert S.residence(da, centre[None], r, 0.1, fs=fs).n_visits[0] == rb.n_visits[0]
    assert (
        S.residence(da, centre[None], r, 0.1, times=da["time"].values).n_visits[0]
        == rb.n_visits[0]
    )


def test_missing_or_contradictory_fs_is_an_error_naming_fs():
    from tiltlab._validate import RecordingError

    x = walk()
    centre = S.from_lonlat(0.0, 0.2)
    no_fs = labelled_tilt(x, fs=50.0, with_fs=False)
    # a DataArray without fs: fine where no time is needed, an error where it is
    assert "time" not in S.tilt_map(no_fs) and S.vmf_fit(no_fs).kappa > 0
    for call in (
        lambda d: S.mkde(d, h=0.05, cell_deg=5.0),
        lambda d: S.residence(d, centre[None], 0.3, 0.1),
        lambda d: S.residence_series(d, 0.3, 0.1, stride=100),
        lambda d: S.passage_times(d, centre, 0.3),
        lambda d: S.vmf_bootstrap(d, n_boot=10, block_s=1.0),
    ):
        with pytest.raises(RecordingError, match="fs"):
            call(no_fs)
        # a Recording without fs
        with pytest.raises(RecordingError, match="fs"):
            call(no_fs.to_dataset())
        # a plain array without fs (or times)
        with pytest.raises(ValueError, match="fs"):
            call(x)
    # fs contradicting the attribute
    da = labelled_tilt(x, fs=50.0)
    with pytest.raises(RecordingError, match="fs"):
        S.tilt_map(da, fs=100.0)
    with pytest.raises(RecordingError, match="fs"):
        S.residence(da, centre[None], 0.3, 0.1, fs=25.0)
    with pytest.raises(RecordingError, match="fs"):
        S.mkde(da.to_dataset().assign_attrs(fs=100.0), h=0.05, fs=50.0)
    # fs contradicting the time coordinate
    bad = da.assign_attrs(fs=200.0)
    with pytest.raises(RecordingError, match="fs"):
        S.passage_times(bad, centre, 0.3)
    with pytest.raises(RecordingError, match="fs"):
        S.tilt_map(bad)
    # times contradicting the time coordinate
    with pytest.raises(RecordingError, match="time"):
        S.passage_times(da, centre, 0.3, times=np.arange(len(x)) / 10.0)


def test_recording_without_gravity_says_how_to_compute_it():
    import xarray as xr

    from tiltlab._validate import RecordingError

    rec = xr.Dataset(
        {"acc": (("time", "axis"), np.tile([0, 0, 1.0], (10, 1)))},
        coords={"time": np.arange(10) / 10.0, "axis": list("xyz")},
        attrs={"fs": 10.0},
    )
    for call in (
        S.tilt_map,
        S.histogram,
        S.locate,
        S.vmf_fit,
        S.kde,
        S.stationarity_thirds,
        lambda r: S.mkde(r, h=0.1),
        lambda r: S.passage_times(r, [0, 0, 1], 0.2),
    ):
        with pytest.raises(
            RecordingError,
            match=r"filters\.gravity\(filters\.estimate\(rec, method\)\)",
        ):
            call(rec)


def test_numeric_parameters_are_checked_with_their_name_and_value():
    rng = np.random.default_rng(21)
    g = S.vmf_sample([0, 0, 1.0], 20, 300, rng)
    x, c = walk(), S.from_lonlat(0.0, 0.2)
    cases = [
        (lambda: S.kde(g, h=-0.1), "h"),
        (lambda: S.kde(g, cell_deg=float("nan")), "cell_deg"),
        (lambda: S.kde(g, tol=2.0), "tol"),
        (lambda: S.equal_area_grid(0.0), "cell_deg"),
        (lambda: S.mkde(x, fs=50.0, h=0.05, diffusion=-1.0), "diffusion"),
        (lambda: S.mkde(x, fs=50.0, h=0.05, step=0.0), "step"),
        (lambda: S.mkde(x, fs=50.0, h=0.05, max_gap=-1.0), "max_gap"),
        (lambda: S.reference_bandwidth(g, n=0), "n"),
        (lambda: S.isopleths(S.kde(g, cell_deg=5.0), levels=[1.5]), "levels"),
        (lambda: S.isopleth_mask(S.kde(g, cell_deg=5.0), 0.0), "level"),
        (lambda: S.vmf_bootstrap(g, n_boot=1), "n_boot"),
        (lambda: S.vmf_bootstrap(g, level=1.0), "level"),
        (lambda: S.vmf_bootstrap(g, block=0), "block"),
        (lambda: S.vmf_bootstrap(g, block_s=-1.0, fs=10.0), "block_s"),
        (lambda: S.vmf_sample([0, 0, 1], -1.0, 10), "kappa"),
        (lambda: S.vmf_sample([0, 0, 1], 1.0, 2.5), "n"),
        (lambda: S.residence(x, c[None], 0.3, -1.0, fs=50.0), "t_out"),
        (lambda: S.residence(x, c[None], float("nan"), 1.0, fs=50.0), "radius"),
        (lambda: S.residence_series(x, 0.3, 1.0, fs=50.0, stride=0), "stride"),
        (lambda: S.visited(S.tilt_map(g), min_count=0), "min_count"),
    ]
    for call, name in cases:
        with pytest.raises(ValueError, match=rf"\b{name}\b"):
            call()
