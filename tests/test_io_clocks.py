"""Real clocks in CSV and multi-file exports: jitter, drift, gaps, epoch times, the
hints in the form the user writes options, and the make_recording options of a mapping."""

import json

import numpy as np
import pandas as pd
import pytest

from tiltlab import io, quality, schema
from tiltlab.io import clock, multi

F_SINE, AMP = 1.3, 0.2  # Hz, g: a slow tilt oscillation on x


def _truth(t):
    return np.column_stack(
        [AMP * np.sin(2 * np.pi * F_SINE * t), np.zeros_like(t), np.ones_like(t)]
    )


def _jittery_times(n=2000, fs=100.0, drift=0.01, seed=3):
    """A board clock: steps of 0.75, 1 and 3 periods, running 1 % slow."""
    rng = np.random.default_rng(seed)
    steps = rng.choice([0.75, 1.0, 3.0], size=n - 1, p=[0.45, 0.45, 0.10])
    return 2.5 + np.r_[0.0, np.cumsum(steps)] / fs * (1 + drift)


def _write(path, t, acc, *, time_text=None, gyr=None):
    cols = {"t": t if time_text is None else time_text}
    cols |= {f"a{k}": acc[:, i] for i, k in enumerate("xyz")}
    if gyr is not None:
        cols |= {f"g{k}": gyr[:, i] for i, k in enumerate("xyz")}
    pd.DataFrame(cols).to_csv(path, index=False, float_format="%.17g")


ACC_ONLY = {"columns": {"acc": ["ax", "ay", "az"]}, "units": {"acc": "g"}}


def test_jittery_drifting_clock_is_resampled_to_the_truth(tmp_path):
    t = _jittery_times()
    p = tmp_path / "board.csv"
    _write(p, t, _truth(t))
    m = {**ACC_ONLY, "time_column": "t"}
    # the grid policy refuses it, and says how to read it, as a JSON key here …
    with pytest.raises(
        schema.RecordingError, match='not on a regular grid.*"clock": "resample"'
    ):
        io.read_csv(p, mapping=m)
    # … and as a keyword when the options are keywords
    with pytest.raises(schema.RecordingError, match="clock='resample'"):
        io.read_csv(p, ACC_ONLY["columns"], ACC_ONLY["units"], time_column="t")
    rec = io.read_csv(p, mapping={**m, "clock": "resample"})
    time = rec.time.values
    # a uniform grid inside the span of the samples
    np.testing.assert_allclose(np.diff(time), 1 / rec.attrs["fs"], rtol=1e-9)
    assert t[0] <= time[0] and time[-1] <= t[-1]
    # the rate is the clock's real mean rate (the drift included), not 1 / median step
    mean_rate = (t.size - 1) / (t[-1] - t[0])
    assert rec.attrs["fs"] == pytest.approx(mean_rate, rel=1e-6)
    assert "duration" in rec.attrs["fs_source"]
    # linear interpolation of a 1.3 Hz sine sampled every ≤ 3 periods: tiny error
    err = np.abs(rec.acc.values - _truth(time)).max()
    step = np.diff(t).max()
    bound = AMP * (2 * np.pi * F_SINE) ** 2 * step**2 / 8  # |f''| h² / 8
    assert err <= bound * 1.01
    assert str(t.size) in rec.attrs["resampled"] and "median" in rec.attrs["resampled"]
    # the input file's numbers are not changed by reading them
    assert np.array_equal(pd.read_csv(p)["t"].to_numpy(), t)


def test_a_real_gap_is_not_interpolated(tmp_path):
    t = _jittery_times(seed=5)
    t = np.where(t > 8.0, t + 1.0, t)  # the logger stopped for one second
    p = tmp_path / "gap.csv"
    _write(p, t, _truth(t))
    m = {**ACC_ONLY, "time_column": "t", "clock": "resample", "fs": 100}
    with pytest.raises(schema.RecordingError, match=r'1 gap: 1\.0.*"gaps": "nan"'):
        io.read_csv(p, mapping=m)
    with pytest.raises(schema.RecordingError, match=r"gaps='nan'"):
        io.read_csv(
            p, ACC_ONLY["columns"], ACC_ONLY["units"], time_column="t", clock="resample"
        )
    rec = io.read_csv(p, mapping={**m, "gaps": "nan"})
    time, acc = rec.time.values, rec.acc.values
    i = int(np.searchsorted(t, 8.0))  # the step t[i-1] → t[i] is the gap
    inside = (time > t[i - 1]) & (time < t[i])
    assert inside.sum() >= 99 and np.isnan(acc[inside]).all()
    assert np.isfinite(acc[~inside]).all()
    np.testing.assert_allclose(acc[~inside], _truth(time[~inside]), atol=2e-3)
    assert "gap" in rec.attrs["gaps"] and rec.attrs["fs"] == 100.0
    # a larger max_gap accepts it as a burst (then it is interpolated, by request)
    rec2 = io.read_csv(p, mapping={**m, "max_gap": 200})
    assert np.isfinite(rec2.acc.values).all()


def test_resample_to_a_coarser_grid_warns_about_aliasing(tmp_path):
    t = _jittery_times(n=500)
    p = tmp_path / "fast.csv"
    _write(p, t, _truth(t))
    m = {**ACC_ONLY, "time_column": "t", "clock": "resample", "fs": 20}
    with pytest.warns(quality.QualityWarning, match="aliases"):
        rec = io.read_csv(p, mapping=m)
    assert rec.attrs["fs"] == 20.0


@pytest.mark.parametrize(
    ("unit", "factor", "integer"),
    [("s", 1.0, False), ("ms", 1e3, False), ("us", 1e6, True), ("ns", 1e9, True)],
)
def test_epoch_times_are_made_relative(tmp_path, unit, factor, integer):
    fs, n = 50.0, 300
    start = pd.Timestamp("2023-05-17T08:30:12.25", tz="UTC")
    rel = np.arange(n) / fs
    raw = (1_684_312_212.25 + rel) * factor  # the same instant, in epoch seconds
    if integer:
        raw = (start.value // int(1e9 / factor)) + np.round(rel * factor).astype(
            np.int64
        )
    p = tmp_path / "epoch.csv"
    _write(p, raw, _truth(rel))
    rec = io.read_csv(p, mapping={**ACC_ONLY, "time_column": "t", "time_units": unit})
    # float epoch seconds carry ~2e-7 s of rounding: the estimate is good to 1e-4
    assert rec.attrs["fs"] == pytest.approx(fs, rel=1e-4)
    assert rec.time.values[0] == 0.0
    np.testing.assert_allclose(rec.time.values, rel, atol=1e-6)
    assert pd.Timestamp(rec.attrs["time_origin"]) == start


def test_datetime_column_and_ns_unit_hint(tmp_path):
    fs, n = 25.0, 200
    start = pd.Timestamp("2021-02-03T04:05:06")
    rel = np.arange(n) / fs
    text = [(start + pd.Timedelta(seconds=s)).isoformat() for s in rel]
    p = tmp_path / "dt.csv"
    _write(p, rel, _truth(rel), time_text=text)
    rec = io.read_csv(
        p, mapping={**ACC_ONLY, "time_column": "t", "time_units": "datetime"}
    )
    np.testing.assert_allclose(rec.time.values, rel, atol=1e-9)
    assert rec.attrs["time_origin"].startswith("2021-02-03T04:05:06")
    # nanoseconds read as seconds: the hint names ns, in the form of the options
    q = tmp_path / "ns.csv"
    _write(q, (rel * 1e9).astype(np.int64) + 10**6, _truth(rel))
    with pytest.raises(
        ValueError, match='looks like nanoseconds: give "time_units": "ns"'
    ):
        io.read_csv(q, mapping={**ACC_ONLY, "time_column": "t"})
    with pytest.raises(
        ValueError, match="looks like nanoseconds: give time_units='ns'"
    ):
        io.read_csv(q, ACC_ONLY["columns"], ACC_ONLY["units"], time_column="t")


def test_mapping_gives_make_recording_options(tmp_path):
    n, fs = 400, 100.0
    rng = np.random.default_rng(1)
    acc = rng.normal(0, 0.01, (n, 3)) + [0, 0, -1.0]  # a logger reporting gravity
    gyr = rng.normal(0, 0.5, (n, 3))
    p = tmp_path / "g.csv"
    _write(p, np.arange(n) / fs, acc, gyr=gyr)
    m = {
        "columns": {"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]},
        "units": {"acc": "g", "gyr": "deg/s"},
        "fs": fs,
        "axes": {"acc": ["-x", "-y", "-z"]},
        "axis_labels": ["forward", "left", "up"],
    }
    rec = io.read_csv(p, mapping=m)
    np.testing.assert_array_equal(rec.acc.values, -acc)
    np.testing.assert_array_equal(rec.gyr.values, gyr)
    assert rec.attrs["axis_labels"] == ["forward", "left", "up"]
    # the gyroscope is optional
    acc_only = io.read_csv(p, mapping={**m, "columns": {"acc": m["columns"]["acc"]}})
    assert "gyr" not in acc_only and acc_only.sizes["time"] == n
    # a preset as a keyword
    rec = io.read_csv(p, mapping=m, preset="tagtools", axes=None)
    assert rec.attrs["frame_preset"] == "tagtools"
    with pytest.raises(ValueError, match="axes.*not a device axis"):
        io.read_csv_mapping({**m, "axes": ["x", "w", "z"]})
    with pytest.raises(ValueError, match="check_units must be true or false"):
        io.read_csv_mapping({**m, "check_units": "no"})
    with pytest.raises(ValueError, match="clock must be one of"):
        io.read_csv_mapping({**m, "clock": "smooth"})
    with pytest.raises(ValueError, match="max_gap is in sample periods"):
        io.read_csv_mapping({**m, "max_gap": 1})


def test_unit_check_error_names_the_switch_as_given(tmp_path):
    n, fs = 400, 100.0
    rng = np.random.default_rng(4)
    acc = rng.normal(0, 0.05, (n, 3)) + [0, 0, 9.81]  # m/s² labelled g
    p = tmp_path / "u.csv"
    _write(p, np.arange(n) / fs, acc)
    m = {**ACC_ONLY, "fs": fs}
    with pytest.raises(quality.UnitCheckError) as err:
        io.read_csv(p, mapping=m)
    assert '"check_units": false in the mapping' in str(err.value)
    with pytest.raises(quality.UnitCheckError, match="check_units=False"):
        io.read_csv(p, ACC_ONLY["columns"], ACC_ONLY["units"], fs=fs)
    rec = io.read_csv(p, mapping={**m, "check_units": False})
    assert rec.acc.attrs["units"] == "g"
    rec = io.read_csv(p, mapping=m, check_units=False)
    assert rec.acc.attrs["units"] == "g"


def test_two_row_header_names_joined_with_a_slash(tmp_path):
    n, fs = 300, 50.0
    rng = np.random.default_rng(8)
    left = rng.normal(0, 0.1, (n, 3)) + [0, 0, 9.81]
    right = rng.normal(0, 0.1, (n, 3)) + [0, 0, 9.81]
    cols = pd.MultiIndex.from_tuples(
        [(s, f"acc_{k}") for k in "xyz" for s in ("left_sensor", "right_sensor")],
        names=["sensor", "axis"],
    )
    data = np.column_stack([x for i in range(3) for x in (left[:, i], right[:, i])])
    p = tmp_path / "two.csv"
    pd.DataFrame(data, columns=cols).to_csv(p, float_format="%.17g")
    names = [f"left_sensor/acc_{k}" for k in "xyz"]
    rec = io.read_csv(p, {"acc": names}, {"acc": "m/s^2"}, fs=fs, header=[0, 1])
    np.testing.assert_array_equal(rec.acc.values, left)
    with pytest.raises(io.ReadError, match=r"header=\[0, 1\]"):
        io.read_csv(p, {"acc": names}, {"acc": "m/s^2"}, fs=fs)


# --------------------------------------------------------------------------- multi-file


def _stream(path, t, v, fmt="csv", time_name="t"):
    if fmt == "csv":
        df = pd.DataFrame({time_name: t, "x": v[:, 0], "y": v[:, 1], "z": v[:, 2]})
        df.to_csv(path, index=False, float_format="%.17g")
    else:
        import scipy.io

        scipy.io.savemat(path, {"buf": np.vstack([t, v.T])})  # 4 × N, [t; x; y; z]


def test_multi_file_export_onto_one_grid(tmp_path):
    rng = np.random.default_rng(9)
    ta = np.sort(rng.uniform(0.0, 10.0, 1000))  # a bursty 100 Hz accelerometer
    tg = 0.3 + np.arange(0, 9.5, 1 / 80.0)  # an 80 Hz gyroscope, starting later
    tm = 0.1 + np.arange(0, 9.0, 1 / 30.0)  # a 30 Hz magnetometer, ending earlier
    _stream(tmp_path / "Accelerometer.csv", ta, _truth(ta))
    _stream(tmp_path / "gyro.mat", tg, np.tile([0.1, 0.0, 0.0], (tg.size, 1)), "mat")
    _stream(
        tmp_path / "Magnetometer.csv", tm, np.tile([20.0, 0.0, -40.0], (tm.size, 1))
    )
    mapping = {
        "files": {
            "acc": {
                "path": "Accelerometer.csv",
                "columns": ["x", "y", "z"],
                "time_column": "t",
                "time_units": "s",
                "units": "g",
            },
            "gyr": {
                "path": "gyro.mat",
                "variable": "buf",
                "layout": "rows",
                "units": "rad/s",
            },
            "mag": {
                "path": "Magnetometer.csv",
                "columns": ["x", "y", "z"],
                "time_column": "t",
                "units": "uT",
            },
        },
        "fs": 100,
        "max_gap": 50,
        "check_units": True,
        "attrs": {"subject": "board"},
    }
    mp = tmp_path / "export.json"
    mp.write_text(json.dumps(mapping))
    rec = io.read_multi(mp)  # relative paths against the mapping file's folder
    time = rec.time.values
    np.testing.assert_allclose(np.diff(time), 1 / 100, rtol=1e-9)
    # the overlap of the three clocks
    assert time[0] == pytest.approx(max(ta[0], tg[0], tm[0]))
    assert time[-1] <= min(ta[-1], tg[-1], tm[-1]) + 1e-12
    assert min(ta[-1], tg[-1], tm[-1]) - time[-1] < 1 / 100
    np.testing.assert_allclose(
        rec.gyr.values, np.tile([0.1, 0, 0], (time.size, 1)), atol=1e-12
    )
    np.testing.assert_allclose(rec.mag.values[:, 2], -40.0, atol=1e-12)
    assert np.abs(rec.acc.values - _truth(time)).max() < 0.01
    assert set(rec.attrs["streams"]) == {"acc", "gyr", "mag"}
    assert rec.attrs["streams"]["gyr"]["source"] == "gyro.mat:buf"
    assert rec.attrs["streams"]["gyr"]["rate_hz"] == pytest.approx(80.0, rel=1e-6)
    assert "overlap" in rec.attrs["merge"] and rec.attrs["subject"] == "board"
    # the same from a dict, relative paths resolved against base; overrides win
    with pytest.warns(quality.QualityWarning, match="aliases"):
        rec2 = multi.read_multi(mapping, base=tmp_path, fs=25)
    assert rec2.attrs["fs"] == 25.0
    # an N × 4 matrix needs layout "columns" (or none: guessed from the shape)
    bad = {
        **mapping,
        "files": {
            **mapping["files"],
            "gyr": {**mapping["files"]["gyr"], "layout": "columns"},
        },
    }
    with pytest.raises(io.ReadError, match="layout 'columns' needs 4 columns"):
        multi.read_multi(bad, base=tmp_path)
    guess = {
        **mapping,
        "files": {
            **mapping["files"],
            "gyr": {**mapping["files"]["gyr"], "layout": None},
        },
    }
    assert multi.read_multi(guess, base=tmp_path).sizes == rec.sizes


def test_multi_file_errors_and_epoch_alignment(tmp_path):
    t0 = 1_700_000_000.0
    ta = t0 + np.arange(0, 5, 0.01)
    tg = t0 + 0.5 + np.arange(0, 5, 0.01)
    _stream(tmp_path / "a.csv", ta, _truth(ta - t0))
    _stream(tmp_path / "g.csv", tg, np.zeros((tg.size, 3)))
    entry = {"columns": ["x", "y", "z"], "time_column": "t"}
    m = {
        "files": {
            "acc": {**entry, "path": "a.csv", "units": "g"},
            "gyr": {**entry, "path": "g.csv", "units": "deg/s"},
        }
    }
    rec = multi.read_multi(m, base=tmp_path)
    # both clocks share one origin: the gyroscope starts 0.5 s later
    assert rec.time.values[0] == pytest.approx(0.5)
    assert pd.Timestamp(rec.attrs["time_origin"]) == pd.Timestamp(
        t0, unit="s", tz="UTC"
    )
    assert rec.attrs["fs"] == pytest.approx(100.0)
    with pytest.raises(ValueError, match=r"'units' must give the unit of 'gyr'"):
        multi.read_multi(
            {"files": {**m["files"], "gyr": {**entry, "path": "g.csv"}}}, base=tmp_path
        )
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['sep'\]"):
        multi.read_multi({**m, "sep": ";"}, base=tmp_path)
    with pytest.raises(ValueError, match="'files' must map"):
        multi.read_multi({"files": {"gyr": m["files"]["gyr"]}}, base=tmp_path)
    far = tmp_path / "far.csv"
    _stream(far, ta + 100, np.zeros((ta.size, 3)))
    with pytest.raises(ValueError, match="do not overlap"):
        multi.read_multi(
            {
                "files": {
                    **m["files"],
                    "gyr": {**entry, "path": "far.csv", "units": "deg/s"},
                }
            },
            base=tmp_path,
        )
    with pytest.raises(io.ReadError, match="no such file"):
        multi.read_multi(m, base=tmp_path / "elsewhere")


def test_interpolate_never_overshoots_and_keeps_inputs():
    rng = np.random.default_rng(0)
    t = np.sort(rng.uniform(0, 1, 200))
    v = rng.normal(size=(200, 3))
    t_copy, v_copy = t.copy(), v.copy()
    grid = clock.uniform_grid(t[0], t[-1], 500.0)
    out = clock.interpolate(t, v, grid)
    i = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, t.size - 2)
    lo = np.minimum(v[i], v[i + 1])
    hi = np.maximum(v[i], v[i + 1])
    assert np.all(out >= lo - 1e-12) and np.all(out <= hi + 1e-12)
    np.testing.assert_array_equal(t, t_copy)
    np.testing.assert_array_equal(v, v_copy)
    fs, n_gaps = clock.estimate_rate(
        np.r_[np.arange(100) / 50.0, 10 + np.arange(100) / 50.0]
    )
    assert fs == pytest.approx(50.0) and n_gaps == 1
