"""The Recording contract: constructor, validation errors, unit conversions."""

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from tiltlab.quality import UnitCheckError
from tiltlab import quaternion as Q
from tiltlab import schema, units
from tiltlab.schema import RecordingError


def rotating_sensor(n=2000, fs=100.0, seed=0):
    """A sensor turning about a tilted axis: acc = specific force of gravity (g), gyr (deg/s)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    omega = np.column_stack(
        [2.0 * np.sin(0.7 * t), 1.5 * np.cos(0.5 * t), 0.5 + 0 * t]
    )  # rad/s
    q = Q.integrate_gyro(omega, fs, Q.random_quaternions(1, rng)[0])
    acc = Q.gravity(q) + rng.normal(0, 0.01, (n, 3))
    return acc, np.degrees(omega), q, fs


def test_make_recording_structure():
    acc, gyr, q, fs = rotating_sensor()
    rec = schema.make_recording(
        acc, gyr, fs, q_ref=q, attrs={"subject": "r1"}, acc_units="g", gyr_units="deg/s"
    )
    assert rec.sizes == {"time": 2000, "axis": 3, "quat": 4}
    assert list(rec.axis.values) == ["x", "y", "z"] and list(rec.quat.values) == [
        "w",
        "x",
        "y",
        "z",
    ]
    assert rec.acc.attrs["units"] == "g" and rec.gyr.attrs["units"] == "deg/s"
    assert (
        rec.attrs["fs"] == fs
        and rec.attrs["frame"] == "sensor"
        and rec.attrs["subject"] == "r1"
    )
    np.testing.assert_allclose(np.diff(rec.time.values), 1 / fs)
    assert schema.provenance(rec)["subject"] == "r1"


def test_inputs_are_not_mutated_or_aliased():
    acc, gyr, q, fs = rotating_sensor(200)
    acc0 = acc.copy()
    rec = schema.make_recording(acc, gyr, fs, acc_units="g", gyr_units="deg/s")
    rec["acc"][:] = 0
    np.testing.assert_array_equal(acc, acc0)


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda r: r.attrs.pop("fs"), "'fs'.*missing"),
        (lambda r: r.attrs.__setitem__("fs", -5), "positive"),
        (lambda r: r.attrs.__setitem__("fs", "fast"), "number of Hz"),
        (lambda r: r.attrs.pop("frame"), "'frame'"),
        (
            lambda r: r["gyr"].attrs.__setitem__("units", "furlong/fortnight"),
            "unknown unit",
        ),
        (
            lambda r: r["gyr"].attrs.__setitem__("units", "g"),
            "do not measure angular velocity",
        ),
        (lambda r: r["acc"].attrs.pop("units"), "no 'units'"),
    ],
)
def test_validate_rejects_bad_metadata(mutate, message):
    acc, gyr, q, fs = rotating_sensor(300)
    rec = schema.make_recording(acc, gyr, fs, q_ref=q, acc_units="g", gyr_units="deg/s")
    mutate(rec)
    with pytest.raises(RecordingError, match=message):
        schema.validate(rec)


def test_validate_rejects_bad_data():
    acc, gyr, q, fs = rotating_sensor(300)
    with pytest.raises(RecordingError, match="mandatory"):
        schema.make_recording(acc, gyr, None, acc_units="g", gyr_units="deg/s")
    with pytest.raises(RecordingError, match=r"shape \(N, 3\)"):
        schema.make_recording(acc[:, :2], gyr, fs, acc_units="g", gyr_units="deg/s")
    with pytest.raises(RecordingError, match="lengths differ: 300 vs 299"):
        schema.make_recording(acc, gyr[:-1], fs, acc_units="g", gyr_units="deg/s")
    bad = acc.copy()
    bad[17, 1] = np.nan
    with pytest.raises(RecordingError, match=r"'acc' has 1 non-finite.*\(17, 1\)"):
        schema.make_recording(bad, gyr, fs, acc_units="g", gyr_units="deg/s")
    schema.make_recording(
        bad, gyr, fs, allow_nan=True, acc_units="g", gyr_units="deg/s"
    )  # gaps accepted on request
    bad[17, 1] = np.inf
    with pytest.raises(RecordingError, match="non-finite"):
        schema.make_recording(
            bad, gyr, fs, allow_nan=True, acc_units="g", gyr_units="deg/s"
        )
    qb = q.copy()
    qb[5] *= 1.01
    with pytest.raises(RecordingError, match="non-unit quaternions.*sample 5"):
        schema.make_recording(acc, gyr, fs, q_ref=qb, acc_units="g", gyr_units="deg/s")


def test_validate_rejects_bad_time():
    acc, gyr, q, fs = rotating_sensor(300)
    t = np.arange(300) / fs
    t_back = t.copy()
    t_back[100] = t_back[99]
    with pytest.raises(RecordingError, match="not strictly increasing"):
        schema.make_recording(
            acc, gyr, fs, time=t_back, acc_units="g", gyr_units="deg/s"
        )
    t_gap = np.concatenate([t[:150], t[150:] + 1 / fs])  # one dropped sample
    with pytest.raises(RecordingError, match="irregular.*interval 149"):
        schema.make_recording(
            acc, gyr, fs, time=t_gap, acc_units="g", gyr_units="deg/s"
        )
    with pytest.raises(RecordingError, match="irregular"):
        schema.make_recording(
            acc, gyr, fs * 2, time=t, acc_units="g", gyr_units="deg/s"
        )  # wrong fs
    small_jitter = t + np.random.default_rng(0).uniform(-0.1, 0.1, 300) / fs
    schema.make_recording(
        acc, gyr, fs, time=small_jitter, acc_units="g", gyr_units="deg/s"
    )


def test_validate_rejects_wrong_dims():
    acc, gyr, q, fs = rotating_sensor(100)
    rec = schema.make_recording(acc, gyr, fs, acc_units="g", gyr_units="deg/s")
    bad = rec.assign(gyr=rec.gyr.transpose("axis", "time"))
    with pytest.raises(RecordingError, match="dims \\('time', 'axis'\\)"):
        schema.validate(bad)
    with pytest.raises(RecordingError, match="xarray.Dataset"):
        schema.validate(rec.acc)


def test_gyro_in_rad_s_labelled_deg_s_is_caught():
    acc, gyr_deg, q, fs = rotating_sensor()
    gyr_rad = np.radians(gyr_deg)
    schema.make_recording(acc, gyr_rad, fs, gyr_units="rad/s", acc_units="g")
    with pytest.raises(UnitCheckError, match="gyr is labelled °/s.*looks like rad/s"):
        schema.make_recording(acc, gyr_rad, fs, gyr_units="deg/s", acc_units="g")
    # beyond any MEMS full scale when °/s values are labelled rad/s
    with pytest.raises(RecordingError, match="gyr is labelled rad/s.*looks like °/s"):
        schema.make_recording(acc, gyr_deg, fs, gyr_units="rad/s", acc_units="g")
    # the check can be switched off explicitly, and the message says how
    with pytest.raises(UnitCheckError, match="check_units=False accepts them"):
        schema.make_recording(acc, gyr_rad, fs, gyr_units="deg/s", acc_units="g")
    schema.make_recording(
        acc, gyr_rad, fs, gyr_units="deg/s", check_units=False, acc_units="g"
    )


def test_every_mislabelled_variable_is_reported_at_once():
    acc, gyr_deg, q, fs = rotating_sensor()
    with pytest.raises(UnitCheckError) as err:
        schema.make_recording(
            acc * 9.81, np.radians(gyr_deg), fs, acc_units="g", gyr_units="deg/s"
        )
    assert {f.var for f in err.value.findings} == {"acc", "gyr"}
    assert "looks like m/s²" in str(err.value) and "looks like rad/s" in str(err.value)
    assert "--no-check-units" in str(err.value.for_switch("cli"))


def test_static_and_shaken_recordings_pass_the_unit_check():
    rng = np.random.default_rng(1)
    # still, with a large bias: nothing to judge
    acc = np.array([0, 0, 1.0]) + rng.normal(0, 0.003, (500, 3))
    gyr = rng.normal(0, 0.05, (500, 3)) + [1.0, -2.0, 0.5]
    schema.make_recording(acc, gyr, 100.0, acc_units="g", gyr_units="deg/s")
    # shaken along a line without rotating: the accelerometer direction swings, the
    # gyroscope reads (correctly) almost nothing; ambiguous at most, never refused
    t = np.arange(3000) / 100.0
    shake = 0.4 * np.sin(2 * np.pi * 0.8 * t)
    acc = np.column_stack([shake, 0 * t, 1.0 + 0 * t]) + rng.normal(0, 0.01, (3000, 3))
    gyr = rng.normal(0, 0.3, (3000, 3))
    schema.make_recording(acc, gyr, 100.0, acc_units="g", gyr_units="deg/s")
    schema.make_recording(acc, np.radians(gyr), 100.0, acc_units="g", gyr_units="rad/s")


def test_units_are_never_assumed():
    acc, gyr, q, fs = rotating_sensor()
    with pytest.raises(RecordingError, match="acc_units is required"):
        schema.make_recording(acc, gyr, fs)
    with pytest.raises(RecordingError, match="gyr_units is required"):
        schema.make_recording(acc, gyr, fs, acc_units="g")
    labelled = xr.DataArray(acc, dims=("time", "axis"), attrs={"units": "g"})
    rec = schema.make_recording(labelled, fs=fs)
    assert rec.acc.attrs["units"] == "g" and "gyr" not in rec
    with pytest.raises(RecordingError, match="contradicts"):
        schema.make_recording(labelled, fs=fs, acc_units="m/s^2")


@given(
    st.floats(-1e3, 1e3, allow_nan=False),
    st.sampled_from(
        [("g", "m/s^2"), ("deg/s", "rad/s"), ("uT", "nT"), ("gauss", "uT")]
    ),
)
@settings(max_examples=100, deadline=None)
def test_unit_conversions_round_trip(x, pair):
    a, b = pair
    y = units.convert(x, a, b)
    np.testing.assert_allclose(units.convert(y, b, a), x, rtol=1e-14, atol=1e-300)


def test_unit_factors_and_errors():
    assert units.conversion_factor("g", "m/s^2") == units.G0
    np.testing.assert_allclose(units.convert(180.0, "°/s", "rad/s"), np.pi)
    assert units.normalise_unit("µT") == "uT"
    with pytest.raises(units.UnitsError, match="cannot convert"):
        units.convert(1.0, "g", "rad/s")
    with pytest.raises(units.UnitsError, match="unknown unit"):
        units.normalise_unit("parsec")


def test_to_units_converts_and_keeps_attrs():
    acc, gyr, q, fs = rotating_sensor(200)
    rec = schema.make_recording(
        acc, gyr, fs, attrs={"subject": "a"}, acc_units="g", gyr_units="deg/s"
    )
    si = schema.to_units(rec, acc="m/s^2", gyr="rad/s")
    np.testing.assert_allclose(si.acc.values, acc * units.G0)
    np.testing.assert_allclose(si.gyr.values, np.radians(gyr))
    assert si.acc.attrs["units"] == "m/s^2" and si.gyr.attrs["units"] == "rad/s"
    assert si.attrs == rec.attrs
    assert rec.acc.attrs["units"] == "g"  # input untouched
    schema.validate(si)
    xr.testing.assert_allclose(schema.to_units(si, acc="g", gyr="deg/s"), rec)
