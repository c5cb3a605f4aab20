"""Bounded memory of the error-state RTS smoother: the checkpointed backward pass equals
the full-storage one, and its working arrays do not grow with the recording's length."""

import numpy as np
import pytest

from tiltlab import filters as F
from tiltlab import quaternion as Q
from tiltlab.filters import rts

HOUR_300HZ = 300 * 3600


def _recording(n, fs=100.0, seed=0):
    """Rest (ZUPT branch), then smooth rotation with gyro bias and noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    env = np.clip((t - 2.0) / 2.0, 0.0, 1.0)
    ph = rng.uniform(0, 2 * np.pi, 3)
    omega = env[:, None] * np.column_stack(
        [np.sin(0.9 * t + ph[0]), 0.7 * np.cos(0.5 * t + ph[1]), np.sin(1.3 * t)]
    )
    q_true = Q.integrate_gyro(
        np.vstack([omega[1:], omega[-1:]]), fs, Q.random_quaternions(1, rng)[0]
    )
    acc = 9.81 * Q.gravity(q_true) + 0.05 * rng.standard_normal((n, 3))
    gyr = omega + [0.004, -0.003, 0.002] + 0.003 * rng.standard_normal((n, 3))
    return acc, gyr, fs


def _run(monkeypatch, block, acc, gyr, fs, **kw):
    monkeypatch.setattr(rts, "_RTS_BLOCK", block)
    return F.rts_smoother(acc, gyr, fs, return_state=True, **kw)


@pytest.mark.parametrize(
    "n, block",
    [
        (5000, 512),  # 10 blocks, the last one partial
        (3 * 256 + 1, 256),  # the last block is the last sample alone
        (3 * 256 + 2, 256),
        (4 * 300, 300),  # N a multiple of the block
        (130, 128),  # the smallest checkpointed case: two blocks
    ],
)
@pytest.mark.parametrize(
    "kw",
    [{}, {"scale_std": 0.01, "scale_noise": 1e-4, "gyr_offset": np.zeros(3)}],
    ids=["default", "scale"],
)
def test_checkpointed_backward_pass_equals_full_storage(monkeypatch, n, block, kw):
    acc, gyr, fs = _recording(n)
    plan = rts._rts_plan(n, block)
    assert plan["checkpoints"] == -(-n // block) >= 2  # several blocks exercised
    q_full, x_full = _run(monkeypatch, None, acc, gyr, fs, **kw)
    q_ck, x_ck = _run(monkeypatch, block, acc, gyr, fs, **kw)
    # the forward recomputation repeats the same floating-point operations
    assert np.allclose(q_ck, q_full, rtol=0.0, atol=1e-12)
    assert np.allclose(x_ck, x_full, rtol=0.0, atol=1e-12)
    # and smoothing did happen (not the forward filter): the start moved
    q_fwd = F.rts_smoother(acc, gyr, fs, smooth=False, **kw)
    assert np.max(np.abs(q_full[: n // 2] - q_fwd[: n // 2])) > 1e-6


def test_default_block_equals_full_storage_over_several_blocks(monkeypatch):
    # the public default (2**14 samples per block) on three blocks
    n = 2 * rts._RTS_BLOCK + 1000
    acc, gyr, fs = _recording(n, fs=300.0, seed=2)
    monkeypatch.setattr(rts, "_RTS_BLOCK", None)
    q_full = F.rts_smoother(acc, gyr, fs)
    monkeypatch.undo()
    assert rts._rts_plan(n, rts._RTS_BLOCK)["checkpoints"] == 3
    assert np.allclose(F.rts_smoother(acc, gyr, fs), q_full, rtol=0.0, atol=1e-12)


def test_forward_only_and_short_recordings_need_no_block(monkeypatch):
    acc, gyr, fs = _recording(700)
    plan = rts._rts_plan(700, 64, smooth=False)
    assert plan["block_bytes"] == plan["checkpoint_bytes"] == 0
    a = F.rts_smoother(acc, gyr, fs, smooth=False)
    monkeypatch.setattr(rts, "_RTS_BLOCK", 64)
    assert np.array_equal(F.rts_smoother(acc, gyr, fs, smooth=False), a)
    # N ≤ B + 1: one block holding every sample, no checkpoints
    short = rts._rts_plan(rts._RTS_BLOCK + 1, rts._RTS_BLOCK)
    assert short["checkpoints"] == 0
    assert short["shapes"]["blk_Pf"] == (rts._RTS_BLOCK + 1, 15, 15)
    assert rts._rts_plan(1, rts._RTS_BLOCK)["shapes"]["blk_qf"] == (1, 4)
    q1 = F.rts_smoother(acc[:1], gyr[:1], fs, q0=[1.0, 0.0, 0.0, 0.0])
    assert np.allclose(q1, [[1.0, 0.0, 0.0, 0.0]])


def test_working_arrays_do_not_grow_with_the_recording():
    b = rts._RTS_BLOCK
    plans = {n: rts._rts_plan(n, b) for n in (10 * b, HOUR_300HZ, 6 * HOUR_300HZ)}
    block_bytes = {p["block_bytes"] for p in plans.values()}
    assert block_bytes == {(b + 1) * 2056}  # the same one block, whatever N
    assert (b + 1) * 2056 < 40e6
    for n, p in plans.items():
        assert p["checkpoints"] == -(-n // b)
        assert p["checkpoint_bytes"] == p["checkpoints"] * 1928  # 0.12 B per sample
        assert p["output_bytes"] == 32 * n  # the (N, 4) quaternions only
        assert p["total_bytes"] == (
            p["output_bytes"] + p["checkpoint_bytes"] + p["block_bytes"]
        )
    six_h = plans[6 * HOUR_300HZ]
    # 6 h at 300 Hz: 0.24 GB in all (the full-storage smoother: 13 GB)
    assert six_h["total_bytes"] < 0.25e9
    assert six_h["checkpoint_bytes"] + six_h["block_bytes"] < 35e6
    assert rts._rts_plan(6 * HOUR_300HZ, None)["total_bytes"] > 13e9
    with_state = rts._rts_plan(6 * HOUR_300HZ, b, return_state=True)
    assert with_state["output_bytes"] == 128 * 6 * HOUR_300HZ


def test_kernel_allocates_exactly_the_planned_arrays(monkeypatch):
    seen = []
    kernel = rts._rts_kernel

    def spy(inputs, params, q0, x0, P0, arrays, smooth):
        seen.append([a.shape for a in arrays])
        return kernel(inputs, params, q0, x0, P0, arrays, smooth)

    monkeypatch.setattr(rts, "_rts_kernel", spy)
    monkeypatch.setattr(rts, "_RTS_BLOCK", 100)
    for n in (1000, 4000):
        acc, gyr, fs = _recording(n)
        F.rts_smoother(acc, gyr, fs)
        assert seen[-1] == list(rts._rts_plan(n, 100)["shapes"].values())
    # every array but the outputs has a size set by the block, not by N (the
    # checkpoints: one row per block)
    small, large = seen
    assert small[3:8] == large[3:8] and small[3][0] == 101
    assert small[0][0] == 10 and large[0][0] == 40
    assert small[-1] == large[-1] == (0, 12)  # no states kept unless returned


def test_memory_limit_message_explains_the_memory():
    acc = np.tile([0.0, 0.0, 9.81], (1000, 1))
    gyr = np.zeros((1000, 3))
    with pytest.raises(ValueError, match="32 B per sample.*checkpoints.*block"):
        F.rts_smoother(acc, gyr, 100.0, max_memory_gb=1e-6)
    with pytest.raises(ValueError, match="block must be"):
        rts._rts_plan(10, 0)
