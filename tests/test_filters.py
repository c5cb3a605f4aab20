"""Tests of tiltlab.filters: ahrs parity, convergence/tracking properties, the registry, wrappers,
and the scoring helpers of tiltlab.evaluate used with them (grids, BROAD errors)."""

import inspect

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from tiltlab import evaluate as E
from tiltlab import filters as F
from tiltlab import quaternion as Q
from tiltlab._validate import RecordingError
from tiltlab.schema import make_recording

RZ90 = np.array([np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5)])
DIP = 64.0
M_ENU = 48.0 * np.array([0.0, np.cos(np.radians(DIP)), -np.sin(np.radians(DIP))])


def _motion(n=1200, fs=200.0, seed=0, noise=True):
    """Smooth random rotation with consistent acc/gyr/mag (ENU), truth q, noisy sensors."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    ph = rng.uniform(0, 2 * np.pi, 3)
    omega = np.column_stack(
        [
            1.5 * np.sin(0.7 * t + ph[0]),
            1.0 * np.cos(0.4 * t + ph[1]),
            0.8 * np.sin(0.9 * t + ph[2]),
        ]
    )
    # truth with the filters' indexing: q[k] = q[k-1] ⊗ exp(ω_k dt/2)
    q_true = Q.integrate_gyro(
        np.vstack([omega[1:], omega[-1:]]), fs, Q.random_quaternions(1, rng)[0]
    )
    s = 1.0 if noise else 0.0
    acc = 9.81 * Q.gravity(q_true) + s * 0.3 * rng.standard_normal((n, 3))
    mag = Q.rotate_inverse(q_true, M_ENU) + s * 0.5 * rng.standard_normal((n, 3))
    gyr = omega + s * 0.02 * rng.standard_normal((n, 3))
    return acc, gyr, mag, q_true, fs


# ------------------------------------------------------------------ ahrs parity (1e-10)

ahrs_filters = pytest.importorskip("ahrs.filters")


@pytest.fixture(scope="module")
def motion():
    return _motion()


def _close(ours, ref):
    return np.max(np.abs(Q.canonical(ours) - Q.canonical(ref)))


@pytest.mark.parametrize("with_mag", [False, True])
def test_madgwick_matches_ahrs(motion, with_mag):
    acc, gyr, mag, q_true, fs = motion
    q0 = Q.normalize(q_true[0] + 0.1)
    if not with_mag:
        ref = ahrs_filters.Madgwick(gyr=gyr, acc=acc, frequency=fs, gain=0.1, q0=q0).Q
        ours = F.madgwick(acc, gyr, fs, beta=0.1, q0=q0)
    else:
        # ahrs MARG runs in Madgwick's NWU frame and ignores q0: compare in ENU via Rz(90°)
        ref = ahrs_filters.Madgwick(gyr=gyr, acc=acc, mag=mag, frequency=fs, gain=0.1).Q
        ref = Q.mul(RZ90, ref)
        ours = F.madgwick(acc, gyr, fs, mag=mag, beta=0.1, q0=ref[0])
    assert _close(ours, ref) < 1e-10


@pytest.mark.parametrize("with_mag", [False, True])
def test_mahony_matches_ahrs(motion, with_mag):
    acc, gyr, mag, q_true, fs = motion
    q0 = Q.normalize(q_true[0] + 0.1)
    b0 = np.array([0.01, -0.02, 0.005])
    kw = dict(gyr=gyr, acc=acc, frequency=fs, k_P=0.8, k_I=0.2, q0=q0, b0=b0.copy())
    if with_mag:
        kw["mag"] = mag
    ref = ahrs_filters.Mahony(**kw).Q
    ours = F.mahony(
        acc,
        gyr,
        fs,
        mag=mag if with_mag else None,
        kp=0.8,
        ki=0.2,
        q0=q0,
        gyr_offset=b0,
    )
    assert _close(ours, ref) < 1e-10


@pytest.mark.parametrize("with_mag", [False, True])
def test_ekf_matches_ahrs_ned_mode(motion, with_mag):
    acc, gyr, mag, q_true, fs = motion
    n = 600  # ahrs's EKF is slow
    acc, gyr, mag = acc[:n], gyr[:n], mag[:n]
    q0 = Q.normalize(q_true[0] + 0.1)
    noises = [0.01, 0.1, 0.2]
    # ahrs frame='NED' uses gravity reference (0, 0, 1), i.e. z up; pass an ENU magnetic reference
    m_ref = np.array([0.0, np.cos(np.radians(DIP)), -np.sin(np.radians(DIP))])
    kw = dict(
        gyr=gyr,
        acc=acc,
        frequency=fs,
        frame="NED",
        q0=q0,
        noises=noises,
        magnetic_ref=m_ref,
    )
    if with_mag:
        kw["mag"] = mag
    ref = ahrs_filters.EKF(**kw).Q
    ours = F.ekf(
        acc,
        gyr,
        fs,
        mag=mag if with_mag else None,
        q0=q0,
        var_gyr=0.01,
        var_acc=0.1,
        var_mag=0.2,
        dip=DIP,
    )
    assert _close(ours, ref) < 1e-10


def test_ahrs_enu_ekf_is_upside_down_and_ours_is_not(motion):
    """Documents the ahrs defect we do not inherit: frame='ENU' gives gravity pointing down."""
    acc, gyr, _, q_true, fs = motion
    acc, gyr = acc[:300], gyr[:300]
    ref = ahrs_filters.EKF(gyr=gyr, acc=acc, frequency=fs, frame="ENU").Q
    ours = F.ekf(acc, gyr, fs)
    g_ref, g_ours = Q.gravity(ref[-50:]), Q.gravity(ours[-50:])
    a = acc[-50:] / np.linalg.norm(acc[-50:], axis=1, keepdims=True)
    assert np.degrees(Q.angle_between(g_ours, a)).mean() < 10
    assert np.degrees(Q.angle_between(g_ref, a)).mean() > 170


# ------------------------------------------------------------------ properties

GAINS = {
    "madgwick": dict(beta=0.5),
    "mahony": dict(
        kp=2.0, ki=0.5
    ),  # closed-loop poles s² + kp s + ki = 0 at -0.3, -1.7
    "ekf": dict(var_gyr=1e-3, var_acc=0.05, var_mag=0.05),
    "complementary": dict(tau_acc_s=0.5, tau_mag_s=0.5),
}


def _lag(method, rate, fs):
    """Madgwick and Mahony (as in ahrs and Madgwick's reference code) evaluate the correction
    at the prior q_{k-1} against a_k: under rotation at ``rate`` rad/s this one-sample lag
    biases the estimate by up to ``rate·Δt`` (rad). The EKF and the complementary filter
    predict first and have no such lag."""
    return rate / fs if method in ("madgwick", "mahony") else 0.0


def _static_tol(method, fs):
    """Madgwick's normalised gradient never vanishes: at rest q moves by β·Δt (quaternion
    norm) every step, i.e. it chatters within a rotation angle of 2·β·Δt of the truth."""
    if method == "madgwick":
        return np.degrees(2.0 * GAINS["madgwick"]["beta"] / fs) + 0.01
    return 0.1


quats = st.integers(0, 2**32 - 1).map(lambda s: Q.random_quaternions(1, s)[0])


@settings(max_examples=15, deadline=None)
@given(q_true=quats, method=st.sampled_from(sorted(GAINS)))
def test_static_sensor_converges_to_true_tilt(q_true, method):
    fs, n = 100.0, 3000
    tilt = np.degrees(Q.tilt_error(q_true, Q.identity()))
    if (
        method == "ekf" and tilt > 150
    ):  # a gradient/EKF update is degenerate near the antipode
        q_true = Q.mul(Q.from_rotvec([0.5, 0.0, 0.0]), q_true)
    acc = np.tile(9.81 * Q.gravity(q_true), (n, 1))
    gyr = np.zeros((n, 3))
    q = getattr(F, method)(acc, gyr, fs, q0=Q.identity(), **GAINS[method])
    assert np.degrees(Q.tilt_error(q[-1], q_true)) < _static_tol(method, fs)


@settings(max_examples=15, deadline=None)
@given(q_true=quats, method=st.sampled_from(sorted(GAINS)))
def test_static_sensor_9d_converges_to_true_orientation(q_true, method):
    fs, n = 100.0, 8000
    acc = np.tile(9.81 * Q.gravity(q_true), (n, 1))
    mag = np.tile(Q.rotate_inverse(q_true, M_ENU), (n, 1))
    q0 = Q.mul(Q.from_rotvec([0.3, -0.4, 1.0]), q_true)  # 1.1 rad off, heading included
    kw = dict(GAINS[method], dip=DIP) if method == "ekf" else GAINS[method]
    if method == "mahony":
        # the vector magnetometer term acts on heading with gains scaled by cos²(dip) (≈ 0.19):
        # kp=3, ki=0.3 keep that loop overdamped (poles ≈ -0.13, -0.44 s⁻¹)
        kw = dict(kp=3.0, ki=0.3)
    q = getattr(F, method)(acc, np.zeros((n, 3)), fs, mag=mag, q0=q0, **kw)
    assert np.degrees(Q.total_error(q[-1], q_true)) < 2 * _static_tol(method, fs)


@settings(max_examples=15, deadline=None)
@given(
    seed=st.integers(0, 10**6),
    method=st.sampled_from(sorted(GAINS)),
    with_mag=st.booleans(),
)
def test_output_quaternions_are_unit(seed, method, with_mag):
    rng = np.random.default_rng(seed)
    n = 300
    acc = rng.normal(0, 15, (n, 3))
    gyr = rng.normal(0, 10, (n, 3))
    mag = rng.normal(0, 50, (n, 3)) if with_mag else None
    kw = dict(GAINS[method], dip=30.0) if method == "ekf" else GAINS[method]
    q = getattr(F, method)(acc, gyr, 50.0, mag=mag, **kw)
    assert np.all(np.isfinite(q))
    assert np.max(np.abs(Q.norm(q) - 1.0)) < 1e-12


@settings(max_examples=15, deadline=None)
@given(
    w=st.tuples(*[st.floats(-3.0, 3.0)] * 3).map(np.array),
    seed=st.integers(0, 2**32 - 1),
    method=st.sampled_from(sorted(GAINS)),
)
def test_constant_rate_rotation_is_tracked(w, seed, method):
    """Tracking within the one-sample-lag bound. Mahony's proportional-integral loop (slowest
    pole at -0.3/s) settles to that bound but its transient can overshoot it slightly (measured:
    < 0.3 % over 400 random rotations), so for Mahony the bound is asserted once the loop has
    settled (second half of a 20 s run) and the transient is only required to stay bounded."""
    fs, n = 200.0, 4000
    q_true = Q.integrate_gyro(np.tile(w, (n, 1)), fs, Q.random_quaternions(1, seed)[0])
    acc = 9.81 * Q.gravity(q_true)
    q = getattr(F, method)(acc, np.tile(w, (n, 1)), fs, q0=q_true[0], **GAINS[method])
    tol = _static_tol(method, fs) + np.degrees(_lag(method, np.linalg.norm(w), fs))
    err = np.degrees(Q.tilt_error(q, q_true))
    if method == "mahony":
        assert err[n // 2 :].max() < tol
        assert err.max() < 2.0 * tol
    else:
        assert err.max() < tol


def test_gyro_only_complementary_equals_integration():
    acc, gyr, _, q_true, fs = _motion(noise=False)
    q = F.complementary(acc, gyr, fs, tau_acc_s=np.inf, q0=q_true[0])
    assert np.degrees(Q.total_error(q, q_true)).max() < 1e-8


def test_mahony_integral_term_estimates_gyro_bias():
    acc, gyr, mag, q_true, fs = _motion(n=16000, noise=False)
    bias = np.array([0.02, -0.03, 0.015])
    q, b = F.mahony(
        acc, gyr + bias, fs, mag=mag, kp=1.0, ki=0.3, q0=q_true[0], return_bias=True
    )
    lag = _lag("mahony", np.linalg.norm(gyr, axis=1).max(), fs)
    assert np.linalg.norm(b[-2000:].mean(axis=0) - bias) < 0.2 * np.linalg.norm(bias)
    assert (
        np.degrees(Q.total_error(q[-2000:], q_true[-2000:])).max()
        < np.degrees(lag) + 0.1
    )


def test_lowpass_tilt_of_static_sensor():
    q_true = Q.random_quaternions(1, 5)[0]
    acc = np.tile(Q.gravity(q_true), (500, 1)) + 0.01 * np.random.default_rng(
        1
    ).standard_normal((500, 3))
    q = F.lowpass_tilt(acc, 100.0, cutoff_hz=1.0)
    assert np.degrees(Q.tilt_error(q[50:-50], q_true)).max() < 0.5
    assert np.allclose(q[:, 3], 0.0)  # heading part zero


@settings(max_examples=30, deadline=None)
@given(q_true=quats)
def test_initial_orientation_triad(q_true):
    acc = 9.81 * Q.gravity(q_true)
    mag = Q.rotate_inverse(q_true, M_ENU)
    assert np.degrees(Q.total_error(F.initial_orientation(acc, mag), q_true)) < 1e-6
    q6 = F.initial_orientation(acc)
    assert np.degrees(Q.tilt_error(q6, q_true)) < 1e-6
    assert abs(q6[3]) < 1e-12


def test_smoother_recovers_tilt_with_bias_and_translation():
    """Static start (bias from rest), then rotation plus bounded oscillating translation."""
    fs, n = 100.0, 6000
    t = np.arange(n) / fs
    move = (t > 5) & (t < 55)
    omega = np.where(
        move[:, None],
        np.column_stack(
            [np.sin(0.9 * t), 0.7 * np.cos(0.5 * t), 0.5 * np.sin(1.3 * t)]
        ),
        0.0,
    )
    q_true = Q.integrate_gyro(
        np.vstack([omega[1:], omega[-1:]]), fs, Q.random_quaternions(1, 3)[0]
    )
    lin = np.where(
        move[:, None],
        3.0 * np.column_stack([np.sin(2.1 * t), np.cos(1.7 * t), np.sin(2.9 * t)]),
        0.0,
    )
    acc = Q.rotate_inverse(q_true, 9.81 * np.array([0, 0, 1.0]) + lin)
    bias = np.array([0.01, -0.008, 0.012])
    q = F.smoother(acc, omega + bias, fs, cutoff_hz=0.1)
    err = np.degrees(Q.tilt_error(q, q_true))[move]
    assert np.sqrt(np.mean(err**2)) < 1.0
    assert np.max(np.abs(Q.norm(q) - 1)) < 1e-12
    b, rest = F.rest_gyro_bias(acc, omega + bias, fs)
    assert np.allclose(b, bias, atol=1e-9) and not rest[move][100:-100].any()
    # the raw low-pass tilt is far worse under the same translation
    ql = F.lowpass_tilt(acc, fs, cutoff_hz=0.1)
    assert np.sqrt(np.mean(np.degrees(Q.tilt_error(ql, q_true))[move] ** 2)) > 5.0


def test_madgwick_batch_equals_single_runs(motion):
    acc, gyr, mag, _, fs = motion
    betas = [0.0, 0.05, 0.3]
    out = F.madgwick_batch(acc, gyr, fs, betas=betas, mag=mag)
    for b, q in zip(betas, out):
        assert np.array_equal(q, F.madgwick(acc, gyr, fs, mag=mag, beta=b))


def test_bad_inputs_raise():
    acc, gyr, _, _, fs = _motion(n=50)
    with pytest.raises(ValueError, match="fs"):
        F.madgwick(acc, gyr, None)
    with pytest.raises(ValueError, match="shape"):
        F.ekf(acc[:, :2], gyr, fs)
    with pytest.raises(ValueError, match="samples"):
        F.mahony(acc, gyr[:10], fs)
    bad = acc.copy()
    bad[3, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        F.complementary(bad, gyr, fs)
    with pytest.raises(ValueError, match="beta"):
        F.madgwick(acc, gyr, fs, beta=-1)
    with pytest.raises(ValueError, match="Nyquist"):
        F.lowpass_tilt(acc, fs, cutoff_hz=fs)


# ------------------------------------------------------------------ recordings and wrappers


def _recording(seed=0, n=1200, in_g=True):
    acc, gyr, mag, q_true, fs = _motion(n=n, seed=seed)
    if in_g:
        return make_recording(
            acc / 9.80665,
            np.degrees(gyr),
            fs,
            mag=mag,
            q_ref=q_true,
            extra={"movement": (("time",), np.ones(n, bool), {})},
            acc_units="g",
            gyr_units="deg/s",
            mag_units="uT",
        )
    return make_recording(
        acc,
        gyr,
        fs,
        acc_units="m/s^2",
        gyr_units="rad/s",
        mag=mag,
        q_ref=q_true,
        extra={"movement": (("time",), np.ones(n, bool), {})},
        mag_units="uT",
    )


@pytest.mark.parametrize(
    "method",
    [
        "madgwick",
        "mahony",
        "ekf",
        "complementary",
        "lowpass",
        "smoother",
        "rts_smoother",
    ],
)
def test_estimate_converts_units_and_records_params(method):
    r_g, r_si = _recording(in_g=True), _recording(in_g=False)
    q1 = F.estimate(r_g, method)
    q2 = F.estimate(r_si, method)
    assert q1.dims == ("time", "quat") and list(q1.quat.values) == list("wxyz")
    assert np.max(np.abs(q1.values - q2.values)) < 1e-9
    assert q1.attrs["method"] == method and q1.attrs["fs"] == r_g.attrs["fs"]
    for k in F.METHODS[method].defaults:
        assert f"param_{k}" in q1.attrs
    g = F.gravity(q1)
    assert g.dims == ("time", "axis") and np.allclose(
        np.linalg.norm(g.values, axis=1), 1.0
    )
    assert np.array_equal(g.time.values, r_g.time.values)


ALL_METHODS = {
    "lowpass",
    "learned_gain",
    "davenport",
    "complementary",
    "madgwick",
    "mahony",
    "ekf",
    "eskf",
    "smoother",
    "rts_smoother",
    "vqf",
    "offline_vqf",
    "imufusion",
    "ahrs_madgwick",
    "ahrs_mahony",
    "ahrs_ekf",
    "riann",
}


def test_registry_lists_every_method_with_defaults_from_the_signature():
    assert set(F.methods()) == set(F.METHODS) == ALL_METHODS
    assert "rts_smoother" in F.methods("offline") and "madgwick" in F.methods("causal")
    for name, m in F.METHODS.items():
        sig = inspect.signature(m.function).parameters
        assert m.defaults == {k: sig[k].default for k in m.defaults}, name
    assert F.defaults("complementary") == {
        "tau_acc_s": 1.0,
        "tau_mag_s": 5.0,
        "init_window_s": 0.1,
    }
    assert F.defaults("lowpass") == {"cutoff_hz": 1.0, "order": 2}
    assert F.METHODS["madgwick"].supports_mag and F.METHODS["vqf"].supports_mag
    assert (
        not F.METHODS["rts_smoother"].supports_mag and not F.METHODS["lowpass"].uses_gyr
    )
    with pytest.raises(
        ValueError, match="rts_smoother"
    ):  # the message lists the valid methods
        F.get_method("kalman-ish")


def test_estimate_unknown_parameter_is_named():
    rec = _recording(n=200)
    with pytest.raises(ValueError, match="'tau_acc'"):
        F.estimate(rec, "complementary", tau_acc=1.0)
    with pytest.raises(ValueError, match="'fc'"):
        F.estimate(rec, "lowpass", fc=1.0)
    with pytest.raises(ValueError, match="'return_bias'"):
        F.estimate(rec, "mahony", return_bias=True)


def test_estimate_vqf_parameters_pass_through_and_are_checked():
    pytest.importorskip("vqf")
    rec = _recording(n=300)
    q = F.estimate(rec, "vqf", tauAcc=2.0)
    assert q.attrs["param_tauAcc"] == 2.0 and np.allclose(Q.norm(q.values), 1.0)
    with pytest.raises(ValueError, match="'bogus'"):
        F.estimate(rec, "vqf", bogus=1.0)


def test_estimate_fs_contradicting_the_time_axis_names_fs():
    rec = _recording(n=400)
    bad = rec.assign_attrs(fs=2.0 * rec.attrs["fs"])
    with pytest.raises(RecordingError, match="fs"):
        F.estimate(bad, "madgwick")


def test_gravity_of_estimate_keeps_time_fs_and_method():
    rec = _recording(n=400)
    rec = rec.assign_coords(
        time=rec["time"].values + 12.5
    )  # a recording not starting at 0
    q = F.estimate(rec, "mahony", kp=0.7)
    assert np.array_equal(q.time.values, rec.time.values)
    g = F.gravity(q)
    assert g.name == "gravity" and g.dims == ("time", "axis")
    assert np.array_equal(g.time.values, rec.time.values)
    assert g.attrs["fs"] == rec.attrs["fs"] and g.attrs["method"] == "mahony"
    assert g.attrs["param_kp"] == 0.7 and g.attrs["frame"] == "sensor"
    assert np.allclose(g.values, Q.gravity(q.values), atol=1e-15)
    plain = F.gravity(q.values)
    assert isinstance(plain, np.ndarray) and np.array_equal(plain, g.values)


@pytest.mark.parametrize(
    "method", ["madgwick", "mahony", "ekf", "complementary", "smoother", "rts_smoother"]
)
def test_estimate_gyro_in_rad_s_equals_deg_s(method):
    acc, gyr, _, _, fs = _motion(n=600, seed=4)
    r_deg = make_recording(
        acc, np.degrees(gyr), fs, acc_units="m/s^2", gyr_units="deg/s"
    )
    r_rad = make_recording(acc, gyr, fs, acc_units="m/s^2", gyr_units="rad/s")
    q_deg, q_rad = F.estimate(r_deg, method), F.estimate(r_rad, method)
    assert np.max(np.abs(q_deg.values - q_rad.values)) < 1e-9


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda a, g, fs: F.complementary(a, g, fs, tau_acc_s=np.nan), "tau_acc_s"),
        (lambda a, g, fs: F.complementary(a, g, fs, tau_mag_s=0.0), "tau_mag_s"),
        (lambda a, g, fs: F.madgwick(a, g, fs, init_window_s=-1.0), "init_window_s"),
        (lambda a, g, fs: F.madgwick_batch(a, g, fs, betas=[0.1, -0.1]), "betas"),
        (lambda a, g, fs: F.mahony(a, g, fs, kp=np.inf), "kp"),
        (lambda a, g, fs: F.mahony(a, g, fs, ki="x"), "ki"),
        (lambda a, g, fs: F.ekf(a, g, fs, var_acc=0.0), "var_acc"),
        (lambda a, g, fs: F.ekf(a, g, fs, dip=np.nan), "dip"),
        (lambda a, g, fs: F.lowpass_tilt(a, fs, order=1.5), "order"),
        (lambda a, g, fs: F.smoother(a, g, fs, cutoff_hz=-0.1), "cutoff_hz"),
        (lambda a, g, fs: F.rest_gyro_bias(a, g, fs, window_s=0.0), "window_s"),
        (
            lambda a, g, fs: F.rest_gyro_bias(a, g, fs, threshold_rad_s=np.nan),
            "threshold_rad_s",
        ),
        (
            lambda a, g, fs: F.rest_gyro_bias(a, g, fs, acc_std_threshold=-1.0),
            "acc_std_threshold",
        ),
        (lambda a, g, fs: F.rest_gyro_bias(a, g, fs, min_rest_s=-1.0), "min_rest_s"),
        (
            lambda a, g, fs: F.rts_smoother(a, g, fs, max_memory_gb=np.nan),
            "max_memory_gb",
        ),
    ],
)
def test_numeric_parameters_are_checked_and_named(call, name):
    acc, gyr, _, _, fs = _motion(n=100)
    with pytest.raises(ValueError, match=name):
        call(acc, gyr, fs)


def test_rest_gyro_bias_renamed_options():
    fs, n = 100.0, 1000
    acc = np.tile([0.0, 0.0, 9.81], (n, 1))
    gyr = np.tile([0.01, -0.02, 0.005], (n, 1))
    gyr[400:600] += 1.0  # 2 s of motion (1.7 rad/s) in the middle
    b, rest = F.rest_gyro_bias(
        acc,
        gyr,
        fs,
        window_s=0.5,
        threshold_rad_s=0.05,
        acc_std_threshold=0.2,
        min_rest_s=1.0,
    )
    assert (
        np.allclose(b, [0.01, -0.02, 0.005])
        and not rest[400:600].any()
        and rest[:300].all()
    )
    # rest periods shorter than min_rest_s are dropped: none is left
    b2, rest2 = F.rest_gyro_bias(acc, gyr, fs, min_rest_s=5.0)
    assert not rest2.any() and np.array_equal(b2, np.zeros(3))


def test_estimate_params_override_and_9d():
    rec = _recording()
    q = F.estimate(rec, "madgwick", use_mag=True, beta=0.2)
    assert q.attrs["param_beta"] == 0.2 and q.attrs["world_frame"] == "ENU"
    assert E.broad_errors(q, rec, movement_only=False)["heading"] < 3.0


def test_estimate_requires_fs_and_known_method():
    rec = _recording()
    with pytest.raises(ValueError, match="fs"):
        F.estimate(
            rec.drop_attrs(deep=False)
            if hasattr(rec, "drop_attrs")
            else rec.assign_attrs(fs=None),
            "madgwick",
        )
    with pytest.raises(ValueError, match="unknown method"):
        F.estimate(rec, "kalman-ish")


def test_grid_search_matches_direct_scores():
    recs = {"a": _recording(seed=1, n=800), "b": _recording(seed=2, n=800)}
    grid = E.grid_search(recs, "madgwick", {"beta": [0.01, 0.1, 0.5]}, n_jobs=2)
    assert grid.dims == ("beta", "recording") and grid.shape == (3, 2)
    for b in [0.01, 0.5]:
        direct = E.tilt_rmse(F.estimate(recs["b"], "madgwick", beta=b), recs["b"])
        assert grid.sel(beta=b, recording="b").item() == pytest.approx(
            direct, rel=1e-12
        )
    g2 = E.grid_search(
        list(recs.values()), "mahony", {"kp": [0.5, 1.0], "ki": [0.0, 0.1]}, n_jobs=1
    )
    assert g2.dims == ("kp", "ki", "recording") and np.all(np.isfinite(g2.values))


# ------------------------------------------------------------------ BROAD error helper


def test_broad_errors_definition():
    rec = _recording(n=400)
    q_ref = rec.q_ref.values.copy()
    assert E.broad_errors(q_ref, rec)["total"] == pytest.approx(0.0, abs=1e-6)
    # a constant heading offset of 30°: heading/total 30°, inclination 0; removable
    q_off = Q.mul(Q.from_rotvec([0.0, 0.0, np.radians(30.0)]), q_ref)
    e = E.broad_errors(q_off, rec)
    assert e["heading"] == pytest.approx(30.0, abs=1e-6) and e[
        "total"
    ] == pytest.approx(30.0, abs=1e-6)
    assert e["inclination"] < 1e-6
    assert E.broad_errors(q_off, rec, remove_heading_offset=True)["heading"] < 1e-6
    # a 5° tilt error about a horizontal world axis; NaN references and non-movement samples are excluded
    q_tilt = Q.mul(Q.from_rotvec([np.radians(5.0), 0.0, 0.0]), q_ref)
    rec2 = rec.copy(deep=True)
    rec2["q_ref"][:100] = np.nan
    rec2["movement"][100:150] = False
    q_bad = q_tilt.copy()
    q_bad[100:150] = Q.identity()
    e2 = E.broad_errors(q_bad, rec2)
    assert e2["n"] == 250 and e2["inclination"] == pytest.approx(5.0, abs=1e-6)


@pytest.mark.realdata
def test_broad_trial_madgwick_reasonable(data_mirror):
    from tiltlab.datasets import load_broad_trial

    rec = load_broad_trial(2)
    e = E.broad_errors(F.estimate(rec, "madgwick", beta=0.02), rec)
    assert e["inclination"] < 2.0
    assert e["n"] > 0


def test_grid_search_dataarray_scores_add_dims_and_must_be_consistent():
    acc, gyr, _, q_true, fs = _motion(n=400)
    recs = [
        make_recording(acc, gyr, fs, acc_units="m/s^2", gyr_units="rad/s", q_ref=q_true)
    ]

    def two(q, rec):
        e = np.degrees(Q.tilt_error(q, rec["q_ref"].values))
        return xr.DataArray(
            [e.mean(), e.max()], dims=("stat",), coords={"stat": ["mean", "max"]}
        )

    g = E.grid_search(recs, "madgwick", {"beta": [0.05, 0.5]}, two, n_jobs=1)
    assert g.dims == ("beta", "recording", "stat") and np.all(
        g.sel(stat="max") >= g.sel(stat="mean")
    )
    calls = iter(range(10))

    def bad(q, rec):
        n = 2 + next(calls) % 2
        return xr.DataArray(np.zeros(n), dims=("stat",))

    with pytest.raises(ValueError):
        E.grid_search(recs, "madgwick", {"beta": [0.05, 0.5]}, bad, n_jobs=1)


# ------------------------------------------------------------------ error-state RTS smoother


def _bounded_motion(fs=100.0, n=4000, seed=0, rest_s=5.0):
    """Rest, then smooth rotation with a bounded translation (position returns to rest), then rest."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    t_end = n / fs - rest_s
    env = np.clip((t - rest_s) / 2.0, 0, 1) * np.clip((t_end - t) / 2.0, 0, 1)
    env = env * env * (3 - 2 * env)
    ph = rng.uniform(0, 2 * np.pi, 6)
    omega = env[:, None] * np.column_stack(
        [
            np.sin(0.9 * t + ph[0]),
            0.7 * np.cos(0.5 * t + ph[1]),
            0.5 * np.sin(1.3 * t + ph[2]),
        ]
    )
    q_true = Q.integrate_gyro(
        np.vstack([omega[1:], omega[-1:]]), fs, Q.random_quaternions(1, rng)[0]
    )
    p = (
        env[:, None]
        * 0.3
        * np.column_stack(
            [np.sin(2.1 * t + ph[3]), np.cos(1.7 * t + ph[4]), np.sin(2.9 * t + ph[5])]
        )
    )
    lin = np.gradient(np.gradient(p, 1 / fs, axis=0), 1 / fs, axis=0)
    acc = Q.rotate_inverse(q_true, 9.81 * np.array([0.0, 0.0, 1.0]) + lin)
    return acc, omega, q_true, env > 0, fs


# filter noise parameters matched to the synthetic sensors below (the defaults are BROAD's)
RTS_KW = dict(gyr_noise=1e-3, acc_noise=0.05)


def _rms_tilt(q, q_true, mask):
    return float(np.sqrt(np.mean(np.degrees(Q.tilt_error(q, q_true))[mask] ** 2)))


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 10**6), smooth=st.booleans())
def test_rts_smoother_outputs_unit_quaternions(seed, smooth):
    rng = np.random.default_rng(seed)
    n = 300
    acc = rng.normal(0, 15, (n, 3))
    gyr = rng.normal(0, 10, (n, 3))
    q, x = F.rts_smoother(
        acc, gyr, 50.0, smooth=smooth, scale_std=0.01, return_state=True
    )
    assert np.all(np.isfinite(q)) and np.all(np.isfinite(x)) and x.shape == (n, 12)
    assert np.max(np.abs(Q.norm(q) - 1.0)) < 1e-12


@settings(max_examples=8, deadline=None)
@given(q_true=quats)
def test_rts_smoother_static_converges_to_true_tilt(q_true):
    fs, n = 100.0, 1500
    rng = np.random.default_rng(1)
    acc = 9.81 * Q.gravity(q_true) + 0.05 * rng.standard_normal((n, 3))
    gyr = 0.002 * rng.standard_normal((n, 3))
    # 2.1° of tilt off (about the filter's 2° prior standard deviation), heading arbitrary
    q0 = Q.mul(Q.from_rotvec([0.03, -0.02, 0.3]), q_true)
    for smooth in (False, True):
        q = F.rts_smoother(acc, gyr, fs, q0=q0, smooth=smooth, **RTS_KW)
        err = np.degrees(Q.tilt_error(q, q_true))
        # same tolerance as the causal filters' static test; the gyro noise alone makes the
        # integrated attitude wander ≈ 0.002 rad/s·√(Δt·T) ≈ 0.04° over the 15 s
        assert err[-100:].max() < 0.1
        if smooth:  # the backward pass carries the converged tilt back to the start
            assert err.max() < 0.1


@settings(max_examples=8, deadline=None)
@given(
    w=st.tuples(*[st.floats(-3.0, 3.0)] * 3).map(np.array),
    seed=st.integers(0, 2**32 - 1),
)
def test_rts_smoother_tracks_constant_rate_rotation(w, seed):
    fs, n = 200.0, 2000
    q_true = Q.integrate_gyro(np.tile(w, (n, 1)), fs, Q.random_quaternions(1, seed)[0])
    acc = 9.81 * Q.gravity(q_true)
    q = F.rts_smoother(acc, np.tile(w, (n, 1)), fs, q0=q_true[0], **RTS_KW)
    assert np.degrees(Q.tilt_error(q, q_true)).max() < 0.05


def test_rts_smoother_recovers_gyro_bias_and_scale_and_beats_forward_pass():
    acc, omega, q_true, move, fs = _bounded_motion()
    bias = np.array([0.01, -0.008, 0.012])
    scale = np.array([0.02, -0.015, 0.01])
    gyr = omega * (1.0 + scale) + bias
    # start from a zero bias so that the filter has to learn it (not the rest estimate)
    kw = dict(RTS_KW, gyr_offset=np.zeros(3), bias_std=0.02, scale_std=0.03)
    qf, xf = F.rts_smoother(acc, gyr, fs, smooth=False, return_state=True, **kw)
    qs, xs = F.rts_smoother(acc, gyr, fs, return_state=True, **kw)
    assert np.allclose(xs[:, :3], bias, atol=5e-4)  # rad/s (0.03 °/s)
    assert np.allclose(xs[:, 9:], scale, atol=2e-3)
    assert np.allclose(xf[-1, :3], bias, atol=5e-4)
    e_f, e_s = _rms_tilt(qf, q_true, move), _rms_tilt(qs, q_true, move)
    assert e_s <= e_f
    assert e_s < 0.1
    # velocity and position states follow the true (bounded) translation
    assert np.max(np.abs(xs[:, 3:9])) < 1.5


def test_rts_smoother_beats_forward_pass_and_lowpass_smoother_with_noise():
    acc, omega, q_true, move, fs = _bounded_motion(seed=3)
    rng = np.random.default_rng(3)
    acc = acc + 0.05 * rng.standard_normal(acc.shape)
    gyr = (
        omega
        + np.array([0.004, 0.002, -0.003])
        + 0.003 * rng.standard_normal(omega.shape)
    )
    e_f = _rms_tilt(F.rts_smoother(acc, gyr, fs, smooth=False, **RTS_KW), q_true, move)
    e_s = _rms_tilt(F.rts_smoother(acc, gyr, fs, **RTS_KW), q_true, move)
    assert e_s <= e_f
    assert e_s < _rms_tilt(F.smoother(acc, gyr, fs), q_true, move)


def test_rts_smoother_estimate_grid_and_bad_inputs():
    rec = _recording(n=600)
    q = F.estimate(rec, "rts_smoother", pos_std=1.0)
    assert q.attrs["method"] == "rts_smoother" and q.attrs["param_pos_std"] == 1.0
    assert np.allclose(Q.norm(q.values), 1.0)
    s = E.grid_search([rec, rec], "rts_smoother", {"gyr_noise": [1e-3, 1e-2]}, n_jobs=1)
    assert s.dims == ("gyr_noise", "recording") and np.all(np.isfinite(s.values))
    assert s.sel(gyr_noise=1e-2).values[0] == pytest.approx(
        E.tilt_rmse(F.estimate(rec, "rts_smoother", gyr_noise=1e-2), rec)
    )
    with pytest.raises(ValueError, match="use_mag"):
        F.estimate(rec, "rts_smoother", use_mag=True)
    acc, gyr = rec["acc"].values * 9.80665, np.radians(rec["gyr"].values)
    with pytest.raises(ValueError, match="gyr_noise"):
        F.rts_smoother(acc, gyr, 100.0, gyr_noise=-1.0)
    with pytest.raises(ValueError, match="tau_s"):
        F.rts_smoother(acc, gyr, 100.0, tau_s=0.0)
    with pytest.raises(ValueError, match="fs"):
        F.rts_smoother(acc, gyr, None)


def test_rts_smoother_refuses_recordings_too_large_for_memory():
    acc = np.tile([0.0, 0.0, 9.81], (1000, 1))
    gyr = np.zeros((1000, 3))
    with pytest.raises(ValueError, match="split the recording"):
        F.rts_smoother(acc, gyr, 100.0, max_memory_gb=1e-6)
    assert F.rts_smoother(acc, gyr, 100.0, smooth=False, max_memory_gb=1e-6).shape == (
        1000,
        4,
    )
