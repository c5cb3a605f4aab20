"""A phone logger's export (one CSV per sensor, own jittery clocks, ns epoch times) read
back through the multi-file mapping: the round trip recovers the recording."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from tiltlab import io, schema, simulate
from tiltlab._validate import RecordingError

START_NS = 1_700_000_000 * 10**9


def _smooth_recording(fs=100.0, duration=20.0):
    """Slow sinusoids (interpolation error negligible) in g and deg/s."""
    t = np.arange(int(duration * fs)) / fs
    w = 2 * np.pi * 0.2
    acc = np.c_[0.3 * np.sin(w * t), 0.2 * np.cos(w * t), np.ones_like(t)]
    gyr = np.c_[20 * np.cos(w * t), -10 * np.sin(w * t), 5 * np.ones_like(t)]
    return schema.make_recording(
        acc, gyr, fs, acc_units="g", gyr_units="deg/s", check_units=False
    )


def _mapping(files):
    return {
        "files": {
            var: {
                "path": path.name,
                "columns": ["x", "y", "z"],
                "time_column": "time",
                "time_units": "ns",
                "units": simulate.PHONE_FILES[var][1],
            }
            for var, path in files.items()
        },
        "fs": 100,
        "preset": "android",
        "check_units": False,
    }


def test_files_have_their_own_increasing_epoch_clocks(tmp_path):
    rec = _smooth_recording()
    files = simulate.phone_export(rec, tmp_path, start_ns=START_NS, seed=2, drift=0.01)
    assert sorted(files) == ["acc", "gyr"]
    rates = []
    for path in files.values():
        table = pd.read_csv(path)
        assert list(table.columns) == ["time", "seconds_elapsed", "z", "y", "x"]
        assert table["time"].dtype == np.int64
        assert (np.diff(table["time"]) > 0).all()
        assert table["time"].iloc[0] >= START_NS
        span = (table["time"].iloc[-1] - table["time"].iloc[0]) * 1e-9
        rates.append((len(table) - 1) / span)
    assert all(abs(r / 100.0 - 1) < 0.012 for r in rates)
    assert rates[0] != rates[1]  # each stream on its own clock


def test_round_trip_through_read_multi(tmp_path):
    rec = _smooth_recording()
    before = rec.copy(deep=True)
    files = simulate.phone_export(rec, tmp_path, start_ns=START_NS, seed=5)
    back = io.read_multi(_mapping(files), base=tmp_path)
    assert rec.identical(before)  # the input is not modified
    assert back["acc"].attrs["units"] == "m/s^2"
    assert back["gyr"].attrs["units"] == "rad/s"
    assert list(back.attrs["axis_labels"]) == ["right", "top", "out of screen"]
    shift = (pd.Timestamp(back.attrs["time_origin"]).value - START_NS) * 1e-9
    t = back["time"].values + shift
    acc = schema.to_units(rec, acc="m/s^2")["acc"].interp(time=t).values
    gyr = schema.to_units(rec, gyr="rad/s")["gyr"].interp(time=t).values
    np.testing.assert_allclose(back["acc"].values, acc, atol=2e-3)
    np.testing.assert_allclose(back["gyr"].values, gyr, atol=2e-3)


def test_magnetometer_written_when_present(tmp_path):
    rec = simulate.simulate_session(
        5.0, 100.0, seed=1, sensor=simulate.SensorModel(magnetometer=True)
    )
    files = simulate.phone_export(rec, tmp_path)
    assert files["mag"].name == "Magnetometer.csv"


@pytest.mark.parametrize(
    "kwargs, message",
    [({"drift": 0.6}, "drift"), ({"jitter": -0.1}, "jitter")],
)
def test_bad_clock_settings_are_named(tmp_path, kwargs, message):
    with pytest.raises(ValueError, match=message):
        simulate.phone_export(_smooth_recording(), tmp_path, **kwargs)


def test_needs_a_recording(tmp_path):
    with pytest.raises(RecordingError, match="acc"):
        simulate.phone_export(_smooth_recording().drop_vars("acc"), tmp_path)
