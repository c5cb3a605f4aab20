"""Tests for tiltlab.trig (Benhamou 2023 trigonometry), checked against quaternion / scipy Rotation algebra."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation

import tiltlab.calibration as cal
import tiltlab.quaternion as tq
import tiltlab.trig as T
from tiltlab import behavior, schema
from tiltlab._validate import RecordingError
from tiltlab.simulate import simulate_heave, simulate_track

PI = np.pi
SET = settings(max_examples=40, deadline=None)

az_s = st.floats(-PI, PI)
el_s = st.floats(-PI / 2 + 1e-3, PI / 2 - 1e-3)
bank_s = st.floats(-PI, PI)
seed_s = st.integers(0, 2**32 - 1)


def wrapdiff(a, b):
    return np.abs(T.wrap_angle(np.asarray(a) - np.asarray(b)))


def random_angles(rng, n, el_margin=1e-3):
    return (
        rng.uniform(-PI, PI, n),
        rng.uniform(-PI / 2 + el_margin, PI / 2 - el_margin, n),
        rng.uniform(-PI, PI, n),
    )


# ---------------------------------------------------------------------------
# frames and notation
# ---------------------------------------------------------------------------


@SET
@given(st.floats(-10, 10))
def test_rotation_matrices_match_scipy(a):
    assert np.allclose(T.R1(a), Rotation.from_euler("x", a).as_matrix(), atol=1e-14)
    # Benhamou's R2 is clockwise about Y: the usual Ry(-a)
    assert np.allclose(T.R2(a), Rotation.from_euler("y", -a).as_matrix(), atol=1e-14)
    assert np.allclose(T.R3(a), Rotation.from_euler("z", a).as_matrix(), atol=1e-14)


@SET
@given(az_s, el_s)
def test_unit_vector_notation(xi, psi):
    v = T.unit_vector(xi, psi)
    assert np.allclose(v, T.R3(xi) @ T.R2(psi) @ np.array([1.0, 0, 0]), atol=1e-15)
    x2, p2 = T.spherical_coords(v)
    assert wrapdiff(x2, xi) < 1e-9 and abs(p2 - psi) < 1e-12


@SET
@given(seed_s)
def test_angles_quaternion_round_trip_and_scipy(seed):
    rng = np.random.default_rng(seed)
    th, ph, la = random_angles(rng, 64)
    q = T.angles_to_quaternion(th, ph, la)
    ref = Rotation.from_euler("ZYX", np.column_stack([th, -ph, la]))
    assert np.all(
        tq.angle_between(tq.to_matrix(q)[..., 0], ref.as_matrix()[..., 0]) < 1e-12
    )
    assert np.all(tq.total_error(q, tq.from_scipy(ref)) < 1e-7)
    assert np.allclose(tq.to_matrix(q), T.angles_to_matrix(th, ph, la), atol=1e-14)
    o = T.angles_from_quaternion(q)
    assert wrapdiff(o.azimuth, th).max() < 1e-10
    assert np.abs(o.elevation - ph).max() < 1e-10
    assert wrapdiff(o.bank, la).max() < 1e-10
    # and starting from random quaternions: q -> angles -> q
    qr = tq.random_quaternions(64, rng)
    o = T.angles_from_quaternion(qr)
    assert (
        np.abs(tq.canonical(T.angles_to_quaternion(*o)) - tq.canonical(qr)).max()
        < 1e-10
    )


@SET
@given(az_s, bank_s, st.sampled_from([-1.0, 1.0]))
def test_singular_elevation_fallback_represents_same_rotation(th, la, sg):
    C = T.angles_to_matrix(th, sg * PI / 2, la)
    o = T.angles_from_matrix(C)
    assert o.bank == 0.0 and abs(o.elevation - sg * PI / 2) < 1e-12
    assert np.allclose(T.angles_to_matrix(*o), C, atol=1e-12)
    # Benhamou's accelero-magnetic pseudo-azimuth gives the same rotation
    f, m = T.acc_from_angles(sg * PI / 2, la), T.mag_from_angles(th, sg * PI / 2, la)
    h = T.heading(f, m)
    assert np.all(np.isfinite(h))
    assert np.allclose(T.angles_to_matrix(*h), C, atol=1e-9)


@SET
@given(seed_s)
def test_acc_from_angles_is_quaternion_gravity_and_sign_conventions(seed):
    rng = np.random.default_rng(seed)
    th, ph, la = random_angles(rng, 32)
    q = T.angles_to_quaternion(th, ph, la)
    f = T.acc_from_angles(ph, la)
    assert np.allclose(
        f, tq.gravity(q), atol=1e-14
    )  # specific force = +g on the up axis
    A = T.acc_from_angles(ph, la, convention="benhamou")
    assert np.allclose(A, T.to_benhamou_acc(f)) and np.allclose(
        T.from_benhamou_acc(A), f
    )
    # a sensor lying flat reads +1 g on z (tiltlab) and -g in Benhamou's sign
    assert np.allclose(T.acc_from_angles(0.0, 0.0), [0, 0, 1])
    assert np.allclose(T.acc_from_angles(0.0, 0.0, 9.81, "benhamou"), [0, 0, -9.81])


def test_gyro_rate_mapping():
    w = np.array([[0.1, 0.2, 0.3]])
    r = T.gyro_to_body_rates(w)
    assert np.allclose(r, [[0.1, -0.2, 0.3]]) and np.allclose(
        T.body_rates_to_gyro(r), w
    )
    # positive Benhamou pitch speed raises the nose: integrating it increases elevation
    q = tq.integrate_gyro(
        np.tile(T.body_rates_to_gyro([0.0, 0.5, 0.0]), (100, 1)), 100.0
    )
    assert T.angles_from_quaternion(q[-1]).elevation > 0.4


def test_bad_inputs_raise():
    with pytest.raises(ValueError):
        T.posture(np.ones((5, 2)))
    with pytest.raises(ValueError):
        T.posture(np.ones(3), convention="ned")
    with pytest.raises(ValueError):
        T.dead_reckon(
            np.ones(4), np.zeros(4), np.zeros(4), np.zeros((2, 3)), np.array([0, 3])
        )
    with pytest.raises(ValueError):
        T.rotations_from_orientations(0, 0, 0, 1, 0, 0, method="other")


# ---------------------------------------------------------------------------
# device -> body
# ---------------------------------------------------------------------------


@SET
@given(seed_s, st.floats(-1.2, 1.2), st.floats(-2.5, 2.5), st.floats(-PI, PI))
def test_mounting_correction_recovers_body_vectors(seed, phi_s, lam_s, dth):
    rng = np.random.default_rng(seed)
    M = T.mounting_matrix(phi_s, lam_s, dth)  # device -> body
    # level rest (theta arbitrary): body reads +1 g on heave
    th_rest = rng.uniform(-PI, PI)
    f_rest_dev = M.T @ T.acc_from_angles(0.0, 0.0)
    p, l = T.mounting_angles(f_rest_dev)
    assert abs(p - phi_s) < 1e-10 and wrapdiff(l, lam_s) < 1e-10
    # azimuth mismatch from the rest magnetic vector and the compass bearing of the body
    m_rest_dev = M.T @ T.mag_from_angles(th_rest, 0.0, 0.0)
    d = T.mounting_azimuth_offset(f_rest_dev, m_rest_dev, PI / 2 - th_rest)
    assert wrapdiff(d, dth) < 1e-9
    # free-moving animal: device vectors -> body vectors
    th, ph, la = random_angles(rng, 16)
    B = np.column_stack(
        [T.acc_from_angles(ph, la), T.mag_from_angles(th, ph, la)]
    ).reshape(16, 2, 3)
    D = np.einsum("ji,...j->...i", M, B)
    assert np.allclose(T.device_to_body(D, p, l, d), B, atol=1e-9)
    # Eq. 1a-c (no azimuth mismatch) equals the matrix form
    M0 = T.mounting_matrix(phi_s, lam_s)
    D0 = np.einsum("ji,...j->...i", M0, B)
    assert np.allclose(
        T.device_to_body_eq1(D0, M0.T @ T.acc_from_angles(0.0, 0.0)), B, atol=1e-10
    )


@SET
@given(
    st.floats(-1.2, 1.2),
    st.floats(-2.5, 2.5),
    arrays(float, 3, elements=st.floats(-5, 5)),
)
def test_gyro_rates_device_to_body_sign_flip(phi_s, lam_s, w):
    direct = T.device_to_body(w, phi_s, lam_s)  # tiltlab omega is a plain vector
    via_rates = T.device_to_body(T.gyro_to_body_rates(w), phi_s, lam_s, rates=True)
    assert np.allclose(T.gyro_to_body_rates(direct), via_rates, atol=1e-12)


# ---------------------------------------------------------------------------
# posture
# ---------------------------------------------------------------------------


@SET
@given(seed_s, st.floats(0.1, 20.0))
def test_posture_eq2_eq3(seed, g):
    rng = np.random.default_rng(seed)
    th, ph, la = random_angles(rng, 64)
    f = T.acc_from_angles(ph, la, g)
    p = T.posture(f)
    assert np.abs(p.elevation - ph).max() < 1e-10 and wrapdiff(p.bank, la).max() < 1e-10
    assert np.allclose(np.cos(p.inclination), np.cos(ph) * np.cos(la), atol=1e-12)
    # zeta = angle between heave axis and world up
    heave = T.angles_to_matrix(th, ph, la)[..., :, 2]
    assert np.allclose(p.inclination, tq.angle_between(heave, [0, 0, 1]), atol=1e-10)
    z, c = T.inclination_from_angles(ph, la)
    assert (
        np.allclose(z, p.inclination, atol=1e-12)
        and wrapdiff(c, p.orientation).max() < 1e-9
    )
    ph2, la2 = T.angles_from_inclination(z, c)
    assert np.abs(ph2 - ph).max() < 1e-9 and wrapdiff(la2, la).max() < 1e-9
    pb = T.posture(T.to_benhamou_acc(f), convention="benhamou")
    assert np.allclose(np.array(pb), np.array(p))


@SET
@given(
    st.floats(0.5, 20), st.floats(1, 100), st.sampled_from([-1, 1]), st.floats(-3, 3)
)
def test_centripetal_and_tangential_corrections(v, r, turn, h):
    g = 9.81
    kappa = turn / r
    # "car": level body in a steady turn, specific force has a lateral component v^2 kappa
    f = np.array([0.0, v**2 * kappa, g])
    assert abs(T.correct_centripetal(T.posture(f).bank, v, kappa, g=g)) < 1e-12
    # sustained forward acceleration h tilts the reference plane by atan(h/g)
    f = np.array([h, 0.0, g])
    assert abs(T.correct_tangential(T.posture(f).elevation, h, g=g)) < 1e-12


@SET
@given(st.floats(-1.0, 1.0), st.floats(0.2, 1.3))
def test_posture_from_magnetic_loop(lam, inc):
    th = np.linspace(-PI, PI, 73)[:-1]
    M = T.mag_from_angles(th, 0.0, lam, T.geomagnetic_field(50.0, inc))
    z, p, l = T.posture_from_magnetic_loop(M, inc)
    assert abs(p) < 1e-10 and abs(l - lam) < 1e-10 and abs(z - abs(lam)) < 1e-10
    ep, eb = T.magnetic_posture(M)
    assert np.all(np.isfinite(ep)) and np.all(np.isfinite(eb))


# ---------------------------------------------------------------------------
# heading
# ---------------------------------------------------------------------------


@SET
@given(
    seed_s,
    st.floats(1.0, 100.0),
    st.floats(-1.4, 1.4),
    st.floats(-0.5, 0.5),
    st.floats(0.1, 20),
)
def test_eq5_eq3_recover_orientation(seed, B, inc, decl, g):
    rng = np.random.default_rng(seed)
    th, ph, la = random_angles(rng, 64)
    field = T.geomagnetic_field(B, inc, decl)
    f = T.acc_from_angles(ph, la, g)
    m = T.mag_from_angles(th, ph, la, field)
    h = T.heading(f, m, declination=decl)
    assert wrapdiff(h.azimuth, th).max() < 1e-10
    assert np.abs(h.elevation - ph).max() < 1e-10 and wrapdiff(h.bank, la).max() < 1e-10
    # Benhamou sign gives the same azimuth only with convention="benhamou"
    hb = T.azimuth(T.to_benhamou_acc(f), m, convention="benhamou", declination=decl)
    assert wrapdiff(hb, th).max() < 1e-10
    # the magnetic azimuth is the true azimuth + declination
    assert wrapdiff(T.apply_declination(T.azimuth(f, m), decl), th).max() < 1e-10


@SET
@given(seed_s, st.floats(-1.0, 1.0))
def test_collar_and_alternative_azimuth(seed, phi_s):
    rng = np.random.default_rng(seed)
    th, ph, _ = random_angles(rng, 16, el_margin=0.3)
    la = np.zeros(16)  # unbanked terrestrial animal
    collar_roll = rng.uniform(-PI, PI, 16)
    # collar device: surge aligned with body surge, rolled about it
    C_dev = T.angles_to_matrix(th, ph, la) @ T.R1(collar_roll)
    o = T.angles_from_matrix(C_dev)
    f, m = (
        T.acc_from_angles(o.elevation, o.bank),
        T.mag_from_angles(o.azimuth, o.elevation, o.bank),
    )
    assert wrapdiff(T.collar_azimuth(f, m), th).max() < 1e-9
    # device tilted by phi* in the sagittal plane: theta = theta_d - atan2(c2, c1)
    la = rng.uniform(-2, 2, 16)
    Cd = T.angles_to_matrix(th, ph, la) @ T.R2(phi_s)
    od = T.angles_from_matrix(Cd)
    assert (
        wrapdiff(T.body_azimuth_from_device(od.azimuth, ph, la, phi_s), th).max() < 1e-9
    )


@SET
@given(seed_s, st.sampled_from(["left", "right"]))
def test_four_point_calibration(seed, flank_on):
    rng = np.random.default_rng(seed)
    field = T.geomagnetic_field(48.0, 1.1)
    gain = rng.uniform(0.5, 2.0, 3) * rng.choice([-1, 1], 3)
    bias = rng.normal(0, 30, 3)

    def raw(th, ph, la):
        return T.mag_from_angles(th, ph, la, field) * gain + bias

    nesw = np.array([PI / 2, 0.0, -PI / 2, PI])  # surge towards N, E, S, W (ccw from E)
    bottom = raw(nesw, 0.0, 0.0)
    bank = (
        -PI / 2 if flank_on == "left" else PI / 2
    )  # left flank down: sway axis below horizon
    flank = raw(nesw, 0.0, bank)
    off, S = cal.four_point_mag_calibration(bottom, flank, flank_on=flank_on)
    assert np.allclose(off, bias)
    th, ph, la = random_angles(rng, 32)
    m = cal.apply_mag_calibration(raw(th, ph, la), off, S)
    assert np.allclose(
        m, T.mag_from_angles(th, ph, la, field) / (48.0 * np.cos(1.1)), atol=1e-9
    )
    assert wrapdiff(T.azimuth(T.acc_from_angles(ph, la), m), th).max() < 1e-9


# ---------------------------------------------------------------------------
# gyroscope rotations
# ---------------------------------------------------------------------------


@SET
@given(arrays(float, 3, elements=st.floats(-3, 3)), st.integers(1, 30))
def test_body_rotations_sum(w, k):
    fs = 100.0
    g = np.tile(w, (k * 4 + k - 1, 1))
    r = T.body_rotations(g, fs, window_s=k / fs, units="rad/s")
    assert r.yaw.shape == (4,)
    assert (
        np.allclose(r.yaw, w[2] * k / fs)
        and np.allclose(r.pitch, -w[1] * k / fs)
        and np.allclose(r.roll, w[0] * k / fs)
    )


# ---------------------------------------------------------------------------
# changes of heading (Eqs. 6-9)
# ---------------------------------------------------------------------------


@SET
@given(seed_s)
def test_arc_interpolation_apex(seed):
    rng = np.random.default_rng(seed)
    th0, ph0, _ = random_angles(rng, 32, el_margin=0.05)
    th1, ph1, _ = random_angles(rng, 32, el_margin=0.05)
    a = T.arc(th0, ph0, th1, ph1)
    x0, x1 = T.unit_vector(th0, ph0), T.unit_vector(th1, ph1)
    assert np.allclose(a.size, tq.angle_between(x0, x1), atol=1e-12)
    assert np.allclose(
        np.cos(a.size),
        np.sin(ph0) * np.sin(ph1) + np.cos(ph0) * np.cos(ph1) * np.cos(th1 - th0),
    )
    q = rng.random(32)
    tq_, pq = T.interpolate_heading(th0, ph0, a.initial, a.size, q)
    # slerp reference
    xq = (
        np.sin((1 - q) * a.size)[:, None] * x0 + np.sin(q * a.size)[:, None] * x1
    ) / np.sin(a.size)[:, None]
    assert np.allclose(T.unit_vector(tq_, pq), xq, atol=1e-9)
    # p = cos(phi) cos(delta) is constant along the arc
    dq = T.arc_inclination(th0, ph0, th1, ph1, q)
    assert np.allclose(
        np.cos(pq) * np.cos(dq), np.cos(ph0) * np.cos(a.initial), atol=1e-9
    )
    assert np.allclose(
        np.cos(ph1) * np.cos(a.final), np.cos(ph0) * np.cos(a.initial), atol=1e-9
    )
    # apex = highest point of the great circle (vector construction)
    n = np.cross(x0, x1)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    top = np.array([0, 0, 1.0]) - n[:, 2:3] * n
    top /= np.linalg.norm(top, axis=1, keepdims=True)
    ph_hat, th_hat = T.great_circle_apex(tq_, pq, dq)
    xt, pt = T.spherical_coords(top)
    assert np.allclose(ph_hat, pt, atol=1e-9)
    assert wrapdiff(th_hat, xt).max() < 1e-7


@SET
@given(seed_s)
def test_posture_change_eq9(seed):
    rng = np.random.default_rng(seed)
    _, ph0, la0 = random_angles(rng, 16)
    _, ph1, la1 = random_angles(rng, 16)
    w = T.posture_change(ph0, la0, ph1, la1)
    assert np.allclose(
        w,
        tq.angle_between(
            T.acc_from_angles(ph0, la0, 3.0), T.acc_from_angles(ph1, la1, 0.5)
        ),
        atol=1e-12,
    )


# ---------------------------------------------------------------------------
# rotations <-> changes of orientation (Eqs. 8, 10-13), against exact rotation algebra
# ---------------------------------------------------------------------------


def _random_steps(rng, n):
    th0, ph0, la0 = random_angles(rng, n, el_margin=0.1)
    di = rng.uniform(-PI, PI, n)
    w = rng.uniform(1e-3, 2.8, n)
    rho = rng.uniform(-3.0, 3.0, n)
    C1 = T.exact_step(th0, ph0, la0, di, w, rho)
    return th0, ph0, la0, di, w, rho, T.angles_from_matrix(C1)


@SET
@given(seed_s)
def test_eq11_is_gyro_integral_and_eq12_13_invert_it(seed):
    rng = np.random.default_rng(seed)
    th0, ph0, la0, di, w, rho, o1 = _random_steps(rng, 32)
    a = T.arc(th0, ph0, o1.azimuth, o1.elevation)
    assert np.allclose(a.size, w, atol=1e-10) and wrapdiff(a.initial, di).max() < 1e-9
    r = T.rotations_from_orientations(th0, ph0, la0, *o1)
    assert wrapdiff(r.roll, rho).max() < 1e-9
    # Eq. 11 = integral of the body rates of the exact step (fine midpoint quadrature)
    i = 0
    rates = T.step_body_rates(w[i], di[i] - la0[i], rho[i], 1.0, 20000).mean(axis=0)
    assert np.allclose(
        [rates[2], -rates[1], rates[0]], [r.yaw[i], r.pitch[i], r.roll[i]], atol=1e-7
    )
    # Eqs. 12-13 invert Eq. 11
    w12, eb = T.arc_from_rotations(*r)
    assert np.abs(w12 - a.size).max() < 1e-10
    assert wrapdiff(eb, a.initial - la0 - r.roll / 2).max() < 1e-10
    dth = T.azimuth_change(ph0, la0, o1.elevation, o1.bank, *r)
    assert wrapdiff(dth, o1.azimuth - th0).max() < 1e-10


@SET
@given(seed_s)
def test_gyro_integration_of_step_reaches_end_orientation(seed):
    rng = np.random.default_rng(seed)
    th0, ph0, la0, di, w, rho, o1 = _random_steps(rng, 1)
    n = 4000
    g = T.step_body_rates(w[0], di[0] - la0[0], rho[0], 1.0, n)
    q = tq.integrate_gyro(
        np.vstack([g, np.zeros((1, 3))]),
        float(n),
        T.angles_to_quaternion(th0[0], ph0[0], la0[0]),
    )
    # zero-order hold of a smoothly varying rate: error O(1/n^2)
    assert tq.total_error(q[-1], T.angles_to_quaternion(*(x[0] for x in o1))) < 1e-5


@SET
@given(seed_s)
def test_eq8_bank_and_eq6_heading_along_exact_step(seed):
    rng = np.random.default_rng(seed)
    th0, ph0, la0, di, w, rho, o1 = _random_steps(rng, 1)
    qs = np.linspace(0, 1, 9)
    oq = T.angles_from_matrix(
        T.exact_step(th0[0], ph0[0], la0[0], di[0], w[0] * qs, rho[0] * qs)
    )
    lb = T.interpolate_bank(
        th0[0], ph0[0], la0[0], o1.azimuth[0], o1.elevation[0], o1.bank[0], qs
    )
    ok = np.cos(oq.elevation) > 1e-3
    assert wrapdiff(lb, oq.bank)[ok].max() < 1e-8
    tq_, pq = T.interpolate_heading(th0[0], ph0[0], di[0], w[0], qs)
    assert np.allclose(
        T.unit_vector(tq_, pq), T.unit_vector(oq.azimuth, oq.elevation), atol=1e-10
    )


@SET
@given(seed_s)
def test_eq10_sequential_equals_heading_in_previous_body_frame(seed):
    rng = np.random.default_rng(seed)
    th0, ph0, la0 = random_angles(rng, 32, el_margin=0.05)
    th1, ph1, _ = random_angles(rng, 32, el_margin=0.05)
    a = T.arc(th0, ph0, th1, ph1)
    al, be = T.sequential_yaw_pitch(a.size, a.initial - la0)
    al2, be2 = T.heading_in_body_frame(th0, ph0, la0, th1, ph1)
    assert wrapdiff(al, al2).max() < 1e-9 and np.abs(be - be2).max() < 1e-9
    w, eta = T.sequential_arc_from_yaw_pitch(al, be)
    assert (
        np.allclose(w, a.size, atol=1e-9)
        and wrapdiff(eta, a.initial - la0)[a.size > 1e-6].max() < 1e-8
    )


@SET
@given(st.floats(1e-3, 1.0), st.floats(-PI, PI))
def test_sequential_agrees_with_simultaneous_only_for_small_steps(w, eta):
    al_s, be_s = T.sequential_yaw_pitch(w, eta)
    r = T.simultaneous_rotations(
        w, eta, eta
    )  # no roll: alpha = w cos(eta), beta = w sin(eta)
    assert np.isclose(r.yaw, w * np.cos(eta)) and np.isclose(r.pitch, w * np.sin(eta))
    # third-order agreement: |difference| <= c w^3 with c ~ 0.21 on (0, 1] rad (grid-measured sup)
    assert abs(al_s - r.yaw) + abs(be_s - r.pitch) <= 0.25 * w**3 + 1e-12


def test_sequential_cannot_balance_yaw_and_pitch():
    w = np.radians(60.0)
    al_s, be_s = T.sequential_yaw_pitch(w, PI / 4)
    r = T.simultaneous_rotations(w, PI / 4, PI / 4)
    assert np.isclose(abs(r.yaw), abs(r.pitch)) and abs(abs(al_s) - abs(be_s)) > 0.05


def test_sub_arcs_converge_to_exact_step():
    rng = np.random.default_rng(7)
    th0, ph0, la0, di, w, rho, o1 = _random_steps(rng, 1)
    C1 = T.exact_step(th0[0], ph0[0], la0[0], di[0], w[0], rho[0])
    errs = []
    for k in (8, 32, 128):
        Ck = T.compose_sub_arcs(th0[0], ph0[0], la0[0], w[0], di[0] - la0[0], rho[0], k)
        errs.append(tq.total_error(tq.from_matrix(Ck), tq.from_matrix(C1)))
        al, be = T.sub_arc_rotations(w[0], di[0] - la0[0], rho[0], k)
    assert errs[0] > errs[1] > errs[2]
    r = T.simultaneous_rotations(w[0], di[0] - la0[0], di[0] - la0[0] - rho[0])
    assert abs(al.sum() - r.yaw) < 0.05 and abs(be.sum() - r.pitch) < 0.05


def test_singular_rotation_inputs_are_finite():
    # no roll, no turn, vertical headings
    assert np.all(np.isfinite(T.arc_from_rotations(0.0, 0.0, 0.0)))
    assert np.all(np.isfinite(T.simultaneous_rotations(0.0, 0.3, 0.3)))
    assert np.all(np.isfinite(T.arc(0.0, PI / 2, 1.0, 0.2)))
    assert np.all(np.isfinite(T.azimuth_change(0.2, 0.1, 0.2, 0.1, 0.0, 0.0, 0.0)))
    assert np.all(np.isfinite(T.great_circle_apex(0.3, 0.0, 0.0)))
    assert np.all(np.isfinite(T.posture(np.array([1.0, 0, 0]))))


# ---------------------------------------------------------------------------
# head relative to body, cap passage
# ---------------------------------------------------------------------------


@SET
@given(seed_s)
def test_head_relative_to_body_matches_quaternion_composition(seed):
    rng = np.random.default_rng(seed)
    b = random_angles(rng, 32)
    h = random_angles(rng, 32)
    o = T.head_relative_to_body(*b, *h)
    qb, qh = T.angles_to_quaternion(*b), T.angles_to_quaternion(*h)
    qrel = tq.mul(tq.conj(qb), qh)
    assert np.all(tq.total_error(T.angles_to_quaternion(*o), qrel) < 1e-6)
    ref = T.angles_from_quaternion(qrel)
    assert (
        wrapdiff(o.azimuth, ref.azimuth).max() < 1e-9
        and wrapdiff(o.bank, ref.bank).max() < 1e-9
    )


@SET
@given(seed_s, st.floats(0.05, 1.2))
def test_cap_passage(seed, radius):
    rng = np.random.default_rng(seed)
    mu = (rng.uniform(-PI, PI), rng.uniform(-1.2, 1.2))
    # I inside, O outside
    i_d, o_d = rng.uniform(0, 0.9) * radius, rng.uniform(1.1, 1.5) * radius
    xi, pi_ = T.interpolate_heading(*mu, rng.uniform(-PI, PI), i_d, 1.0)
    xo, po = T.interpolate_heading(*mu, rng.uniform(-PI, PI), o_d, 1.0)
    w_ip, frac, xp, pp = T.cap_passage(xi, pi_, xo, po, *mu, radius)
    assert 0 <= frac <= 1
    P = T.unit_vector(xp, pp)
    assert np.isclose(tq.angle_between(P, T.unit_vector(*mu)), radius, atol=1e-9)
    assert np.isclose(tq.angle_between(P, T.unit_vector(xi, pi_)), w_ip, atol=1e-9)


# ---------------------------------------------------------------------------
# dead reckoning
# ---------------------------------------------------------------------------


@SET
@given(seed_s, st.integers(5, 60))
def test_dead_reckoning_exact_data_and_anchors(seed, every):
    rng = np.random.default_rng(seed)
    tr = simulate_track(240, 1.0, rng=rng)
    idx = np.unique(np.r_[np.arange(0, 240, every), 240])
    anchors = tr.positions[idx] + [1000.0, -2000.0, 50.0]
    # perfect headings, speed known only up to a factor: reconstruction is exact
    pos = T.dead_reckon(3.7 * tr.speed, tr.azimuth, tr.elevation, anchors, idx)
    assert np.abs(pos - tr.positions - [1000.0, -2000.0, 50.0]).max() < 1e-8
    # noisy headings and biased speed/declination: still ends exactly on every anchor
    az = tr.azimuth + 0.3 + rng.normal(0, 0.2, 240)
    el = tr.elevation + rng.normal(0, 0.1, 240)
    pos = T.dead_reckon(tr.speed * rng.uniform(0.5, 1.5, 240), az, el, anchors, idx)
    assert np.abs(pos[idx] - anchors).max() < 1e-9
    # 2-D collar version = 3-D with zero elevation
    p2 = T.dead_reckon_2d(tr.speed, az, anchors[:, :2], idx)
    p3 = T.dead_reckon(
        tr.speed,
        az,
        np.zeros(240),
        np.column_stack([anchors[:, :2], np.zeros(len(idx))]),
        idx,
    )
    assert (
        np.abs(p2 - p3[:, :2]).max() < 1e-8
        and np.abs(p2[idx] - anchors[:, :2]).max() < 1e-9
    )


@SET
@given(seed_s)
def test_dead_reckoning_current_correction(seed):
    rng = np.random.default_rng(seed)
    tr = simulate_track(200, 1.0, rng=rng)
    idx = np.arange(0, 201, 50)
    cur = rng.normal(0, 0.3, (len(idx) - 1, 2))
    drift = np.vstack([np.zeros((1, 2)), np.cumsum(np.repeat(cur, 50, axis=0), axis=0)])
    ground = tr.positions + np.column_stack([drift, np.zeros(201)])
    pos = T.dead_reckon(
        tr.speed, tr.azimuth, tr.elevation, ground[idx], idx, dt_s=1.0, current=cur
    )
    assert (
        np.abs(pos - ground).max() < 1e-8
    )  # exact swimming data + known current -> exact path
    water = T.dead_reckon(
        tr.speed,
        tr.azimuth,
        tr.elevation,
        ground[idx],
        idx,
        dt_s=1.0,
        current=cur,
        return_water=True,
    )
    assert np.abs(water[50] - (ground[50] - [*(50 * cur[0]), 0])).max() < 1e-8


def test_dead_reckoning_null_proxy_fallback():
    pos = T.dead_reckon(
        np.zeros(10),
        np.zeros(10),
        np.zeros(10),
        np.array([[0.0, 0, 0], [10.0, 5, 1]]),
        np.array([0, 10]),
    )
    assert (
        np.all(np.isfinite(pos))
        and np.allclose(pos[-1], [10, 5, 1])
        and np.allclose(pos[5], [5, 2.5, 0.5])
    )


@SET
@given(
    st.floats(-PI, PI),
    st.floats(-1.4, 1.4),
    st.floats(-1e-3, 1e-3),
    st.floats(-1e-3, 1e-3),
)
def test_lonlat_local_round_trip(lon0, lat0, dlon, dlat):
    X, Y = T.lonlat_to_local(lon0, lat0, lon0 + dlon, lat0 + dlat)
    lon, lat = T.local_to_lonlat(X, Y, lon0, lat0, lat0 + dlat)
    assert wrapdiff(lon, lon0 + dlon) < 1e-12 and abs(lat - lat0 - dlat) < 1e-14
    assert np.isclose(Y, T.EARTH_RADIUS * dlat)


# ---------------------------------------------------------------------------
# oscillations
# ---------------------------------------------------------------------------


@SET
@given(st.floats(0.1, 0.3), st.floats(0, 2 * PI))
def test_crossings_of_a_sinusoid(period, phase):
    fs = 200.0
    t = np.arange(int(4 * fs)) / fs
    x = 1.0 + 0.5 * np.sin(2 * PI * t / period + phase)
    c = T.crossing_times(x, fs, level=1.0)
    d = np.diff(c)
    assert np.allclose(d, period / 2, atol=2e-3)
    s = T.oscillation_stats(x, fs, level=1.0, window_s=1.0)
    assert np.allclose(s.period, period, atol=4e-3) and np.all(s.cv < 0.05)


@settings(max_examples=10, deadline=None)
@given(seed_s)
def test_flapping_vs_gliding_cv(seed):
    x = simulate_heave(20.0, 100.0, rng=seed)  # labelled: fs = 100 Hz travels in attrs
    s = T.oscillation_stats(x, level=1.0, window_s=2.0)
    flap, glide = s.cv[s.time < 10], s.cv[s.time > 10]
    assert np.nanmax(flap) < 0.5 < np.nanmin(glide)
    assert np.allclose(s.period[s.time < 10], 0.18, atol=0.01)


def test_anchored_errors_shrink_to_zero_with_every_step_anchored():
    tr = simulate_track(300, 1.0, rng=2)
    rng = np.random.default_rng(2)
    az = tr.azimuth + rng.normal(0, 0.2, 300)
    mean, mx = T.anchored_errors(tr.positions, tr.speed, az, tr.elevation, [1, 50, 300])
    assert mx[0] < 1e-9 and mean[1] > 0 and mx.shape == (3,)


# ---------------------------------------------------------------------------
# real data (optical ground truth)
# ---------------------------------------------------------------------------


@pytest.mark.realdata
def test_broad_posture_and_heading_against_optical_truth(data_mirror):
    import tiltlab.datasets as datasets

    ds = datasets.load_broad_trial(1)
    q = ds.q_ref.values
    ok = np.all(np.isfinite(q), axis=1) & ~ds.movement.values
    ref = T.angles_from_quaternion(q[ok])
    h = T.heading(
        behavior.static_acceleration(ds.acc.values, ds.fs, window_s=0.5)[ok],
        behavior.static_acceleration(ds.mag.values, ds.fs, window_s=0.5)[ok],
    )
    d_az = T.wrap_angle(h.azimuth - ref.azimuth)
    offset = np.angle(np.mean(np.exp(1j * d_az)))  # optical frame vs magnetic North
    assert abs(np.degrees(offset)) < 5.0
    # at rest, accelero-magnetic orientation agrees with the optical one to well under a degree
    assert np.median(np.abs(np.degrees(h.elevation - ref.elevation))) < 0.5
    assert np.median(np.abs(np.degrees(T.wrap_angle(h.bank - ref.bank)))) < 0.5
    assert np.median(np.abs(np.degrees(T.wrap_angle(d_az - offset)))) < 1.0


# ---------------------------------------------------------------------------
# metadata travels: Recordings and labelled DataArrays in, labelled out
# ---------------------------------------------------------------------------


def _trig_recording(n=400, fs=50.0, gyr_units="deg/s", seed=0):
    rng = np.random.default_rng(seed)
    th, ph, la = random_angles(rng, n, el_margin=0.2)
    acc = T.acc_from_angles(ph, la)
    mag = T.mag_from_angles(th, ph, la)
    gyr = rng.normal(0, 50.0, (n, 3))
    if gyr_units == "rad/s":
        gyr = np.radians(gyr)
    rec = schema.make_recording(
        acc,
        gyr,
        fs,
        gyr_units=gyr_units,
        mag=mag,
        check_units=False,
        acc_units="g",
        mag_units="uT",
    )
    return rec, (th, ph, la)


def test_posture_and_heading_read_a_recording():
    rec, (th, ph, la) = _trig_recording()
    p = T.posture(rec)
    assert p.elevation.dims == ("time",) and p.elevation.attrs["fs"] == 50.0
    assert p.elevation.attrs["units"] == "rad"
    np.testing.assert_array_equal(
        p.elevation.values, T.posture(rec["acc"].values).elevation
    )
    np.testing.assert_array_equal(p.bank.time.values, rec.time.values)
    h = T.heading(rec)  # acc and mag both read from the Recording
    assert (
        wrapdiff(h.azimuth.values, th).max() < 1e-10 and h.azimuth.attrs["fs"] == 50.0
    )
    np.testing.assert_array_equal(
        h.azimuth.values, T.azimuth(rec["acc"], rec["mag"]).values
    )
    np.testing.assert_array_equal(
        T.azimuth(rec).values, T.azimuth(rec["acc"].values, rec["mag"].values)
    )
    ep, _ = T.magnetic_posture(rec)
    assert ep.dims == ("time",)
    # plain in, plain out
    assert isinstance(T.posture(rec["acc"].values).elevation, np.ndarray)
    with pytest.raises(ValueError, match="mag"):
        T.heading(rec["acc"].values)


def test_body_rotations_read_units_and_fs_from_attrs():
    rec_deg, _ = _trig_recording(gyr_units="deg/s")
    rec_rad, _ = _trig_recording(gyr_units="rad/s")
    a = T.body_rotations(rec_deg, window_s=0.2)
    b = T.body_rotations(
        rec_rad["gyr"].assign_attrs(fs=50.0), window_s=0.2
    )  # a labelled DataArray
    c = T.body_rotations(
        np.radians(rec_deg["gyr"].values), 50.0, window_s=0.2, units="rad/s"
    )
    for x, y, z in zip(a, b, c, strict=True):
        np.testing.assert_allclose(x.values, y.values, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(x.values, z, rtol=1e-12, atol=1e-15)
    assert a.yaw.attrs["fs"] == pytest.approx(5.0) and a.yaw.attrs["units"] == "rad"
    assert a.yaw.time.values[0] == pytest.approx(0.1)  # centre of the first 0.2 s step
    # a plain gyroscope needs its units, and fs
    with pytest.raises(RecordingError, match="units"):
        T.body_rotations(rec_deg["gyr"].values, 50.0, window_s=0.2)
    with pytest.raises(RecordingError, match="fs"):
        T.body_rotations(rec_deg["gyr"].values, window_s=0.2, units="deg/s")
    # a labelled input without fs, or contradicting it
    no_fs = rec_deg.copy()
    no_fs.attrs = {k: v for k, v in rec_deg.attrs.items() if k != "fs"}
    with pytest.raises(RecordingError, match="fs"):
        T.body_rotations(no_fs, window_s=0.2)
    with pytest.raises(RecordingError, match="fs"):
        T.body_rotations(rec_deg, 100.0, window_s=0.2)
    with pytest.raises(ValueError, match="window_s"):
        T.body_rotations(rec_deg, window_s=-1.0)


def test_oscillations_accept_labelled_signals():
    x = simulate_heave(20.0, 100.0, rng=1)
    assert x.attrs["fs"] == 100.0 and x.attrs["units"] == "g"
    s = T.oscillation_stats(x, level=1.0, window_s=2.0)
    p = T.oscillation_stats(x.values, 100.0, level=1.0, window_s=2.0)
    np.testing.assert_array_equal(s.cv.values, p.cv)
    np.testing.assert_array_equal(s.time, p.time)
    assert s.period.attrs == {"fs": 0.5, "units": "s"}
    shifted = x.assign_coords(time=x.time + 100.0)
    np.testing.assert_allclose(
        T.crossing_times(shifted, level=1.0),
        T.crossing_times(x.values, 100.0, level=1.0) + 100.0,
    )
    with pytest.raises(RecordingError, match="fs"):
        T.crossing_times(x.values, level=1.0)
    with pytest.raises(ValueError, match="level"):
        T.crossing_times(x, level=np.nan)
    with pytest.raises(ValueError, match="smooth_s"):
        T.oscillation_stats(x, level=1.0, window_s=2.0, smooth_s=0.0)


def test_numeric_parameters_are_checked():
    with pytest.raises(ValueError, match="singular_tol"):
        T.azimuth(np.ones(3), np.ones(3), singular_tol=-1.0)
    with pytest.raises(ValueError, match="g must"):
        T.correct_tangential(0.1, 0.2, g=0.0)
    with pytest.raises(ValueError, match="k must"):
        T.sub_arc_rotations(1.0, 0.2, 0.3, 0)
    with pytest.raises(ValueError, match="duration_s"):
        T.step_body_rates(1.0, 0.2, 0.3, 0.0, 10)
    with pytest.raises(ValueError, match="dt_s"):
        T.dead_reckon(
            np.ones(4),
            np.zeros(4),
            np.zeros(4),
            np.zeros((2, 3)),
            np.array([0, 4]),
            current=np.zeros((1, 2)),
        )
    with pytest.raises(ValueError, match="radius"):
        T.lonlat_to_local(0.0, 0.0, 0.1, 0.1, radius=-1.0)
    with pytest.raises(ValueError, match="dt_s"):
        simulate_track(10, 0.0)
