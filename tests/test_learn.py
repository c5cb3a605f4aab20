"""tiltlab.learn: losses, optimiser, model readings, data windows, deterministic
training, model files and the committed cross-validation."""

import dataclasses
import json
import math
from pathlib import Path

import hypothesis.strategies as hst
import numpy as np
import pytest
from hypothesis import given, settings

torch = pytest.importorskip("torch")

from tiltlab import datasets  # noqa: E402
from tiltlab import quaternion as quat  # noqa: E402
from tiltlab.filters._common import initial_orientation  # noqa: E402
from tiltlab.filters.vectors import davenport, magnetic_dip  # noqa: E402

learn = pytest.importorskip("tiltlab.learn")
from tiltlab.learn import training as T  # noqa: E402
from tiltlab.learn.__main__ import main as learn_main  # noqa: E402

COMMITTED = Path(__file__).resolve().parents[1] / "data" / "learn"
_quats = hst.lists(
    hst.floats(-1, 1, allow_nan=False, allow_subnormal=False), min_size=4, max_size=4
).filter(lambda v: np.linalg.norm(v) > 0.1)


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


# ------------------------------------------------------------------ losses


@settings(max_examples=60, deadline=None)
@given(_quats, _quats)
def test_qmul_matches_the_numba_kernel(p, q):
    p, q = _unit(p), _unit(q)
    got = learn.losses.qmul(torch.tensor(p), torch.tensor(q)).numpy()
    assert np.allclose(got, quat.mul(p, q), atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(_quats, _quats)
def test_qae_is_the_rotation_angle_and_sign_invariant(p, q):
    p, q = _unit(p), _unit(q)
    tp, tq = torch.tensor(p)[None], torch.tensor(q)[None]
    angle = float(learn.qae(tp, tq))
    assert 0.0 <= angle <= math.pi + 1e-12
    assert angle == pytest.approx(float(quat.total_error(q, p)), abs=2e-6)
    assert float(learn.qae(tp, -tq)) == pytest.approx(angle, abs=1e-12)


@pytest.mark.parametrize("kind", sorted(learn.LOSSES))
@settings(max_examples=30, deadline=None)
@given(p=_quats, q=_quats)
def test_sample_losses_are_sign_invariant_and_minimal_at_the_reference(kind, p, q):
    p, q = torch.tensor(_unit(p))[None], torch.tensor(_unit(q))[None]
    value = float(learn.sample_loss(p, q, kind))
    assert float(learn.sample_loss(p, -q, kind)) == pytest.approx(value, abs=1e-9)
    at_ref = float(learn.sample_loss(p, p, kind))
    assert at_ref <= value + 1e-9
    if kind in ("acos", "l1_product", "l2_product"):
        assert at_ref == pytest.approx(0.0, abs=1e-3)


def test_product_losses_use_the_conjugate():
    """Eq. 8 as printed (q ⊗ q̃, no conjugate) would not vanish at q̃ = q; ours does."""
    q = torch.tensor(_unit([0.3, 0.5, -0.2, 0.7]))[None]
    printed = (
        learn.losses.qmul(q, q) - torch.tensor([1.0, 0, 0, 0], dtype=q.dtype)
    ).abs()
    assert float(printed.sum()) > 0.5
    assert float(learn.sample_loss(q, q, "l1_product")) == pytest.approx(0, abs=1e-12)


def test_taylor_forms_approximate_arccos_near_orthogonality():
    x = torch.tensor([0.0, 0.1, 0.2], dtype=torch.float64)
    q_ref = torch.tensor([[1.0, 0, 0, 0]] * 3, dtype=torch.float64)
    q_est = torch.stack([x, torch.sqrt(1 - x**2), 0 * x, 0 * x], dim=1)
    exact = torch.arccos(x)
    t1 = learn.sample_loss(q_ref, q_est, "acos_taylor1")
    t2 = learn.sample_loss(q_ref, q_est, "acos_taylor2")
    assert torch.all((t2 - exact).abs() <= (t1 - exact).abs() + 1e-15)
    assert torch.allclose(t1, math.pi / 2 - x)


def test_totals_follow_eqs_10_and_11():
    v = torch.tensor([3.0, -4.0])
    assert float(learn.total_loss(v, "L1")) == 7.0
    assert float(learn.total_loss(v, "L2")) == pytest.approx(5.0)
    with pytest.raises(ValueError, match="total"):
        learn.total_loss(v, "L3")
    with pytest.raises(ValueError, match="loss"):
        learn.sample_loss(v[None].repeat(1, 2), v[None].repeat(1, 2), "mse")


# ------------------------------------------------------------------ optimiser


def test_lookahead_moves_slow_weights_alpha_towards_fast_every_k_steps():
    w = torch.nn.Parameter(torch.tensor([1.0]))
    opt = learn.Lookahead(torch.optim.SGD([w], lr=0.1), k=3, alpha=0.5)
    for _ in range(3):  # gradient of w²/2 is w: fast steps w <- 0.9 w
        opt.zero_grad()
        (w * w / 2).sum().backward()
        opt.step()
    fast = 0.9**3
    assert float(w.detach()) == pytest.approx(1.0 + 0.5 * (fast - 1.0))
    with pytest.raises(ValueError, match="alpha"):
        learn.Lookahead(torch.optim.SGD([w], lr=0.1), alpha=0.0)
    with pytest.raises(ValueError, match="k"):
        learn.Lookahead(torch.optim.SGD([w], lr=0.1), k=0)


# ------------------------------------------------------------------ Davenport / QUEST


@settings(max_examples=40, deadline=None)
@given(_quats, hst.floats(-80, 80))
def test_davenport_recovers_the_orientation_of_exact_vectors(q, dip_deg):
    q = _unit(q)[None]
    dip = math.radians(dip_deg)
    up = np.array([[0.0, 0.0, 1.0]])
    field = np.array([[0.0, math.cos(dip), -math.sin(dip)]])
    acc = 9.81 * quat.rotate_inverse(q, up)
    mag = 48.0 * quat.rotate_inverse(q, field)
    est = davenport(acc, mag, dip=dip)
    assert float(np.degrees(quat.total_error(est, q))[0]) < 1e-6
    assert magnetic_dip(acc, mag) == pytest.approx(dip, abs=1e-9)
    triad = initial_orientation(acc, mag)[None]
    assert float(np.degrees(quat.total_error(triad, q))[0]) < 1e-6


def test_davenport_bad_inputs_name_the_problem():
    with pytest.raises(ValueError, match="mag"):
        davenport([0, 0, 1.0], [0, 0, 0.0], dip=0.5)
    with pytest.raises(ValueError, match="acc"):
        davenport(np.ones((2, 3)), np.ones((3, 3)), dip=0.5)
    with pytest.raises(ValueError, match="dip"):
        davenport([0, 0, 1.0], [0, 1.0, 0], dip=float("nan"))


# ------------------------------------------------------------------ model readings


def test_window_shorter_than_receptive_field_is_refused():
    with pytest.raises(ValueError, match="receptive field"):
        learn.OrientationCNN(20)  # kernel 3, gaps 1+2+4+8: 31 samples


def test_untrained_quaternion_variant_is_pure_gyro_integration():
    """Residual reading of Fig. 5: the zero-initialised head returns q_ω,t."""
    torch.manual_seed(0)
    model = learn.OrientationCNN(37).eval()
    x = torch.randn(5, 10, 37)
    q_w = torch.tensor(_unit(np.random.default_rng(0).normal(size=(5, 4))))
    x[:, :4, -1] = q_w.float()
    out = model(x)
    assert torch.allclose(out, q_w.float(), atol=1e-6)


def test_gain_variant_blends_between_gyro_and_vector_orientations():
    torch.manual_seed(1)
    model = learn.OrientationCNN(37, variant="gain").eval()
    x = torch.randn(4, 10, 37)
    q_w = torch.tensor([[1.0, 0, 0, 0]] * 4)
    q_v = torch.tensor([[math.cos(0.3), math.sin(0.3), 0, 0]] * 4)
    x[:, :4, -1] = q_w
    out = model(x, -q_v)  # the sign of q_∇ must not matter
    angle_w = learn.qae(q_w, out)
    angle_v = learn.qae(q_v, out)
    assert torch.allclose(angle_w + angle_v, torch.full((4,), 0.6), atol=1e-5)
    with pytest.raises(ValueError, match="q_vec"):
        model(x)


def test_config_errors_name_the_field():
    for field, value in [
        ("loss", "mse"),
        ("total", "L3"),
        ("variant", "lstm"),
        ("lr", -1.0),
        ("epochs", 0),
        ("init_deg", float("nan")),
    ]:
        with pytest.raises(ValueError, match=field):
            learn.TrainConfig(**{field: value})
    with pytest.raises(ValueError, match="activations"):
        learn.TrainConfig(activations=("gelu", "swish", "tanh"))


# ------------------------------------------------------------------ data and training


@pytest.fixture(scope="module")
def small_sequences(data_mirror):
    rec = datasets.load_broad_trial(1).isel(time=slice(0, 6000))
    rec2 = datasets.load_broad_trial(24).isel(time=slice(0, 6000))
    return rec, [learn.sequence(rec), learn.sequence(rec2)]


@pytest.mark.realdata
def test_window_integration_reproduces_the_reference_motion(small_sequences):
    """q_ω at the end of a window, started from the reference at its start, is the
    reference at its end up to the gyro's drift over 0.13 s."""
    rec, (seq, _) = small_sequences
    window = learn.TrainConfig().window(seq.fs)
    ends = learn.window_ends(seq, window, 50)
    x = T._inputs(
        torch.from_numpy(seq.Q),
        torch.zeros(ends.size, window, 3),
        torch.zeros(ends.size, window, 3),
        torch.from_numpy(ends),
        torch.from_numpy(seq.q_ref[ends - window]),
        window,
    )
    err = np.degrees(quat.total_error(x[:, :4, -1].double().numpy(), seq.q_ref[ends]))
    assert np.median(err) < 0.5


def _small_config(**kw):
    return learn.TrainConfig(
        epochs=3, batch=64, stride=16, channels=8, threads=1, seed=3, **kw
    )


@pytest.mark.realdata
def test_training_is_deterministic_and_the_loss_decreases(small_sequences):
    _, seqs = small_sequences
    cfg = _small_config()
    m1, h1 = learn.train(seqs, cfg)
    m2, h2 = learn.train(seqs, cfg)
    for (k, a), b in zip(m1.state_dict().items(), m2.state_dict().values()):
        assert torch.equal(a, b), k
    assert h1 == [dict(h, seconds=a["seconds"]) for h, a in zip(h2, h1)]
    assert h1[-1]["loss"] < h1[0]["loss"]
    other, _ = learn.train(seqs, _small_config(lr=2e-3))
    assert not torch.equal(m1.head.weight, other.head.weight)


def _head(seq, n):
    """The first ``n`` samples of a Sequence."""
    cut = {f: getattr(seq, f)[:n] for f in ("Q", "acc", "mag", "q_vec", "q_ref")}
    return dataclasses.replace(seq, **cut)


@pytest.mark.realdata
def test_closed_loop_batched_across_sequences_equals_one_by_one(small_sequences):
    """Batching across recordings changes only float32 rounding, not the recursion."""
    _, (a, b) = small_sequences
    b = _head(b, 4500)
    cfg = _small_config(variant="gain")
    model, _ = learn.train([a], cfg, max_steps=3)
    with torch.no_grad():
        alone = [learn.closed_loop_estimate(model, s, cfg) for s in (a, b)]
        together = learn.closed_loop_estimates(model, [a, b], cfg)
        single = learn.closed_loop_estimates(model, [a], cfg)
    assert [q.shape for q in together] == [(len(a), 4), (4500, 4)]
    assert np.array_equal(single[0], alone[0])  # one sequence: the same batches
    for q, r in zip(together, alone):
        assert np.max(quat.total_error(q, r)) < 1e-5
    assert learn.closed_loop_estimates(model, [], cfg) == []
    with pytest.raises(ValueError, match="different sampling rates"):
        learn.closed_loop_estimates(
            model, [a, dataclasses.replace(b, fs=2 * b.fs)], cfg
        )
    with pytest.raises(ValueError, match="has 10 samples"):
        learn.closed_loop_estimates(model, [a, _head(b, 10)], cfg)


@pytest.mark.realdata
def test_compare_batches_a_fold_and_keeps_the_per_trial_result(data_mirror):
    folder = COMMITTED
    table = learn.compare(folder, trials=[6, 1])  # both held out by fold 0
    assert list(table["trial"].unique()) == [1, 6]
    first = table[table["trial"] == 1]["method"].tolist()
    assert first[:2] == ["CNN (quaternion)", "CNN (learned gain)"]
    assert first[2:] == list(learn.BASELINES)
    for t in (1, 6):
        rec = datasets.load_broad_trial(t)
        q = learn.learned_estimate(rec, folder / "gain_fold0.pt")
        alone = learn.cv.trial_errors(q.values, rec)["inclination"]
        row = table[(table["trial"] == t) & (table["method"] == "CNN (learned gain)")]
        assert abs(float(row["inclination"].iloc[0]) - alone) < 1e-4


@pytest.mark.realdata
def test_saved_model_round_trip_and_closed_loop_run(small_sequences, tmp_path):
    rec, seqs = small_sequences
    cfg = _small_config(variant="gain")
    model, _ = learn.train(seqs, cfg, max_steps=5)
    digest = learn.save(model, cfg, seqs[0].fs, tmp_path / "m.pt")
    assert digest == learn.sha256(tmp_path / "m.pt")
    loaded, cfg2, fs = learn.load_model(tmp_path / "m.pt")
    assert cfg2 == cfg and fs == seqs[0].fs
    q1 = learn.closed_loop_estimate(model, seqs[0], cfg)
    q2 = learn.closed_loop_estimate(loaded, seqs[0], cfg)
    assert np.array_equal(q1, q2)
    assert q1.shape == (len(seqs[0]), 4)
    assert np.allclose(np.linalg.norm(q1, axis=1), 1.0, atol=1e-5)
    labelled = learn.learned_estimate(rec, tmp_path / "m.pt")
    assert labelled.dims == ("time", "quat") and labelled.attrs["fs"] == rec.attrs["fs"]
    half = rec.isel(time=slice(0, None, 2)).assign_attrs(fs=rec.attrs["fs"] / 2)
    with pytest.raises(ValueError, match="fs"):
        learn.learned_estimate(half, tmp_path / "m.pt")


def test_sequence_refuses_time_gaps(data_mirror):
    rec = datasets.load_broad_trial(1).isel(time=slice(0, 3000))
    gap = rec.isel(time=np.r_[0:1000, 1300:3000])
    with pytest.raises(Exception, match="gap"):
        learn.sequence(gap)


def test_sequence_needs_a_magnetometer(data_mirror):
    rec = datasets.load_broad_trial(1).isel(time=slice(0, 500)).drop_vars("mag")
    with pytest.raises(Exception, match="mag"):
        learn.sequence(rec)


# ------------------------------------------------------------------ committed files


def test_committed_models_match_their_checksums_and_folds():
    sums = learn.check_files(COMMITTED)
    weights = [n for n in sums if n.endswith(".pt")]
    assert weights and sum((COMMITTED / n).stat().st_size for n in weights) < 2e6
    run = json.loads((COMMITTED / "run.json").read_text())
    flat = [t for f in run["folds"] for t in f]
    assert sorted(flat) == sorted(run["trials"]) and len(set(flat)) == len(flat)
    assert run["command"].startswith("python -m tiltlab.learn train")
    groups = datasets.broad_trial_groups() if datasets.data_dir() else None
    if groups:  # every test fold holds disturbed trials
        for f in run["folds"]:
            assert any("disturbed" in groups[t] for t in f)
    for variant in run["configs"]:
        for k in range(len(run["folds"])):
            model, cfg, fs = learn.load_model(COMMITTED / f"{variant}_fold{k}.pt")
            assert cfg.variant == variant and fs == pytest.approx(285.714, abs=1e-3)


def test_check_files_names_a_tampered_file(tmp_path):
    (tmp_path / "a.json").write_text("{}")
    (tmp_path / "SHA256SUMS").write_text(f"{'0' * 64}  a.json\n")
    with pytest.raises(ValueError, match="a.json"):
        learn.check_files(tmp_path)
    assert learn_main(["check", str(tmp_path)]) == 1
    assert learn_main(["check", str(COMMITTED)]) == 0
