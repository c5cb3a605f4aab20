"""Real recordings made by other projects, read through read_csv / read_multi and a
mapping (files in TILTLAB_DATA_DIR/foreign, described in its README.md)."""

import numpy as np
import pandas as pd
import pytest

from tiltlab import io, schema
from tiltlab.io import multi


def _board_mapping():
    # MATLAB v7.3 files, one per sensor. In MATLAB each buffer is N × 4 ([t, x, y, z]
    # as columns; h5py shows the transpose, 4 × N). Units are not stated: acc in g,
    # gyro in deg/s, mag in gauss are inferred (README). The accelerometer reports
    # gravity (−1 g on z when z is up), so all its signs are reversed to give specific
    # force; the gyroscope's x has a flipped sign (README).
    mat = {"layout": "columns"}
    return {
        "files": {
            "acc": {
                "path": "mpu6050_accelerometer.mat",
                "variable": "accelBuffer",
                "units": "g",
                **mat,
            },
            "gyr": {
                "path": "mpu6050_gyroscope.mat",
                "variable": "gyroBuffer",
                "units": "deg/s",
                **mat,
            },
            "mag": {
                "path": "hmc5883l_compass.mat",
                "variable": "compassBuffer",
                "units": "gauss",
                **mat,
            },
        },
        "fs": 100,
        # samples arrive in bursts (steps up to 0.28 s, mean rate 99.3 Hz): nothing is
        # lost, so bursts up to 30 periods are interpolated across
        "max_gap": 30,
        "axes": {"acc": ["-x", "-y", "-z"], "gyr": ["-x", "y", "z"]},
        "axis_labels": ["forward", "left", "up"],
    }


@pytest.mark.parametrize(
    "folder", ["unmoved-with-x-pointing-forward", "roll-and-tilt-at-45-90"]
)
def test_board_sunsided_three_mat_files(foreign, folder):
    base = foreign / "board_sunsided" / folder
    rec = multi.read_multi(_board_mapping(), base=base)
    time, acc = rec.time.values, rec.acc.values
    assert rec.attrs["fs"] == 100.0
    np.testing.assert_allclose(np.diff(time), 0.01, rtol=1e-9)
    for v in ("acc", "gyr", "mag"):
        assert np.isfinite(rec[v].values).all()  # no NaN inside the overlap
    streams = rec.attrs["streams"]
    assert streams["acc"]["source"] == "mpu6050_accelerometer.mat:accelBuffer"
    assert 95 < streams["acc"]["rate_hz"] < 101 and 70 < streams["mag"]["rate_hz"] < 80
    assert streams["mag"]["samples"] < streams["acc"]["samples"]
    assert "overlap" in rec.attrs["merge"]
    # the grid lies inside every stream's span
    for v in ("acc", "gyr", "mag"):
        raw = io.read_matrix(base / streams[v]["source"].split(":")[0])
        assert raw[0, 0] <= time[0] + 1e-9 and time[-1] <= raw[-1, 0] + 1e-9
    if folder.startswith("unmoved"):
        # lying still, z up: about 1 g, along +z (specific force) after the mapping
        assert np.median(np.linalg.norm(acc, axis=1)) == pytest.approx(1.0, abs=0.06)
        assert np.median(acc[:, 2]) > 0.95
        # a still board: the gyroscope shows its bias only (≈ 4.5 deg/s on x, negated)
        assert np.median(rec.gyr.values[:, 0]) == pytest.approx(-4.5, abs=0.5)
    else:
        assert np.median(acc[:200, 2]) > 0.9  # it starts flat, z up


def test_board_sunsided_bursts_are_gaps_at_the_default_max_gap(foreign):
    base = foreign / "board_sunsided" / "roll-and-tilt-at-45-90"
    m = {k: v for k, v in _board_mapping().items() if k != "max_gap"}
    with pytest.raises(
        schema.RecordingError, match=r'longer than max_gap = 5.*"gaps": "nan"'
    ):
        multi.read_multi(m, base=base)


def _twlogger_mapping(folder):
    cal = pd.read_csv(folder / "Tag1_LSM303cal.csv")
    return {
        "columns": {
            "acc": ["ACCELX", "ACCELY", "ACCELZ"],
            "mag": ["MAGX", "MAGY", "MAGZ"],
        },
        # raw LSM303 counts; the file does not give the sensitivity. The scale factors
        # are inferred: the source's calibration poly term (AccPoly1, MagPoly1) gives
        # |acc| ≈ 9.8 m/s² at rest and |mag| of tens of µT (README: units inferred)
        "units": {"acc": "m/s^2", "mag": "uT"},
        "scale": {"acc": float(cal["AccPoly1"][0]), "mag": float(cal["MagPoly1"][0])},
        "time_column": "Timestamp(Ms)",
        "time_units": "ms",
        "clock": "resample",
        # the source's processing script flips y ("Acc [x -y z]", same for mag)
        "axes": {"acc": ["x", "-y", "z"], "mag": ["x", "-y", "z"]},
        "low_memory": False,
    }


def test_tag_twlogger_ms_clock_acc_and_mag_only(foreign):
    folder = foreign / "tag_twlogger"
    path = folder / "T1D0711-00.CSV"
    m = _twlogger_mapping(folder)
    # the ms clock steps 15–16 ms but jumps by ~0.1 s every 2000 samples (flushes to
    # the card): these are real gaps, located in the message
    with pytest.raises(schema.RecordingError, match=r"data row 1999"):
        io.read_csv(path, mapping=m)
    # on a k/fs grid it is refused, with the resample hint
    with pytest.raises(schema.RecordingError, match='"clock": "resample"'):
        io.read_csv(path, mapping={**m, "clock": "grid", "gaps": "nan"})
    rec = io.read_csv(path, mapping={**m, "gaps": "nan"})
    assert set(rec.data_vars) == {"acc", "mag"}  # no gyroscope: a valid Recording
    raw_ms = pd.read_csv(path, usecols=["Timestamp(Ms)"])["Timestamp(Ms)"].to_numpy()
    steps = np.diff(raw_ms)
    # fs from the ms clock: (n − 1) / duration without the gaps, ≈ 64 Hz (not the 50 Hz
    # of the settings file, which the wall-clock column supports: README)
    assert 1000 / steps.max() < rec.attrs["fs"] < 1000 / np.median(steps) * 1.05
    assert 60 < rec.attrs["fs"] < 68
    np.testing.assert_allclose(np.diff(rec.time.values), 1 / rec.attrs["fs"], rtol=1e-9)
    assert str(raw_ms.size) in rec.attrs["resampled"]
    acc = rec.acc.values
    ok = np.isfinite(acc).all(axis=1)
    assert 0 < (~ok).sum() < 0.01 * ok.size and "gap" in rec.attrs["gaps"]
    assert np.median(np.linalg.norm(acc[ok], axis=1)) == pytest.approx(9.81, rel=0.05)
    # the y flip: the raw y column, negated and scaled
    raw_y = pd.read_csv(path, usecols=["ACCELY"])["ACCELY"].to_numpy()
    assert np.sign(np.median(acc[ok, 1])) == -np.sign(np.median(raw_y))


def test_foot_gaitmap_two_row_header(foreign):
    path = foreign / "foot_gaitmap" / "imu_sample.csv"
    side = "left_sensor"
    m = {
        "columns": {
            "acc": [f"{side}/acc_{k}" for k in "xyz"],
            "gyr": [f"{side}/gyr_{k}" for k in "xyz"],
        },
        "units": {"acc": "m/s^2", "gyr": "deg/s"},  # gaitmap's user guide
        "fs": 204.8,  # the docstring's rate; there is no time column
        "header": [0, 1],
        "axis_labels": ["toe", "left", "up"],  # gaitmap's foot sensor frame
    }
    rec = io.read_csv(path, mapping=m)
    assert rec.attrs["fs"] == 204.8 and rec.sizes["time"] == 7928
    assert rec.sizes["time"] / 204.8 == pytest.approx(38.7, abs=0.05)
    table = pd.read_csv(path, header=[0, 1])
    np.testing.assert_array_equal(rec.gyr.values[:, 2], table[(side, "gyr_z")])
    # walking: the median |acc| stays near g, z (up) carries gravity
    norm = np.linalg.norm(rec.acc.values, axis=1)
    assert 8.0 < np.median(norm) < 12.5
    assert np.median(rec.acc.values[:, 2]) > 5.0
    assert "gyr" in rec and rec.gyr.attrs["units"] == "deg/s"
