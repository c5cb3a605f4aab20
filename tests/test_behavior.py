"""Immobility detection (Fayat §2.9), the automatic valley threshold and the circling index."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from tiltlab import behavior as B
from tiltlab.intervals import intervals_to_mask, mask_to_intervals
from tiltlab import quaternion as Q
from tiltlab import schema


@given(arrays(np.bool_, st.integers(0, 300)))
@settings(max_examples=200, deadline=None)
def test_interval_round_trip(mask):
    iv = mask_to_intervals(mask)
    np.testing.assert_array_equal(intervals_to_mask(iv, mask.size), mask)
    assert np.all(iv[:, 1] > iv[:, 0])
    assert np.all(iv[1:, 0] > iv[:-1, 1])  # runs are separated by at least one False


def _speed(segments, fs):
    """Piecewise-constant speed: list of (duration_s, value)."""
    return np.concatenate([np.full(int(round(d * fs)), v, float) for d, v in segments])


def test_fayat_rules_merge_and_minimum_duration():
    fs = 100.0
    # 1 s still, 0.05 s burst (merged), 0.3 s still -> one 1.35 s period
    # then 1 s moving, 0.3 s still (dropped: < 0.5 s), 1 s moving, 0.6 s still (kept)
    s = _speed([(1.0, 2), (0.05, 50), (0.3, 3), (1.0, 80), (0.3, 5), (1.0, 90), (0.6, 1)], fs)
    m = B.detect_immobility(s, fs)
    iv = mask_to_intervals(m)
    np.testing.assert_array_equal(iv, [[0, 135], [365, 425]])
    # a 0.1 s gap is not merged (strictly less than 0.1 s merges)
    s2 = _speed([(1.0, 2), (0.1, 50), (1.0, 2)], fs)
    assert len(mask_to_intervals(B.detect_immobility(s2, fs))) == 2
    # threshold is strict: exactly 12 deg/s is movement
    assert not B.detect_immobility(np.full(200, 12.0), fs).any()
    assert B.detect_immobility(np.full(200, 11.999), fs).all()


@given(arrays(np.float64, st.integers(1, 400), elements=st.floats(0, 100)), st.sampled_from([50.0, 100.0, 300.0]))
@settings(max_examples=100, deadline=None)
def test_immobility_invariants(speed, fs):
    m = B.detect_immobility(speed, fs)
    iv = mask_to_intervals(m)
    # every kept period is long enough, and every sample below threshold outside kept periods
    # belongs to a short period
    assert np.all(iv[:, 1] - iv[:, 0] >= 0.5 * fs)
    # merging only adds samples next to still periods: a still sample is either kept or in a short run
    raw = mask_to_intervals(speed < 12.0)
    for a, b in raw:
        if b - a >= 0.5 * fs:
            assert m[a:b].all()


def test_valley_threshold_on_bimodal_mixture():
    rng = np.random.default_rng(0)
    still = 10 ** rng.normal(np.log10(3.0), 0.25, 30000)
    moving = 10 ** rng.normal(np.log10(80.0), 0.3, 50000)
    thr = B.valley_threshold(np.concatenate([still, moving]))
    # the density minimum between modes at 3 and 80 deg/s with these widths is near 14 deg/s
    assert 8.0 < thr < 25.0
    with pytest.raises(ValueError, match="not bimodal"):
        B.valley_threshold(10 ** rng.normal(1.0, 0.3, 10000))


def test_immobility_on_recording_and_units():
    fs = 100.0
    s_deg = _speed([(2.0, 1), (2.0, 60), (2.0, 1)], fs)
    gyr = np.column_stack([s_deg, 0 * s_deg, 0 * s_deg])
    acc = np.tile([0, 0, 1.0], (gyr.shape[0], 1))
    rec_deg = schema.make_recording(acc, gyr, fs, check_units=False)
    rec_rad = schema.make_recording(acc, np.radians(gyr), fs, gyr_units="rad/s", check_units=False)
    a = B.immobility(rec_deg)
    b = B.immobility(rec_rad)
    np.testing.assert_array_equal(a.values, b.values)
    assert a.sum() == 400 and a.attrs["threshold_deg_s"] == 12.0
    # an offset larger than the threshold hides every still period unless it is removed
    biased = schema.make_recording(acc, gyr + [-20.0, 0, 0], fs, check_units=False)
    assert B.immobility(biased).sum() < 400
    np.testing.assert_array_equal(B.immobility(biased, gyr_offset=[-20.0, 0, 0]).values, a.values)
    with pytest.raises(ValueError, match="'auto'"):
        B.immobility(rec_deg, threshold="valley")


def test_circling_index_of_steady_turning():
    # a head tilted 30 deg, turning about the vertical at 1 turn per 10 s (6 turns/min), CCW
    fs, n = 100.0, 3000
    tilt = Q.from_rotvec([np.radians(30), 0, 0])
    yaw_rate = 2 * np.pi / 10.0
    omega_world = np.array([0, 0, yaw_rate])
    # world-frame yaw: q(t) = exp(yaw t) ⊗ tilt; sensor-frame angular velocity = R(q)^T ω_world
    t = np.arange(n) / fs
    q = Q.mul(Q.from_rotvec(np.outer(t, omega_world)), tilt)
    gyr = np.degrees(Q.rotate_inverse(q, omega_world))
    g = Q.gravity(q)
    assert B.circling_index(gyr, g) == pytest.approx(6.0, rel=1e-12)
    assert B.circling_index(-gyr, g) == pytest.approx(-6.0, rel=1e-12)
    # the naive sensor-z component underestimates it on a tilted head
    assert np.mean(gyr[:, 2]) * 60 / 360 == pytest.approx(6.0 * np.cos(np.radians(30)), rel=1e-9)


def test_real_rat_example(data_mirror):
    import tiltlab.datasets as d

    rat = d.load_fayat_example()
    fixed = B.immobility(rat)
    auto = B.immobility(rat, threshold="auto")
    assert 0.0 < float(fixed.mean()) < 1.0
    assert 3.0 < auto.attrs["threshold_deg_s"] < 40.0


def test_speed_modes_find_a_planted_mixture():
    rng = np.random.default_rng(0)
    s = np.r_[10 ** rng.normal(np.log10(3.0), 0.15, 30000), 10 ** rng.normal(np.log10(100.0), 0.2, 60000)]
    m = B.speed_modes(s)
    assert m["still_mode"] == pytest.approx(3.0, rel=0.15)
    assert m["moving_mode"] == pytest.approx(100.0, rel=0.15)
    assert 6.0 < m["valley"] < 40.0 and m["depth"] < 0.05
    assert np.isnan(B.speed_modes(10 ** rng.normal(1.0, 0.2, 10000))["valley"])
    assert B.valley_threshold(s) == m["valley"]


def test_recording_speed_offsets():
    from tiltlab.simulate import simulate_session

    rec = simulate_session(20.0, 100.0, seed=4, keep_true=True)
    raw = B.recording_speed(rec, offset=None)
    np.testing.assert_allclose(raw, np.linalg.norm(rec["gyr"].values, axis=1))
    true = np.linalg.norm(rec["gyr_true"].values, axis=1)
    auto = B.recording_speed(rec)  # uses the simulation's true mean offset
    assert np.median(np.abs(auto - true)) < 1.0 < np.median(np.abs(raw - true))
    # without the truth, the quietest-window estimate still removes most of the offset
    blind = rec.copy()
    blind.attrs = {k: v for k, v in rec.attrs.items() if k != "true_gyr_offset_mean"}
    assert np.median(np.abs(B.recording_speed(blind) - true)) < np.median(np.abs(raw - true))
    with pytest.raises(ValueError, match="'auto'"):
        B.recording_speed(rec, offset="median")
