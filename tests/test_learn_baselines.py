"""Baselines tuned on the networks' training folds (``tiltlab.learn.baselines``)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("torch")
learn = pytest.importorskip("tiltlab.learn")

from tiltlab import datasets, evaluate, filters  # noqa: E402
from tiltlab.io import IntegrityError  # noqa: E402

SMALL_GRIDS = {
    "Madgwick 9D": {"beta": [0.02, 0.1]},
    "ESKF 9D": {"acc_noise": [0.1, 0.5]},
}


@pytest.fixture(scope="module")
def recordings(data_mirror):
    """Three BROAD trials cut to their first minute (movement starts at ~35 s)."""
    return {
        t: datasets.load_broad_trial(t).isel(time=slice(0, 18000)) for t in (1, 2, 24)
    }


class Loader:
    """A loader that records which trials it is asked for."""

    def __init__(self, recordings):
        self.recordings = recordings
        self.calls: list[int] = []

    def __call__(self, trial):
        self.calls.append(int(trial))
        return self.recordings[int(trial)]


def test_a_held_out_trial_is_never_loaded_for_its_own_tuning(recordings):
    load = Loader(recordings)
    one = learn.tune_baselines([[1]], trials=[1, 2, 24], load=load, grids=SMALL_GRIDS)
    assert sorted(load.calls) == [2, 24]
    assert list(one["n_train"]) == [2, 2]
    # the same fold among two: its choice is unchanged by the other fold's trials
    two = learn.tune_baselines(
        [[1], [2]], trials=[1, 2, 24], load=Loader(recordings), grids=SMALL_GRIDS
    )
    fold0 = two[two["fold"] == 0].reset_index(drop=True)
    assert list(fold0["parameters"]) == list(one["parameters"])
    np.testing.assert_allclose(fold0["train_inclination"], one["train_inclination"])


def test_the_choice_is_the_argmin_of_the_training_trials_mean_score(recordings):
    table = learn.tune_baselines(
        [[1], [2]], trials=[1, 2, 24], load=Loader(recordings), grids=SMALL_GRIDS
    )
    for label, grid in SMALL_GRIDS.items():
        method, use_mag = learn.TUNED_BASELINES[label]
        scores = evaluate.grid_search(
            recordings, method, grid, use_mag=use_mag, n_jobs=1
        )
        for k, train in enumerate([[2, 24], [1, 24]]):
            mean = scores.sel(recording=train).mean("recording")
            (name,) = grid
            row = table[(table["method"] == label) & (table["fold"] == k)].iloc[0]
            assert row[name] == mean[name].values[int(np.argmin(mean.values))]
            assert row["train_inclination"] == pytest.approx(float(mean.min()))
    assert table.attrs["units"]["beta"] == "rad/s"
    assert table.attrs["units"]["train_inclination"] == "deg"
    assert set(table.attrs["long_name"]) == set(table.columns)
    assert np.isnan(table.loc[table["method"] == "ESKF 9D", "beta"]).all()


def test_held_out_trials_are_scored_with_their_folds_parameters(recordings, tmp_path):
    table = learn.tune_baselines(
        [[1], [2]], trials=[1, 2, 24], load=Loader(recordings), grids=SMALL_GRIDS
    )
    learn.save_tuned(table, tmp_path)
    back = learn.load_tuned(tmp_path)
    assert back.equals(table) and back.attrs == table.attrs
    rows = learn.tuned_compare(back, load=Loader(recordings))
    assert sorted(set(rows["trial"])) == [1, 2]
    assert len(rows) == 2 * 2 * 2  # trials x baselines x (tuned, defaults)
    assert rows.attrs["units"]["inclination"] == "deg"
    row = rows[(rows["method"] == "ESKF 9D (tuned)") & (rows["trial"] == 2)].iloc[0]
    chosen = table[(table["method"] == "ESKF 9D") & (table["fold"] == 1)].iloc[0]
    q = filters.estimate(
        recordings[2], "eskf", use_mag=True, acc_noise=chosen["acc_noise"]
    )
    assert row["inclination"] == pytest.approx(
        evaluate.tilt_rmse(q.values, recordings[2])
    )
    summary = learn.tuned_summary(rows)
    assert list(summary.index) == ["Madgwick 9D", "ESKF 9D"]
    assert summary.attrs["role"]["p"] == "p-value"
    assert (summary["n_trials"] == 2).all()


def test_summary_has_no_p_value_where_tuning_kept_the_defaults():
    import pandas as pd

    table = pd.DataFrame(
        {
            "method": ["A (tuned)"] * 3 + ["A (defaults)"] * 3,
            "trial": [1, 2, 3] * 2,
            "inclination": [1.0, 2.0, 3.0] * 2,
        }
    )
    summary = learn.tuned_summary(table)
    assert np.isnan(summary.loc["A", "p"]) and summary.loc["A", "n_lower"] == 0
    with pytest.raises(ValueError, match="defaults=True"):
        learn.tuned_summary(table[table["method"] == "A (tuned)"])


def test_bad_folds_and_grids_name_the_problem():
    def never(trial):
        raise AssertionError("nothing may be loaded before the inputs are checked")

    with pytest.raises(ValueError, match="folds is empty"):
        learn.tune_baselines([], load=never)
    with pytest.raises(ValueError, match="fold 1 holds no trial"):
        learn.tune_baselines([[1], []], load=never)
    with pytest.raises(ValueError, match="must not overlap"):
        learn.tune_baselines([[1, 2], [2, 3]], load=never)
    with pytest.raises(ValueError, match="holds out every trial"):
        learn.tune_baselines([[1, 2]], load=never)
    with pytest.raises(ValueError, match="not in trials"):
        learn.tune_baselines([[1], [5]], trials=[1, 2, 3], load=never)
    with pytest.raises(ValueError, match="unknown baseline 'VQF 9D'"):
        learn.tune_baselines([[1], [2]], load=never, grids={"VQF 9D": {"tauAcc": [1]}})
    with pytest.raises(ValueError, match="no value"):
        learn.tune_baselines(
            [[1], [2]], load=never, grids={"Madgwick 9D": {"beta": []}}
        )
    with pytest.raises(ValueError, match="gain"):
        learn.tune_baselines(
            [[1], [2]], load=never, grids={"Madgwick 9D": {"gain": [1]}}
        )


def test_a_tampered_parameter_file_is_refused(recordings, tmp_path):
    table = learn.tune_baselines(
        [[1]], trials=[1, 2], load=Loader(recordings), grids=SMALL_GRIDS
    )
    path = learn.save_tuned(table, tmp_path)
    path.write_text(path.read_text().replace('"n_train": 1', '"n_train": 9'))
    with pytest.raises(IntegrityError, match="params.json: sha256"):
        learn.load_tuned(tmp_path)
    (tmp_path / "SHA256SUMS").unlink()
    with pytest.raises(ValueError, match="no SHA256SUMS"):
        learn.load_tuned(tmp_path)


def test_committed_parameters_match_their_checksum_and_the_networks_folds():
    import json
    from pathlib import Path

    root = Path(__file__).resolve().parents[1] / "data"
    chosen = learn.load_tuned(root / "learn_baselines")
    folds = json.loads((root / "learn" / "run.json").read_text())["folds"]
    assert set(chosen["method"]) == set(learn.TUNED_BASELINES)
    for label, part in chosen.groupby("method"):
        assert [list(t) for t in part.sort_values("fold")["test_trials"]] == folds
        assert (part["n_train"] == 24).all()
