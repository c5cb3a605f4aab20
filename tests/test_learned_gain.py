"""The learned-gain Mahony filter: parity with its parent, exact gradient, weights."""

from pathlib import Path

import numpy as np
import pytest

from tiltlab import filters
from tiltlab.filters.learned_gain import (
    FEATURES,
    GainWeights,
    learned_gain,
    load_gain_weights,
    save_gain_weights,
)

WEIGHTS = (
    Path(__file__).resolve().parents[1]
    / "src"
    / "tiltlab"
    / "_weights"
    / "learned_gain"
    / "weights.json"
)


def _motion(n=2000, fs=100.0, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    gyr = np.stack([np.sin(t), 0.5 * np.cos(0.7 * t), 0.2 * np.sin(0.3 * t)], axis=1)
    gyr = gyr + rng.normal(0, 0.02, (n, 3)) + [0.01, -0.02, 0.005]
    q = filters.mahony(np.tile([0, 0, 9.81], (n, 1)), gyr, fs, kp=0.0, ki=0.0)
    w, x, y, z = q.T
    up = np.stack(
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], 1
    )
    acc = 9.81 * up + rng.normal(0, 0.3, (n, 3))
    return acc, gyr + rng.normal(0, 0.01, (n, 3)), fs, q


def _random_weights(kp=1.0, ki=0.05, kb=0.02, tau=0.0, seed=1):
    rng = np.random.default_rng(seed)
    f = len(FEATURES)
    return GainWeights(
        kp,
        ki,
        kb,
        tau,
        rng.normal(0, 1, f),
        rng.uniform(0.5, 2, f),
        *rng.normal(0, 0.3, (3, f + 1)),
        {},
    )


def test_zero_weights_are_exactly_mahony():
    acc, gyr, fs, _ = _motion()
    w = GainWeights.parent(1.3, 0.04)
    q, b = learned_gain(acc, gyr, fs, weights=w, return_bias=True)
    q2, b2 = filters.mahony(acc, gyr, fs, kp=1.3, ki=0.04, return_bias=True)
    assert np.max(np.abs(q - q2)) <= 1e-12
    assert np.max(np.abs(b - b2)) <= 1e-12


@pytest.mark.parametrize("tau", [0.0, 2.0])
def test_gradient_matches_central_differences(tau):
    """Back-propagation through the whole recursion gives the exact gradient."""
    from tiltlab.learn.gain_schedule import _with, gain_trial, schedule_loss

    acc, gyr, fs, q_ref = _motion(n=1500)
    trial = gain_trial(acc, gyr, fs, q_ref, np.ones(len(acc), bool), q_ref[0])
    w = _random_weights(tau=tau)
    theta = np.concatenate([w.w_p, w.w_i, w.w_b])
    loss, g = schedule_loss([trial], w)
    assert loss > 0
    fd = np.empty_like(theta)
    for i in range(theta.size):
        e = np.zeros_like(theta)
        e[i] = 1e-6
        up = schedule_loss([trial], _with(w, theta + e), grad=False)[0]
        dn = schedule_loss([trial], _with(w, theta - e), grad=False)[0]
        fd[i] = (up - dn) / 2e-6
    np.testing.assert_allclose(g, fd, rtol=1e-4, atol=1e-7 * np.abs(g).max())


def test_weights_round_trip_and_checksum_refusal(tmp_path):
    w = _random_weights()
    path = tmp_path / "w.json"
    save_gain_weights(w, path)
    back = load_gain_weights(path)
    assert back.kb == w.kb and np.array_equal(back.w_b, w.w_b)
    path.write_text(path.read_text().replace('"kp": 1.0', '"kp": 2.0'))
    with pytest.raises(ValueError, match="checksum"):
        load_gain_weights(path)
    with pytest.raises(ValueError, match="checksum"):
        learned_gain(*_motion(n=50)[:3], weights=path)
    (tmp_path / "SHA256SUMS").unlink()
    with pytest.raises(ValueError, match="SHA256SUMS"):
        load_gain_weights(path)
    with pytest.raises(FileNotFoundError):
        load_gain_weights(tmp_path / "missing.json")


def test_bad_inputs_are_refused():
    acc, gyr, fs, _ = _motion(n=100)
    with pytest.raises(ValueError, match="needs weights"):
        learned_gain(acc, gyr, fs, weights=None)
    with pytest.raises(TypeError, match="weights"):
        learned_gain(acc, gyr, fs, weights=3)
    bad = acc.copy()
    bad[5, 1] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        learned_gain(bad, gyr, fs, weights=GainWeights.parent(1.0, 0.0))
    with pytest.raises(ValueError, match="too large"):
        learned_gain(acc, gyr, fs, weights=GainWeights.parent(500.0, 0.0))
    with pytest.raises(ValueError, match="w_p"):
        _check_bad_length()
    with pytest.raises(ValueError, match="kp"):
        GainWeights.parent(-1.0, 0.0)


def _check_bad_length():
    from tiltlab.filters.learned_gain import _checked_weights

    f = len(FEATURES)
    _checked_weights(
        1,
        0,
        0,
        0,
        np.zeros(f),
        np.ones(f),
        np.zeros(2),
        np.zeros(f + 1),
        np.zeros(f + 1),
        {},
    )


def test_lowpass_zero_tau_is_mahony_and_positive_tau_differs():
    acc, gyr, fs, _ = _motion()
    q = learned_gain(acc, gyr, fs, weights=GainWeights.parent(1.0, 0.01, 0.0, 1e-9))
    q2 = filters.mahony(acc, gyr, fs, kp=1.0, ki=0.01)
    assert np.max(np.abs(q - q2)) < 1e-6
    q3 = learned_gain(acc, gyr, fs, weights=GainWeights.parent(1.0, 0.01, 0.0, 3.0))
    assert np.max(np.abs(q3 - q2)) > 1e-4
    with pytest.raises(ValueError, match="tau_acc_s"):
        GainWeights.parent(1.0, 0.0, 0.0, -1.0)


def test_inputs_are_not_mutated():
    acc, gyr, fs, _ = _motion(n=300)
    a0, g0 = acc.copy(), gyr.copy()
    w = _random_weights(tau=1.0)
    w_p = w.w_p.copy()
    learned_gain(acc, gyr, fs, weights=w, q0=[1, 0, 0, 0], gyr_offset=[0, 0, 0])
    assert np.array_equal(acc, a0) and np.array_equal(gyr, g0)
    assert np.array_equal(w.w_p, w_p)


def test_registered_as_a_6d_causal_method():
    m = filters.get_method("learned_gain")
    assert m.kind == "causal" and not m.supports_mag
    assert "learned_gain" in filters.methods("causal")


@pytest.mark.realdata
def test_short_broad_trial_runs_and_is_accurate(data_mirror):
    from tiltlab.datasets import load_broad_trial
    from tiltlab.evaluate import broad_errors

    if not WEIGHTS.is_file():
        pytest.skip("no trained weights in the package")
    rec = load_broad_trial(2).isel(time=slice(0, 20000))
    q = filters.estimate(rec, "learned_gain", weights=str(WEIGHTS))
    assert q.shape == (20000, 4) and q.attrs["param_weights"] == str(WEIGHTS)
    assert np.array_equal(filters.estimate(rec, "learned_gain").values, q.values)
    assert np.allclose(np.linalg.norm(q.values, axis=1), 1.0)
    assert broad_errors(q, rec)["inclination"] < 5.0
    with pytest.raises(ValueError, match="magnetometer"):
        filters.estimate(rec, "learned_gain", weights=str(WEIGHTS), use_mag=True)


@pytest.mark.realdata
def test_gain_compare_scores_each_trial_with_its_folds_learned_and_parent_weights(
    data_mirror,
):
    from tiltlab import datasets, learn
    from tiltlab.filters.learned_gain import GainWeights, load_gain_weights

    folder = WEIGHTS.parent
    folds = [[1, 6], [2, 7], [3, 8], [4, 9], [5, 10]]
    short = {2: datasets.load_broad_trial(2).isel(time=slice(0, 20000))}
    table = learn.gain_compare(folds, folder, trials=[2], load=short.__getitem__)
    assert list(table["method"]) == list(learn.GAIN_LABELS)
    w = load_gain_weights(folder / "fold1.json")  # trial 2 is held out by fold 1
    parent = GainWeights.parent(w.kp, w.ki, w.kb, w.tau_acc_s, w.mean, w.std)
    q = filters.estimate(short[2], "learned_gain", weights=parent)
    expected = learn.cv.trial_errors(q.values, short[2])["inclination"]
    got = table.set_index("method").loc[learn.GAIN_LABELS[1], "inclination"]
    assert got == pytest.approx(expected, rel=1e-12)
    assert "GainWeights(kp=" in q.attrs["param_weights"]
    with pytest.raises(ValueError, match="held out by no fold"):
        learn.gain_compare(folds, folder, trials=[11], load=short.__getitem__)
