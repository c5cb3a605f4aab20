"""Tests of the helpers chapter 4 calls: ``evaluate.best_params``, ``evaluate.estimator``,
``evaluate.tilt_difference_rms``, ``evaluate.pooled_errors`` and
``datasets.broad_trial_kind``."""

import doctest

import numpy as np
import pytest
import xarray as xr

from tiltlab import datasets as D
from tiltlab import evaluate as E
from tiltlab import filters as F
from tiltlab import quaternion as Q
from tiltlab.evaluate import recipes
from tiltlab.schema import make_recording


def _rec(n=1200, fs=100.0, seed=0):
    """A rotating recording with a still first third, ``q_ref``, ``tilt_ref`` and a
    ``movement`` mask."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    omega = np.column_stack(
        [1.2 * np.sin(0.9 * t), 0.8 * np.cos(0.5 * t), 0.5 * np.sin(1.3 * t)]
    )
    omega[: n // 3] = 0.0
    q = Q.integrate_gyro(
        np.vstack([omega[1:], omega[-1:]]), fs, Q.random_quaternions(1, rng)[0]
    )
    acc = Q.gravity(q) + 0.01 * rng.standard_normal((n, 3))
    gyr = np.degrees(omega) + 0.2 * rng.standard_normal((n, 3))
    movement = np.ones(n, bool)
    movement[: n // 3] = False
    return make_recording(
        acc,
        gyr,
        fs,
        q_ref=q,
        extra={
            "movement": (("time",), movement, {}),
            "tilt_ref": (("time", "axis"), Q.gravity(q), {"units": "1"}),
        },
        acc_units="g",
        gyr_units="deg/s",
    )


@pytest.fixture(scope="module")
def recs():
    return {i: _rec(seed=i) for i in range(3)}


def test_docstring_examples_run():
    for module in (recipes, D):
        result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert result.failed == 0, module.__name__


# ------------------------------------------------------------------ best_params


def test_best_params_is_the_optimum_without_its_score():
    rng = np.random.default_rng(3)
    scores = xr.DataArray(
        rng.random((3, 4, 5)),
        dims=("kp", "ki", "recording"),
        coords={"kp": [0.1, 0.3, 1.0], "ki": [0.0, 0.01, 0.03, 0.1]},
    )
    best = E.best_params(scores)
    opt = E.optimum(scores)
    assert "score" not in best
    assert best == {k: v for k, v in opt.items() if k != "score"}
    mean = scores.mean("recording")
    assert float(mean.sel(best)) == pytest.approx(float(mean.min()))
    # a named recording dim and a reduced parameter list behave like optimum's
    one = scores.sel(ki=0.0, drop=True).rename(recording="session")
    assert E.best_params(one, dim="session") == {
        "kp": E.optimum(one, dim="session")["kp"]
    }
    with pytest.raises(ValueError, match="select or reduce"):
        E.best_params(scores, params=["kp"])


# ------------------------------------------------------------------ estimator


def test_estimator_runs_the_method_with_its_parameters(recs):
    rec = recs[0]
    f = E.estimator("madgwick", beta=0.05)
    q = f(rec)
    assert np.allclose(q.values, F.estimate(rec, "madgwick", beta=0.05).values)
    assert q.attrs["param_beta"] == 0.05
    assert f.__name__ == "madgwick(beta=0.05)"
    # default parameters without keywords, and the options of filters.estimate
    assert np.allclose(E.estimator("lowpass")(rec).values, F.estimate(rec, "lowpass"))
    g = E.estimator("lowpass", gaps="segments", cutoff_hz=2.0)
    assert g(rec).attrs["param_cutoff_hz"] == 2.0


def test_estimator_refuses_unknown_names_at_once():
    with pytest.raises(ValueError, match="unknown method"):
        E.estimator("kalmann")
    with pytest.raises(ValueError):
        E.estimator("madgwick", gain=0.1)


def test_estimators_feed_error_table(recs):
    params = {"madgwick": {"beta": 0.05}, "lowpass": {"cutoff_hz": 1.0}}
    est = {m: E.estimator(m, **p) for m, p in params.items()}
    table = E.error_table(recs, est, n_jobs=1)
    for m, p in params.items():
        for k, rec in recs.items():
            expected = E.tilt_rmse(F.estimate(rec, m, **p), rec)
            assert float(table.sel(estimator=m, recording=k)) == pytest.approx(expected)


# ------------------------------------------------------------------ tilt_difference_rms


def test_tilt_difference_rms_matches_pairwise(recs):
    rec = recs[1]
    q = {m: F.estimate(rec, m) for m in ("smoother", "madgwick")}
    moving = rec["movement"].values
    expected = E.pairwise_tilt_rms(q, mask=moving).sel(
        estimator="smoother", other="madgwick"
    )
    got = E.tilt_difference_rms(rec, "smoother", "madgwick")  # "movement" by default
    assert isinstance(got, float)
    assert got == pytest.approx(float(expected))
    assert E.tilt_difference_rms(rec, "madgwick", "smoother") == pytest.approx(got)
    everything = E.pairwise_tilt_rms(q).sel(estimator="smoother", other="madgwick")
    assert E.tilt_difference_rms(rec, "smoother", "madgwick", mask=None) == (
        pytest.approx(float(everything))
    )
    assert E.tilt_difference_rms(
        rec, "smoother", "madgwick", mask=moving
    ) == pytest.approx(got)


def test_tilt_difference_rms_refusals(recs):
    rec = recs[0].drop_vars("movement")
    with pytest.raises(ValueError, match="no 'movement' variable"):
        E.tilt_difference_rms(rec, "smoother", "madgwick")
    with pytest.raises(ValueError, match="two different methods"):
        E.tilt_difference_rms(rec, "smoother", "smoother", mask=None)


# ------------------------------------------------------------------ pooled_errors


def test_pooled_errors_concatenate_in_order(recs):
    p = {"beta": 0.1}
    expected = np.concatenate(
        [
            E.tilt_errors(F.estimate(r, "madgwick", **p), r["tilt_ref"])
            for r in recs.values()
        ]
    )
    got = E.pooled_errors(recs, "madgwick", p)  # a mapping's values
    assert got.shape == (sum(r.sizes["time"] for r in recs.values()),)
    assert np.allclose(got, expected)
    assert np.allclose(E.pooled_errors(list(recs.values()), "madgwick", p), expected)
    # default parameters, and quaternions as the reference
    rec = recs[0]
    by_q = E.pooled_errors([rec], "lowpass", reference="q_ref")
    assert np.allclose(by_q, E.tilt_errors(F.estimate(rec, "lowpass"), rec["q_ref"]))


def test_pooled_errors_refusals(recs):
    with pytest.raises(ValueError, match="must not be empty"):
        E.pooled_errors([], "madgwick")
    with pytest.raises(ValueError, match="no 'truth' reference"):
        E.pooled_errors(recs, "madgwick", reference="truth")
    with pytest.raises(ValueError):
        E.pooled_errors(recs, "madgwick", {"gain": 1.0})


# ------------------------------------------------------------------ broad_trial_kind

GROUPS = {
    2: ["all_trials", "undisturbed", "rotation", "slow", "no_breaks"],
    8: ["all_trials", "undisturbed", "rotation", "fast", "with_breaks"],
    14: ["all_trials", "undisturbed", "translation", "slow", "with_breaks"],
    21: ["all_trials", "undisturbed", "combined", "fast", "no_breaks"],
    24: ["all_trials", "disturbed", "tapping"],
}


def test_broad_trial_kind_from_groups():
    kinds = {k: D.broad_trial_kind(k, GROUPS) for k in (2, 8, 14, 21)}
    assert kinds == {
        2: "slow rotation",
        8: "fast rotation",
        14: "slow translation",
        21: "fast combined",
    }
    with pytest.raises(D.DataError, match="none of the motion groups"):
        D.broad_trial_kind(24, GROUPS)
    with pytest.raises(D.DataError, match="no BROAD trial 13"):
        D.broad_trial_kind(13, GROUPS)


def test_broad_trial_kind_of_the_real_trials(data_mirror):
    groups = D.broad_trial_groups()
    und = [k for k in sorted(groups) if "undisturbed" in groups[k]]
    kinds = {k: D.broad_trial_kind(k, groups) for k in und}
    assert D.broad_trial_kind(und[0]) == kinds[und[0]]  # groups read when omitted
    paces = {"fast" if "fast" in groups[k] else "slow" for k in und}
    assert {v.split()[0] for v in kinds.values()} == paces
    assert {v.split()[1] for v in kinds.values()} <= {
        "rotation",
        "translation",
        "combined",
    }
    assert kinds[6] == "fast rotation"
