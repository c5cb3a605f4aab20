"""Tests of the helpers chapters 3 and 5 call: ``calibration.recording_norm_error``,
``calibration.allan_noise_table``, ``learn.layer_settings``, ``learn.layer_table`` and
``learn.config_table``."""

import doctest

import numpy as np
import pytest

from tiltlab import calibration as C
from tiltlab.calibration import summaries
from tiltlab.schema import make_recording

torch = pytest.importorskip("torch")
from tiltlab import learn as L  # noqa: E402
from tiltlab.learn import tables  # noqa: E402


def test_docstring_examples_run():
    for module in (summaries, tables):
        result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert result.failed == 0, module.__name__


# ------------------------------------------------------------------ norm_error
def _acc(n=50, seed=0):
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((n, 3))
    return a / np.linalg.norm(a, axis=1, keepdims=True) * rng.uniform(0.9, 1.1, (n, 1))


def test_recording_norm_error_matches_definition_and_converts_units():
    a = _acc()
    want = np.abs(1 - np.linalg.norm(a, axis=1))
    np.testing.assert_allclose(C.recording_norm_error(a), want)
    np.testing.assert_allclose(C.recording_norm_error(a * 9.80665, units="m/s^2"), want)
    rec = make_recording(a * 9.80665, None, 100.0, acc_units="m/s^2")
    np.testing.assert_allclose(C.recording_norm_error(rec), want)
    np.testing.assert_allclose(C.recording_norm_error(rec.acc), want)


def test_recording_norm_error_of_a_calibrated_recording_is_smaller():
    a = _acc() / np.linalg.norm(_acc(), axis=1, keepdims=True) + [0.05, 0.0, 0.0]
    assert (
        C.recording_norm_error(a - [0.05, 0.0, 0.0]).max()
        < 1e-12
        < C.recording_norm_error(a).mean()
    )


def test_recording_norm_error_nan_passes_and_bad_shapes_fail():
    a = _acc(5)
    a[2, 1] = np.nan
    e = C.recording_norm_error(a)
    assert np.isnan(e[2]) and np.isfinite(np.delete(e, 2)).all()
    with pytest.raises(ValueError):
        C.recording_norm_error(np.ones((5, 2)))
    with pytest.raises(Exception):
        C.recording_norm_error(np.ones((5, 3)), units="furlong")


# ------------------------------------------------------------------ allan_noise_table
def _old_fmt(v):
    return ", ".join(
        "not found" if np.isnan(x) else f"{x:.2g}" for x in np.atleast_1d(v)
    )


def _old_close(v, truth):
    v = np.atleast_1d(v)
    return "yes" if np.all(np.abs(v - truth) < 0.1 * truth) else "no"


def _noise():
    return C.AllanNoise(
        arw=np.array([0.0141, 0.0139, 0.0150]),
        bias_instability=np.array([0.0011, 0.0012, 0.0010]),
        tau_min=np.array([80.0, 95.0, 70.0]),
        rrw=np.array([2.1e-4, np.nan, 1.9e-4]),
    )


def test_allan_table_is_the_chapters_former_table():
    n, N, K = _noise(), 0.02 / np.sqrt(2), 2e-4
    t = C.allan_noise_table(n, {"arw": N, "rrw": K, "bias_instability": None})
    assert list(t.columns) == ["simulated", "read off the curve (x, y, z)", "recovered"]
    assert list(t.index) == list(summaries.ALLAN_ROWS.values())
    assert t["simulated"].tolist() == [f"{N:.2g}", f"{K:.2g}", "none"]
    assert t.iloc[:, 1].tolist() == [
        _old_fmt(n.arw),
        _old_fmt(n.rrw),
        _old_fmt(n.bias_instability),
    ]
    assert "not found" in t.iloc[1, 1]
    assert t["recovered"].tolist() == [
        _old_close(n.arw, N),
        _old_close(n.rrw, K),
        "no (spurious)",
    ]
    assert t["recovered"].tolist() == ["yes", "no", "no (spurious)"]


def test_allan_table_without_truth_scalars_and_absent_terms():
    t = C.allan_noise_table(_noise())
    assert list(t.columns) == ["read off the curve (x, y, z)"]
    n1 = C.AllanNoise(arw=0.01, bias_instability=np.nan, tau_min=50.0, rrw=1e-4)
    t1 = C.allan_noise_table(n1, {"arw": 0.0105}, rtol=0.1)
    assert t1["recovered"].tolist() == ["yes", "no (spurious)", "yes"]
    assert C.allan_noise_table(n1, {"arw": 0.0105}, rtol=0.01).iloc[0, 2] == "no"


def test_allan_table_bad_inputs():
    with pytest.raises(ValueError, match="unknown terms"):
        C.allan_noise_table(_noise(), {"white": 0.1})
    with pytest.raises(ValueError, match="rtol"):
        C.allan_noise_table(_noise(), {}, rtol=0)


# ------------------------------------------------------------------ learn tables
def test_layer_table_of_the_orientation_cnn():
    cfg = L.TrainConfig(channels=8)
    model = L.build_model(cfg, 500.0)
    t = L.layer_table(model)
    leaves = [(n, m) for n, m in model.named_modules() if n and not list(m.children())]
    assert t.index.name == "layer" and list(t.index) == [n for n, _ in leaves]
    assert list(t.columns) == ["type", "settings", "weights"]
    assert t["weights"].sum() == sum(p.numel() for p in model.parameters())
    assert any(s.startswith("10 → 8 channels") for s in t["settings"])


def test_layer_settings_of_known_layers():
    model = torch.nn.Sequential(
        torch.nn.Conv1d(10, 8, 3, dilation=2),
        torch.nn.BatchNorm1d(8),
        torch.nn.ReLU(),
        torch.nn.Linear(8, 4),
    )
    t = L.layer_table(model)
    assert t["settings"].tolist() == [
        "10 → 8 channels, kernel 3, dilation 2",
        "8 channels",
        "",
        "8 → 4",
    ]
    assert t["weights"].tolist() == [10 * 8 * 3 + 8, 2 * 8, 0, 8 * 4 + 4]


def test_layer_table_of_a_model_without_layers_is_empty():
    t = L.layer_table(torch.nn.Identity())
    assert t.empty and list(t.columns) == ["type", "settings", "weights"]
    assert L.layer_settings(torch.nn.BatchNorm1d(5)) == "5 channels"


def test_config_table_values_meanings_and_skips():
    cfg = L.TrainConfig()
    t = L.config_table(cfg, {"lr": "learning rate", "dilations": "dilations"})
    d = cfg.to_dict()
    assert list(t.index) == [k for k in d if k not in ("variant", "threads", "seed")]
    assert t.loc["lr", "value"] == f"{cfg.lr:g}"
    assert t.loc["dilations", "value"] == ", ".join(map(str, cfg.dilations))
    assert (
        t.loc["epochs", "value"] == str(cfg.epochs) and t.loc["epochs", "meaning"] == ""
    )
    assert "seed" in L.config_table(cfg, skip=()).index


def test_config_table_rejects_unknown_names():
    with pytest.raises(ValueError, match="not settings"):
        L.config_table(L.TrainConfig(), {"learning_rate": "lr"})
    with pytest.raises(ValueError, match="not settings"):
        L.config_table(L.TrainConfig(), skip=("nope",))
