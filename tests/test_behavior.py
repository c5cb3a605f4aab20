"""Immobility detection (Fayat §2.9), the automatic valley threshold, the circling index,
static acceleration and DBA (Benhamou §2, §9), and the metadata they read."""

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation

from tiltlab import behavior as B
from tiltlab import dsp, filters, schema
from tiltlab._validate import RecordingError
from tiltlab.intervals import intervals_to_mask, mask_to_intervals
from tiltlab import quaternion as Q

SET = settings(max_examples=40, deadline=None)
seed_s = st.integers(0, 2**32 - 1)


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
    s = _speed(
        [(1.0, 2), (0.05, 50), (0.3, 3), (1.0, 80), (0.3, 5), (1.0, 90), (0.6, 1)], fs
    )
    m = B.detect_immobility(s, fs)
    iv = mask_to_intervals(m)
    np.testing.assert_array_equal(iv, [[0, 135], [365, 425]])
    # a 0.1 s gap is not merged (strictly less than 0.1 s merges)
    s2 = _speed([(1.0, 2), (0.1, 50), (1.0, 2)], fs)
    assert len(mask_to_intervals(B.detect_immobility(s2, fs))) == 2
    # threshold is strict: exactly 12 deg/s is movement
    assert not B.detect_immobility(np.full(200, 12.0), fs).any()
    assert B.detect_immobility(np.full(200, 11.999), fs).all()


@given(
    arrays(np.float64, st.integers(1, 400), elements=st.floats(0, 100)),
    st.sampled_from([50.0, 100.0, 300.0]),
)
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
    rec_deg = schema.make_recording(
        acc, gyr, fs, acc_units="g", gyr_units="deg/s", check_units=False
    )
    rec_rad = schema.make_recording(
        acc, np.radians(gyr), fs, acc_units="g", gyr_units="rad/s", check_units=False
    )
    a = B.immobility(rec_deg)
    b = B.immobility(rec_rad)
    np.testing.assert_array_equal(a.values, b.values)
    assert a.sum() == 400 and a.attrs["threshold_deg_s"] == 12.0
    # an offset larger than the threshold hides every still period unless it is removed
    biased = schema.make_recording(
        acc,
        gyr + [-20.0, 0, 0],
        fs,
        acc_units="g",
        gyr_units="deg/s",
        check_units=False,
    )
    assert B.immobility(biased).sum() < 400
    np.testing.assert_array_equal(
        B.immobility(biased, gyr_offset=[-20.0, 0, 0]).values, a.values
    )
    with pytest.raises(ValueError, match="'auto'"):
        B.immobility(rec_deg, threshold_deg_s="valley")


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
    assert B.circling_index(gyr, g, units="deg/s") == pytest.approx(6.0, rel=1e-12)
    assert B.circling_index(-gyr, g, units="deg/s") == pytest.approx(-6.0, rel=1e-12)
    # the naive sensor-z component underestimates it on a tilted head
    assert np.mean(gyr[:, 2]) * 60 / 360 == pytest.approx(
        6.0 * np.cos(np.radians(30)), rel=1e-9
    )


def test_real_rat_example(data_mirror):
    import tiltlab.datasets as d

    rat = d.load_fayat_example()
    fixed = B.immobility(rat)
    auto = B.immobility(rat, threshold_deg_s="auto")
    assert 0.0 < float(fixed.mean()) < 1.0
    assert 3.0 < auto.attrs["threshold_deg_s"] < 40.0


def test_speed_modes_find_a_planted_mixture():
    rng = np.random.default_rng(0)
    s = np.r_[
        10 ** rng.normal(np.log10(3.0), 0.15, 30000),
        10 ** rng.normal(np.log10(100.0), 0.2, 60000),
    ]
    m = B.speed_modes(s)
    assert m["still_mode"] == pytest.approx(3.0, rel=0.15)
    assert m["moving_mode"] == pytest.approx(100.0, rel=0.15)
    assert 6.0 < m["valley"] < 40.0 and m["depth"] < 0.05
    assert np.isnan(B.speed_modes(10 ** rng.normal(1.0, 0.2, 10000))["valley"])
    assert B.valley_threshold(s) == m["valley"]


def test_recording_speed_offsets():
    from tiltlab.simulate import simulate_session

    rec = simulate_session(20.0, 100.0, seed=4, keep_true=True)
    raw = B.recording_speed(rec, gyr_offset=None)
    np.testing.assert_allclose(raw, np.linalg.norm(rec["gyr"].values, axis=1))
    true = np.linalg.norm(rec["gyr_true"].values, axis=1)
    # "auto": the quietest-window estimate (calibration.robust_gyro_offset), never the truth
    auto = B.recording_speed(rec)
    assert np.median(np.abs(auto - true)) < 1.0 < np.median(np.abs(raw - true))
    # the simulator's truth attribute is not read: removing it changes nothing
    blind = rec.copy()
    blind.attrs = {k: v for k, v in rec.attrs.items() if k != "true_gyr_offset_mean"}
    assert np.median(np.abs(B.recording_speed(blind) - true)) < np.median(
        np.abs(raw - true)
    )
    np.testing.assert_array_equal(B.recording_speed(blind).values, auto.values)
    with pytest.raises(ValueError, match="'auto'"):
        B.recording_speed(rec, gyr_offset="median")


# ---------------------------------------------------------------------------
# static / dynamic acceleration
# ---------------------------------------------------------------------------


@SET
@given(seed_s, st.integers(1, 40))
def test_static_acceleration_windows(seed, k):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(157, 3))
    fs = 50.0
    s = B.static_acceleration(a, fs, window_s=k / fs)
    i = 80
    before, after = k // 2, k - 1 - k // 2
    assert np.allclose(s[i], a[i - before : i + after + 1].mean(axis=0))
    assert np.all(np.isfinite(s)) and s.shape == a.shape
    j = B.static_acceleration(a, fs, window_s=k / fs, mode="jumping")
    assert j.shape == (157 // k, 3) and np.allclose(j[0], a[:k].mean(axis=0))
    c = np.tile([0.1, -0.2, 0.97], (157, 1))
    assert np.allclose(B.static_acceleration(c, fs, window_s=k / fs), c)


@SET
@given(seed_s)
def test_dba_is_rotation_invariant_and_odba_is_not(seed):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(300, 3)) * [0.3, 0.1, 0.05] + [0, 0, 1]
    R = Rotation.random(random_state=seed % 2**31).as_matrix()
    ar = a @ R.T
    assert np.allclose(
        B.dba(a, 100.0, window_s=0.5), B.dba(ar, 100.0, window_s=0.5), atol=1e-12
    )
    od, odr = B.odba(a, 100.0, window_s=0.5), B.odba(ar, 100.0, window_s=0.5)
    assert np.all(od >= B.dba(a, 100.0, window_s=0.5) - 1e-12)
    assert not np.allclose(od, odr, rtol=1e-3)


def test_step_summary():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(1005, 3))
    s = B.step_summary(a, 100.0, window_s=1.0)
    assert s.static.shape == (10, 3) and s.dba.shape == (10,)
    full = B.static_acceleration(a, 100.0, window_s=1.0)
    assert np.allclose(s.static[3], full[350]) and np.isclose(s.time[3], 3.5)
    d = np.linalg.norm(a - full, axis=1)
    assert np.isclose(s.dba[2], d[200:300].mean())


def test_activity_bad_inputs():
    with pytest.raises(ValueError):
        B.static_acceleration(np.ones((10, 3)), fs=0, window_s=1)
    with pytest.raises(ValueError, match="mode"):
        B.static_acceleration(np.ones((10, 3)), 10.0, window_s=1, mode="hopping")
    with pytest.raises(ValueError, match="window_s"):
        B.dba(np.ones((10, 3)), 10.0, window_s=0.0)


# ------------------------------------------------------------ metadata travels


def _session(duration_s=60.0, seed=3):
    from tiltlab.simulate import simulate_session

    return simulate_session(duration_s, 100.0, seed=seed, keep_true=False)


def _in_rad_s(rec):
    gyr = rec["gyr"]
    return rec.assign(
        gyr=(gyr.dims, np.radians(gyr.values), {**gyr.attrs, "units": "rad/s"})
    )


def _without_fs(obj):
    out = obj.copy()
    out.attrs = {k: v for k, v in obj.attrs.items() if k != "fs"}
    return out


def test_angular_speed_reads_units_and_fs_from_the_recording():
    rec = _session()
    rad = _in_rad_s(rec)
    assert rad["gyr"].attrs["units"] == "rad/s"
    speed = B.angular_speed(rec)
    assert isinstance(speed, xr.DataArray) and speed.dims == ("time",)
    assert speed.attrs["units"] == "deg/s" and speed.attrs["fs"] == 100.0
    np.testing.assert_array_equal(speed.time.values, rec.time.values)
    np.testing.assert_allclose(B.angular_speed(rad).values, speed.values, rtol=1e-12)
    np.testing.assert_allclose(
        B.angular_speed(rad["gyr"]).values, speed.values, rtol=1e-12
    )
    plain = B.angular_speed(rec["gyr"].values, units="deg/s")
    assert isinstance(plain, np.ndarray)
    np.testing.assert_array_equal(plain, speed.values)
    # the detector reads fs (and the speed's units) from the labelled speed
    m = B.detect_immobility(speed, threshold_deg_s=12)
    assert m.attrs["fs"] == 100.0 and m.attrs["threshold_deg_s"] == 12.0
    np.testing.assert_array_equal(m.values, B.detect_immobility(speed.values, 100.0))
    in_rad = speed.copy(data=np.radians(speed.values)).assign_attrs(units="rad/s")
    np.testing.assert_array_equal(
        B.detect_immobility(in_rad, threshold_deg_s=12).values, m.values
    )


def test_immobility_of_a_rad_s_recording_equals_deg_s():
    # regression: a rad/s gyroscope thresholded as if in deg/s is 57x off
    rec = _session()
    rad = _in_rad_s(rec)
    for thr in (12.0, "auto"):
        a = B.immobility(rec, threshold_deg_s=thr, gyr_offset="auto")
        b = B.immobility(rad, threshold_deg_s=thr, gyr_offset="auto")
        assert 0.05 < float(a.mean()) < 0.95
        np.testing.assert_array_equal(a.values, b.values)
        assert a.attrs["threshold_deg_s"] == pytest.approx(
            b.attrs["threshold_deg_s"], rel=1e-12
        )
    # the same from a labelled gyroscope and from a plain one with fs and units
    a = B.immobility(rec)
    np.testing.assert_array_equal(
        B.immobility(rad["gyr"].assign_attrs(fs=100.0)).values, a.values
    )
    plain = B.immobility(rad["gyr"].values, 100.0, units="rad/s")
    assert isinstance(plain, np.ndarray)
    np.testing.assert_array_equal(plain, a.values)


def test_detect_immobility_is_the_dsp_still_mask():
    rng = np.random.default_rng(5)
    s = np.abs(rng.normal(10.0, 8.0, 3000))
    for fs in (50.0, 100.0, 300.0):
        ref = dsp.still_mask(s, fs, threshold=12.0, merge_gap_s=0.1, min_duration_s=0.5)
        np.testing.assert_array_equal(B.detect_immobility(s, fs), ref)


def test_a_missing_fs_is_an_error_naming_fs():
    rec = _session(20.0)
    no_fs = _without_fs(rec)
    speed = _without_fs(B.angular_speed(rec))
    calls = [
        lambda: B.immobility(no_fs),
        lambda: B.immobility(no_fs["gyr"]),
        lambda: B.detect_immobility(speed),
        lambda: B.detect_immobility(speed.values),
        lambda: B.recording_speed(no_fs),
        lambda: B.gyro_spectrum(no_fs),
        lambda: B.static_acceleration(no_fs, window_s=0.5),
        lambda: B.dba(no_fs, window_s=0.5),
        lambda: B.odba(no_fs["acc"], window_s=0.5),
        lambda: B.step_summary(no_fs, window_s=0.5),
    ]
    for call in calls:
        with pytest.raises(RecordingError, match="fs"):
            call()
    # a contradictory fs is an error too
    with pytest.raises(RecordingError, match="fs"):
        B.immobility(rec, 200.0)
    # speed without an offset estimate needs no fs
    assert B.recording_speed(no_fs, gyr_offset=None).shape == (rec.sizes["time"],)


def test_a_missing_or_contradictory_unit_is_an_error_naming_it():
    rec = _session(20.0)
    with pytest.raises(RecordingError, match="units"):
        B.angular_speed(rec["gyr"].values)
    with pytest.raises(RecordingError, match="units"):
        B.angular_speed(rec, units="rad/s")
    with pytest.raises(RecordingError, match="units"):
        B.immobility(rec["gyr"].values, 100.0)
    unitless = rec["gyr"].assign_attrs(fs=100.0)
    del unitless.attrs["units"]
    with pytest.raises(RecordingError, match="units"):
        B.immobility(unitless)
    with pytest.raises(RecordingError, match="units"):
        B.circling_index(
            rec["gyr"].values, np.tile([0, 0, 1.0], (rec.sizes["time"], 1))
        )


def test_circling_index_reads_gyroscope_units_and_a_gravity_dataarray():
    fs, n = 100.0, 3000
    tilt = Q.from_rotvec([np.radians(30), 0, 0])
    omega_world = np.array([0, 0, 2 * np.pi / 10.0])
    t = np.arange(n) / fs
    q = Q.mul(Q.from_rotvec(np.outer(t, omega_world)), tilt)
    gyr = Q.rotate_inverse(q, omega_world)  # rad/s
    rec = schema.make_recording(
        Q.gravity(q), gyr, fs, acc_units="g", gyr_units="rad/s", check_units=False
    )
    g = filters.gravity(
        xr.DataArray(q, dims=("time", "quat"), coords={"time": rec.time.values})
    )
    assert B.circling_index(rec, g) == pytest.approx(6.0, rel=1e-12)
    assert B.circling_index(rec["gyr"], g.values) == pytest.approx(6.0, rel=1e-12)
    az = B.azimuthal_speed(rec, g)
    assert az.attrs["units"] == "deg/s" and az.attrs["fs"] == fs
    np.testing.assert_allclose(az.values, 36.0, rtol=1e-12)
    moving = np.arange(n) < n // 2
    assert B.circling_index(rec, g, moving=moving) == pytest.approx(6.0, rel=1e-12)
    with pytest.raises(RecordingError, match="time"):
        B.circling_index(rec, g.assign_coords(time=g.time + 1.0))


def test_behavior_numeric_parameters_are_checked():
    s = np.full(200, 5.0)
    with pytest.raises(ValueError, match="threshold_deg_s"):
        B.detect_immobility(s, 100.0, threshold_deg_s=-1.0)
    with pytest.raises(ValueError, match="merge_gap_s"):
        B.detect_immobility(s, 100.0, merge_gap_s=-0.1)
    with pytest.raises(ValueError, match="min_duration_s"):
        B.detect_immobility(s, 100.0, min_duration_s=np.nan)
    with pytest.raises(ValueError, match="bins"):
        B.speed_modes(s, bins=0)
    with pytest.raises(ValueError, match="min_prominence"):
        B.speed_modes(s, min_prominence=2.0)
    with pytest.raises(ValueError, match="threshold_deg_s"):
        B.realism_table({}, threshold_deg_s=0.0)
    with pytest.raises(ValueError, match="nperseg_s"):
        B.gyro_spectrum(np.zeros((100, 3)), 100.0, units="deg/s", nperseg_s=0.0)
    with pytest.raises(ValueError, match="gyr_offset"):
        B.immobility(np.zeros((100, 3)), 100.0, units="deg/s", gyr_offset=[1.0, 2.0])


def test_activity_keeps_labels_and_units():
    rec = _session(20.0)
    st_ = B.static_acceleration(rec, window_s=0.5)
    assert st_.dims == ("time", "axis") and st_.attrs == {"fs": 100.0, "units": "g"}
    np.testing.assert_array_equal(
        st_.values, B.static_acceleration(rec["acc"].values, 100.0, window_s=0.5)
    )
    d = B.dba(rec, window_s=0.5)
    assert d.dims == ("time",) and d.attrs["units"] == "g"
    np.testing.assert_array_equal(
        d.values, B.dba(rec["acc"].values, 100.0, window_s=0.5)
    )
    j = B.static_acceleration(rec, window_s=0.5, mode="jumping")
    assert j.attrs["fs"] == 2.0 and j.sizes["time"] == rec.sizes["time"] // 50
    s = B.step_summary(rec, window_s=1.0)
    p = B.step_summary(rec["acc"].values, 100.0, window_s=1.0)
    np.testing.assert_allclose(s.time, p.time + float(rec.time[0]))
    np.testing.assert_array_equal(s.dba.values, p.dba)


def test_dba_nan_only_where_the_window_touches_a_gap():
    """A gap (NaN samples) makes DBA NaN within half a window of it; elsewhere the
    values equal those of the same recording without the gap."""
    from tiltlab import behavior

    rng = np.random.default_rng(4)
    fs, k = 100.0, 50  # window 0.5 s = 50 samples
    a = np.c_[rng.normal(0, 0.1, (2000, 2)), 1 + rng.normal(0, 0.1, 2000)]
    gappy = a.copy()
    gappy[1000:1010] = np.nan
    full = behavior.dba(a, fs, window_s=0.5)
    cut = behavior.dba(gappy, fs, window_s=0.5)
    near = np.zeros(2000, bool)
    near[1000 - (k - 1 - k // 2) : 1010 + k // 2] = True
    assert np.isnan(cut[near]).all()
    np.testing.assert_allclose(cut[~near], full[~near], rtol=1e-12)
    assert np.isfinite(behavior.odba(gappy, fs, window_s=0.5)[~near]).all()
