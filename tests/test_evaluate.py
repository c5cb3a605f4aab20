"""Tests of tiltlab.evaluate: error definitions, Table-1 statistics, binning, CDFs, LOTO selection,
the mocap reference pipeline and DataArray-valued grid searches."""

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from tiltlab import evaluate as E
from tiltlab import filters as F
from tiltlab import quaternion as Q
from tiltlab.schema import make_recording


def _rec(n=1500, fs=100.0, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    omega = np.column_stack(
        [1.2 * np.sin(0.9 * t), 0.8 * np.cos(0.5 * t), 0.5 * np.sin(1.3 * t)]
    )
    omega[: n // 3] = 0.0  # a still first third
    q = Q.integrate_gyro(
        np.vstack([omega[1:], omega[-1:]]), fs, Q.random_quaternions(1, rng)[0]
    )
    acc = Q.gravity(q) + 0.01 * rng.standard_normal((n, 3))
    gyr = np.degrees(omega) + 0.2 * rng.standard_normal((n, 3))
    immobile = np.zeros(n, bool)
    immobile[: n // 3] = True
    rec = make_recording(
        acc,
        gyr,
        fs,
        q_ref=q,
        extra={
            "immobile": (("time",), immobile, {}),
            "tilt_ref": (("time", "axis"), Q.gravity(q), {"units": "1"}),
        },
        acc_units="g",
        gyr_units="deg/s",
    )
    return rec, q


# ------------------------------------------------------------------ errors


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000))
def test_tilt_errors_equal_broad_inclination(seed):
    rng = np.random.default_rng(seed)
    qa, qb = Q.random_quaternions(50, rng), Q.random_quaternions(50, rng)
    incl = np.degrees(Q.tilt_error(qa, qb))
    assert np.allclose(E.tilt_errors(qa, qb), incl, atol=1e-6)
    # a reference given as gravity vectors (any norm) gives the same angles
    assert np.allclose(E.tilt_errors(qa, 3.0 * Q.gravity(qb)), incl, atol=1e-6)


def test_tilt_errors_heading_invariant_and_nan():
    rng = np.random.default_rng(1)
    q = Q.random_quaternions(20, rng)
    yaw = Q.from_rotvec(np.array([0.0, 0.0, 1.3]))
    assert np.allclose(E.tilt_errors(Q.mul(yaw, q), q), 0.0, atol=1e-5)
    ref = q.copy()
    ref[3] = np.nan
    e = E.tilt_errors(q, ref)
    assert np.isnan(e[3]) and np.all(np.isfinite(np.delete(e, 3)))
    with pytest.raises(ValueError):
        E.tilt_errors(q, q[:5])


def test_shift_quaternions_integer_and_fractional():
    rec, q = _rec()
    s = E.shift_quaternions(q, 2)
    assert np.allclose(Q.canonical(s[:-2]), Q.canonical(q[2:]), atol=1e-12)
    assert np.allclose(Q.norm(E.shift_quaternions(q, 0.4)), 1.0)
    # a half-sample shift lies between the neighbours
    h = E.shift_quaternions(q, 0.5)
    k = 900

    def ang(a, b):
        return 2 * np.arccos(min(1.0, abs(float(np.dot(a, b)))))

    assert 0 < ang(h[k], q[k]) < ang(q[k + 1], q[k])
    assert ang(h[k], q[k]) == pytest.approx(ang(h[k], q[k + 1]), rel=1e-3)
    assert np.array_equal(E.shift_quaternions(q, 0.0), q)
    with pytest.raises(ValueError):
        E.shift_quaternions(q, np.nan)


def test_shifted_score_recovers_a_delay():
    rec, q = _rec()
    delayed = np.vstack([q[:1], q[:-1]])  # estimate lagging the reference by one sample
    fn = E.shifted_score(
        [0.0, 0.5, 1.0],
        score_fn=lambda qq, r: np.nanmean(E.tilt_errors(qq, r["q_ref"].values)),
    )
    s = fn(delayed, rec)
    assert s.dims == ("shift",) and int(np.argmin(s.values)) == 2
    assert float(s.sel(shift=1.0)) < 0.01 * float(s.sel(shift=0.0))


# ------------------------------------------------------------------ statistics


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000))
def test_error_stats_match_numpy(seed):
    rng = np.random.default_rng(seed)
    e = rng.gamma(2.0, 0.5, 300)
    e[::17] = np.nan
    s = E.error_stats(e)
    f = e[np.isfinite(e)]
    assert s["n"] == f.size
    assert np.isclose(s["mean"], f.mean()) and np.isclose(s["std"], f.std(ddof=1))
    assert s["q25"] <= s["median"] <= s["q75"] <= s["q95"]
    assert np.isclose(s["rmse"], np.sqrt(np.mean(f**2)))


def test_table1_layout_and_split():
    e = np.r_[np.full(10, 0.5), np.full(30, 2.0)]
    im = np.r_[np.ones(10, bool), np.zeros(30, bool)]
    t = E.table1({"a": e, "b": 2 * e}, im)
    assert list(t.index) == list(E.STATISTICS)
    assert t[("immobile", "a")]["mean"] == pytest.approx(0.5)
    assert t[("moving", "b")]["median"] == pytest.approx(4.0)
    assert t.columns.names == E.FAYAT_TABLE1.columns.names
    assert E.FAYAT_TABLE1.shape == (6, 8)
    # published numbers are internally consistent (quantiles ordered)
    q = E.FAYAT_TABLE1.loc[["q25", "median", "q75", "q95"]].values
    assert np.all(np.diff(q, axis=0) >= 0)


def test_binned_by_speed_and_ecdf():
    sp = np.r_[np.full(50, 5.0), np.full(50, 50.0)]
    e = np.r_[np.full(50, 1.0), np.full(50, 3.0)]
    b = E.binned_by_speed({"m": e}, sp, [0, 10, 100, 1000])
    assert b["median"].sel(estimator="m").values[:2].tolist() == [1.0, 3.0]
    assert (
        np.isnan(b["median"].sel(estimator="m").values[2])
        and b["n"].values.sum() == 100
    )
    x, f = E.ecdf(np.r_[3.0, 1.0, np.nan, 2.0])
    assert x.tolist() == [1.0, 2.0, 3.0] and f[-1] == 1.0 and np.all(np.diff(f) > 0)
    with pytest.raises(ValueError):
        E.binned_by_speed({"m": e}, sp, [10, 0])


# ------------------------------------------------------------------ LOTO


def test_loto_never_uses_the_held_out_trial():
    # trial a prefers p=1 strongly, b-d prefer p=0 mildly. Without a, p=0 wins, so a is scored at
    # p=0 (5, not its own optimum 0); without b, a's preference carries p=1 (b scored 2).
    s = xr.DataArray(
        [[5.0, 1.0, 1.0, 1.0], [0.0, 2.0, 2.0, 2.0]],
        dims=("p", "recording"),
        coords={"p": [0, 1], "recording": list("abcd")},
    )
    out = E.loto(s)
    assert out["p"].values.tolist() == [0, 1, 1, 1]
    assert out["score"].values.tolist() == [5.0, 2.0, 2.0, 2.0]
    assert out.attrs["mean"] == pytest.approx(2.75)
    assert (
        out.attrs["optimistic_mean"] == pytest.approx(1.5)
        and out.attrs["optimistic_p"] == 1
    )
    assert out.attrs["mean"] >= out.attrs["optimistic_mean"]


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000))
def test_loto_is_never_better_than_the_optimistic_optimum(seed):
    rng = np.random.default_rng(seed)
    s = xr.DataArray(
        rng.random((3, 4, 5)),
        dims=("a", "b", "recording"),
        coords={"a": [1, 2, 3], "b": [0.1, 0.2, 0.3, 0.4], "recording": range(5)},
    )
    out = E.loto(s)
    assert out.attrs["mean"] >= out.attrs["optimistic_mean"] - 1e-12
    best = E.optimum(s)
    assert best["score"] == pytest.approx(float(s.mean("recording").min()))
    summ = E.loto_summary({"m": s})
    assert summ.loc["m", "loto_mean"] == pytest.approx(out.attrs["mean"])


def test_loto_errors():
    s = xr.DataArray(np.ones((2, 1)), dims=("p", "recording"))
    with pytest.raises(ValueError):
        E.loto(s)
    with pytest.raises(ValueError):
        E.loto(
            xr.DataArray(np.ones((2, 3, 2)), dims=("p", "recording", "state")),
            params=["p"],
        )


# ------------------------------------------------------------------ grids, tables


def test_grid_search_with_state_scores_and_error_table():
    recs = {i: _rec(seed=i)[0] for i in range(2)}
    g = E.grid_search(recs, "madgwick", {"beta": [0.05, 0.5]}, E.state_scores, n_jobs=2)
    assert g.dims == ("beta", "recording", "state")
    assert g["state"].values.tolist() == ["immobile", "moving", "all"]
    assert np.all(np.isfinite(g.values)) and np.all(g.values >= 0)
    # each cell equals the direct computation
    q = F.estimate(recs[1], "madgwick", beta=0.5)
    assert np.allclose(
        g.sel(beta=0.5, recording=1).values, E.state_scores(q, recs[1]).values
    )
    t = E.error_table(
        recs,
        {"m": lambda r: F.estimate(r, "madgwick", beta=0.5)},
        score_fn=lambda qq, r: float(E.state_scores(qq, r).sel(state="all")),
        n_jobs=2,
    )
    assert t.dims == ("estimator", "recording")
    assert np.allclose(t.sel(estimator="m").values, g.sel(beta=0.5, state="all").values)


def test_pairwise_tilt_rms_symmetric():
    rec, q = _rec()
    est = {
        "a": q,
        "b": F.estimate(rec, "madgwick", beta=0.1),
        "c": F.estimate(rec, "lowpass", cutoff_hz=1.0),
    }
    p = E.pairwise_tilt_rms(est)
    assert np.allclose(p.values, p.values.T) and np.allclose(np.diag(p.values), 0.0)
    assert np.all(p.values[~np.eye(3, dtype=bool)] > 0)
    with pytest.raises(ValueError):
        E.pairwise_tilt_rms({"a": q})


def test_adapters_run_and_agree_on_tilt():
    rec, q = _rec(n=600)
    for m in ("imufusion", "ahrs_madgwick"):
        est = F.estimate(rec, m)
        e = E.tilt_errors(est, q)
        assert np.nanmedian(e[100:]) < 5.0
    a, b = (
        F.estimate(rec, "ahrs_mahony", kp=0.5, ki=0.0),
        F.estimate(rec, "mahony", kp=0.5, ki=0.0),
    )
    assert np.max(np.abs(Q.canonical(a.values) - Q.canonical(b.values))) < 1e-6


# ------------------------------------------------------------------ mocap pipeline


def test_mocap_reference_recovers_truth():
    S = pytest.importorskip("tiltlab.simulate")
    # offsets zero (as after a tumble-test calibration); scale, cross-axis and noise errors drawn
    sensor = S.SensorModel(acc_offset=(0.0, 0.0, 0.0), gyr_offset=(0.0, 0.0, 0.0))
    rec, mocap = S.simulate_mocap_session(60.0, seed=3, sensor=sensor)
    ref = E.mocap_reference(rec, mocap)
    assert {"tilt_ref", "immobile"} <= set(ref.data_vars)
    assert ref.sizes["time"] <= rec.sizes["time"]
    err = E.tilt_errors(ref["q_ref"].values, ref["tilt_ref"].values)
    # the optical reference is within a few optical uncertainties of the truth, and QC drops ~2 %
    assert np.nanmedian(err) < 5 * max(ref.attrs["optical_tilt_uncertainty_deg"], 0.2)
    assert 0.01 < np.isnan(err).mean() < 0.05
    with pytest.raises(ValueError):
        E.mocap_reference(rec.drop_vars("sync"), mocap, gyr_offset=np.zeros(3))


# ------------------------------------------------------------------ one table per trial


def test_error_summary_matches_broad_rmse_and_statistics():
    rec, q = _rec(n=900)
    movement = np.zeros(900, bool)
    movement[300:] = True
    rec = rec.assign(movement=(("time",), movement))
    est = {m: F.estimate(rec, m) for m in ("madgwick", "lowpass")}
    table = E.error_summary(est, rec)
    assert list(table.index) == ["madgwick", "lowpass"]
    assert list(table.columns) == ["rmse", "mean", "median", "q95", "n"]
    assert table.attrs["mask"] == "movement" and (table["n"] == 600).all()
    for m, qe in est.items():
        assert table.loc[m, "rmse"] == pytest.approx(E.tilt_rmse(qe, rec), abs=1e-6)
    # without the mask variable every sample is scored; a direction reference works too
    whole = E.error_summary(est, rec.drop_vars("movement"), ref="tilt_ref")
    assert whole.attrs["mask"] is None and (whole["n"] == 900).all()
    e = E.tilt_errors(est["madgwick"], q)
    assert whole.loc["madgwick", "median"] == pytest.approx(np.median(e), abs=1e-9)
    with pytest.raises(ValueError, match="ground truth"):
        E.error_summary(est, rec.drop_vars("q_ref"))
    with pytest.raises(ValueError, match="empty"):
        E.error_summary({}, rec)
