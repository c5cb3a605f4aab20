"""Tests of tiltlab.simulate: ground truth is exact, outputs are reproducible and the
behaviour has the statistical properties the rest of the package relies on."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from hypothesis import given, settings
from hypothesis import strategies as st

from tiltlab import io, quaternion, schema
from tiltlab.behavior import speed_modes
from tiltlab.sphere import fibonacci_lattice
from tiltlab.simulate import (
    ACC_OFFSET_RANGE_G,
    GYR_OFFSET_RANGE_DPS,
    STATES,
    BehaviourParams,
    CohortDesign,
    Lesion,
    MarkerSupport,
    SensorModel,
    apply_sensor_model,
    draw_sensor,
    head_frame_from_markers,
    head_kinematics,
    load_cohort,
    mocap_markers,
    session_plan,
    simulate_cohort,
    simulate_mocap_session,
    simulate_session,
    stage_angles,
    stage_quaternion,
    tumble_test,
)
from tiltlab.units import G0


@pytest.fixture(scope="module")
def ideal60():
    return simulate_session(60.0, 100.0, seed=11, sensor=SensorModel.ideal())


# ------------------------------------------------------------ exact ground truth


@pytest.mark.parametrize("fs", [100.0, 300.0])
def test_integrating_ideal_gyro_reproduces_q_ref(fs):
    rec = simulate_session(60.0, fs, seed=3, sensor=SensorModel.ideal())
    q = rec["q_ref"].values
    q_int = quaternion.integrate_gyro(np.radians(rec["gyr"].values), fs, q[0])
    err = quaternion.total_error(q_int, q)
    assert err.max() < 1e-6
    # and the motion is not trivial: the head turned by much more than the tolerance
    assert quaternion.total_error(q, q[:1]).max() > 0.5


def test_ideal_accelerometer_is_gravity_plus_linear_acceleration(ideal60):
    rec = ideal60
    expected = quaternion.rotate_inverse(
        rec["q_ref"].values, np.array([0.0, 0.0, 1.0]) + rec["a_lin"].values
    )
    np.testing.assert_allclose(rec["acc"].values, expected, rtol=0, atol=1e-12)
    assert rec["acc"].attrs["units"] == "g" and rec["gyr"].attrs["units"] == "deg/s"
    assert rec["a_lin"].attrs["units"] == "g" and rec["a_lin"].attrs["frame"] == "world"
    # the linear acceleration is not negligible (a head moves)
    assert np.percentile(np.linalg.norm(rec["a_lin"].values, axis=1), 99) > 0.1


def test_linear_acceleration_matches_sensor_position():
    # a_lin is the second derivative of the stored sensor position, up to a
    # discretisation error that vanishes as fs grows
    # (the rotational jitter is an Ornstein-Uhlenbeck process, so the error shrinks like
    # sqrt(1/fs) rather than 1/fs)
    rel = []
    for fs in (300.0, 3000.0, 30000.0):
        rec = simulate_session(2.0, fs, seed=5, sensor=SensorModel.ideal())
        pos = rec["pos"].values
        acc_fd = (pos[2:] - 2 * pos[1:-1] + pos[:-2]) * fs**2 / G0
        a = rec["a_lin"].values
        a_mid = 0.5 * (a[:-2] + a[1:-1])  # the central difference straddles two steps
        rel.append(np.sqrt(np.mean((acc_fd - a_mid) ** 2)) / np.sqrt(np.mean(a_mid**2)))
    assert rel[0] > rel[1] * 2 > rel[2] * 4
    assert rel[2] < 0.05


def test_recording_is_valid_and_round_trips(tmp_path, ideal60):
    rec = simulate_session(20.0, 100.0, seed=1, sensor=SensorModel(magnetometer=True))
    schema.validate(rec)
    path = io.save_netcdf(rec, tmp_path / "s.nc")
    back = io.load_netcdf(path, validate=True)
    assert back.identical(rec)
    assert list(back["state"].attrs["flag_meanings"].split()) == list(STATES)
    # removing the true hard and soft iron leaves the local field rotated into the sensor frame
    a = back.attrs
    m = (back["mag"].values - np.asarray(a["true_mag_hard_iron"])) @ np.linalg.inv(
        np.asarray(a["true_mag_soft_iron"])
    ).T
    m_true = quaternion.rotate_inverse(
        back["q_ref"].values, np.asarray(a["true_field_world_uT"])
    )
    assert np.sqrt(np.mean((m - m_true) ** 2)) < 1.0  # 0.6 µT noise + 0.15 µT steps
    assert np.linalg.norm(a["true_field_world_uT"]) == pytest.approx(47.0)


# ------------------------------------------------------------ reproducibility


def test_same_seed_bit_identical_and_different_seed_differs():
    a = simulate_session(15.0, 100.0, seed=123)
    b = simulate_session(15.0, 100.0, seed=123)
    c = simulate_session(15.0, 100.0, seed=124)
    assert a.identical(b)
    for v in a.data_vars:
        assert np.array_equal(a[v].values, b[v].values)
    assert not np.array_equal(a["acc"].values, c["acc"].values)
    assert not np.array_equal(a["q_ref"].values, c["q_ref"].values)


@settings(max_examples=5, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_head_kinematics_deterministic_and_unit(seed):
    m1 = head_kinematics(3.0, 50.0, seed=seed)
    m2 = head_kinematics(3.0, 50.0, seed=seed)
    assert np.array_equal(m1.q, m2.q) and np.array_equal(m1.a_lin, m2.a_lin)
    np.testing.assert_allclose(np.linalg.norm(m1.q, axis=1), 1.0, atol=1e-12)
    assert m1.state.dtype == np.int8 and set(np.unique(m1.state)) <= set(
        range(len(STATES))
    )


# ------------------------------------------------------------ behaviour statistics


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_angular_speed_is_bimodal_with_valley_near_12_dps(seed):
    rec = simulate_session(600.0, 100.0, seed=seed)
    # offset-corrected measured gyroscope, as Fayat et al. threshold it
    gyr = rec["gyr"].values - np.asarray(rec.attrs["true_gyr_offset_mean"])
    m = speed_modes(np.linalg.norm(gyr, axis=1))
    valley, low, high, depth = (
        m["valley"],
        m["still_mode"],
        m["moving_mode"],
        m["depth"],
    )
    assert 6.0 <= valley <= 20.0
    assert low < 6.0 < 20.0 < high
    # a clear dip between the modes (the real rat's valley is at ~0.6 of its still mode)
    assert depth < 0.7


def test_immobility_fraction_follows_the_planted_value():
    for f in (0.2, 0.6):
        m = head_kinematics(
            3600.0, 10.0, seed=4, behaviour=BehaviourParams(immobility_fraction=f)
        )
        assert abs(np.mean(m.state == 0) - f) < 0.08


@pytest.mark.parametrize(
    "side,sign", [("left", -1.0), ("right", 1.0)]
)  # sign of g_y toward the lesion
def test_lesion_tilts_immobile_head_toward_the_lesion_side(side, sign):
    m = head_kinematics(900.0, 20.0, seed=8, lesion=Lesion(tilt_deg=30.0, side=side))
    g = quaternion.gravity(m.q)[m.state == 0]
    mu = g.mean(axis=0)
    mu /= np.linalg.norm(mu)
    # angle of the mean immobile tilt to the xz plane, counted positive toward the lesion
    toward = math.degrees(math.asin(sign * mu[1]))
    assert abs(toward - 30.0) < 5.0
    # the baseline tilt point itself is exactly 30° from the sagittal plane
    g0 = np.asarray(m.params["baseline_tilt"])
    assert math.degrees(math.asin(sign * g0[1])) == pytest.approx(30.0, abs=1e-9)


def test_circling_lesion_turns_counter_clockwise():
    m = head_kinematics(
        1200.0, 50.0, seed=2, lesion=Lesion(circling_cpm=6.0, side="left")
    )
    act = m.state != 0
    az = np.sum(m.omega * quaternion.gravity(m.q), axis=1)
    cpm = az[act].mean() * 60 / (2 * math.pi)
    assert cpm > 2.0
    assert np.any(m.state == STATES.index("circling"))


# ------------------------------------------------------------ sensor model


def test_sensor_errors_are_applied_as_specified():
    n, fs = 20000, 100.0
    true = {"acc": np.tile([0.0, 0.0, 1.0], (n, 1)), "gyr": np.zeros((n, 3))}
    s = SensorModel(
        acc_offset=(0.05, -0.02, 0.01),
        gyr_offset=(3.0, -5.0, 1.0),
        acc_scale=(0.0,) * 3,
        gyr_scale=(0.0,) * 3,
        acc_misalign=((0.0,) * 3,) * 3,
        gyr_misalign=((0.0,) * 3,) * 3,
        acc_temp_coef=(0.0,) * 3,
        gyr_temp_coef=(0.0,) * 3,
        acc_bias_walk=0.0,
        gyr_bias_walk=0.0,
    )
    out = apply_sensor_model(true, s, np.random.default_rng(0), fs)
    d = out["acc"] - true["acc"]
    np.testing.assert_allclose(d.mean(0), s.acc_offset, atol=5e-5)
    np.testing.assert_allclose(d.std(0), 300e-6 * math.sqrt(fs / 2), rtol=0.1)
    np.testing.assert_allclose(
        (out["gyr"] - true["gyr"]).mean(0), s.gyr_offset, atol=0.01
    )
    lsb = 2 * 16.0 / 65536
    np.testing.assert_allclose(out["acc"] / lsb, np.round(out["acc"] / lsb), atol=1e-6)


def test_scale_temperature_and_saturation():
    n, fs = 3000, 50.0
    rng = np.random.default_rng(1)
    x = rng.normal(0, 1.0, (n, 3))
    s = SensorModel.ideal()
    s = SensorModel(
        **{
            **s.__dict__,
            "acc_scale": (0.02, -0.01, 0.0),
            "acc_temp_coef": (1e-3, 0.0, -2e-3),
            "temp_start": 25.0,
            "temp_end": 35.0,
            "acc_range": 2.0,
        }
    )
    out = apply_sensor_model({"acc": x, "gyr": np.zeros((n, 3))}, s, rng, fs)
    T = out["temp"]
    assert T[0] == pytest.approx(25.0) and np.all(np.diff(T) > 0)
    expected = x * (1 + np.array([0.02, -0.01, 0.0])) + (T - 31.0)[:, None] * np.array(
        [1e-3, 0.0, -2e-3]
    )
    inside = np.all(np.abs(expected) < 1.9, axis=1)
    np.testing.assert_allclose(out["acc"][inside], expected[inside], atol=1e-12)
    assert out["acc"].max() < 2.0 and out["acc"].min() >= -2.0
    assert out["truth"]["n_saturated_acc"] == int(
        np.count_nonzero((expected < -2.0) | (expected > 2.0 - 4.0 / 65536))
    )


def test_default_offsets_follow_fayat_ranges():
    rng = np.random.default_rng(2)
    draws = [draw_sensor(None, rng) for _ in range(600)]
    acc = np.concatenate([d.acc_offset for d in draws])
    gyr = np.concatenate([d.gyr_offset for d in draws])
    np.testing.assert_allclose(
        np.percentile(acc, [5, 95]), ACC_OFFSET_RANGE_G, atol=0.01
    )
    np.testing.assert_allclose(
        np.percentile(gyr, [5, 95]), GYR_OFFSET_RANGE_DPS, atol=1.5
    )


# ------------------------------------------------------------ tumble test


@settings(max_examples=30, deadline=None)
@given(
    st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(
        lambda v: np.linalg.norm(v) > 1e-3
    )
)
def test_stage_angles_bring_gravity_to_target(v):
    g = np.asarray(v) / np.linalg.norm(v)
    b, c = stage_angles(g)
    np.testing.assert_allclose(
        quaternion.gravity(stage_quaternion(b, c)), g, atol=1e-12
    )


@pytest.mark.parametrize("n", [1, 7, 50, 501])
def test_fibonacci_lattice_targets_are_uniform(n):
    g = fibonacci_lattice(n)
    np.testing.assert_allclose(np.linalg.norm(g, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(g[:, 2], 1 - (2 * np.arange(n) + 1) / n, atol=1e-12)
    assert np.linalg.norm(g.mean(axis=0)) < 2.0 / n


def test_tumble_test_holds_targets_and_triggers():
    fs = 300.0
    rec = tumble_test(20, fs, seed=4)
    trig = np.flatnonzero(rec["trigger"].values)
    assert trig.size == 21
    targets = np.asarray(rec.attrs["targets"])
    w = int(0.4 * fs)
    for i, k in enumerate(trig[1:]):
        held = rec["acc_true"].values[k - w : k]
        np.testing.assert_allclose(
            held, np.broadcast_to(targets[i], held.shape), atol=1e-12
        )
        assert np.all(rec["orientation"].values[k - w : k] == i)
        assert np.abs(rec["gyr_true"].values[k - w : k]).max() < 1e-9
    q = rec["q_ref"].values
    q_int = quaternion.integrate_gyro(np.radians(rec["gyr_true"].values), fs, q[0])
    assert quaternion.total_error(q_int, q).max() < 1e-9
    # measured static accelerometer is offset from the truth by about the true offset
    k = trig[5]
    d = rec["acc"].values[k - w : k].mean(0) - rec["acc_true"].values[k - w : k].mean(0)
    assert np.linalg.norm(d - np.asarray(rec.attrs["true_acc_offset_mean"])) < 0.05


def test_three_point_tumble_is_nearly_orthogonal():
    rec = tumble_test(seed=9, kind="three_point")
    g = np.asarray(rec.attrs["achieved_tilt"])
    assert g.shape == (3, 3)
    gram = g @ g.T
    assert np.abs(gram - np.eye(3)).max() < 0.35
    assert rec["trigger"].sum() == 4


# ------------------------------------------------------------ motion capture


def test_mocap_head_frame_recovers_orientation_without_noise():
    m = head_kinematics(10.0, 300.0, seed=6)
    mc, sync = mocap_markers(
        m,
        rng=np.random.default_rng(0),
        noise_mm=0.0,
        occlusion_rate=0.0,
        reflection_rate=0.0,
    )
    mk = mc["markers"].values
    H = head_frame_from_markers(mk[:, 0], mk[:, 1], mk[:, 2])
    qs = np.asarray(mc.attrs["true_support_q"])
    expected = quaternion.to_matrix(quaternion.mul(mc["q_ref"].values, qs))
    np.testing.assert_allclose(H, expected, atol=1e-9)


def test_mocap_noise_sync_and_gross_errors():
    rec, mc = simulate_mocap_session(120.0, 300.0, seed=2, slip_fraction=2e-3)
    mk = mc["markers"].values
    d12 = np.linalg.norm(mk[:, 0] - mk[:, 1], axis=1)
    clean = ~mc["gross_error"].values.any(axis=1)
    assert abs(np.median(d12[clean]) - 32.0) < 0.05
    assert (
        0.15 < np.std(d12[clean]) < 0.3
    )  # Fayat: 0.21 mm after excluding gross errors
    assert np.isnan(mk).any() and 0.002 < (~clean).mean() < 0.06
    gaps = np.diff(np.flatnonzero(rec["sync"].values))
    assert set(np.unique(gaps)) <= {5, 6, 7}
    slips = np.count_nonzero(gaps != 6)
    assert slips == mc.attrs["n_slips"] and 0 < slips < 0.01 * gaps.size
    # each TTL is registered by the first IMU sample at or after its frame (lag < 1 period)
    t_ttl = mc["t_true"].values[mc["ttl"].values]
    t_sync = rec["time"].values[rec["sync"].values]
    lag = t_sync - t_ttl[: t_sync.size]
    assert lag.min() >= -1e-9 and lag.max() < 1.0 / 300


# ------------------------------------------------------------ cohort


def _design():
    return CohortDesign(groups={"Kainate": 2, "Arsanilate": 1, "Healthy": 1})


def test_cohort_round_trips_and_is_independent_of_workers(tmp_path):
    d = _design()
    p1 = simulate_cohort(
        tmp_path / "a",
        design=d,
        duration_s=8.0,
        fs=50.0,
        seed=7,
        workers=2,
        progress=False,
    )
    p2 = simulate_cohort(
        tmp_path / "b",
        design=d,
        duration_s=8.0,
        fs=50.0,
        seed=7,
        workers=1,
        progress=False,
    )
    c1, c2 = load_cohort(p1), load_cohort(p2)
    assert len(c1) == 4 * 7
    assert set(c1.sessions.columns) >= {
        "subject",
        "group",
        "timepoint",
        "hours",
        "file",
    }
    pd.testing.assert_frame_equal(c1.truth, c2.truth)
    n = 0
    for (row, rec), (_, rec2) in zip(
        c1.iter_sessions(validate=True), c2.iter_sessions(validate=True)
    ):
        assert (
            rec.attrs["subject"] == row["subject"]
            and rec.attrs["session"] == row["timepoint"]
        )
        assert rec.identical(rec2)
        assert rec.sizes["time"] == 400
        n += 1
    assert n == 28
    rec = c1.load("Arsanilate01", "7d")
    truth = c1.truth.set_index(["subject", "timepoint"]).loc[("Arsanilate01", "7d")]
    g0 = np.asarray(rec.attrs["baseline_tilt"])
    assert math.degrees(math.asin(-g0[1])) == pytest.approx(
        truth["tilt_to_xz_deg_true"], abs=1e-9
    )
    with pytest.raises(FileExistsError):
        simulate_cohort(
            p1, design=d, duration_s=8.0, fs=50.0, seed=7, workers=1, progress=False
        )


def test_planted_effects_follow_the_paper_time_courses():
    plan = session_plan(CohortDesign(), seed=0, duration_s=1200.0, fs=100.0)
    assert len(plan) == 58 * 7
    m = plan.groupby(["group", "timepoint"]).mean(numeric_only=True)
    ars = m.loc["Arsanilate"]
    kai = m.loc["Kainate"]
    # arsanilate: tilt peaks at 7 d near 40° and partially recovers; circling is late
    assert (
        ars["tilt_deg_planted"].idxmax() == "7d"
        and 30 < ars.loc["7d", "tilt_deg_planted"] < 50
    )
    assert 0 < ars.loc["28d", "tilt_deg_planted"] < ars.loc["7d", "tilt_deg_planted"]
    assert (
        ars.loc["1h", "circling_cpm_planted"] == 0
        and ars.loc["14d", "circling_cpm_planted"] > 1
    )
    # kainate: acute, strongest loss of mobility at 1 h, recovered by 7 d
    assert kai["mobility_planted"].idxmin() == "1h" and kai.loc[
        "7d", "mobility_planted"
    ] == pytest.approx(1.0)
    assert kai["immobility_planted"].idxmax() == "1h" and ars[
        "immobility_planted"
    ].idxmax() in ("1d", "2d")
    # anaesthesia raises immobility in the healthy group at 1 h and 1 d only
    h = m.loc["Healthy", "immobility_planted"]
    assert h["1h"] > h["1d"] > h["baseline"] and abs(h["7d"] - h["baseline"]) < 0.03


# ------------------------------------------------------------ input validation


def test_bad_inputs_raise():
    with pytest.raises(ValueError):
        head_kinematics(10.0, 0.0, seed=0)
    with pytest.raises(ValueError):
        head_kinematics(-1.0, 100.0, seed=0)
    with pytest.raises(ValueError):
        BehaviourParams(immobility_fraction=1.0)
    with pytest.raises(ValueError):
        Lesion(side="up")
    with pytest.raises(ValueError):
        SensorModel(acc_offset=(1.0, 2.0))
    with pytest.raises(ValueError):
        fibonacci_lattice(0)
    with pytest.raises(ValueError):
        tumble_test(seed=0, kind="spiral")
    with pytest.raises(ValueError):
        MarkerSupport(markers_mm=((0, 0, 0), (1, 0, 0)))
    with pytest.raises(FileNotFoundError):
        load_cohort("/nonexistent/cohort")


@pytest.mark.realdata
def test_real_rat_and_simulation_share_the_bimodal_angular_speed(data_mirror):
    from tiltlab.datasets import load_fayat_example
    from tiltlab.behavior import realism_table

    table = realism_table(
        {"real": load_fayat_example(), "sim": simulate_session(600.0, 100.0, seed=1)}
    )
    for col in ("real", "sim"):
        assert 6.0 <= table.loc["valley (deg/s)", col] <= 20.0
        assert (
            table.loc["still mode (deg/s)", col]
            < 6.0
            < 40.0
            < table.loc["moving mode (deg/s)", col]
        )
