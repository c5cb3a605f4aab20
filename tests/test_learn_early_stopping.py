"""Early stopping of the learned estimators: validation trials kept out of each fold's
training, the weights of the best validation epoch returned, training stopped after
``patience`` epochs without improvement, and the training steps unchanged by the
validation pass."""

import math

import pytest

torch = pytest.importorskip("torch")

from tiltlab import datasets, learn  # noqa: E402
from tiltlab.learn import cv  # noqa: E402
from tiltlab.learn import training as T  # noqa: E402


@pytest.fixture(scope="module")
def sequences(data_mirror):
    recs = [datasets.load_broad_trial(t).isel(time=slice(0, 3000)) for t in (1, 24)]
    val = datasets.load_broad_trial(6).isel(time=slice(0, 2000))
    return [learn.sequence(r) for r in recs], [learn.sequence(val)]


def _config(**kw):
    return learn.TrainConfig(
        epochs=4, batch=64, stride=32, channels=8, threads=1, seed=5, **kw
    )


@pytest.mark.realdata
def test_validation_does_not_change_the_training_steps(sequences):
    """Without patience every epoch runs; the validation pass draws no random numbers,
    so the training losses are those of a run without validation."""
    train_set, val = sequences
    _, plain = learn.train(train_set, _config())
    model, hist = learn.train(train_set, _config(), validation=val)
    assert [h["loss"] for h in hist] == [h["loss"] for h in plain]
    errs = [h["val_qae_deg"] for h in hist]
    assert all(math.isfinite(e) and e >= 0 for e in errs)
    # the returned weights are those of the best validation epoch
    assert T.validation_error(model, val, _config()) == pytest.approx(min(errs))
    best = [h["best"] for h in hist]
    assert best == [i == 0 or e < min(errs[:i]) for i, e in enumerate(errs)]


@pytest.mark.realdata
def test_patience_stops_after_epochs_without_improvement(sequences, monkeypatch):
    """With a validation error that only worsens after the first epoch, patience 1
    stops after the second epoch and returns the first epoch's weights."""
    train_set, val = sequences
    calls = []

    def fake_error(model, seqs, config):
        calls.append({k: v.clone() for k, v in model.state_dict().items()})
        return float(len(calls))  # 1, 2, 3 …: never improves after epoch 1

    monkeypatch.setattr(T, "validation_error", fake_error)
    model, hist = learn.train(train_set, _config(patience=1), validation=val)
    assert len(hist) == 2 and [h["best"] for h in hist] == [True, False]
    for k, v in model.state_dict().items():
        assert torch.equal(v, calls[0][k]), k


@pytest.mark.realdata
def test_patience_without_validation_is_refused(sequences):
    train_set, _ = sequences
    with pytest.raises(ValueError, match="patience = 2 epochs needs validation"):
        learn.train(train_set, _config(patience=2))


def test_patience_must_be_a_nonnegative_integer():
    with pytest.raises(ValueError, match="patience"):
        learn.TrainConfig(patience=-1)


def test_validation_split_is_spread_deterministic_and_leaves_training_trials():
    pool = [3, 1, 4, 15, 9, 2, 6, 5, 8, 7]
    got = cv.validation_split(pool, 3)
    assert got == cv.validation_split(sorted(pool), 3)
    assert len(set(got)) == 3 and set(got) <= set(pool)
    assert cv.validation_split(pool, 0) == []
    with pytest.raises(ValueError, match="at least one must remain"):
        cv.validation_split([1, 2], 2)
    with pytest.raises(ValueError, match="n"):
        cv.validation_split([1, 2, 3], -1)


def test_old_configurations_load_with_patience_off():
    """A configuration stored before early stopping existed (no ``patience``) reads
    back with patience 0: the committed models' settings are unchanged."""
    d = learn.TrainConfig().to_dict()
    del d["patience"]
    assert learn.TrainConfig.from_dict(d).patience == 0
