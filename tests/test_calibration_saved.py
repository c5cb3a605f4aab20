"""A calibration saved to a file and applied to another session; the magnetometer
calibration figure recipe."""

from __future__ import annotations

import json

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from tiltlab import calibration, plot, simulate
from tiltlab.calibration import (
    Calibration,
    CalibrationError,
    load_calibration_file,
    save_calibration_file,
)


@pytest.fixture(scope="module")
def tumble():
    return simulate.tumble_test(8, 50.0, seed=2)


@pytest.fixture()
def full_cal():
    temps = np.linspace(25.0, 35.0, 8)
    offs = np.column_stack([0.1 * (temps - 30), -0.05 * (temps - 30), 0 * temps])
    tm = calibration.fit_temperature_model(temps, offs, degree=2, units="deg/s")
    return Calibration(
        name="bench",
        acc_offset=[0.01, -0.02, 0.03],
        acc_matrix=np.eye(3) * 1.01,
        gyr_temp=tm,
        mag_offset=[5.0, -3.0, 1.0],
        mag_matrix=np.diag([1.1, 0.9, 1.0]),
        rotation=np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
        target_frame="head",
        info={"n_poses": 8, "note": "bench test"},
    )


def test_round_trip_keeps_every_correction(tmp_path, full_cal):
    path = save_calibration_file(full_cal, tmp_path / "cal.json")
    assert path == tmp_path / "cal.json"
    loaded = load_calibration_file(path)
    assert loaded.to_dict() == full_cal.to_dict()
    assert loaded.fingerprint() == full_cal.fingerprint()
    record = json.loads(path.read_text())
    assert record["fingerprint"] == full_cal.fingerprint()
    assert record["format"] == "tiltlab-calibration"


def test_round_trip_of_a_fitted_calibration_applies_like_the_original(tmp_path, tumble):
    cal = calibration.tumble_calibration(tumble).calibration
    loaded = load_calibration_file(save_calibration_file(cal, tmp_path / "tumble.json"))
    assert loaded == cal
    other = simulate.tumble_test(8, 50.0, seed=3)
    a, b = calibration.calibrate(other, cal), calibration.calibrate(other, loaded)
    np.testing.assert_array_equal(a.acc.values, b.acc.values)
    history = calibration.applied_calibrations(b)
    assert [h["fingerprint"] for h in history] == [cal.fingerprint()]
    with pytest.raises(CalibrationError, match="already applied"):
        calibration.calibrate(b, cal)


def test_saving_and_loading_mutate_nothing(tmp_path, full_cal):
    before = full_cal.to_dict()
    path = save_calibration_file(full_cal, tmp_path / "cal.json")
    content = path.read_bytes()
    load_calibration_file(path)
    assert full_cal.to_dict() == before
    assert path.read_bytes() == content


def test_changed_corrections_are_refused_naming_the_fingerprint(tmp_path, full_cal):
    path = save_calibration_file(full_cal, tmp_path / "cal.json")
    record = json.loads(path.read_text())
    record["calibration"]["acc_offset"][0] += 0.001
    path.write_text(json.dumps(record))
    with pytest.raises(CalibrationError, match="changed after saving.*fingerprint"):
        load_calibration_file(path)


def test_changed_name_is_refused_naming_the_checksum(tmp_path, full_cal):
    path = save_calibration_file(full_cal, tmp_path / "cal.json")
    record = json.loads(path.read_text())
    record["calibration"]["name"] = "someone else's sensor"
    path.write_text(json.dumps(record))
    with pytest.raises(CalibrationError, match="name or info"):
        load_calibration_file(path)


def test_missing_file_names_the_path(tmp_path):
    with pytest.raises(FileNotFoundError, match="no calibration file at .*none.json"):
        load_calibration_file(tmp_path / "none.json")


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("{not json", "not valid JSON"),
        (b"\xff\xfe\x00", "not valid JSON"),
        ('{"acc_offset": [0, 0, 0]}', "not a calibration file"),
        ("[1, 2, 3]", "not a calibration file"),
        ('{"format": "tiltlab-calibration", "version": 99}', "version 99"),
        ('{"format": "tiltlab-calibration", "version": 1}', "incomplete"),
    ],
)
def test_corrupt_files_are_refused_naming_the_problem(tmp_path, content, message):
    path = tmp_path / "bad.json"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    with pytest.raises(CalibrationError, match=message):
        load_calibration_file(path)


def test_invalid_entry_is_refused(tmp_path, full_cal):
    path = save_calibration_file(full_cal, tmp_path / "cal.json")
    record = json.loads(path.read_text())
    record["calibration"]["acc_offset"] = [1.0, 2.0]
    path.write_text(json.dumps(record))
    with pytest.raises(CalibrationError, match="invalid calibration entry.*acc_offset"):
        load_calibration_file(path)


def test_save_refuses_what_is_not_a_calibration(tmp_path):
    with pytest.raises(TypeError, match="Calibration"):
        save_calibration_file({"acc_offset": [0, 0, 0]}, tmp_path / "cal.json")


def _mag_readings():
    rng = np.random.default_rng(4)
    m = rng.normal(size=(300, 3))
    m = 45.0 * m / np.linalg.norm(m, axis=1, keepdims=True)
    W = np.array([[1.1, 0.05, 0.0], [0.05, 0.9, 0.02], [0.0, 0.02, 1.0]])
    return m @ W.T + [12.0, -8.0, 4.0]


def test_mag_figure_draws_projections_and_norms_without_mutating():
    raw = _mag_readings()
    fit = calibration.fit_mag_ellipsoid(raw, field=45.0)
    cal = calibration.apply_mag_calibration(raw, fit.offset, fit.matrix)
    raw0, cal0 = raw.copy(), cal.copy()
    fig = plot.mag_calibration_figure(raw, cal, field=45.0, planes=("xy", "yz", "xz"))
    assert len(fig.axes) == 4
    np.testing.assert_array_equal(raw, raw0)
    np.testing.assert_array_equal(cal, cal0)
    assert "µT" in fig.axes[0].get_xlabel()
    assert fig.axes[-1].get_xlabel() == "sample"
    norm_line = fig.axes[-1].get_lines()[1].get_ydata()
    np.testing.assert_allclose(norm_line, 45.0, rtol=0.02)
    plt.close(fig)


def test_mag_figure_reads_a_recording_and_its_time():
    rec = simulate.simulate_session(
        4.0, 50.0, seed=1, sensor=simulate.SensorModel(magnetometer=True)
    )
    offset, matrix = calibration.minmax_mag_calibration(rec)
    cal = calibration.apply_mag_calibration(rec, offset, 40.0 * matrix)
    fig = plot.mag_calibration_figure(rec, cal)
    assert fig.axes[-1].get_xlabel() == "time (s)"
    assert rec.mag.attrs["units"] in ("uT", "µT")
    plt.close(fig)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [({"planes": ("xx",)}, "two different axes"), ({"time": [0, 1]}, "time must")],
)
def test_mag_figure_refuses_bad_options(kwargs, message):
    raw = _mag_readings()
    with pytest.raises(ValueError, match=message):
        plot.mag_calibration_figure(raw, raw, **kwargs)


def test_mag_figure_refuses_mismatched_shapes():
    raw = _mag_readings()
    with pytest.raises(ValueError, match="same shape"):
        plot.mag_calibration_figure(raw, raw[:10])
