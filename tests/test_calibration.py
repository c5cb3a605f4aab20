"""Tests for tiltlab.calibration: synthetic inputs built here with numpy + tiltlab.quaternion."""

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import tiltlab.calibration as C
from tiltlab import quaternion as Q
from tiltlab import frames, schema, units

FS = 300.0


def _sensor_matrix(rng, scale_sd=0.01, mis_sd=0.005):
    E = rng.normal(0, mis_sd, (3, 3)) * (1 - np.eye(3))
    return (np.eye(3) + np.diag(rng.normal(0, scale_sd, 3))) @ (np.eye(3) + E)


def _static_means(dirs, T, o, noise, rng):
    return dirs @ T.T + o + rng.normal(0, noise, dirs.shape)


def _tumble_record(
    rng, dirs, gyr_offset, hold_s=1.0, move_s=0.5, acc_offset=(0.03, -0.05, 0.02)
):
    """Piecewise static acc with smooth moves (gyro bursts) between holds; returns acc, gyr, true still mask."""
    acc, gyr, still = [], [], []
    nh, nm = int(hold_s * FS), int(move_s * FS)
    for d in dirs:
        acc.append(np.tile(d, (nh, 1)))
        gyr.append(np.zeros((nh, 3)))
        still.append(np.ones(nh, bool))
        acc.append(np.tile(d, (nm, 1)) + rng.normal(0, 0.2, (nm, 3)))
        w = 150.0 * np.sin(np.pi * np.arange(nm) / nm)[:, None] * rng.normal(0, 1, 3)
        gyr.append(w)
        still.append(np.zeros(nm, bool))
    acc = (
        np.concatenate(acc)
        + np.asarray(acc_offset)
        + rng.normal(0, 0.003, (sum(map(len, still)), 3))
    )
    gyr = np.concatenate(gyr) + np.asarray(gyr_offset) + rng.normal(0, 0.1, acc.shape)
    return acc, gyr, np.concatenate(still)


# ------------------------------------------------------------------ static periods


@settings(max_examples=40, deadline=None)
@given(st.lists(st.booleans(), min_size=1, max_size=200))
def test_mask_intervals_round_trip(bits):
    m = np.array(bits)
    iv = C.mask_to_intervals(m)
    assert np.array_equal(C.intervals_to_mask(iv, m.size), m)
    assert np.all(iv[:, 1] > iv[:, 0])


def test_merge_and_min_length():
    m = np.array([1, 1, 0, 1, 1, 0, 0, 0, 1], bool)
    assert C.mask_to_intervals(m, merge_gap=1).tolist() == [[0, 5], [8, 9]]
    assert C.mask_to_intervals(m, min_length=2).tolist() == [[0, 2], [3, 5]]


def test_detect_static_with_large_gyro_offsets():
    rng = np.random.default_rng(0)
    dirs = C.fibonacci_lattice(8)
    off = np.array([-22.6, 10.5, 4.0])  # Fayat's 5th/95th percentile offsets
    acc, gyr, still = _tumble_record(rng, dirs, off)
    iv = C.detect_static(gyr, FS, threshold_deg_s=3.0, min_duration_s=0.4)
    assert iv.shape[0] == len(dirs)
    found = C.intervals_to_mask(iv, len(still))
    assert not np.any(found & ~still)  # never inside a movement
    assert found.sum() > 0.8 * still.sum()
    # the robust first pass is what makes it work: raw thresholding finds nothing
    assert (
        C.detect_static(gyr, FS, threshold_deg_s=3.0, gyr_offset=np.zeros(3)).shape[0]
        == 0
    )
    np.testing.assert_allclose(C.robust_gyro_offset(gyr, FS), off, atol=0.05)
    go, se = C.gyro_offset(gyr, iv)
    assert np.all(np.abs(go - off) < 5 * se + 0.02)


def test_trigger_intervals():
    tr = np.zeros(1000)
    tr[[300, 301, 302, 700]] = 1
    iv = C.static_intervals_from_trigger(tr, FS, window_s=0.4)
    assert iv.tolist() == [[180, 300], [580, 700]]
    gyr = np.zeros((1000, 3))
    assert np.array_equal(C.detect_static(gyr, FS, trigger=tr), iv)


def test_static_means_rejects_saturation():
    x = np.zeros((100, 3))
    x[:, 2] = 2.0
    with pytest.raises(C.CalibrationError, match="saturated"):
        C.static_means(x, [[0, 50]], full_scale=2.0)
    with pytest.raises(C.CalibrationError, match="still periods"):
        C.static_means(x, [[0, 50]], min_periods=3)


# ------------------------------------------------------------------ accelerometer fits


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.integers(3, 30))
def test_fit_offsets_exact_without_scale_errors(seed, n):
    rng = np.random.default_rng(seed)
    dirs = Q.gravity(Q.random_quaternions(n, rng))
    if n == 3 and C.triplet_orthogonality(dirs) < 0.3:
        dirs = np.eye(3)
    o = rng.uniform(-0.1, 0.07, 3)
    fit = C.fit_offsets(dirs + o)
    np.testing.assert_allclose(fit.offset, o, atol=1e-8)
    assert fit.mean_abs_error < 1e-8


def test_three_orthogonal_positions_bar():
    """< 0.002 g from three orthogonal positions (sensor without scale errors, realistic noise)."""
    rng = np.random.default_rng(1)
    for _ in range(20):
        o = rng.uniform(-0.1, 0.07, 3)
        R = Rotation.random(
            random_state=rng
        ).as_matrix()  # orthogonal triplet, any attitude
        means = _static_means(R.T, np.eye(3), o, 3e-4, rng)
        fit = C.fit_offsets(means)
        assert np.max(np.abs(fit.offset - o)) < 0.002


def test_three_point_offset_absorbs_scale_error():
    """With z, x, y up, the offset-only solution is off by the scale error of each axis (the floor's origin)."""
    rng = np.random.default_rng(2)
    s = rng.normal(0, 0.01, 3)
    o = np.array([0.02, -0.04, 0.01])
    fit = C.fit_offsets(np.eye(3) @ np.diag(1 + s) + o)
    np.testing.assert_allclose(fit.offset - o, s, atol=2e-4)


def test_offset_uncertainty_is_calibrated():
    rng = np.random.default_rng(3)
    o = np.array([0.05, -0.02, 0.03])
    dirs = C.fibonacci_lattice(20)
    errs, ses = [], []
    for _ in range(200):
        means = _static_means(dirs, np.eye(3), o, 1e-3, rng)
        fit = C.fit_offsets(means, sem=np.full(means.shape, 1e-3))
        errs.append(fit.offset - o)
        ses.append(fit.stderr)
    z = np.array(errs) / np.array(ses)
    assert 0.8 < z.std() < 1.2


def test_ellipsoid_bar_50_lattice_positions():
    """Offsets < 0.0005 g and scale/misalignment < 0.2 % from 50 lattice positions."""
    rng = np.random.default_rng(4)
    dirs = C.fibonacci_lattice(50)
    for _ in range(10):
        T = _sensor_matrix(rng)
        o = rng.uniform(-0.1, 0.07, 3)
        means = _static_means(
            dirs, T, o, 3.3e-4, rng
        )  # 300 µg/√Hz over 120 samples at 300 Hz
        fit = C.fit_ellipsoid(means)
        assert np.max(np.abs(fit.offset - o)) < 0.0005
        assert (
            np.max(np.abs(fit.matrix - C.identifiable_matrix(np.linalg.inv(T)))) < 0.002
        )
        corrected = (means - fit.offset) @ fit.matrix.T
        assert np.mean(np.abs(np.linalg.norm(corrected, axis=1) - 1)) < 1e-3
        # offset-only fit leaves a floor well above the noise
        assert C.fit_offsets(means).mean_abs_error > 2 * fit.mean_abs_error


def test_ellipsoid_symmetric_gauge_and_uncertainty():
    rng = np.random.default_rng(5)
    A = rng.normal(0, 0.05, (3, 3))
    W = np.eye(3) + 0.5 * (A + A.T)  # symmetric soft iron
    h = np.array([10.0, -5.0, 3.0])
    m = (
        47.0 * Q.gravity(Q.random_quaternions(2000, rng)) @ W.T
        + h
        + rng.normal(0, 0.3, (2000, 3))
    )
    fit = C.fit_mag_ellipsoid(m, field=47.0)
    np.testing.assert_allclose(fit.offset, h, atol=5 * fit.offset_stderr.max() + 0.05)
    np.testing.assert_allclose(fit.matrix, np.linalg.inv(W), atol=0.005)


def test_known_directions_12_parameters():
    rng = np.random.default_rng(6)
    dirs = C.fibonacci_lattice(30)
    T = Rotation.from_rotvec([0.02, -0.01, 0.03]).as_matrix() @ _sensor_matrix(rng)
    o = np.array([0.01, 0.02, -0.03])
    fit = C.fit_known_directions(_static_means(dirs, T, o, 2e-4, rng), dirs)
    np.testing.assert_allclose(fit.sensor_matrix, T, atol=5e-4)
    np.testing.assert_allclose(fit.offset, o, atol=3e-4)
    assert np.all(fit.offset_stderr > 0)


def test_bad_geometry_raises():
    rng = np.random.default_rng(7)
    ang = rng.uniform(0, 2 * np.pi, 30)
    ring = np.column_stack(
        [np.cos(ang), np.sin(ang), np.zeros(30)]
    )  # coplanar: a great circle
    with pytest.raises(C.CalibrationError):
        C.fit_ellipsoid(ring + 0.01)
    with pytest.raises(C.CalibrationError):
        C.fit_known_directions(ring + 0.01, ring)
    line = np.array([[0, 0, 1.0], [0, 0, 1.0001], [0, 0, 0.9999]])
    with pytest.raises(C.CalibrationError):
        C.fit_offsets(line)
    with pytest.raises(C.CalibrationError, match="at least"):
        C.fit_offsets(np.eye(3)[:2])
    with pytest.raises(C.CalibrationError, match="at least"):
        C.fit_ellipsoid(C.fibonacci_lattice(8))
    with pytest.raises(C.CalibrationError, match="saturated"):
        C.fit_offsets(np.array([[0, 0, 0.5], [1, 0, 0], [0, 1, 0]]))  # clipped at 0.5 g


def test_batch_offsets_match_single_fits():
    rng = np.random.default_rng(8)
    dirs = C.fibonacci_lattice(50)
    means = _static_means(
        dirs, _sensor_matrix(rng), np.array([0.02, -0.03, 0.05]), 3e-4, rng
    )
    sub = C.all_subsets(50, 4, max_subsets=20, rng=rng)
    batch = C.fit_offsets_batch(means[sub])
    single = np.array([C.fit_offsets(means[s]).offset for s in sub])
    cost = lambda o, s: np.sum((np.linalg.norm(means[s] - o, axis=1) - 1) ** 2)  # noqa: E731
    for b, o, s in zip(batch, single, sub):
        assert (
            cost(b, s) <= cost(o, s) * (1 + 1e-9) + 1e-15
        )  # same minimum (the valley can be flat)
    np.testing.assert_allclose(batch, single, atol=1e-6)


def test_lattice_and_stage_design():
    g = C.fibonacci_lattice(50)
    np.testing.assert_allclose(np.linalg.norm(g, axis=1), 1.0)
    pitch, roll = C.stage_angles(g)
    np.testing.assert_allclose(
        Q.gravity(C.stage_quaternion(pitch, roll)), g, atol=1e-12
    )
    idx = C.lattice_subset(g, 6)
    assert len(set(idx.tolist())) == 6
    assert C.triplet_orthogonality(np.eye(3)) == pytest.approx(1.0)


# ------------------------------------------------------------------ temperature


def test_temperature_model_recovers_cubic():
    rng = np.random.default_rng(9)
    t = np.linspace(27, 35, 12)
    coef = np.array(
        [[1e-5, -2e-4, 3e-3, 0.02], [-2e-5, 1e-4, -1e-3, -0.05], [0, 5e-5, 2e-3, 0.01]]
    )
    off = np.stack([np.polyval(c, t - 31) for c in coef], axis=1)
    model = C.fit_temperature_model(t, off + rng.normal(0, 1e-6, off.shape))
    tt = np.linspace(27.5, 34.5, 50)
    truth = np.stack([np.polyval(c, tt - 31) for c in coef], axis=1)
    np.testing.assert_allclose(model(tt), truth, atol=2e-5)
    x = truth + 0.5
    np.testing.assert_allclose(C.compensate_temperature(x, tt, model), 0.5, atol=2e-5)
    with pytest.raises(C.CalibrationError, match="outside"):
        model(np.array([50.0]))
    with pytest.raises(C.CalibrationError, match="distinct"):
        C.fit_temperature_model([30, 30, 31, 31], off[:4])
    assert (
        C.TemperatureModel.from_dict(json.loads(json.dumps(model.to_dict()))) == model
    )


# ------------------------------------------------------------------ drift


def test_drift_arithmetic_and_methods():
    assert C.deg_per_hour(0.95385) == pytest.approx(3433.86)
    assert C.deg_per_hour(0.004718) == pytest.approx(16.9848)
    rng = np.random.default_rng(10)
    fs, n = 25.0, 25 * 600
    bias = np.array([0.29, -0.95, 0.82])
    g = bias + rng.normal(0, 0.05, (n, 3))
    raw = C.correct_drift(g, fs, method="none")
    np.testing.assert_allclose(raw.angle[-1] / (n / fs), bias, atol=0.01)
    for method, kw in (
        ("first_window", {}),
        ("linear_fit", {}),
        ("prior", {"prior_deg_s": bias}),
    ):
        res = C.correct_drift(g, fs, method=method, **kw)
        assert np.max(np.abs(res.angle[-1])) < 0.05 * np.max(np.abs(raw.angle[-1]))
    with pytest.raises(ValueError, match="prior"):
        C.correct_drift(g, fs, method="prior")


def test_allan_deviation_white_noise():
    rng = np.random.default_rng(11)
    fs, nd = 100.0, 0.01  # noise density °/s/√Hz
    x = rng.normal(
        0, nd * np.sqrt(fs), (200_000, 3)
    )  # white noise of density nd (two-sided sd·√(1/fs))
    taus, ad = C.allan_deviation(x, fs)
    assert np.all(np.diff(np.log(ad[:, 0])) < 0.05)  # decreasing
    slope = np.polyfit(np.log(taus), np.log(ad[:, 0]), 1)[0]
    assert slope == pytest.approx(-0.5, abs=0.05)
    noise = C.allan_noise_parameters(taus, ad)
    np.testing.assert_allclose(noise.arw, nd, rtol=0.1)


# ------------------------------------------------------------------ magnetometer


def test_four_point_and_minmax_on_diagonal_distortion():
    rng = np.random.default_rng(12)
    field = 47.0 * np.array([0, np.cos(np.radians(61)), -np.sin(np.radians(61))])
    D = np.diag([1.05, 0.97, 1.02])
    h = np.array([12.0, -8.0, 3.0])
    bottom_q, flank_q = C.four_point_poses("left")
    raw = lambda q: Q.rotate_inverse(q, field) @ D.T + h  # noqa: E731
    off, S = C.four_point_mag_calibration(raw(bottom_q), raw(flank_q), "left")
    np.testing.assert_allclose(off, h, atol=1e-9)
    # each axis reads +1 pointing (horizontally) North
    cal = C.apply_mag_calibration(raw(bottom_q), off, S)
    assert cal[0, 0] == pytest.approx(1.0) and cal[1, 1] == pytest.approx(1.0)
    m = raw(Q.random_quaternions(20_000, rng))
    off2, S2 = C.minmax_mag_calibration(m)
    np.testing.assert_allclose(off2, h, atol=0.2)
    np.testing.assert_allclose(
        np.diag(S2) / np.diag(S2)[0], (1 / np.diag(D)) / (1 / D[0, 0]), rtol=0.01
    )


# ------------------------------------------------------------------ clocks


def _smooth_signal(rng, n, fs):
    f = np.fft.rfftfreq(n, 1 / fs)
    spec = (rng.normal(size=f.size) + 1j * rng.normal(size=f.size)) / (
        1 + (f / 3.0) ** 4
    )
    return np.fft.irfft(spec, n)


@pytest.mark.parametrize("lag_samples", [90.0, 90.37, -12.8])
def test_lag_recovered_below_0_2_samples(lag_samples):
    rng = np.random.default_rng(13)
    fs, n = 100.0, 6000
    t = np.arange(n + 400) / fs
    base = np.column_stack([_smooth_signal(rng, t.size, fs) for _ in range(3)])
    from scipy.interpolate import CubicSpline

    spl = CubicSpline(t, base)
    ti = t[200 : 200 + n]
    x = spl(ti) + rng.normal(0, 0.01 * base.std(), (n, 3))
    y = 2.0 * spl(ti - lag_samples / fs) + rng.normal(
        0, 0.01 * base.std(), (n, 3)
    )  # y lags x, other gain
    est = C.estimate_lag(x, y, fs, max_lag_s=2.0)
    assert abs(est.lag_samples - lag_samples) < 0.2
    assert est.correlation > 0.9


@pytest.mark.parametrize("drift", [1e-4, -1e-4])
def test_ttl_slip_repair_keeps_within_one_sample(drift):
    cycle, n_frames = 6, 60_000
    frame_t = np.arange(n_frames)  # mocap frame index = time in video periods
    imu_of_frame = (
        frame_t * (1 + drift) + 0.3
    )  # the same instants in IMU sample units (clocks drift apart)
    ttl_frames = np.arange(0, n_frames, cycle)
    ttl_idx = np.ceil(imu_of_frame[ttl_frames]).astype(
        int
    )  # first IMU sample at/after each TTL
    rep = C.repair_ttl_slips(frame_t, ttl_idx, cycle=cycle)
    assert (rep.n_duplicated if drift > 0 else rep.n_deleted) > 0
    t_mocap = imu_of_frame[
        rep.mocap
    ]  # true IMU-time of the mocap frame paired with each IMU sample
    # at each TTL the registered sample is 0..1 sample after the frame; within a cycle the clocks
    # drift apart by at most cycle·|drift| more, so one sample is exceeded by at most that
    assert np.max(np.abs(t_mocap - rep.imu_index)) <= 1.0 + cycle * abs(drift)
    naive = frame_t[: rep.imu_index.size]
    assert (
        np.max(np.abs(imu_of_frame[naive] - (ttl_idx[0] + np.arange(naive.size)))) > 1.0
    )
    with pytest.raises(C.CalibrationError, match="slip"):
        C.repair_ttl_slips(frame_t, np.delete(ttl_idx, 5), cycle=cycle)


# ------------------------------------------------------------------ frames


def test_head_frame_and_marker_qc():
    rng = np.random.default_rng(15)
    q = Q.random_quaternions(500, rng)
    local = np.array([[0, 16.0, 30], [0, -16.0, 30], [35.0, -16, 30]])
    p = Q.rotate(q[:, None, :], local[None]) + rng.normal(0, 0.15, (500, 3, 3))
    R = C.head_frame_from_markers(p[:, 0], p[:, 1], p[:, 2])
    np.testing.assert_allclose(
        R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape), atol=1e-12
    )
    ang = np.degrees(
        Q.angle_between(C.tilt_from_markers(p[:, 0], p[:, 1], p[:, 2]), Q.gravity(q))
    )
    assert np.median(ang) < 1.0
    u = (p[:10, 0] - p[:10, 1]) / np.linalg.norm(
        p[:10, 0] - p[:10, 1], axis=1, keepdims=True
    )
    p[:10, 0] += 4.0 * u  # spurious reflections that stretch d12 by 4 mm
    qc = C.marker_distance_qc(p[:, 0], p[:, 1])
    assert qc.keep.sum() == 490 and not qc.keep[:10].any()
    assert qc.sigma_kept < qc.sigma_all
    assert C.optical_tilt_uncertainty(0.21, 32.0) == pytest.approx(
        np.degrees(np.arctan(0.21 / 32.0))
    )
    # the head frame is tiltlab.frames' (one implementation), re-exported here
    assert C.head_frame_from_markers is frames.head_frame_from_markers
    with pytest.raises(ValueError, match="collinear"):
        C.head_frame_from_markers(
            np.zeros(3), np.array([1.0, 0, 0]), np.array([2.0, 0, 0])
        )


def test_kabsch_recovers_mounting_below_0_1_deg():
    rng = np.random.default_rng(16)
    n = 6000
    R0 = Rotation.from_rotvec(np.radians([3.0, -2.0, 4.0])).as_matrix()  # IMU -> head
    # slowly varying still head tilts, in the head frame
    tilts = (
        Rotation.from_rotvec(
            np.radians(20) * np.cumsum(rng.normal(0, 0.02, (n, 3)), axis=0)
        )
        .inv()
        .apply([0, 0, 1])
    )
    acc = tilts @ R0 + rng.normal(0, 0.003, (n, 3))  # IMU frame: R0ᵀ z_head
    al = C.imu_to_head_alignment(acc, tilts, FS)
    err = np.degrees(Rotation.from_matrix(al.matrix @ R0.T).magnitude())
    assert err < 0.1
    with pytest.raises(C.CalibrationError, match="span"):
        C.imu_to_head_alignment(
            np.tile([0, 0, 1.0], (n, 1)) + rng.normal(0, 1e-4, (n, 3)),
            np.tile([0, 0, 1.0], (n, 1)),
            FS,
        )


def test_mounting_rotation_levels_rest_acceleration():
    a_rest = Rotation.from_euler("xy", [8, -12], degrees=True).inv().apply([0, 0, 1.0])
    M = C.mounting_rotation(a_rest)
    np.testing.assert_allclose(M @ a_rest, [0, 0, 1.0], atol=1e-12)


# ------------------------------------------------------------------ Calibration / calibrate


def _rec(rng, n=600, **kw):
    acc = np.tile([0.0, 0.0, 1.0], (n, 1)) + rng.normal(0, 0.003, (n, 3))
    gyr = rng.normal(0, 0.1, (n, 3))
    return schema.make_recording(acc, gyr, FS, acc_units="g", gyr_units="deg/s", **kw)


def test_calibration_json_and_double_application():
    rng = np.random.default_rng(17)
    rec = _rec(rng, q_ref=np.tile([1.0, 0, 0, 0], (600, 1)))
    cal = C.Calibration(
        name="t",
        acc_offset=[0.01, 0.02, -0.03],
        acc_matrix=np.eye(3) * 1.01,
        gyr_offset=[1, 2, 3],
        info={"note": "x"},
    )
    assert C.Calibration.from_json(cal.to_json()) == cal
    out = C.calibrate(rec, cal)
    np.testing.assert_allclose(
        out.acc.values, (rec.acc.values - [0.01, 0.02, -0.03]) * 1.01
    )
    np.testing.assert_allclose(out.gyr.values, rec.gyr.values - [1, 2, 3])
    assert (
        rec.acc.values[0, 2] != out.acc.values[0, 2]
    )  # input untouched, output changed
    assert C.applied_calibrations(out)[0]["applied"] == [
        "acc_offset",
        "acc_matrix",
        "gyr_offset",
    ]
    with pytest.raises(C.CalibrationError, match="already applied"):
        C.calibrate(out, C.Calibration.from_json(cal.to_json()))
    with pytest.raises(C.CalibrationError, match="already corrected"):
        C.calibrate(out, C.Calibration(acc_offset=[0.001, 0, 0]))
    C.calibrate(out, C.Calibration(acc_offset=[0.001, 0, 0]), allow_stacking=True)


def test_calibrate_respects_units_and_rotation():
    rng = np.random.default_rng(18)
    rec = _rec(rng, q_ref=Q.random_quaternions(600, rng))
    si = schema.to_units(rec, acc="m/s^2", gyr="rad/s")
    R = Rotation.from_rotvec([0.1, -0.2, 0.05]).as_matrix()
    cal = C.Calibration(
        acc_offset=[0.01, 0, 0], gyr_offset=[0.5, 0, 0], rotation=R, target_frame="head"
    )
    a, b = C.calibrate(rec, cal), C.calibrate(si, cal)
    np.testing.assert_allclose(b.acc.values / units.G0, a.acc.values, atol=1e-12)
    np.testing.assert_allclose(np.degrees(b.gyr.values), a.gyr.values, atol=1e-10)
    assert b.acc.attrs["units"] == "m/s^2" and a.attrs["frame"] == "head"
    # world vectors are unchanged by a frame change: R(q') v' = R(q) v
    v = rec.acc.values - [0.01, 0, 0]
    np.testing.assert_allclose(
        Q.rotate(a.q_ref.values, a.acc.values),
        Q.rotate(rec.q_ref.values, v),
        atol=1e-12,
    )


def test_temperature_calibration_needs_temp():
    rng = np.random.default_rng(19)
    t = np.linspace(28, 34, 8)
    model = C.fit_temperature_model(
        t, np.column_stack([0.001 * (t - 31), 0 * t, 0 * t]), units="g"
    )
    rec = _rec(rng)
    with pytest.raises(C.CalibrationError, match="temp"):
        C.calibrate(rec, C.Calibration(acc_temp=model))
    temp = np.linspace(29, 33, 600)
    rec_t = _rec(rng, temp=temp, temp_units="degC")
    out = C.calibrate(rec_t, C.Calibration(acc_temp=model))
    np.testing.assert_allclose(
        rec_t.acc.values[:, 0] - out.acc.values[:, 0], 0.001 * (temp - 31), atol=1e-12
    )
    with pytest.raises(ValueError, match="either"):
        C.Calibration(acc_offset=[0, 0, 0], acc_temp=model)


def test_tumble_calibration_end_to_end():
    rng = np.random.default_rng(20)
    dirs = C.fibonacci_lattice(20)
    o = np.array([0.03, -0.05, 0.02])
    acc, gyr, _ = _tumble_record(rng, dirs, [-10.0, 5.0, 2.0], acc_offset=o)
    rec = schema.make_recording(acc, gyr, FS, acc_units="g", gyr_units="deg/s")
    res = C.tumble_calibration(rec, model="ellipsoid")
    assert res.intervals.shape[0] == 20
    np.testing.assert_allclose(res.calibration.acc_offset, o, atol=1e-3)
    out = C.calibrate(rec, res.calibration)
    still = C.intervals_to_mask(res.intervals, len(acc))
    assert np.abs(np.linalg.norm(out.acc.values[still], axis=1).mean() - 1) < 1e-3


# ------------------------------------------------------------------ metadata travels


def test_rad_s_gyroscope_gives_the_same_still_periods():
    """Thresholds are in °/s: a rad/s gyroscope (labelled or plain with units=) gives the
    same still periods as the same data in °/s."""
    rng = np.random.default_rng(21)
    acc, gyr, _ = _tumble_record(rng, C.fibonacci_lattice(8), [-12.0, 6.0, 3.0])
    rec = schema.make_recording(acc, gyr, FS, acc_units="g", gyr_units="deg/s")
    kw = dict(threshold_deg_s=3.0, min_duration_s=0.4)
    ref = C.detect_static(gyr, FS, **kw)
    assert ref.shape[0] == 8
    rad = schema.to_units(rec, gyr="rad/s")
    assert rad.gyr.attrs["units"] == "rad/s"
    labelled = (rec, rad, rec.gyr.assign_attrs(fs=FS), rad.gyr.assign_attrs(fs=FS))
    for data in labelled:
        np.testing.assert_array_equal(C.detect_static(data, **kw), ref)
    np.testing.assert_array_equal(C.detect_static(rad.gyr, FS, **kw), ref)
    np.testing.assert_array_equal(
        C.detect_static(np.radians(gyr), FS, units="rad/s", **kw), ref
    )
    # the offset pass and the drift integration convert too
    np.testing.assert_allclose(
        C.robust_gyro_offset(rad), np.radians(C.robust_gyro_offset(gyr, FS))
    )
    np.testing.assert_allclose(C.integrate_rate(rad).values, C.integrate_rate(gyr, FS))
    # an acceleration criterion reads the Recording's acc, in g whatever its units
    acc_kw = dict(kw, acc_std_threshold_g=0.01)
    np.testing.assert_array_equal(
        C.detect_static(schema.to_units(rad, acc="m/s^2"), **acc_kw),
        C.detect_static(gyr, FS, acc=acc, **acc_kw),
    )


def test_missing_or_contradictory_fs_is_an_error_naming_fs():
    rng = np.random.default_rng(22)
    rec = _rec(rng)
    gyr = rec.gyr.values
    tilt = Q.gravity(Q.random_quaternions(len(gyr), rng))  # head tilts, well spread
    calls = {
        "detect_static": lambda d, **k: C.detect_static(d, **k),
        "robust_gyro_offset": lambda d, **k: C.robust_gyro_offset(d, **k),
        "integrate_rate": lambda d, **k: C.integrate_rate(d, **k),
        "correct_drift": lambda d, **k: C.correct_drift(d, method="none", **k),
        "allan_deviation": lambda d, **k: C.allan_deviation(d, **k),
        "offsets_vs_temperature": lambda d, **k: C.offsets_vs_temperature(
            d, np.full(len(gyr), 30.0), window_s=1.0, **k
        ),
        "imu_to_head_alignment": lambda d, **k: C.imu_to_head_alignment(d, tilt, **k),
        "estimate_lag": lambda d, **k: C.estimate_lag(d, d, **k),
    }
    for name, f in calls.items():
        with pytest.raises(ValueError, match="fs"):  # plain array, no fs
            f(gyr)
        with pytest.raises(ValueError, match="fs"):  # labelled, but no fs attribute
            f(rec.gyr)
        with pytest.raises(
            ValueError, match="fs = 600.*contradicts"
        ):  # vs the Recording's fs
            f(rec, fs=2 * FS)
        f(rec)  # the Recording's fs is used when none is given
        f(gyr, fs=FS)
    with pytest.raises(ValueError, match="fs"):
        C.static_intervals_from_trigger(np.zeros(100))
    with pytest.raises(ValueError, match="fs"):
        C.drift_slope(np.zeros((100, 3)))
    with pytest.raises(ValueError, match="fs must be a positive"):
        C.detect_static(gyr, -1.0)
    np.testing.assert_allclose(C.robust_gyro_offset(rec), C.robust_gyro_offset(gyr, FS))


def test_labelled_inputs_give_labelled_outputs():
    rng = np.random.default_rng(23)
    rec = _rec(rng, n=3000)
    res = C.correct_drift(rec, method="linear_fit", window_s=1.0)
    assert res.angle.dims == ("time", "axis") and res.angle.attrs["units"] == "deg"
    assert res.angle.attrs["fs"] == FS
    np.testing.assert_allclose(
        res.slope, C.drift_slope(C.integrate_rate(rec)), atol=1e-12
    )
    np.testing.assert_array_equal(
        C.correct_drift(rec.gyr.values, FS, method="linear_fit").angle, res.angle.values
    )
    taus, ad = C.allan_deviation(rec)
    taus2, ad2 = C.allan_deviation(rec.gyr.values, FS)
    np.testing.assert_array_equal(ad, ad2)
    go, _ = C.gyro_offset(rec, [[0, 3000]])
    np.testing.assert_allclose(go, np.median(rec.gyr.values, axis=0))


def test_parameters_are_checked_by_name():
    rng = np.random.default_rng(24)
    gyr = rng.normal(0, 0.1, (600, 3))
    for kw in (
        {"threshold_deg_s": 0.0},
        {"smooth_s": -1.0},
        {"min_duration_s": np.nan},
        {"merge_gap_s": -0.1},
        {"trim_s": -1},
        {"acc_std_threshold_g": -1.0},
    ):
        ((name, value),) = kw.items()
        with pytest.raises(ValueError, match=name):
            C.detect_static(gyr, FS, acc=np.tile([0, 0, 1.0], (600, 1)), **kw)
    with pytest.raises(ValueError, match="window_s"):
        C.robust_gyro_offset(gyr, FS, window_s=0)
    with pytest.raises(ValueError, match="quantile"):
        C.robust_gyro_offset(gyr, FS, quantile=1.5)
    with pytest.raises(ValueError, match="window_s"):
        C.correct_drift(gyr, FS, window_s=-3)
    with pytest.raises(ValueError, match="method"):
        C.correct_drift(gyr, FS, method="bogus")
    with pytest.raises(ValueError, match="cutoff_hz"):
        C.imu_to_head_alignment(
            np.tile([0, 0, 1.0], (600, 1)),
            np.tile([0, 0, 1.0], (600, 1)),
            FS,
            cutoff_hz=200.0,
        )
    with pytest.raises(ValueError, match="drop_fraction"):
        C.marker_distance_qc(np.zeros((10, 3)), np.ones((10, 3)), drop_fraction=1.0)
    with pytest.raises(ValueError, match="cycle"):
        C.repair_ttl_slips(np.arange(100), [0, 6, 12], cycle=0)
    with pytest.raises(ValueError, match="full_scale_g"):
        C.tumble_calibration(_rec(rng), full_scale_g=-2.0)


# ------------------------------------------------------------------ layering, low-pass, magnetometer


def test_calibration_imports_only_lower_layers():
    import subprocess
    import sys

    code = (
        "import sys, tiltlab.calibration; "
        "print(' '.join(sorted(m for m in sys.modules if m.startswith('tiltlab'))))"
    )
    mods = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.split()
    for upper in (
        "simulate",
        "trig",
        "sphere",
        "filters",
        "behavior",
        "evaluate",
        "plot",
        "cli",
    ):
        assert not any(
            m == f"tiltlab.{upper}" or m.startswith(f"tiltlab.{upper}.") for m in mods
        ), upper
    assert not hasattr(C, "lowpass")  # the one low-pass is tiltlab.dsp.lowpass


def test_dsp_lowpass_is_the_alignment_lowpass():
    """The zero-phase 2 Hz Butterworth of Fayat §2.6.5, now tiltlab.dsp.lowpass."""
    from scipy.signal import butter, sosfiltfilt

    from tiltlab.dsp import lowpass

    rng = np.random.default_rng(25)
    t = np.arange(3000) / FS
    x = np.column_stack(
        [np.sin(2 * np.pi * 0.3 * t), np.cos(2 * np.pi * 0.5 * t), np.zeros_like(t)]
    )
    noisy = (
        x + 0.05 * np.sin(2 * np.pi * 40 * t)[:, None] + rng.normal(0, 0.01, x.shape)
    )
    y = lowpass(noisy, FS, 2.0)
    np.testing.assert_allclose(
        y, sosfiltfilt(butter(2, 2.0, fs=FS, output="sos"), noisy, axis=0), atol=1e-12
    )
    np.testing.assert_allclose(y[300:-300], x[300:-300], atol=0.01)  # no phase lag
    with pytest.raises(ValueError, match="cutoff_hz"):
        lowpass(noisy, FS, FS)


def test_apply_mag_calibration_is_labelled_and_fit_message_is_precise():
    rng = np.random.default_rng(26)
    m = 47.0 * Q.gravity(Q.random_quaternions(50, rng)) + [10.0, -5.0, 3.0]
    rec = schema.make_recording(
        np.tile([0, 0, 1.0], (50, 1)),
        np.zeros((50, 3)),
        FS,
        mag=m,
        acc_units="g",
        gyr_units="deg/s",
        mag_units="uT",
    )
    out = C.apply_mag_calibration(rec, [10.0, -5.0, 3.0])
    assert (
        out.dims == ("time", "axis")
        and out.attrs["units"] == "uT"
        and out.attrs["fs"] == FS
    )
    np.testing.assert_allclose(np.linalg.norm(out.values, axis=1), 47.0)
    S = np.diag([2.0, 1.0, 0.5])
    np.testing.assert_allclose(
        C.apply_mag_calibration(m, [10.0, -5.0, 3.0], S), (m - [10.0, -5.0, 3.0]) @ S.T
    )
    with pytest.raises(C.CalibrationError, match="do not vary"):
        C.fit_mag_ellipsoid(np.tile([1.0, 2.0, 3.0], (20, 1)))
    with pytest.raises(ValueError, match="field"):
        C.fit_mag_ellipsoid(m, field=-47.0)
    with pytest.raises(C.CalibrationError, match="zero range"):
        C.four_point_mag_calibration(np.zeros((4, 3)), np.zeros((4, 3)))
