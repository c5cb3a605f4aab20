"""Fayat et al. 2021 figure panels: Fig. 1b band, Fig. 1e calibration log, Fig. A3."""

from __future__ import annotations

import json

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from tiltlab import behavior, calibration, plot  # noqa: E402


@pytest.fixture(autouse=True)
def _close():
    yield
    plt.close("all")


def _means(seed=0, n_rep=10, n_orient=7):
    rng = np.random.default_rng(seed)
    g = rng.normal(size=(n_orient, 3))
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    return (
        g[None] * 1.01
        + [0.02, -0.03, 0.01]
        + rng.normal(0, 0.002, (n_rep, n_orient, 3))
    )


# -- Fig. 1b: the band is the percentiles of the repetitions --------------------------


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    lo=st.floats(0, 49),
    hi=st.floats(51, 100),
    n_rep=st.integers(1, 12),
)
def test_band_is_the_percentiles_of_the_repetitions(seed, lo, hi, n_rep):
    m = _means(seed, n_rep)
    off = np.random.default_rng(seed).normal(0, 0.03, (n_rep, 3))
    band = calibration.norm_error_band(m, off, percentiles=(lo, hi))
    err = np.abs(1 - np.linalg.norm(m - off[:, None, :], axis=-1))
    np.testing.assert_allclose(band["low"], np.percentile(err, lo, axis=0))
    np.testing.assert_allclose(band["high"], np.percentile(err, hi, axis=0))
    np.testing.assert_allclose(band["median"], np.median(err, axis=0))
    assert np.all(band["low"] <= band["median"] + 1e-15)
    assert np.all(band["median"] <= band["high"] + 1e-15)
    assert band.attrs["units"] == {"median": "g", "low": "g", "high": "g"}


def test_band_offset_for_all_repetitions_equals_repeated_rows():
    m = _means(1)
    o = np.array([0.02, -0.03, 0.01])
    a = calibration.norm_error_band(m, o)
    b = calibration.norm_error_band(m, np.tile(o, (m.shape[0], 1)))
    pd.testing.assert_frame_equal(a, b)
    # a perfect sensor with only that offset: correction leaves no error at all
    g = m[0] - o
    exact = (g / np.linalg.norm(g, axis=1, keepdims=True) + o)[None].repeat(3, axis=0)
    corrected = calibration.norm_error_band(exact, o)
    np.testing.assert_allclose(corrected.to_numpy(), 0.0, atol=1e-12)


def test_band_does_not_mutate_its_input():
    m = _means(2)
    before = m.copy()
    calibration.norm_error_band(m, np.zeros(3))
    np.testing.assert_array_equal(m, before)


@pytest.mark.parametrize(
    ("means", "offsets", "percentiles", "message"),
    [
        (np.zeros((4, 3)), None, (5, 95), "means must have shape"),
        (np.zeros((2, 4, 2)), None, (5, 95), "means must have shape"),
        (np.full((2, 4, 3), np.nan), None, (5, 95), "non-finite"),
        (np.ones((2, 4, 3)), np.zeros(2), (5, 95), "offsets must be"),
        (np.ones((2, 4, 3)), np.zeros((3, 3)), (5, 95), "offsets must be"),
        (np.ones((2, 4, 3)), None, (95, 5), "percentiles must be"),
        (np.ones((2, 4, 3)), None, (-1, 95), "percentiles must be"),
    ],
)
def test_band_bad_inputs_are_named(means, offsets, percentiles, message):
    with pytest.raises(ValueError, match=message):
        calibration.norm_error_band(means, offsets, percentiles=percentiles)


def test_band_figure_draws_a_band_per_condition():
    m = _means(3)
    bands = {
        "raw": calibration.norm_error_band(m),
        "corrected": calibration.norm_error_band(m, [0.02, -0.03, 0.01]),
    }
    ax = plot.norm_error_band_figure(bands)
    assert len(ax.lines) == 2 and len(ax.collections) == 2
    np.testing.assert_allclose(ax.lines[1].get_ydata(), bands["corrected"]["median"])
    assert "(g)" in ax.get_ylabel()
    with pytest.raises(ValueError, match="bands must be"):
        plot.norm_error_band_figure({})
    with pytest.raises(ValueError, match="missing"):
        plot.norm_error_band_figure({"raw": pd.DataFrame({"median": [1.0]})})


# -- Fig. 1e: the calibration log -----------------------------------------------------


def _save(folder, date, k, **info):
    cal = calibration.Calibration(
        name=f"cal {k}",
        acc_offset=[0.01 * k, -0.02, 0.03],
        gyr_offset=[1.0 + k, -2.0, 0.5],
        info={"date": date, **info},
    )
    return calibration.save_calibration_file(cal, folder / f"cal_{k}.json"), cal


def test_log_round_trip_with_dates_in_order(tmp_path):
    dates = ["2021-07-01", "2021-01-15", "2021-12-31", "2021-03-02"]
    saved = [
        _save(tmp_path, d, k, acc_offset_stderr=[1e-4, 2e-4, 3e-4])
        for k, d in enumerate(dates)
    ]
    log = calibration.calibration_log([p for p, _ in saved])
    assert log.index.is_monotonic_increasing
    assert list(log.index) == sorted(pd.Timestamp(d) for d in dates)
    for path, cal in saved:
        row = log[log["file"] == str(path)].iloc[0]
        assert row.name == pd.Timestamp(cal.info["date"])
        assert tuple(row[[f"acc_offset_{a}" for a in "xyz"]]) == cal.acc_offset
        assert tuple(row[[f"gyr_offset_{a}" for a in "xyz"]]) == cal.gyr_offset
        assert row["acc_offset_z_stderr"] == 3e-4
        assert row["name"] == cal.name
    assert "gyr_offset_x_stderr" not in log  # no stderr saved for the gyroscope
    assert log.attrs["units"]["acc_offset_x"] == "g"
    assert log.attrs["units"]["gyr_offset_y"] == "deg/s"
    fig = plot.calibration_log_figure(log)
    assert len(fig.axes) == 2


def test_log_bad_inputs_are_named(tmp_path):
    with pytest.raises(ValueError, match="at least one"):
        calibration.calibration_log([])
    undated = calibration.save_calibration_file(
        calibration.Calibration(acc_offset=[0, 0, 0]), tmp_path / "undated.json"
    )
    with pytest.raises(ValueError, match="'date'"):
        calibration.calibration_log([undated])
    bad, _ = _save(tmp_path, "not a date", 9)
    with pytest.raises(ValueError, match="'date'"):
        calibration.calibration_log([bad])
    good, _ = _save(tmp_path, "2021-02-02", 1)
    record = json.loads(good.read_text())
    record["calibration"]["acc_offset"][0] += 0.5
    edited = tmp_path / "edited.json"
    edited.write_text(json.dumps(record))
    with pytest.raises(calibration.CalibrationError, match="changed after saving"):
        calibration.calibration_log([good, edited])
    with pytest.raises(ValueError, match="indexed by date"):
        plot.calibration_log_figure(pd.DataFrame({"acc_offset_x": [0.0]}))
    log = calibration.calibration_log([good])
    with pytest.raises(ValueError, match="no offsets"):
        plot.calibration_log_figure(log[["name"]])


# -- Fig. A3: the two distributions add up to the raw one ----------------------------


def test_immobility_distributions_add_up_to_the_raw_one():
    rng = np.random.default_rng(4)
    fs = 100.0
    speed = np.exp(rng.normal(1.5, 1.5, 6000))
    speed[::97] = 0.0  # cannot be placed on a log axis
    still = np.asarray(behavior.detect_immobility(speed, fs, threshold_deg_s=12.0))
    ax = plot.immobility_speed_distribution(speed, still, threshold=12.0, bins=40)
    raw, imm, mov = (p.get_data() for p in ax.patches)
    np.testing.assert_allclose(imm.values + mov.values, raw.values)
    np.testing.assert_array_equal(raw.edges, imm.edges)
    assert raw.values.sum() == pytest.approx(1.0)
    assert ax.get_xscale() == "log"
    assert any(np.allclose(ln.get_xdata(), 12.0) for ln in ax.lines)
    # the rules move samples across the threshold: short gaps above it are merged
    assert np.any((speed >= 12.0) & still)


@pytest.mark.parametrize(
    ("speed", "mask", "kw", "message"),
    [
        (np.ones((3, 2)), np.ones((3, 2), bool), {}, "speed must be"),
        (np.ones(5), np.ones(4, bool), {}, "immobile must have the shape"),
        (np.ones(5), np.ones(5), {}, "immobile must be a boolean"),
        (np.zeros(5), np.ones(5, bool), {}, "no positive finite"),
        (np.ones(5), np.ones(5, bool), {"threshold": -1.0}, "threshold must be"),
        (np.ones(5), np.ones(5, bool), {"bins": 0}, "bins must be"),
    ],
)
def test_immobility_figure_bad_inputs_are_named(speed, mask, kw, message):
    with pytest.raises(ValueError, match=message):
        plot.immobility_speed_distribution(speed, mask, **kw)
