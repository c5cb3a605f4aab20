"""Quaternion kernels against scipy.spatial.transform.Rotation, and their invariants."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation

from tiltlab import quaternion as Q

TOL = 1e-12

finite = st.floats(-1.0, 1.0, allow_nan=False, allow_infinity=False)


@st.composite
def unit_quats(draw, n=st.integers(1, 20)):
    k = draw(n)
    raw = draw(arrays(np.float64, (k, 4), elements=finite))
    norms = np.linalg.norm(raw, axis=1)
    raw[norms < 1e-3] = [1.0, 0.0, 0.0, 0.0]
    return raw / np.linalg.norm(raw, axis=1, keepdims=True)


def special_quats():
    """Identity, exact and near 180° rotations, tiny rotations, both signs of w."""
    rv = [
        [0, 0, 0],
        [np.pi, 0, 0],
        [0, np.pi, 0],
        [0, 0, np.pi],
        [np.pi / np.sqrt(2), np.pi / np.sqrt(2), 0],
        [np.pi - 1e-9, 0, 0],
        [0, np.pi - 1e-7, 1e-7],
        [1e-12, 0, 0],
        [1e-9, -2e-9, 3e-9],
        [1e-5, 1e-5, -1e-5],
        [0.3, -0.2, 0.1],
    ]
    q = Rotation.from_rotvec(rv).as_quat(scalar_first=True)
    return np.vstack([q, -q])


def test_special_cases_against_scipy():
    q = special_quats()
    r = Rotation.from_quat(q, scalar_first=True)
    np.testing.assert_allclose(Q.to_matrix(q), r.as_matrix(), atol=TOL)
    # rotation vectors are unique only for angles < π; compare rotations instead at π
    back = Q.from_rotvec(Q.to_rotvec(q))
    assert np.all(Q.total_error(back, q) < 1e-9)
    np.testing.assert_allclose(Q.to_rotvec(q[:5:4]), r[:5:4].as_rotvec(), atol=TOL)
    np.testing.assert_allclose(Q.to_rotvec(q[7:11]), r[7:11].as_rotvec(), atol=TOL)
    m = r.as_matrix()
    np.testing.assert_allclose(
        np.abs(np.sum(Q.from_matrix(m) * q, axis=1)), 1.0, atol=TOL
    )


@given(unit_quats(), unit_quats())
@settings(max_examples=60, deadline=None)
def test_mul_matches_scipy_composition(p, q):
    n = min(len(p), len(q))
    p, q = p[:n], q[:n]
    ref = (
        Rotation.from_quat(p, scalar_first=True)
        * Rotation.from_quat(q, scalar_first=True)
    ).as_quat(scalar_first=True)
    np.testing.assert_allclose(Q.canonical(Q.mul(p, q)), Q.canonical(ref), atol=TOL)


@given(unit_quats(), arrays(np.float64, (3,), elements=st.floats(-100, 100)))
@settings(max_examples=60, deadline=None)
def test_rotate_matches_scipy_apply(q, v):
    r = Rotation.from_quat(q, scalar_first=True)
    scale = max(1.0, np.abs(v).max())
    np.testing.assert_allclose(Q.rotate(q, v), r.apply(v), atol=TOL * scale)
    np.testing.assert_allclose(
        Q.rotate_inverse(q, v), r.inv().apply(v), atol=TOL * scale
    )
    # round trip
    np.testing.assert_allclose(
        Q.rotate_inverse(q, Q.rotate(q, v)),
        np.broadcast_to(v, (len(q), 3)),
        atol=TOL * scale,
    )


@given(unit_quats())
@settings(max_examples=60, deadline=None)
def test_matrix_and_rotvec_round_trips(q):
    r = Rotation.from_quat(q, scalar_first=True)
    m = Q.to_matrix(q)
    np.testing.assert_allclose(m, r.as_matrix(), atol=TOL)
    # q and -q are the same rotation (and both are 'canonical' when w = 0): compare up to sign
    np.testing.assert_allclose(
        np.abs(np.sum(Q.from_matrix(m) * q, axis=1)), 1.0, atol=1e-12
    )
    rv = Q.to_rotvec(q)
    angle = np.linalg.norm(rv, axis=1)
    ok = angle < np.pi - 1e-6  # the axis sign is ambiguous at exactly π
    np.testing.assert_allclose(rv[ok], r[ok].as_rotvec(), atol=TOL)
    np.testing.assert_allclose(
        np.abs(np.sum(Q.from_rotvec(rv) * q, axis=1)), 1.0, atol=1e-12
    )
    np.testing.assert_allclose(
        np.abs(np.sum(Q.exp(Q.log(q)) * q, axis=1)), 1.0, atol=1e-12
    )


@given(unit_quats())
@settings(max_examples=60, deadline=None)
def test_gravity_is_world_up_in_sensor_frame(q):
    g = Q.gravity(q)
    np.testing.assert_allclose(
        g, Rotation.from_quat(q, scalar_first=True).inv().apply([0, 0, 1]), atol=TOL
    )
    np.testing.assert_allclose(np.linalg.norm(g, axis=1), 1.0, atol=TOL)


@given(unit_quats(), unit_quats())
@settings(max_examples=80, deadline=None)
def test_error_angles(p, q):
    n = min(len(p), len(q))
    p, q = p[:n], q[:n]
    # total error = angle of the relative rotation (scipy's magnitude)
    rel = (
        Rotation.from_quat(p, scalar_first=True)
        * Rotation.from_quat(q, scalar_first=True).inv()
    )
    np.testing.assert_allclose(Q.total_error(p, q), rel.magnitude(), atol=1e-9)
    # tilt error = angle between gravity directions in the sensor frame = BROAD's inclination error
    tilt = Q.tilt_error(p, q)
    np.testing.assert_allclose(
        tilt, Q.angle_between(Q.gravity(p), Q.gravity(q)), atol=1e-9
    )
    e = Q.error_quaternion(p, q)
    broad = 2 * np.arccos(np.clip(np.sqrt(e[:, 0] ** 2 + e[:, 3] ** 2), 0, 1))
    np.testing.assert_allclose(tilt, broad, atol=1e-6)  # arccos loses precision near 0
    head = Q.heading_error(p, q)
    assert np.all((head >= 0) & (head <= np.pi + 1e-12))
    # the decomposition: total rotation is made of a heading part and a tilt part
    assert np.all(Q.total_error(p, q) <= head + tilt + 1e-9)
    # heading error is invariant to composing both estimates with the same sensor-frame rotation,
    # except where it is undefined (inclination error near 180°: w and z of the error both ~0)
    s = Q.random_quaternions(1, 7)
    ok = np.hypot(e[:, 0], e[:, 3]) > 1e-4
    np.testing.assert_allclose(
        Q.heading_error(Q.mul(p, s), Q.mul(q, s))[ok], head[ok], atol=1e-8
    )


def test_heading_and_tilt_errors_of_pure_rotations():
    rng = np.random.default_rng(3)
    q = Q.random_quaternions(500, rng)
    yaw = rng.uniform(-np.pi, np.pi, 500)
    qz = Q.from_rotvec(np.column_stack([0 * yaw, 0 * yaw, yaw]))
    # a world-frame rotation about vertical changes heading only
    p = Q.mul(qz, q)
    np.testing.assert_allclose(Q.heading_error(p, q), np.abs(yaw), atol=1e-9)
    np.testing.assert_allclose(Q.tilt_error(p, q), 0.0, atol=1e-9)
    # a world-frame rotation about a horizontal axis changes inclination only
    ang = rng.uniform(0, np.pi, 500)
    az = rng.uniform(-np.pi, np.pi, 500)
    axis = np.column_stack([np.cos(az), np.sin(az), 0 * az])
    p = Q.mul(Q.from_rotvec(axis * ang[:, None]), q)
    np.testing.assert_allclose(Q.tilt_error(p, q), ang, atol=1e-9)
    np.testing.assert_allclose(Q.heading_error(p, q), 0.0, atol=1e-9)


def test_broadcasting_and_no_mutation():
    q = Q.random_quaternions(10, 1)
    q_copy = q.copy()
    v = np.array([1.0, 2.0, 3.0])
    out = Q.rotate(q, v)
    assert out.shape == (10, 3)
    assert Q.mul(q[0], q).shape == (10, 4)
    assert Q.rotate(q.reshape(2, 5, 4), v).shape == (2, 5, 3)
    np.testing.assert_array_equal(q, q_copy)
    with pytest.raises(ValueError, match="last dimension 4"):
        Q.mul(np.zeros(3), q)
    with pytest.raises(ValueError, match="zero quaternion"):
        Q.normalize(np.zeros(4))


def test_integrate_gyro_constant_rate_is_exact():
    fs, w = 200.0, np.array([0.3, -1.1, 2.0])
    n = 2001
    q = Q.integrate_gyro(np.tile(w, (n, 1)), fs)
    t = np.arange(n) / fs
    ref = Rotation.from_rotvec(np.outer(t, w)).as_quat(scalar_first=True)
    assert np.max(Q.total_error(q, ref)) < 1e-10
    np.testing.assert_allclose(Q.norm(q), 1.0, atol=1e-14)
    with pytest.raises(ValueError, match="fs"):
        Q.integrate_gyro(np.zeros((3, 3)), None)


@given(arrays(np.float64, (50, 3), elements=st.floats(-20, 20)), st.floats(10, 1000))
@settings(max_examples=30, deadline=None)
def test_integrate_gyro_matches_scipy_step_composition(omega, fs):
    q = Q.integrate_gyro(omega, fs)
    steps = Rotation.from_rotvec(omega[:-1] / fs)
    r = Rotation.identity()
    ref = [r]
    for s in steps:
        r = r * s
        ref.append(r)
    ref = np.array([x.as_quat(scalar_first=True) for x in ref])
    assert np.max(Q.total_error(q, ref)) < 1e-9


def test_scipy_conversion_is_explicit_about_order():
    q = np.array([np.cos(0.2), np.sin(0.2), 0.0, 0.0])
    r = Q.to_scipy(q)
    np.testing.assert_allclose(
        r.as_quat(), [np.sin(0.2), 0, 0, np.cos(0.2)]
    )  # scipy: scalar last
    np.testing.assert_allclose(Q.from_scipy(r), q)


def test_random_quaternions_are_uniform_enough():
    q = Q.random_quaternions(20000, 0)
    np.testing.assert_allclose(Q.norm(q), 1.0, atol=1e-14)
    g = Q.gravity(q)
    # uniform rotations put gravity uniformly on the sphere: each coordinate ~ U(-1, 1)
    assert np.all(np.abs(g.mean(axis=0)) < 0.03)
    np.testing.assert_allclose(np.mean(g**2, axis=0), 1 / 3, atol=0.02)
