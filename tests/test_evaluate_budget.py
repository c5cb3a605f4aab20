"""The error budget: its total is BROAD's RMSE, its spread bounds RMSE differences, and
its slow/fast split puts slow and fast errors where they belong."""

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from tiltlab import evaluate
from tiltlab import quaternion as quat

FS = 100.0


def _recording(n: int, seed: int, gaps: bool = True) -> xr.Dataset:
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    # a smooth reference motion: tilt about x and y of tens of degrees
    rv = np.column_stack(
        [0.4 * np.sin(0.7 * t), 0.3 * np.sin(1.1 * t + 1.0), 0.5 * t % 1.0]
    )
    q_ref = quat.from_rotvec(rv)
    if gaps:
        q_ref[rng.integers(0, n, n // 50)] = np.nan
    movement = np.ones(n, bool)
    movement[: n // 10] = False
    return xr.Dataset(
        {
            "q_ref": (("time", "quat"), q_ref),
            "movement": (("time",), movement),
        },
        attrs={"fs": FS},
    )


def _perturbed(rec: xr.Dataset, rotvec: np.ndarray) -> np.ndarray:
    q_ref = rec["q_ref"].values
    filled = np.where(np.isfinite(q_ref), q_ref, [1.0, 0.0, 0.0, 0.0])
    return quat.mul(filled, quat.from_rotvec(rotvec))


def test_total_is_broad_inclination_rmse_at_every_shift():
    rec = _recording(3000, 0)
    rng = np.random.default_rng(1)
    est = {
        "a": _perturbed(rec, 0.01 * rng.normal(size=(3000, 3))),
        "b": _perturbed(rec, np.tile([0.004, -0.002, 0.0], (3000, 1))),
    }
    for shift in (0.0, 0.5):
        b = evaluate.error_budget(rec, est, shift=shift)
        for m, q in est.items():
            want = evaluate.tilt_rmse(evaluate.shift_quaternions(q, shift), rec)
            assert b["total"].sel(estimator=m).item() == pytest.approx(want, rel=1e-9)
        assert b.attrs["shift"] == shift and b.attrs["baseline"] == "a"
        assert all(b[v].attrs["units"] == "deg" for v in ("total", "slow", "fast"))


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    scale=st.floats(1e-4, 0.3),
    offset=st.floats(-0.2, 0.2),
)
def test_spread_bounds_the_rmse_difference(seed, scale, offset):
    rec = _recording(800, seed)
    rng = np.random.default_rng(seed)
    est = {
        "base": _perturbed(rec, scale * rng.normal(size=(800, 3))),
        "other": _perturbed(
            rec, offset + scale * rng.standard_cauchy(size=(800, 3)).clip(-20, 20)
        ),
    }
    b = evaluate.error_budget(rec, est, baseline="base")
    diff = abs(
        b["total"].sel(estimator="other") - b["total"].sel(estimator="base")
    ).item()
    assert diff <= b["spread"].sel(estimator="other").item() + 1e-9
    assert b["spread"].sel(estimator="base").item() == 0.0


def test_constant_error_is_slow_and_jitter_is_fast():
    n = 6000
    t = np.arange(n) / FS
    # level sensor turning in heading: its x axis stays horizontal, so a rotation of
    # 0.5° about x is a tilt error of 0.5°
    # (scored away from the filter's edge transients: the first and last second)
    rec = xr.Dataset(
        {
            "q_ref": (("time", "quat"), quat.from_rotvec(np.outer(0.3 * t, [0, 0, 1]))),
            "movement": (("time",), (t > 1.0) & (t < t[-1] - 1.0)),
        },
        attrs={"fs": FS},
    )
    const = np.tile(np.radians([0.5, 0.0, 0.0]), (n, 1))
    jitter = np.radians(0.5) * np.column_stack(
        [np.sin(2 * np.pi * 20 * t), np.zeros(n), np.zeros(n)]
    )
    b = evaluate.error_budget(
        rec,
        {"const": _perturbed(rec, const), "jitter": _perturbed(rec, jitter)},
    )
    c, j = b.sel(estimator="const"), b.sel(estimator="jitter")
    assert c["total"].item() == pytest.approx(0.5, rel=1e-6)
    assert c["slow"].item() == pytest.approx(0.5, rel=1e-3)
    assert c["fast"].item() < 1e-3
    assert j["fast"].item() == pytest.approx(j["total"].item(), rel=1e-3)
    assert j["slow"].item() < 1e-3 * j["total"].item()


def test_inputs_are_not_changed():
    rec = _recording(500, 3)
    q = _perturbed(rec, np.full((500, 3), 0.01))
    before, ref_before = q.copy(), rec["q_ref"].values.copy()
    evaluate.error_budget(rec, {"q": q}, shift=0.3)
    np.testing.assert_array_equal(q, before)
    np.testing.assert_array_equal(rec["q_ref"].values, ref_before)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"estimates": {}}, "at least one estimate"),
        ({"baseline": "nope"}, "baseline 'nope'"),
        ({"estimates": {"q": np.ones((10, 4))}}, "shape"),
    ],
)
def test_bad_inputs_name_the_problem(kwargs, match):
    rec = _recording(500, 4)
    args = {"estimates": {"q": _perturbed(rec, np.zeros((500, 3)))}} | kwargs
    with pytest.raises(ValueError, match=match):
        evaluate.error_budget(rec, **args)


def test_no_valid_sample_is_refused():
    rec = _recording(500, 5)
    rec["movement"][:] = False
    with pytest.raises(ValueError, match="no valid samples"):
        evaluate.error_budget(rec, {"q": _perturbed(rec, np.zeros((500, 3)))})


def test_broad_offline_methods_share_their_fast_error(data_mirror):
    from tiltlab import datasets
    from tiltlab import filters as F

    rec = datasets.load("broad:2")
    fs = rec.attrs["fs"]
    a, g = rec["acc"].values, rec["gyr"].values
    est = {
        "offline_vqf": F.run_offline_vqf(a, g, fs),
        "smoother": F.smoother(a, g, fs, cutoff_hz=0.1),
    }
    b = evaluate.error_budget(rec, est)
    # both follow the same gyroscope: their fast errors agree to a few hundredths
    fast = b["fast"].values
    assert abs(fast[0] - fast[1]) < 0.02
    tot = b["total"].values
    assert abs(tot[1] - tot[0]) <= b["spread"].values[1]
