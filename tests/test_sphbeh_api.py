"""Renamed names and settings records of tiltlab.sphere and tiltlab.behavior."""

import numpy as np
import pytest

from tiltlab import behavior as B
from tiltlab import schema
from tiltlab import sphere as S


def test_slerp_is_a_warning_alias_of_slerp_vectors():
    a, b = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]
    t = np.linspace(0.0, 1.0, 7)
    new = S.slerp_vectors(a, b, t)
    with pytest.warns(FutureWarning, match="slerp was renamed slerp_vectors"):
        old = S.slerp(a, b, t)
    np.testing.assert_array_equal(old, new)
    assert S.slerp.__deprecated_alias_of__ is S.slerp_vectors
    np.testing.assert_allclose(new[3], [np.sqrt(0.5), np.sqrt(0.5), 0.0], atol=1e-15)


def _path():
    t = np.linspace(0.0, 2.0, 60)
    return np.column_stack([np.cos(t), np.sin(t), 0.3 * np.ones_like(t)])


def test_mkde_takes_the_kde_settings_as_keywords():
    path = _path()
    grid = S.equal_area_grid(4.0)
    a = S.mkde(path, fs=10.0, h=0.1, grid=grid, kernel="gauss", tol=1e-6)
    b = S.mkde(
        path, fs=10.0, h=0.1, grid=grid, kernel="gauss", tol=1e-6, quadrature="mass"
    )
    np.testing.assert_array_equal(a.density, b.density)
    assert a.grid is grid
    point = S.mkde(path, fs=10.0, h=0.1, grid=grid, quadrature="point")
    assert not np.array_equal(point.density, a.density)
    with pytest.raises(TypeError, match="unexpected keyword argument 'kernal'"):
        S.mkde(path, fs=10.0, h=0.1, kernal="vmf")
    with pytest.raises(ValueError, match="kernel must be"):
        S.mkde(path, fs=10.0, h=0.1, cell_deg=10.0, kernel="box")
    with pytest.raises(ValueError, match="cell_deg"):
        S.mkde(path, fs=10.0, h=0.1, cell_deg=0.0)


def test_kde_mass_quadrature_integrates_to_one_for_narrow_and_wide_kernels():
    x = S.vmf_sample([0.2, -0.1, 1.0], 30.0, 300, rng=3)
    for h in (1e-4, 0.05, 3.0):
        est = S.kde(x, h=h, cell_deg=6.0)
        assert est.integral() == pytest.approx(1.0, abs=1e-12)
    gauss = S.kde(x, h=0.5, cell_deg=6.0, kernel="gauss")
    assert gauss.integral() == pytest.approx(-np.expm1(-2.0 / 0.25), abs=1e-12)


def _rec(n=1500, fs=100.0):
    rng = np.random.default_rng(4)
    gyr = rng.normal(0.0, 1.0, (n, 3)) + [2.0, -1.0, 0.5]
    gyr[500:1000] += 80.0 * np.sin(np.arange(500) / 8.0)[:, None]
    acc = np.tile([0.0, 0.0, 1.0], (n, 1)) + rng.normal(0.0, 0.004, (n, 3))
    acc[500:1000] += 0.3 * np.sin(np.arange(500) / 5.0)[:, None]
    return schema.make_recording(acc, gyr, fs=fs, acc_units="g", gyr_units="deg/s")


def test_recording_speed_old_keywords_warn_and_match():
    rec = _rec()
    new = B.recording_speed(rec, gyr_offset=[2.0, -1.0, 0.5])
    with pytest.warns(FutureWarning, match="'offset' was renamed 'gyr_offset'"):
        old = B.recording_speed(rec, offset=[2.0, -1.0, 0.5])
    np.testing.assert_array_equal(old.values, new.values)
    with pytest.warns(FutureWarning, match="'gyr' was renamed 'data'"):
        by_gyr = B.recording_speed(gyr=rec, gyr_offset=[2.0, -1.0, 0.5])
    np.testing.assert_array_equal(by_gyr.values, new.values)
    assert new.attrs["gyr_offset_deg_s"] == [2.0, -1.0, 0.5]
    with pytest.raises(TypeError, match="pass 'gyr_offset' only"):
        B.recording_speed(rec, offset=None, gyr_offset=None)


def test_immobility_accelerometer_settings_pass_through_and_unknown_refused():
    rec = _rec()
    a = B.immobility(rec, rule="accelerometer", threshold_g=0.05, window_s=1.0)
    b = B.acc_immobility(rec, threshold_g=0.05, window_s=1.0)
    assert a.identical(b)
    assert a.attrs["threshold_g"] == 0.05 and a.attrs["window_s"] == 1.0
    assert a.attrs["rule"] == "accelerometer" and a.attrs["threshold_units"] == "g"
    with pytest.raises(TypeError, match="unexpected keyword argument 'threshold'"):
        B.immobility(rec, threshold=3.0)


def test_immobility_gyroscope_rule_attrs_and_mask():
    rec = _rec()
    m = B.immobility(rec, gyr_offset=[2.0, -1.0, 0.5], merge_gap_s=0.2)
    assert m.attrs["rule"] == "gyroscope"
    assert m.attrs["threshold_units"] == "deg/s"
    assert m.attrs["merge_gap_s"] == 0.2 and m.attrs["min_duration_s"] == 0.5
    assert m.attrs["rule_description"] == "angular speed < 12 deg/s (fixed)"
    assert bool(m.values[:450].all()) and not bool(m.values[550:950].any())
    speed = B.recording_speed(rec, gyr_offset=[2.0, -1.0, 0.5])
    direct = B.detect_immobility(speed, merge_gap_s=0.2)
    np.testing.assert_array_equal(direct.values, m.values)


def test_dba_and_odba_share_the_dynamic_part():
    rng = np.random.default_rng(5)
    acc = rng.normal(0.0, 0.1, (400, 3)) + [0.0, 0.0, 1.0]
    dyn = acc - B.static_acceleration(acc, 50.0, window_s=0.3)
    np.testing.assert_array_equal(
        B.dba(acc, 50.0, window_s=0.3), np.linalg.norm(dyn, axis=1)
    )
    np.testing.assert_array_equal(
        B.odba(acc, 50.0, window_s=0.3), np.abs(dyn).sum(axis=1)
    )
