"""LaCanna's combined drift correction, running slope, hold changes, 1-rad test."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tiltlab import calibration, simulate
from tiltlab.simulate.turntable import back_and_forth

FS = 25.0


def _static(rate, n=3000, noise=0.0, seed=0):
    g = np.tile(np.asarray(rate, float), (n, 1))
    return g + np.random.default_rng(seed).normal(0, noise, g.shape)


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.floats(-2, 2), min_size=3, max_size=3),
    st.lists(st.floats(-0.5, 0.5), min_size=3, max_size=3),
)
def test_combined_removes_a_linear_drift_exactly_after_the_window(rate, prior_err):
    g = _static(rate)
    prior = np.add(rate, prior_err)
    c = calibration.correct_drift(g, FS, method="combined", prior_deg_s=prior)
    k0 = int(30 * FS)
    np.testing.assert_allclose(c.angle[k0:], 0.0, atol=1e-8)
    np.testing.assert_allclose(c.slope, rate, atol=1e-10)
    # before the window only the prior acts: its error integrates
    t = np.arange(k0) / FS
    np.testing.assert_allclose(c.angle[:k0], -t[:, None] * prior_err, atol=1e-8)


def test_combined_with_the_true_prior_is_exact_everywhere():
    g = _static([0.29, -0.94, 0.83])
    c = calibration.correct_drift(
        g, FS, method="combined", prior_deg_s=[0.29, -0.94, 0.83]
    )
    np.testing.assert_allclose(c.angle, 0.0, atol=1e-9)


def test_combined_ends_where_the_linear_fit_ends():
    g = _static([0.3, -0.9, 0.8], noise=0.05, seed=3)
    c = calibration.correct_drift(g, FS, method="combined", prior_deg_s=[0, 0, 0.5])
    lf = calibration.correct_drift(g, FS, method="linear_fit")
    np.testing.assert_allclose(c.angle[-1], lf.angle[-1], atol=1e-8)
    np.testing.assert_allclose(c.slope, lf.slope, atol=1e-10)


def test_combined_is_causal_and_does_not_mutate():
    g = _static([0.3, -0.9, 0.8], noise=0.05, seed=4)
    g0 = g.copy()
    full = calibration.correct_drift(g, FS, method="combined", prior_deg_s=[0.3, -1, 1])
    half = calibration.correct_drift(
        g[:1500], FS, method="combined", prior_deg_s=[0.3, -1, 1]
    )
    np.testing.assert_allclose(full.angle[:1500], half.angle, atol=1e-9)
    np.testing.assert_array_equal(g, g0)


def test_running_slope_matches_drift_slope_on_every_prefix():
    rng = np.random.default_rng(1)
    th = np.cumsum(rng.normal(0.2, 1.0, (400, 3)), axis=0) / FS
    r = calibration.running_slope(th, FS)
    assert np.all(np.isnan(r[0]))
    for k in (1, 57, 399):
        np.testing.assert_allclose(
            r[k], calibration.drift_slope(th[: k + 1], FS), rtol=1e-7, atol=1e-10
        )


def test_combined_bad_inputs_name_the_problem():
    g = _static([0.1, 0.1, 0.1], n=100)
    with pytest.raises(ValueError, match="prior_deg_s"):
        calibration.correct_drift(g, FS, method="combined")
    with pytest.raises(calibration.CalibrationError, match="window_s"):
        calibration.correct_drift(g, FS, method="combined", prior_deg_s=[0, 0, 0])


def test_hold_changes_bad_inputs():
    th = np.zeros((100, 3))
    with pytest.raises(ValueError, match="holds"):
        calibration.hold_changes(th, FS, holds=[[0, 10]])
    with pytest.raises(ValueError, match="holds"):
        calibration.hold_changes(th, FS, holds=[[0, 10], [5, 20]])
    with pytest.raises(ValueError, match="holds"):
        calibration.hold_changes(th, FS, holds=[[0, 10], [20, 200]])


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_ideal_one_radian_test_reads_one_radian(axis):
    m = back_and_forth(axis, FS, n_rotations=3)
    th = calibration.integrate_rate(m.gyr, FS)
    ch = calibration.hold_changes(th, FS, holds=m.holds)
    i = "xyz".index(axis)
    np.testing.assert_allclose(ch[:, i], np.degrees([1, -1] * 3), atol=1e-3)
    np.testing.assert_allclose(np.delete(ch, i, axis=1), 0.0, atol=1e-12)
    # the accelerometer reads gravity in the rotated frame (unit norm)
    np.testing.assert_allclose(np.linalg.norm(m.acc, axis=1), 1.0, atol=1e-12)


def test_scale_error_shortens_the_change_proportionally():
    m = back_and_forth("x", FS, n_rotations=2)
    s = simulate.SensorModel.ideal()
    s = simulate.SensorModel(**{**s.to_dict(), "gyr_scale": (-0.02, 0.0, 0.0)})
    out = simulate.apply_sensor_model(
        {"acc": m.acc, "gyr": m.gyr}, s, np.random.default_rng(0), FS
    )
    th = calibration.integrate_rate(out["gyr"], FS)
    ch = calibration.hold_changes(th, FS, holds=m.holds)
    np.testing.assert_allclose(ch[0::2, 0], 0.98 * np.degrees(1), atol=1e-3)


def test_back_and_forth_bad_inputs():
    with pytest.raises(ValueError, match="axis"):
        back_and_forth("w", FS)
    with pytest.raises(ValueError, match="amplitude_rad"):
        back_and_forth("x", FS, amplitude_rad=0.0)
    with pytest.raises(ValueError, match="peak_rate_deg_s"):
        back_and_forth("x", FS, peak_rate_deg_s=-1.0)


def test_drift_error_table_reads_the_angles():
    t = np.arange(250)[:, None] / FS
    angles = {"ramp": t * [1.0, -2.0, 0.0], "zero": np.zeros((250, 3))}
    tab = calibration.drift_error_table(angles, FS, at_s=(4.0,))
    np.testing.assert_allclose(tab.loc["ramp", "at 4 s"], 8.0)
    np.testing.assert_allclose(tab.loc["ramp", "at end"], 2 * 249 / FS)
    np.testing.assert_allclose(tab.loc["ramp", "rms"], np.sqrt(np.mean(5 * t**2 / 3)))
    assert (tab.loc["zero"] == 0).all()
    assert tab.attrs["units"]["max"] == "deg"
    with pytest.raises(ValueError, match="at_s"):
        calibration.drift_error_table(angles, FS, at_s=(100.0,))
    with pytest.raises(ValueError, match="same length"):
        calibration.drift_error_table(
            {"a": np.zeros((5, 3)), "b": np.zeros((6, 3))}, FS
        )


def test_radian_test_ideal_and_slow_clock():
    from tiltlab.simulate.turntable import radian_test

    rng = np.random.default_rng(0)
    ideal = simulate.SensorModel.ideal()
    tab = radian_test(ideal, rng, FS, n_rotations=2, lead_s=5.0)
    assert tab.shape == (2, 3) and tab.attrs["units"]["x_deg"] == "deg"
    np.testing.assert_allclose(tab.abs(), np.degrees(1.0), atol=1e-3)
    slow = radian_test(ideal, rng, 24.5, fs_assumed=FS, n_rotations=2, lead_s=5.0)
    np.testing.assert_allclose(slow.abs(), 0.98 * np.degrees(1.0), atol=1e-3)
    with pytest.raises(ValueError, match="drift"):
        radian_test(ideal, rng, FS, drift="magic")
