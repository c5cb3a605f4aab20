"""Bad input, faults and scale for tiltlab.sphere and tiltlab.trig: every public function
gives a right answer or a clear error (naming the argument), and undefined quantities are
NaN with a warning (tiltlab._validate's policy)."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
import scipy.stats as st
import xarray as xr

import tiltlab.quaternion as tq
from tiltlab import sphere as S
from tiltlab import trig as T

NAN, INF = float("nan"), float("inf")
POLE_N, POLE_S = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])
GRID1 = S.equal_area_grid(1.0)  # pole along z
GRID5 = S.equal_area_grid(5.0, pole=[0.3, -0.2, 1.0])


def _no_warnings(call):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return call()


def _names(message: str, name: str) -> bool:
    return re.search(rf"\b{re.escape(name)}\b", message) is not None


# ---------------------------------------------------------------------------
# 1. KDE mass: the integral is 1 for kernels anywhere, any bandwidth
# ---------------------------------------------------------------------------

_rng = np.random.default_rng(2024)
_RANDOM = _rng.normal(size=(3, 3))
CENTRES = {
    "north-pole": POLE_N,
    "south-pole": POLE_S,
    "near-pole-0.3deg": S.from_lonlat(0.7, np.radians(89.7)),
    "polar-ring-edge": S.from_lonlat(-2.0, np.arcsin(1 - 2 / GRID1.n_lat) + 1e-9),
    "equator": np.array([1.0, 0.0, 0.0]),
    "equator-cell-corner": S.from_lonlat(GRID1.lon_edges[7], 0.0),
    **{f"random-{i}": v / np.linalg.norm(v) for i, v in enumerate(_RANDOM)},
}
BANDWIDTHS = [1e-6, 1e-3, 0.01, 0.05, 0.2, 1.0, 10.0, 1e6]


@pytest.mark.parametrize("h", BANDWIDTHS)
@pytest.mark.parametrize("where", list(CENTRES))
def test_kde_of_one_kernel_integrates_to_one_anywhere(where, h):
    res = _no_warnings(lambda: S.kde(CENTRES[where][None], grid=GRID1, h=h))
    assert res.integral() == pytest.approx(1.0, abs=1e-9)
    assert np.all(np.isfinite(res.density)) and res.density.min() >= 0


@pytest.mark.parametrize("h", [0.002, 0.05, 0.3])
@pytest.mark.parametrize("grid", [GRID1, GRID5], ids=["1deg", "5deg-tilted"])
def test_kde_of_many_samples_and_mkde_integrate_to_one(grid, h):
    rng = np.random.default_rng(3)
    x = np.concatenate(
        [S.vmf_sample(POLE_N, 50.0, 200, rng), S.vmf_sample([1, 1, 0], 5.0, 200, rng)]
    )
    w = rng.random(len(x))
    assert S.kde(x, grid=grid, h=h, weights=w).integral() == pytest.approx(1, abs=1e-9)
    walk = S.slerp_vectors(POLE_N, [1.0, 0, 0], np.linspace(0, 1, 40))
    assert S.mkde(walk, fs=10.0, grid=grid, h=h).integral() == pytest.approx(
        1, abs=1e-9
    )


def test_kde_at_the_pole_is_the_exact_cell_average():
    # a pole-centred kernel depends on s only: the mass of each ring of cells is exact
    se = GRID1.s_edges
    for h in (0.01, 0.05, 0.2, 1.0):
        k = 1 / h**2
        ring = (np.exp(k * (se[1:] - 1)) - np.exp(k * (se[:-1] - 1))) / -np.expm1(
            -2 * k
        )
        res = S.kde(POLE_N[None], grid=GRID1, h=h)
        mass = res.density * GRID1.cell_area
        # (cells below tol = 1e-10 of the largest are truncated)
        np.testing.assert_allclose(mass.sum(axis=1), ring, rtol=1e-8, atol=1e-10)
        # ... shared equally by the cells of each ring
        np.testing.assert_allclose(mass, mass[:, :1] * np.ones((1, GRID1.n_lon)))


def test_point_quadrature_is_kept_and_loses_mass_at_the_pole():
    # the documented failure of quadrature="point" (the bug behind the default "mass")
    pt = S.kde(POLE_N[None], grid=GRID1, h=0.05, quadrature="point")
    assert pt.integral() == pytest.approx(0.215, abs=0.01)
    # where the grid resolves the kernel, "mass" and "point" agree to rounding
    eq = np.array([[0.0, 1.0, 0.0]])
    a = S.kde(eq, grid=GRID1, h=0.2, quadrature="point").density
    b = S.kde(eq, grid=GRID1, h=0.2).density
    # (up to the truncation at tol = 1e-10 of the peak, ~4, at the edge of the support)
    np.testing.assert_allclose(b, a, rtol=1e-9, atol=1e-9)
    with pytest.raises(ValueError, match=r"\bh\b.*too small"):
        S.kde(eq, grid=GRID1, h=1e-200, quadrature="point")


def test_gauss_kernel_keeps_its_own_mass():
    for h in (0.3, 1.0, 3.0):
        g = S.kde(np.array([[0.0, 0, 1]]), grid=GRID1, h=h, kernel="gauss")
        assert g.integral() == pytest.approx(-np.expm1(-2 / h**2), rel=1e-9)


def test_very_narrow_kernel_lands_in_the_nearest_cell():
    x = S.from_lonlat(0.4321, 0.1234)
    res = S.kde(x[None], grid=GRID1, h=1e-7)
    c = GRID1.centres().reshape(-1, 3)
    assert np.argmax(res.density.ravel()) == np.argmax(c @ x)
    assert np.count_nonzero(res.density) == 1


# ---------------------------------------------------------------------------
# 2. KDE degenerate input: identical samples, weights, zero vectors
# ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call",
    [
        lambda: S.kde(np.tile([0.0, 0.0, 1.0], (50, 1))),
        lambda: S.kde(np.array([[0.3, 0.4, 0.5]])),
        lambda: S.reference_bandwidth(np.tile([1.0, 2.0, 3.0], (7, 1))),
        lambda: S.reference_bandwidth(
            np.tile([1.0, 2.0, 3.0], (7, 1)), method="benhamou"
        ),
        lambda: S.mkde(np.tile([0.0, 1.0, 0.0], (5, 1)), fs=10.0),
    ],
    ids=["kde-50-identical", "kde-one-sample", "ref-mle", "ref-benhamou", "mkde-still"],
)
def test_identical_samples_name_the_bandwidth_rule(call):
    with pytest.raises(ValueError) as info:
        call()
    msg = str(info.value)
    assert "reference_bandwidth" in msg and re.search(r"identical|single sample", msg)
    assert "pass h" in msg


def test_identical_samples_with_a_given_bandwidth_are_fine():
    res = S.kde(np.tile([0.0, 0.0, 1.0], (50, 1)), h=0.1)
    assert res.integral() == pytest.approx(1.0, abs=1e-9)


def test_no_mean_direction_names_the_rule():
    with pytest.raises(ValueError, match=r"reference_bandwidth.*no mean direction"):
        S.kde(np.array([[1.0, 0, 0], [-1.0, 0, 0]]))


_X = S.vmf_sample([0, 0, 1.0], 10.0, 30, rng=5)
BAD_WEIGHTS = {
    "negative": -np.ones(30),
    "nan": np.r_[np.ones(29), NAN],
    "inf": np.r_[np.ones(29), INF],
    "shape": np.ones(7),
    "all-zero": np.zeros(30),
}
WEIGHTED = {
    "kde": lambda w: S.kde(_X, h=0.2, weights=w, cell_deg=10.0),
    "grid_for": lambda w: S.grid_for(_X, 10.0, weights=w),
    "vmf_fit": lambda w: S.vmf_fit(_X, weights=w),
    "reference_bandwidth": lambda w: S.reference_bandwidth(_X, weights=w),
    "stationarity_thirds": lambda w: S.stationarity_thirds(_X, weights=w),
    "histogram": lambda w: S.histogram(_X, S.sphere_mesh(100), weights=w),
    "vmf_bootstrap": lambda w: S.vmf_bootstrap(_X, weights=w, n_boot=5),
}


@pytest.mark.parametrize("bad", list(BAD_WEIGHTS))
@pytest.mark.parametrize("func", list(WEIGHTED))
def test_bad_weights_are_an_error_naming_weights(func, bad):
    if bad == "all-zero" and func in ("histogram", "grid_for"):
        pytest.skip("zero weights are valid there (an empty histogram, default grid)")
    with pytest.raises(ValueError) as info:
        WEIGHTED[func](BAD_WEIGHTS[bad])
    assert _names(str(info.value), "weights"), info.value


ZERO_DIRECTION = {
    "kde/vectors": lambda: S.kde(np.r_[_X, [[0.0, 0, 0]]], h=0.2),
    "mkde/vectors": lambda: S.mkde(np.r_[_X, [[0.0, 0, 0]]], fs=10.0, h=0.2),
    "vmf_fit/x": lambda: S.vmf_fit(np.zeros((4, 3))),
    "reference_bandwidth/vectors": lambda: S.reference_bandwidth(np.zeros((4, 3))),
    "grid_for/vectors": lambda: S.grid_for(np.zeros((4, 3))),
    "tilt_map/vectors": lambda: S.tilt_map(np.r_[_X, [[0.0, 0, 0]]]),
    "histogram/vectors": lambda: S.histogram(np.zeros((4, 3)), S.sphere_mesh(100)),
    "slerp/a": lambda: S.slerp_vectors([0.0, 0, 0], [1.0, 0, 0], 0.5),
    "slerp/b": lambda: S.slerp_vectors([1.0, 0, 0], [0.0, 0, 0], 0.5),
    "angle/u": lambda: S.angle([0.0, 0, 0], [1.0, 0, 0]),
    "angle/v": lambda: S.angle([1.0, 0, 0], [0.0, 0, 0]),
    "equal_area_grid/pole": lambda: S.equal_area_grid(5.0, pole=(0.0, 0, 0)),
    "equal_area_grid/meridian": lambda: S.equal_area_grid(5.0, meridian=(0.0, 0, 0)),
    "rotation_to_pole/point": lambda: S.rotation_to_pole([0.0, 0, 0]),
    "rotate_to_pole/baseline": lambda: S.rotate_to_pole(_X, [0.0, 0, 0]),
    "sagittal_angle/mu": lambda: S.sagittal_angle([0.0, 0, 0]),
    "vmf_pdf/mu": lambda: S.vmf_pdf(_X, [0.0, 0, 0], 1.0),
    "vmf_pdf/x": lambda: S.vmf_pdf(np.zeros((2, 3)), [0.0, 0, 1], 1.0),
    "vmf_sample/mu": lambda: S.vmf_sample([0.0, 0, 0], 1.0, 5),
    "spherical_triangle_area/a": lambda: S.spherical_triangle_area(
        [0.0, 0, 0], [0.0, 1, 0], [0.0, 0, 1]
    ),
    "triangulate/vertices": lambda: S.triangulate(
        np.r_[S.fibonacci_lattice(20), [[0.0, 0, 0]]]
    ),
    "residence/centres": lambda: S.residence(_X, np.zeros((1, 3)), 0.3, 1.0, fs=10.0),
    "passage_times/centre": lambda: S.passage_times(_X, [0.0, 0, 0], 0.3, fs=10.0),
}


@pytest.mark.parametrize("case", list(ZERO_DIRECTION))
def test_zero_vectors_as_directions_are_an_error_naming_the_argument(case):
    name = case.split("/")[1]
    with pytest.raises(ValueError) as info:
        ZERO_DIRECTION[case]()
    assert _names(str(info.value), name), info.value


# ---------------------------------------------------------------------------
# 3. von Mises-Fisher limits and fits
# ---------------------------------------------------------------------------

SMALL_KAPPA = [0.0, 1e-300, 1e-12, 1e-8, 1e-3]


@pytest.mark.parametrize("kappa", SMALL_KAPPA)
def test_vmf_density_tends_to_uniform(kappa):
    x = S.vmf_sample([0.3, 0.1, -1.0], 2.0, 100, rng=1)
    p = _no_warnings(lambda: S.vmf_pdf(x, [0.0, 0, 1], kappa))
    np.testing.assert_allclose(p, 1 / (4 * np.pi), rtol=2.5 * kappa + 1e-15)
    lp = _no_warnings(lambda: S.vmf_logpdf(x, [0.0, 0, 1], kappa))
    np.testing.assert_allclose(lp, -np.log(4 * np.pi), atol=2.5 * kappa + 1e-15)


@pytest.mark.parametrize("kappa", [1e-6, 1e-3, 0.5, 3.0, 20.0])
def test_vmf_density_is_continuous_and_normalised(kappa):
    # exact integral of the density over mu.x (an analytic check of the constant)
    t = np.linspace(-1, 1, 200_001)
    x = np.column_stack([np.sqrt(1 - t**2), np.zeros_like(t), t])
    p = S.vmf_pdf(x, [0, 0, 1.0], kappa)
    assert 2 * np.pi * np.trapezoid(p, t) == pytest.approx(1.0, rel=1e-8)


@pytest.mark.parametrize("kappa", [1e4, 1e6])
def test_vmf_density_large_kappa_is_finite(kappa):
    x = np.array([[0, 0, 1.0], [0, 1.0, 0], [0, 0, -1.0]])
    lp = _no_warnings(lambda: S.vmf_logpdf(x, [0, 0, 1.0], kappa))
    assert np.all(np.isfinite(lp))
    assert lp[0] == pytest.approx(np.log(kappa / (2 * np.pi)), rel=1e-12)
    assert S.vmf_pdf(x, [0, 0, 1.0], kappa)[2] == 0.0


@pytest.mark.parametrize("kappa", SMALL_KAPPA)
def test_vmf_sampler_tends_to_uniform(kappa):
    x = _no_warnings(lambda: S.vmf_sample([0.0, 0, 1], kappa, 20_000, rng=11))
    np.testing.assert_allclose(np.linalg.norm(x, axis=1), 1, atol=1e-12)
    # uniform on the sphere: z uniform on [-1, 1] (Archimedes), longitude uniform
    assert st.kstest(x[:, 2], st.uniform(-1, 2).cdf).pvalue > 1e-3
    lon = np.arctan2(x[:, 1], x[:, 0])
    assert st.kstest(lon, st.uniform(-np.pi, 2 * np.pi).cdf).pvalue > 1e-3


@pytest.mark.parametrize("kappa", [1e4, 1e6, 1e8])
def test_vmf_sampler_large_kappa(kappa):
    x = _no_warnings(lambda: S.vmf_sample([0.0, 0, 1], kappa, 20_000, rng=12))
    assert np.all(np.isfinite(x))
    c = x[:, 2]
    # 1 - mu.x is exponential with mean 1/kappa
    assert np.mean(1 - c) == pytest.approx(1 / kappa, rel=0.05)


def test_vmf_cap_area_kappa_zero_limit():
    for p in (0.1, 0.5, 0.95):
        assert S.vmf_cap_area(0.0, p) == pytest.approx(4 * np.pi * p, rel=1e-15)
        assert S.vmf_cap_area(1e-9, p) == pytest.approx(4 * np.pi * p, rel=1e-8)
        assert S.vmf_cap_area(1e-3, p) == pytest.approx(
            -2 * np.pi * np.log1p(-p * -np.expm1(-2e-3)) / 1e-3, rel=1e-12
        )


BAD_KAPPA = [-1.0, NAN, INF, -INF]
KAPPA_FUNCS = {
    "vmf_pdf": lambda k: S.vmf_pdf(_X, [0, 0, 1.0], k),
    "vmf_logpdf": lambda k: S.vmf_logpdf(_X, [0, 0, 1.0], k),
    "vmf_sample": lambda k: S.vmf_sample([0, 0, 1.0], k, 5),
    "vmf_cap_area": lambda k: S.vmf_cap_area(k, 0.5),
    "a3": lambda k: S.a3(k),
}


@pytest.mark.parametrize("kappa", BAD_KAPPA, ids=["neg", "nan", "inf", "-inf"])
@pytest.mark.parametrize("func", list(KAPPA_FUNCS))
def test_bad_kappa_is_an_error_naming_kappa(func, kappa):
    if kappa == INF and func in ("a3", "vmf_cap_area"):  # the limits are defined
        assert S.a3(INF) == 1.0 and S.vmf_cap_area(INF, 0.5) == 0.0
        return
    with pytest.raises(ValueError) as info:
        KAPPA_FUNCS[func](kappa)
    assert _names(str(info.value), "kappa"), info.value


def test_fit_of_a_single_or_identical_samples_is_infinite_kappa_with_a_warning():
    for x in ([[0.0, 0, 2]], np.tile([0.6, 0.8, 0.0], (5, 1))):
        with pytest.warns(RuntimeWarning, match=r"kappa is infinite"):
            fit = S.vmf_fit(x)
        x0 = np.asarray(x, float)[0]
        np.testing.assert_allclose(fit.mu, x0 / np.linalg.norm(x0))
        assert np.isinf(fit.kappa) and fit.rbar == 1.0


@pytest.mark.parametrize(
    "x",
    [
        [[1.0, 0, 0], [-1.0, 0, 0]],
        [[0, 0, 1.0], [0, 0, -1.0], [0, 1.0, 0], [0, -1.0, 0]],
    ],
    ids=["pair", "two-pairs"],
)
def test_fit_of_antipodal_pairs_is_an_error_naming_x(x):
    with pytest.raises(ValueError) as info:
        S.vmf_fit(x)
    assert _names(str(info.value), "x") and "no mean direction" in str(info.value)


# ---------------------------------------------------------------------------
# 4. trig: labels kept, undefined heading, quaternions and matrices checked
# ---------------------------------------------------------------------------

FS = 20.0
TIME = 3.0 + np.arange(8) / FS


def _da(values, name, units="rad", extra=None):
    v = np.asarray(values, float)
    dims = ("time",) + (("quat",) if v.ndim == 2 and v.shape[1] == 4 else ())
    coords = {"time": TIME}
    if len(dims) == 2:
        coords["quat"] = list("wxyz")
    return xr.DataArray(
        v,
        dims=dims,
        coords=coords,
        name=name,
        attrs={"fs": FS, "units": units, **(extra or {})},
    )


def test_wrap_angle_keeps_everything():
    a = _da(np.linspace(-10, 10, 8), "azimuth", extra={"method": "madgwick"})
    w = T.wrap_angle(a)
    assert isinstance(w, xr.DataArray) and w.name == "azimuth"
    assert w.attrs == a.attrs and np.array_equal(w["time"], TIME)
    np.testing.assert_allclose(np.cos(w), np.cos(a))
    assert np.all((w > -np.pi) & (w <= np.pi))
    d = T.wrap_angle(_da([190.0, -190, 540, 0, 10, 20, 30, 40], "a", units="deg"))
    np.testing.assert_allclose(d[:3], [-170, 170, 180])
    assert isinstance(T.wrap_angle(np.array([4.0])), np.ndarray)


def test_angles_from_quaternion_keeps_time_and_fs():
    rng = np.random.default_rng(1)
    q = tq.random_quaternions(8, rng)
    o = T.angles_from_quaternion(_da(q, "q", units="1"))
    ref = T.angles_from_quaternion(q)
    for field, r in zip(o, ref, strict=True):
        assert isinstance(field, xr.DataArray) and field.dims == ("time",)
        assert np.array_equal(field["time"], TIME) and field.attrs["fs"] == FS
        assert field.attrs["units"] == "rad"
        np.testing.assert_array_equal(field.values, r)
    # a quaternion DataArray with quat first is transposed
    o2 = T.angles_from_quaternion(_da(q, "q").transpose("quat", "time"))
    np.testing.assert_array_equal(o2.azimuth.values, ref.azimuth)


def test_angles_from_matrix_keeps_time():
    C = T.angles_to_matrix(np.linspace(-1, 1, 8), 0.2, 0.3)
    da = xr.DataArray(
        C, dims=("time", "row", "col"), coords={"time": TIME}, attrs={"fs": FS}
    )
    o = T.angles_from_matrix(da)
    assert np.array_equal(o.bank["time"], TIME) and o.bank.attrs["fs"] == FS
    np.testing.assert_allclose(o.azimuth.values, np.linspace(-1, 1, 8), atol=1e-12)


def test_azimuth_change_and_angle_functions_keep_labels():
    rng = np.random.default_rng(2)
    el0, bk0, el1, bk1 = (
        _da(rng.uniform(-1, 1, 8), n) for n in ("e0", "b0", "e1", "b1")
    )
    yaw, pitch, roll = (_da(rng.uniform(-0.2, 0.2, 8), n) for n in ("y", "p", "r"))
    out = T.azimuth_change(el0, bk0, el1, bk1, yaw, pitch, roll)
    plain = T.azimuth_change(
        *(a.values for a in (el0, bk0, el1, bk1, yaw, pitch, roll))
    )
    assert isinstance(out, xr.DataArray) and out.name == "azimuth_change"
    assert np.array_equal(out["time"], TIME) and out.attrs == {"fs": FS, "units": "rad"}
    np.testing.assert_array_equal(out.values, plain)
    # tuples / named tuples, mixed with plain numbers
    a = T.arc(el0, el1, 0.3, 0.1)
    assert all(
        isinstance(f, xr.DataArray) and np.array_equal(f["time"], TIME) for f in a
    )
    r = T.simultaneous_rotations(el0, bk0, bk1)
    assert r.yaw.name == "yaw" and np.array_equal(r.roll["time"], TIME)
    # degrees are converted
    deg = _da(np.degrees(el0.values), "e0", units="deg")
    np.testing.assert_allclose(
        T.posture_change(deg, bk0, el1, bk1), T.posture_change(el0, bk0, el1, bk1)
    )


def test_labelled_angles_must_match_in_length_and_be_angles():
    a = _da(np.zeros(8), "a")
    # arguments from different times are allowed (two consecutive orientations);
    # the output carries the first labelled argument's time
    b = a.assign_coords(time=TIME + 1.0)
    out = T.posture_change(a, 0.0, b, 0.0)
    assert np.array_equal(out["time"], a["time"])
    with pytest.raises(ValueError, match=r"\bbank\b.*m/s"):
        T.correct_centripetal(_da(np.zeros(8), "bank", units="m/s"), 1.0, 0.1)
    with pytest.raises(ValueError, match=r"\bel0\b.*\bel1\b"):
        T.posture_change(a, 0.0, a[:5], 0.0)
    # units "1" are radians (SI)
    one = T.wrap_angle(_da([4.0] * 8, "a", units="1"))
    assert float(one[0]) == pytest.approx(4.0 - 2 * np.pi)


UNDEFINED_HEADING = {
    "zero-mag": (np.array([0.1, 0.0, 1.0]), np.zeros(3)),
    "mag-parallel-up": (np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 40.0])),
    "mag-parallel-down": (np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -40.0])),
    "mag-parallel-tilted": (np.array([0.3, 0.4, 0.8]), -50 * np.array([0.3, 0.4, 0.8])),
    "zero-acc": (np.zeros(3), np.array([0.0, 30.0, -40.0])),
}


@pytest.mark.parametrize("case", list(UNDEFINED_HEADING))
@pytest.mark.parametrize("func", ["azimuth", "heading"])
def test_undefined_heading_is_nan_with_a_warning(func, case):
    a0, m0 = UNDEFINED_HEADING[case]
    good_a, good_m = np.array([0.0, 0.0, 1.0]), np.array([0.0, 30.0, -40.0])
    acc, mag = np.stack([good_a, a0, good_a]), np.stack([good_m, m0, good_m])
    with pytest.warns(RuntimeWarning, match=r"\bmag\b.*\bacc\b|undefined"):
        out = getattr(T, func)(acc, mag)
    az = out if func == "azimuth" else out.azimuth
    assert np.isnan(az[1]) and np.all(np.isfinite(az[[0, 2]]))
    if func == "heading":
        assert np.all(np.isfinite(np.asarray(out)[:, [0, 2]]))
        assert np.isnan(out.elevation[1]) == (case == "zero-acc")


def test_undefined_heading_in_labelled_data_is_nan_and_labelled():
    acc = xr.DataArray(
        np.tile([0.0, 0, 1], (8, 1)),
        dims=("time", "axis"),
        coords={"time": TIME},
        attrs={"fs": FS, "units": "g"},
    )
    mag = acc.copy(data=np.tile([0.0, 0, 40.0], (8, 1))).assign_attrs(units="uT")
    with pytest.warns(RuntimeWarning):
        az = T.azimuth(acc, mag)
    assert isinstance(az, xr.DataArray) and bool(np.isnan(az).all())
    assert np.array_equal(az["time"], TIME)


@pytest.mark.parametrize("func", ["posture", "magnetic_posture"])
def test_zero_vector_posture_is_nan_with_a_warning(func):
    v = np.array([[0.0, 0, 1], [0, 0, 0], [0.1, 0.2, 0.9]])
    with pytest.warns(RuntimeWarning, match=r"\b(acc|mag)\b.*zero"):
        out = getattr(T, func)(v)
    out = np.asarray(out)
    assert np.all(np.isnan(out[:, 1])) and np.all(np.isfinite(out[:, [0, 2]]))


def test_non_unit_quaternions_are_refused_naming_q():
    rng = np.random.default_rng(4)
    q = tq.random_quaternions(6, rng)
    ref = T.angles_from_quaternion(q)
    with pytest.raises(ValueError, match=r"\bq\b.*unit.*normalise them first"):
        T.angles_from_quaternion(q * np.array([2.0, 1, 0.5, 1, 1, 3])[:, None])
    # normalised explicitly, they give the angles of the unit quaternions
    o = T.angles_from_quaternion(tq.normalize(q * 3.0))
    np.testing.assert_allclose(np.asarray(o), np.asarray(ref), atol=1e-12)
    # within 1e-6: accepted, no warning
    o = _no_warnings(lambda: T.angles_from_quaternion(q * (1 + 5e-7)))
    np.testing.assert_allclose(np.asarray(o), np.asarray(ref), atol=1e-12)
    # NaN rows (gaps) give NaN angles
    qn = q.copy()
    qn[2] = NAN
    o = _no_warnings(lambda: T.angles_from_quaternion(qn))
    assert (
        np.all(np.isnan(np.asarray(o)[:, 2])) and np.isfinite(np.asarray(o)[:, 3]).all()
    )


BAD_ROTATIONS = {
    "q-zero": (lambda: T.angles_from_quaternion([0.0, 0, 0, 0]), "q"),
    "q-zero-row": (
        lambda: T.angles_from_quaternion([[1.0, 0, 0, 0], [0, 0, 0, 0]]),
        "q",
    ),
    "q-inf": (lambda: T.angles_from_quaternion([INF, 0, 0, 0]), "q"),
    "q-width": (lambda: T.angles_from_quaternion([1.0, 0, 0]), "q"),
    "q-singular_tol": (
        lambda: T.angles_from_quaternion([1.0, 0, 0, 0], NAN),
        "singular_tol",
    ),
    "matrix-reflection": (
        lambda: T.angles_from_matrix(np.diag([1.0, 1, -1])),
        "matrix",
    ),
    "matrix-improper": (lambda: T.angles_from_matrix(-np.eye(3)), "matrix"),
    "matrix-scaled": (lambda: T.angles_from_matrix(2 * np.eye(3)), "matrix"),
    "matrix-inf": (lambda: T.angles_from_matrix(np.full((3, 3), INF)), "matrix"),
    "matrix-shape": (lambda: T.angles_from_matrix(np.eye(2)), "matrix"),
    "matrix-singular_tol": (
        lambda: T.angles_from_matrix(np.eye(3), -1.0),
        "singular_tol",
    ),
    "wrap-inf": (lambda: T.wrap_angle([0.0, INF]), "angle"),
}


@pytest.mark.parametrize("case", list(BAD_ROTATIONS))
def test_bad_rotations_are_errors_naming_the_argument(case):
    call, name = BAD_ROTATIONS[case]
    with pytest.raises(ValueError) as info:
        call()
    assert _names(str(info.value), name), info.value


def test_reflection_in_a_stack_of_rotations_is_refused():
    C = T.angles_to_matrix(np.zeros(3), 0.1, 0.2)
    C[1] = C[1] @ np.diag([1.0, -1, 1])
    with pytest.raises(ValueError, match=r"matrix.*reflection"):
        T.angles_from_matrix(C)
    C[1] = np.nan  # a missing sample
    assert np.isnan(T.angles_from_matrix(C).azimuth[1])


# ---------------------------------------------------------------------------
# 5. numeric parameters: finiteness and domain, with the name and the value
# ---------------------------------------------------------------------------

_G = S.vmf_sample([0, 0, 1.0], 20, 60, rng=8)
_WALK = S.slerp_vectors(POLE_N, [1.0, 0, 0], np.linspace(0, 1, 30))
_ACC = np.tile([0.0, 0, 1], (4, 1))
_MAG = np.tile([0.0, 30, -40], (4, 1))

PARAMETERS = [
    # (id, call, name, value pattern or None)
    ("kde-h-zero", lambda: S.kde(_G, h=0.0), "h", r"0"),
    ("kde-h-inf", lambda: S.kde(_G, h=INF), "h", r"inf"),
    ("kde-tol-nan", lambda: S.kde(_G, h=0.1, tol=NAN), "tol", r"nan"),
    ("kde-cell_deg-inf", lambda: S.kde(_G, h=0.1, cell_deg=INF), "cell_deg", r"inf"),
    (
        "kde-quadrature",
        lambda: S.kde(_G, h=0.1, quadrature="simpson"),
        "quadrature",
        r"simpson",
    ),
    (
        "kde-kernel",
        lambda: S.kde(_G, h=0.1, kernel="epanechnikov"),
        "kernel",
        r"epanechnikov",
    ),
    ("kde-grid", lambda: S.kde(_G, h=0.1, grid="1deg"), "grid", r"str"),
    ("grid-cells", lambda: S.equal_area_grid(1e-3), "cell_deg", r"0\.001"),
    ("grid-cell_deg-100", lambda: S.equal_area_grid(100.0), "cell_deg", r"100"),
    (
        "grid-rotation",
        lambda: S.EqualAreaGrid(10, 5, np.diag([1.0, 1, -1])),
        "rotation",
        None,
    ),
    ("grid-n_lat", lambda: S.EqualAreaGrid(10, 1, np.eye(3)), "n_lat", r"1"),
    ("grid_for-cell_deg", lambda: S.grid_for(_G, -2.0), "cell_deg", r"-2"),
    (
        "mkde-step-tiny",
        lambda: S.mkde(_WALK, fs=10.0, h=0.1, step=1e-9),
        "step",
        r"1e-09",
    ),
    ("mkde-h-nan", lambda: S.mkde(_WALK, fs=10.0, h=NAN), "h", r"nan"),
    (
        "mkde-max_gap-nan",
        lambda: S.mkde(_WALK, fs=10.0, h=0.1, max_gap=NAN),
        "max_gap",
        r"nan",
    ),
    ("mkde-fs-zero", lambda: S.mkde(_WALK, fs=0.0, h=0.1), "fs", r"0"),
    ("mkde-one-sample", lambda: S.mkde(_WALK[:1], fs=1.0, h=0.1), "vectors", r"1"),
    ("reference_bandwidth-n", lambda: S.reference_bandwidth(_G, n=-4), "n", r"-4"),
    ("a3_inverse-rbar", lambda: S.a3_inverse(1.5), "rbar", r"1\.5"),
    ("a3_inverse-rbar-nan", lambda: S.a3_inverse([0.5, NAN]), "rbar", r"nan"),
    ("a3_inverse-tol", lambda: S.a3_inverse(0.5, tol=0.0), "tol", r"0"),
    ("a3_inverse-max_iter", lambda: S.a3_inverse(0.5, max_iter=0), "max_iter", r"0"),
    ("vmf_cap_area-level", lambda: S.vmf_cap_area(5.0, 2.0), "level", r"2"),
    ("vmf_cap_area-level-nan", lambda: S.vmf_cap_area(5.0, NAN), "level", r"nan"),
    ("vmf_sample-n", lambda: S.vmf_sample([0, 0, 1.0], 1.0, -3), "n", r"-3"),
    (
        "vmf_bootstrap-block_s-nan",
        lambda: S.vmf_bootstrap(_G, block_s=NAN, fs=10.0),
        "block_s",
        r"nan",
    ),
    (
        "isopleths-cell_area-nan",
        lambda: S.isopleths(np.ones(4), NAN),
        "cell_area",
        r"nan",
    ),
    (
        "isopleths-cell_area-zero",
        lambda: S.isopleths(np.ones(4), 0.0),
        "cell_area",
        r"0",
    ),
    (
        "isopleths-density-negative",
        lambda: S.isopleths(-np.ones(4), 1.0),
        "density",
        r"-1",
    ),
    (
        "isopleth_mask-level-nan",
        lambda: S.isopleth_mask(np.ones(4), NAN, 1.0),
        "level",
        r"nan",
    ),
    ("slerp-t-nan", lambda: S.slerp_vectors(POLE_N, [1.0, 0, 0], NAN), "t", None),
    ("sphere_mesh-n-small", lambda: S.sphere_mesh(3), "n", r"3"),
    ("sphere_mesh-n-float", lambda: S.sphere_mesh(100.5), "n", r"100\.5"),
    (
        "triangulate-lut_m",
        lambda: S.triangulate(S.fibonacci_lattice(20), lut_m=0),
        "lut_m",
        r"0",
    ),
    ("locate-mesh", lambda: S.locate(_G, mesh="fine"), "mesh", r"str"),
    (
        "visited-min_count",
        lambda: S.visited(np.ones(5), min_count=0.5),
        "min_count",
        r"0\.5",
    ),
    (
        "residence-radius-inf",
        lambda: S.residence(_WALK, _WALK[:2], INF, 1.0, fs=10.0),
        "radius",
        r"inf",
    ),
    (
        "residence-ref_times",
        lambda: S.residence(_WALK, _WALK[:2], 0.2, 1.0, fs=10.0, ref_times=[1.0]),
        "ref_times",
        r"\(2,\)",
    ),
    (
        "passage_times-centre",
        lambda: S.passage_times(_WALK, _WALK[:2], 0.2, fs=10.0),
        "centre",
        r"\(2, 3\)",
    ),
    (
        "passage_times-radius",
        lambda: S.passage_times(_WALK, POLE_N, 2.0, fs=10.0),
        "radius",
        r"2",
    ),
    (
        "residence_series-t_out",
        lambda: S.residence_series(_WALK, 0.2, -1.0, fs=10.0),
        "t_out",
        r"-1",
    ),
    ("tilt_map-fs", lambda: S.tilt_map(_G, fs=-5.0), "fs", r"-5"),
    # trig
    (
        "azimuth-singular_tol-nan",
        lambda: T.azimuth(_ACC, _MAG, singular_tol=NAN),
        "singular_tol",
        r"nan",
    ),
    (
        "heading-declination-inf",
        lambda: T.heading(_ACC, _MAG, declination=INF),
        "declination",
        r"non-finite",
    ),
    ("heading-shapes", lambda: T.heading(_ACC, _MAG[:3]), "mag", r"\(3, 3\)"),
    (
        "cap_passage-radius",
        lambda: T.cap_passage(0, 0, 0.5, 0, 0, 0, 2.0),
        "radius",
        r"2",
    ),
    (
        "cap_passage-radius-nan",
        lambda: T.cap_passage(0, 0, 0.5, 0, 0, 0, NAN),
        "radius",
        r"nan",
    ),
    (
        "head_relative-singular_tol",
        lambda: T.head_relative_to_body(0, 0, 0, 0, 0, 0, singular_tol=0.0),
        "singular_tol",
        r"0",
    ),
    (
        "body_rotations-window_s-nan",
        lambda: T.body_rotations(np.zeros((20, 3)), 10.0, window_s=NAN, units="rad/s"),
        "window_s",
        r"nan",
    ),
    (
        "body_rotations-fs-inf",
        lambda: T.body_rotations(np.zeros((20, 3)), INF, window_s=1.0, units="rad/s"),
        "fs",
        r"inf",
    ),
    (
        "oscillation_stats-smooth_s",
        lambda: T.oscillation_stats(
            np.sin(np.arange(100.0)), 10.0, level=0.0, window_s=2.0, smooth_s=-1.0
        ),
        "smooth_s",
        r"-1",
    ),
    (
        "crossing_times-fs",
        lambda: T.crossing_times(np.sin(np.arange(100.0)), NAN),
        "fs",
        r"nan",
    ),
    (
        "step_body_rates-duration",
        lambda: T.step_body_rates(0.5, 0.1, 0.0, INF, 10),
        "duration_s",
        r"inf",
    ),
    (
        "compose_sub_arcs-k",
        lambda: T.compose_sub_arcs(0, 0, 0, 0.5, 0.1, 0.0, 2.5),
        "k",
        r"2\.5",
    ),
    (
        "correct_centripetal-g-inf",
        lambda: T.correct_centripetal(0.1, 1.0, 0.2, g=INF),
        "g",
        r"inf",
    ),
    (
        "local_to_lonlat-radius",
        lambda: T.local_to_lonlat(1.0, 1.0, 0.0, 0.0, 0.1, radius=0.0),
        "radius",
        r"0",
    ),
    (
        "dead_reckon-anchors-nan",
        lambda: T.dead_reckon(
            np.ones(4), np.zeros(4), np.zeros(4), [[0, 0, 0], [NAN, 0, 0]], [0, 4]
        ),
        "anchors",
        r"non-finite",
    ),
    (
        "dead_reckon-speed-nan",
        lambda: T.dead_reckon(
            np.r_[1.0, NAN, 1, 1], np.zeros(4), np.zeros(4), np.zeros((2, 3)), [0, 4]
        ),
        "speed",
        r"non-finite",
    ),
    (
        "dead_reckon_2d-az-length",
        lambda: T.dead_reckon_2d(np.ones(10), np.zeros(9), np.zeros((2, 2)), [0, 10]),
        "az",
        r"9",
    ),
    (
        "dead_reckon-current-nan",
        lambda: T.dead_reckon(
            np.ones(4),
            np.zeros(4),
            np.zeros(4),
            np.zeros((2, 3)),
            [0, 4],
            dt_s=1.0,
            current=[[NAN, 0.0]],
        ),
        "current",
        r"non-finite",
    ),
    (
        "anchored_errors-intervals",
        lambda: T.anchored_errors(
            np.zeros((5, 3)), np.ones(4), np.zeros(4), np.zeros(4), [0]
        ),
        "intervals",
        r"0",
    ),
    (
        "magnetic_loop-sum-zero",
        lambda: T.posture_from_magnetic_loop(
            np.array([[0, 0, 1.0], [0, 0, -1.0]]), 1.0
        ),
        "mag_loop",
        r"zero",
    ),
]


@pytest.mark.parametrize(
    ("call", "name", "value"),
    [pytest.param(c, n, v, id=i) for i, c, n, v in PARAMETERS],
)
def test_numeric_parameters_are_checked_with_name_and_value(call, name, value):
    with pytest.raises(ValueError) as info:
        call()
    msg = str(info.value)
    assert _names(msg, name), msg
    if value is not None:
        assert re.search(value, msg), msg


def test_local_to_lonlat_at_the_pole_is_nan_with_a_warning():
    with pytest.warns(RuntimeWarning, match="pole"):
        lon, lat = T.local_to_lonlat(10.0, 5.0, 0.3, np.pi / 2, np.pi / 2)
    assert np.isnan(lon) and np.isfinite(lat)
