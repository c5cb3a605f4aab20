"""Tests of the error-state Kalman filter tiltlab.filters.eskf: tracking with a gyro bias,
bias convergence at rest, 9D heading convergence, the registry and parameter checks."""

import numpy as np
import pytest

from tiltlab import filters as F
from tiltlab import quaternion as Q
from tiltlab.schema import make_recording

G = 9.81
DIP = 64.0
M_ENU = 48.0 * np.array([0.0, np.cos(np.radians(DIP)), -np.sin(np.radians(DIP))])
BIAS = np.array([0.02, -0.015, 0.01])  # rad/s (≈ 1.1, 0.9, 0.6 °/s)


def _constant_rate(omega, n=6000, fs=100.0, bias=BIAS, seed=0, q0=None):
    """Truth from a constant rate (the filters' indexing is immaterial for a constant ω),
    exact acc = R(q)ᵀ g e_z and mag = R(q)ᵀ m_ENU, gyro = ω + bias + 1e-3 rad/s noise."""
    rng = np.random.default_rng(seed)
    om = np.tile(np.asarray(omega, float), (n, 1))
    q_true = Q.integrate_gyro(om, fs, q0)
    acc = Q.rotate_inverse(q_true, [0.0, 0.0, G])
    mag = Q.rotate_inverse(q_true, M_ENU)
    gyr = om + bias + 1e-3 * rng.standard_normal((n, 3))
    return acc, gyr, mag, q_true, fs


Q_START = Q.from_rotvec([0.3, -0.2, 1.0])


@pytest.mark.parametrize("with_mag", [False, True])
def test_tracks_constant_rate_rotation_with_gyro_bias(with_mag):
    acc, gyr, mag, q_true, fs = _constant_rate([0.3, 0.2, 0.5], q0=Q_START)
    q, b = F.eskf(acc, gyr, fs, mag=mag if with_mag else None, return_bias=True)
    assert q.shape == (len(acc), 4) and np.allclose(Q.norm(q), 1.0)
    late = slice(len(acc) // 2, None)  # after 30 s
    assert np.degrees(Q.tilt_error(q[late], q_true[late])).max() < 1.0
    # the rotation makes every bias component observable (in 6D too)
    assert np.all(np.abs(b[-1] - BIAS) < 0.1 * np.abs(BIAS))
    if with_mag:
        assert np.degrees(Q.heading_error(q[late], q_true[late])).max() < 1.0


def test_static_sensor_converges_to_the_bias():
    acc, gyr, mag, q_true, fs = _constant_rate(np.zeros(3), q0=Q_START)
    late = slice(len(acc) // 2, None)
    # 9D: the whole bias and attitude
    q, b = F.eskf(acc, gyr, fs, mag=mag, return_bias=True)
    assert np.abs(b[-1] - BIAS).max() < 1e-3  # rad/s (5 % of the smallest component)
    assert np.degrees(Q.tilt_error(q[late], q_true[late])).max() < 0.2
    assert np.degrees(Q.heading_error(q[late], q_true[late])).max() < 0.5
    # 6D: the bias perpendicular to gravity (its component along gravity is unobservable)
    q6, b6 = F.eskf(acc, gyr, fs, return_bias=True)
    up = acc[0] / np.linalg.norm(acc[0])
    err = b6[-1] - BIAS
    assert np.linalg.norm(err - np.dot(err, up) * up) < 1e-3
    assert np.degrees(Q.tilt_error(q6[late], q_true[late])).max() < 0.2
    # without bias estimation (bias_std = bias_noise = 0) the bias tilts the estimate
    q_nb = F.eskf(acc, gyr, fs, bias_std=0.0, bias_noise=0.0)
    assert (
        Q.tilt_error(q_nb[late], q_true[late]).mean()
        > 2.0 * Q.tilt_error(q6[late], q_true[late]).mean()
    )


def test_9d_heading_converges_from_a_wrong_initial_heading():
    acc, gyr, mag, q_true, fs = _constant_rate(
        [0.2, -0.1, 0.4], n=6000, q0=Q_START, bias=np.zeros(3)
    )
    wrong = Q.mul(Q.from_rotvec([0.0, 0.0, np.radians(60.0)]), q_true[0])
    q = F.eskf(acc, gyr, fs, mag=mag, q0=wrong)
    hd = np.degrees(Q.heading_error(q, q_true))
    assert hd[0] > 59.0
    assert hd[len(hd) // 2 :].max() < 1.0
    assert (
        np.degrees(Q.tilt_error(q[len(hd) // 2 :], q_true[len(hd) // 2 :])).max() < 1.0
    )


@pytest.mark.parametrize("use_mag", [False, True])
def test_estimate_on_a_recording_equals_the_array_call(use_mag):
    acc, gyr, mag, _, fs = _constant_rate([0.3, 0.2, 0.5], n=800, q0=Q_START)
    rec = make_recording(
        acc / 9.80665,
        np.degrees(gyr),
        fs,
        acc_units="g",
        gyr_units="deg/s",
        mag=mag,
        mag_units="uT",
    )
    qr = F.estimate(rec, "eskf", use_mag=use_mag)
    qa = F.eskf(acc, gyr, fs, mag=mag if use_mag else None)
    assert np.max(np.abs(qr.values - qa)) < 1e-9
    assert qr.attrs["method"] == "eskf"
    for k in F.METHODS["eskf"].defaults:
        assert f"param_{k}" in qr.attrs
    assert "eskf" in F.methods() and "eskf" in F.methods("causal")
    assert F.METHODS["eskf"].supports_mag
    assert set(F.METHODS["eskf"].options) == {"q0", "gyr_offset"}


@pytest.mark.parametrize(
    "kw, name",
    [
        ({"gyr_noise": -1.0}, "gyr_noise"),
        ({"bias_noise": np.nan}, "bias_noise"),
        ({"acc_noise": 0.0}, "acc_noise"),
        ({"norm_gain": np.inf}, "norm_gain"),
        ({"mag_noise": "x"}, "mag_noise"),
        ({"bias_std": -0.1}, "bias_std"),
        ({"tilt_std": np.nan}, "tilt_std"),
        ({"heading_std": -1.0}, "heading_std"),
        ({"init_window_s": -1.0}, "init_window_s"),
        ({"gyr_offset": [0.0, 0.0]}, "gyr_offset"),
        ({"q0": [0.0, 0.0, 0.0, 0.0]}, "q0"),
    ],
)
def test_bad_parameters_raise_and_are_named(kw, name):
    acc, gyr, _, _, fs = _constant_rate(np.zeros(3), n=50)
    with pytest.raises(ValueError, match=name):
        F.eskf(acc, gyr, fs, **kw)


def test_bad_inputs_raise():
    acc, gyr, mag, _, fs = _constant_rate(np.zeros(3), n=50)
    with pytest.raises(ValueError, match="fs"):
        F.eskf(acc, gyr, 0.0)
    with pytest.raises(ValueError, match="gyr"):
        F.eskf(acc, gyr[:-1], fs)
    with pytest.raises(ValueError, match="mag"):
        F.eskf(acc, gyr, fs, mag=mag[:10])
