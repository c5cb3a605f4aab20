"""A simulated motion-capture study (simulate.mocap_study)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from tiltlab import calibration, simulate


def _by_hand(seed: int, i: int, duration_s: float, fs: float, n_tumble: int):
    """The protocol step by step, as chapter 4 wrote it before the function existed."""
    sensor = simulate.draw_sensor(None, np.random.default_rng([seed, i]))
    tumble = simulate.tumble_test(n_tumble, fs, seed=[seed, i, 1], sensor=sensor)
    cal = calibration.tumble_calibration(tumble).calibration
    rec, mocap = simulate.simulate_mocap_session(
        duration_s, fs, seed=[seed, i, 2], sensor=sensor
    )
    return calibration.calibrate(rec, cal), mocap, rec


def test_each_rat_is_the_protocol_step_by_step():
    study = simulate.mocap_study([1, 3], 15.0, 100.0, seed=7, n_tumble=12)
    assert list(study) == [1, 3]
    for i, rat in study.items():
        rec, mocap, raw = _by_hand(7, i, 15.0, 100.0, 12)
        xr.testing.assert_identical(rat.recording, rec)
        xr.testing.assert_identical(rat.mocap, mocap)
        xr.testing.assert_identical(rat.raw, raw)
        xr.testing.assert_identical(
            calibration.calibrate(rat.raw, rat.calibration), rec
        )


def test_a_rat_does_not_depend_on_the_others():
    alone = simulate.mocap_study([2], 10.0, 100.0, seed=3, n_tumble=12)[2]
    among = simulate.mocap_study(3, 10.0, 100.0, seed=3, n_tumble=12)[2]
    xr.testing.assert_identical(alone.raw, among.raw)
    assert alone.sensor == among.sensor


def test_the_given_sensor_errors_are_kept():
    model = simulate.SensorModel(acc_offset=(0.0, 0.0, 0.0))
    study = simulate.mocap_study(
        1, 10.0, 100.0, seed=0, sensor_model=model, n_tumble=12
    )
    rat = study[0]
    assert tuple(rat.sensor.acc_offset) == (0.0, 0.0, 0.0)
    assert rat.sensor.gyr_offset is not None  # drawn


@pytest.mark.parametrize(
    ("rats", "kw", "message"),
    [
        (0, {}, "no rat"),
        ([], {}, "no rat"),
        ([1, 1], {}, "distinct"),
        ([-1], {}, "non-negative"),
        (1, {"n_tumble": 3}, "n_tumble"),
    ],
)
def test_bad_input_names_the_problem(rats, kw, message):
    with pytest.raises(ValueError, match=message):
        simulate.mocap_study(rats, 10.0, 100.0, seed=0, **kw)
