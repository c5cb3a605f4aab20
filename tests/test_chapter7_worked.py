"""Chapter 7's worked examples, row by row: the values printed in the captions of
Benhamou's Figs. 2 and 3 (as π/x) and the round-off agreement of the frame, heading and
rotation formulas on the chapter's random draws. The chapter shows one comparison per
result; these tests hold the full tables."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import tiltlab.quaternion as tq
import tiltlab.trig as T

PI = np.pi

#: divisors x of π/x printed in the caption of Benhamou's Fig. 2
FIG2 = {
    "arc size": "3.637",
    "initial inclination": "3.256",
    "final inclination": "19.023",
    "apex elevation": "2.978",
    "apex azimuth": "1.784",
}
#: divisors printed in the caption of Fig. 3 (α = π/3, β = π/6)
FIG3 = {"arc size": "2.80", "eta": "5.34"}


def _same_digits(value: float, printed: str) -> str:
    return f"{value:.{len(printed.split('.')[1])}f}"


def test_fig2_caption_values_with_phi_prev_pi_over_6():
    t0, p0, t1, p1 = PI / 6, PI / 6, PI / 2, PI / 3
    a = T.arc(t0, p0, t1, p1)
    apex_el, apex_az = T.great_circle_apex(t0, p0, a.initial)
    ours = dict(
        zip(FIG2, PI / np.array([a.size, a.initial, a.final, apex_el, apex_az]))
    )
    for name, printed in FIG2.items():
        assert _same_digits(ours[name], printed) == printed, name


def test_fig3_caption_values_and_eq10_round_trip():
    w, eta = T.sequential_arc_from_yaw_pitch(PI / 3, PI / 6)
    ours = dict(zip(FIG3, PI / np.array([w, eta])))
    for name, printed in FIG3.items():
        assert _same_digits(ours[name], printed) == printed, name
    yaw, pitch = T.sequential_yaw_pitch(w, eta)
    assert yaw == pytest.approx(PI / 3, abs=1e-12)
    assert pitch == pytest.approx(PI / 6, abs=1e-12)


@pytest.fixture
def angles():
    rng = np.random.default_rng(0)
    n = 2000
    th = rng.uniform(-PI, PI, n)
    ph = rng.uniform(-1.55, 1.55, n)
    la = rng.uniform(-PI, PI, n)
    return th, ph, la


def test_frame_bridge_rows_agree_to_round_off(angles):
    th, ph, la = angles
    q = T.angles_to_quaternion(th, ph, la)
    scipy_c = Rotation.from_euler("ZYX", np.column_stack([th, -ph, la])).as_matrix()
    back = T.angles_from_quaternion(q)
    rows = {
        "C vs scipy": np.abs(T.angles_to_matrix(th, ph, la) - scipy_c).max(),
        "R(q) vs C": np.abs(tq.to_matrix(q) - scipy_c).max(),
        "azimuth round trip": np.abs(T.wrap_angle(back.azimuth - th)).max(),
        "elevation round trip": np.abs(back.elevation - ph).max(),
        "bank round trip": np.abs(T.wrap_angle(back.bank - la)).max(),
        "gravity": np.abs(T.acc_from_angles(ph, la) - tq.gravity(q)).max(),
    }
    for name, value in rows.items():
        assert value < 1e-12, name


def test_heading_rows_agree_to_round_off(angles):
    th, ph, la = angles
    f = T.acc_from_angles(ph, la)
    m = T.mag_from_angles(th, ph, la, T.geomagnetic_field(48, 1.1, 0.05))
    h = T.heading(f, m, declination=0.05)
    assert np.abs(T.wrap_angle(h.azimuth - th)).max() < 1e-12
    assert np.abs(h.elevation - ph).max() < 1e-12
    assert np.abs(T.wrap_angle(h.bank - la)).max() < 1e-12
    vertical = T.heading(
        T.acc_from_angles(PI / 2, 0.7), T.mag_from_angles(0.3, PI / 2, 0.7)
    )
    assert (
        np.abs(
            T.angles_to_matrix(*vertical) - T.angles_to_matrix(0.3, PI / 2, 0.7)
        ).max()
        < 1e-12
    )


def test_eq12_eq13_rows_agree_to_round_off():
    rng = np.random.default_rng(1)
    n = 2000
    s0 = (
        rng.uniform(-PI, PI, n),
        rng.uniform(-1.4, 1.4, n),
        rng.uniform(-PI, PI, n),
    )
    di, w, rho = (
        rng.uniform(-PI, PI, n),
        rng.uniform(1e-3, 2.8, n),
        rng.uniform(-3, 3, n),
    )
    s1 = T.angles_from_matrix(T.exact_step(*s0, di, w, rho))
    rot = T.rotations_from_orientations(*s0, *s1)
    w12, _ = T.arc_from_rotations(*rot)
    dth = T.azimuth_change(s0[1], s0[2], s1.elevation, s1.bank, *rot)
    assert np.abs(w12 - w).max() < 1e-10
    assert np.abs(T.wrap_angle(dth - (s1.azimuth - s0[0]))).max() < 1e-10
