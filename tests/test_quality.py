"""Data quality: saturation masks, plausibility of values for their units, aliasing, and
how validate and the command line report them."""

import json
import warnings

import numpy as np
import pytest

from tiltlab import cli, datasets, io, quality, schema
from tiltlab import quaternion as Q
from tiltlab.quality import QualityWarning
from tiltlab.schema import RecordingError

FS = 100.0


def moving_sensor(n=3000, fs=FS, seed=0):
    """A sensor turning about a tilted axis: acc (g) and gyr (deg/s), ~1 g magnitude."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    omega = np.column_stack([2.0 * np.sin(0.7 * t), 1.5 * np.cos(0.5 * t), 0.5 + 0 * t])
    q = Q.integrate_gyro(omega, fs, Q.random_quaternions(1, rng)[0])
    acc = Q.gravity(q) + rng.normal(0, 0.01, (n, 3))
    return acc, np.degrees(omega)


def still_sensor(n=1000, seed=1):
    rng = np.random.default_rng(seed)
    acc = np.array([0.0, 0.0, 1.0]) + rng.normal(0, 0.003, (n, 3))
    gyr = rng.normal(0, 0.1, (n, 3)) + [0.5, -0.3, 0.2]
    return acc, gyr


def quiet_validate(rec, **kw):
    """validate, failing on any QualityWarning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", QualityWarning)
        return schema.validate(rec, **kw)


# --------------------------------------------------------------------------- saturation


def clipped_sine(n=1000, amp=3.0, rail=2.0):
    t = np.arange(n) / FS
    x = np.column_stack(
        [amp * np.sin(2 * np.pi * 0.5 * t), 0.3 * np.cos(t), 1.0 + 0 * t]
    )
    return x, np.clip(x, -rail, rail)


def test_saturation_flags_the_clipped_runs_of_a_sine():
    raw, clipped = clipped_sine()
    mask = quality.saturation(clipped)
    expected = np.abs(clipped[:, 0]) >= 0.999 * 2.0
    np.testing.assert_array_equal(mask, expected)
    assert mask.sum() > 100  # every crest and trough, flat at the rail for many samples
    # runs of consecutive samples, not isolated ones
    d = np.diff(np.concatenate(([0], mask.astype(int), [0])))
    runs = np.flatnonzero(d == -1) - np.flatnonzero(d == 1)
    assert runs.min() >= 3
    # the unclipped sine peaks once per crest: nothing flagged
    assert not quality.saturation(raw).any()


def test_saturation_with_a_known_full_scale():
    raw, clipped = clipped_sine()
    # with the full scale given, a sample at the rail is clipped even alone
    one = raw.copy()
    one[:, 0] = 0.5
    one[123, 0] = 4.0
    assert quality.saturation(one).sum() == 0  # a single peak: not a rail
    mask = quality.saturation(one, limit=4.0)
    assert mask.sum() == 1 and mask[123]
    # asymmetric range, and the fraction
    assert quality.saturation(clipped, limit=(-2.0, 5.0)).sum() == np.sum(
        clipped[:, 0] <= -1.998
    )
    assert not quality.saturation(clipped, limit=2.1).any()
    assert quality.saturation(clipped, limit=2.1, fraction=0.95).any()
    for bad in (0, -1, (1, 2), "wide", (np.nan, 1)):
        with pytest.raises(ValueError, match="limit must be a positive full scale"):
            quality.saturation(clipped, limit=bad)
    with pytest.raises(ValueError, match="fraction must be in"):
        quality.saturation(clipped, fraction=0)
    with pytest.raises(ValueError, match="min_run must be at least 1"):
        quality.saturation(clipped, min_run=0)


def test_saturation_is_not_fooled_by_constant_or_quantised_still_signals():
    acc = np.tile([0.0, 0.0, 1.0], (500, 1))
    assert not quality.saturation(acc).any()
    rng = np.random.default_rng(3)
    lsb = 4000 / 2**16  # 16-bit, ±2000 deg/s
    coarse = np.round(rng.normal(0, 0.03, (2000, 3)) / lsb) * lsb  # noise < 1 LSB
    assert not quality.saturation(coarse).any()
    biased = np.round((rng.normal(0, 0.2, (2000, 3)) + 1.0) / lsb) * lsb
    assert not quality.saturation(biased).any()


def test_saturation_of_labelled_inputs():
    acc, gyr = moving_sensor(1000)
    gyr_clipped = np.clip(gyr, -90.0, 90.0)
    rec = schema.make_recording(
        acc,
        gyr_clipped,
        FS,
        gyr_range=90.0,
        acc_range=16,
        check_saturation=False,
        acc_units="g",
        gyr_units="deg/s",
    )
    assert rec.gyr.attrs["range"] == 90.0 and rec.acc.attrs["range"] == 16.0
    expected = (np.abs(gyr_clipped) >= 0.999 * 90).any(axis=1)
    assert expected.sum() > 10
    np.testing.assert_array_equal(quality.saturation(rec, var="gyr"), expected)
    np.testing.assert_array_equal(quality.saturation(rec.gyr), expected)  # DataArray
    np.testing.assert_array_equal(quality.saturation(rec), expected)  # acc|gyr|mag
    assert not quality.saturation(rec, var="acc").any()
    with pytest.raises(ValueError, match="give var= too"):
        quality.saturation(rec, limit=90.0)
    with pytest.raises(RecordingError, match="no variable 'mag'"):
        quality.saturation(rec, var="mag")
    with pytest.raises(RecordingError, match="gyr_range must be a positive full scale"):
        schema.make_recording(
            acc, gyr, FS, gyr_range=-5, acc_units="g", gyr_units="deg/s"
        )
    bad = rec.copy()
    bad["gyr"].attrs["range"] = "huge"
    with pytest.raises(RecordingError, match="'gyr' attribute 'range'"):
        schema.validate(bad)


def test_validate_warns_about_clipped_samples():
    acc, gyr = moving_sensor(1000)
    gyr_clipped = np.clip(gyr, -90.0, 90.0)
    n_clip = int((np.abs(gyr_clipped) >= 0.999 * 90).any(axis=1).sum())
    with pytest.warns(
        QualityWarning, match=rf"gyr: {n_clip} of 1000 samples .* clipped"
    ):
        rec = schema.make_recording(
            acc, gyr_clipped, FS, gyr_range=90.0, acc_units="g", gyr_units="deg/s"
        )
    # without the range attribute, the flat runs at the largest value give it away
    with pytest.warns(QualityWarning, match="its largest value, reached on runs"):
        schema.make_recording(acc, gyr_clipped, FS, acc_units="g", gyr_units="deg/s")
    # the check can be switched off; an unclipped recording is quiet
    quiet_validate(rec, check_saturation=False)
    quiet_validate(
        schema.make_recording(
            acc, gyr, FS, gyr_range=2000.0, acc_units="g", gyr_units="deg/s"
        )
    )
    # a full scale the data exceed is stale (e.g. units changed by hand)
    stale = rec.copy()
    stale["gyr"] = stale.gyr * (np.pi / 180) * 100
    stale["gyr"].attrs.update(units="deg/s", range=0.5)
    with pytest.warns(QualityWarning) as record:
        schema.validate(stale, check_units=False)
    first, second = (str(w.message) for w in record)
    assert first.startswith("gyr reaches 157.1 °/s, beyond its full scale (attribute")
    assert "clipped at ±157.08 °/s, its largest value" in second  # judged from the data


def test_to_units_converts_the_full_scale():
    acc, gyr = moving_sensor(500)
    rec = schema.make_recording(
        acc,
        gyr,
        FS,
        acc_range=(-4.0, 8.0),
        gyr_range=2000.0,
        acc_units="g",
        gyr_units="deg/s",
    )
    assert rec.acc.attrs["range"] == [-4.0, 8.0]
    si = schema.to_units(rec, acc="m/s^2", gyr="rad/s")
    np.testing.assert_allclose(si.acc.attrs["range"], [-4 * 9.80665, 8 * 9.80665])
    assert si.gyr.attrs["range"] == pytest.approx(np.radians(2000.0))
    quiet_validate(si)


# --------------------------------------------------------------------------- plausibility


def test_acc_in_m_s2_labelled_g_is_an_error_and_the_reverse():
    acc, gyr = moving_sensor(600)
    with pytest.raises(
        RecordingError,
        match=r"acc is labelled g but its median magnitude is 9\.8\d*: looks like m/s²",
    ):
        schema.make_recording(acc * 9.80665, gyr, FS, acc_units="g", gyr_units="deg/s")
    with pytest.raises(
        RecordingError,
        match=r"acc is labelled m/s² but its median magnitude is 1: looks like g",
    ):
        schema.make_recording(acc, gyr, FS, acc_units="m/s^2", gyr_units="deg/s")
    schema.make_recording(acc * 9.80665, gyr, FS, acc_units="m/s^2", gyr_units="deg/s")
    f = quality.check_acc_units(acc * 9.80665, "g")
    assert (
        f.severity == "error" and f.var == "acc" and f.value == pytest.approx(9.8, 0.02)
    )
    assert quality.check_acc_units(acc, "g") is None


def test_acc_far_from_1_g_is_a_warning():
    acc, gyr = moving_sensor(600)
    with pytest.warns(
        QualityWarning, match=r"acc: median magnitude 0\.3 g .* far from"
    ):
        schema.make_recording(acc * 0.3, gyr, FS, acc_units="g", gyr_units="deg/s")
    assert quality.check_acc_units(acc * 3.5, "g").severity == "warning"


def test_raw_counts_are_an_error():
    acc, gyr = still_sensor()
    counts = np.round(acc * 16384).astype(np.int16)  # ±2 g, 16 bit
    with pytest.raises(
        RecordingError,
        match=r"acc is labelled g but its median magnitude is 1\.6\d*e\+04 g .*"
        "looks like raw ADC counts: scale them to physical units first",
    ):
        schema.make_recording(counts, gyr, FS, acc_units="g", gyr_units="deg/s")
    f = quality.check_raw_counts(counts, "g", var="acc")
    assert f.severity == "error" and "raw ADC counts" in f.message
    # not integral: a wrong scale, still an error
    f = quality.check_raw_counts(acc * 1000.5, "g", var="acc")
    assert "far beyond any physical acceleration" in f.message
    gyr_counts = np.round(moving_sensor(600)[1] * 131.0)  # ±250 deg/s
    rec = schema.make_recording(
        moving_sensor(600)[0],
        gyr_counts,
        FS,
        validate_result=False,
        acc_units="g",
        gyr_units="deg/s",
    )
    with pytest.raises(RecordingError, match="gyr is labelled °/s .* raw ADC counts"):
        schema.validate(rec)


def test_gyro_in_deg_s_labelled_rad_s():
    acc, gyr = still_sensor()
    fast = gyr + [0.0, 0.0, 3000.0]  # spinning at 3000 deg/s about gravity
    with pytest.raises(
        RecordingError,
        match=r"gyr is labelled rad/s but its 99th percentile magnitude is 3000 .*"
        r"beyond any MEMS gyroscope\): looks like °/s \(set units='deg/s'\)",
    ):
        schema.make_recording(acc, fast, FS, gyr_units="rad/s", acc_units="g")
    f = quality.check_gyr_units(gyr + [0, 0, 50.0], "rad/s")
    assert f.severity == "warning" and "looks like °/s" in f.message
    assert quality.check_gyr_units(gyr + [0, 0, 20.0], "rad/s") is None


def test_slow_rotation_in_rad_s_labelled_deg_s():
    # a sensor slowly turned over (90 deg in 60 s): too slow for the dynamic check
    n = 6000
    t = np.arange(n) / FS
    angle = np.pi / 2 * t / t[-1]
    acc = np.column_stack([np.sin(angle), 0 * t, np.cos(angle)])
    rate = np.full(n, (np.pi / 2) / t[-1])  # rad/s
    gyr = np.column_stack([0 * t, rate, 0 * t])
    schema.make_recording(acc, gyr, FS, gyr_units="rad/s", acc_units="g")
    with pytest.raises(
        RecordingError,
        match=r"gyr is labelled °/s but integrates to 1\.5\d*° .* tilts by (89|90)°: "
        "looks like rad/s",
    ):
        schema.make_recording(acc, gyr, FS, gyr_units="deg/s", acc_units="g")
    assert quality.check_gyr_units(np.degrees(gyr), "deg/s", acc=acc, fs=FS) is None
    # a still recording cannot tell
    acc0, gyr0 = still_sensor()
    assert quality.check_gyr_units(gyr0, "deg/s", acc=acc0, fs=FS) is None


def test_temperature():
    acc, gyr = still_sensor()
    with pytest.raises(RecordingError, match=r"temp is labelled °C but .* look like K"):
        schema.make_recording(
            acc,
            gyr,
            FS,
            temp=np.full(len(acc), 303.0),
            acc_units="g",
            gyr_units="deg/s",
            temp_units="degC",
        )
    with pytest.raises(RecordingError, match=r"temp is labelled K but .* look like °C"):
        schema.make_recording(
            acc,
            gyr,
            FS,
            temp=np.full(len(acc), 30.0),
            temp_units="K",
            acc_units="g",
            gyr_units="deg/s",
        )
    with pytest.warns(QualityWarning, match=r"temp: 1000 of 1000 values are outside"):
        schema.make_recording(
            acc,
            gyr,
            FS,
            temp=np.full(len(acc), 120.0),
            acc_units="g",
            gyr_units="deg/s",
            temp_units="degC",
        )
    quiet_validate(
        schema.make_recording(
            acc,
            gyr,
            FS,
            temp=np.full(len(acc), 31.0),
            acc_units="g",
            gyr_units="deg/s",
            temp_units="degC",
        )
    )
    quiet_validate(
        schema.make_recording(
            acc,
            gyr,
            FS,
            temp=np.full(len(acc), 304.0),
            temp_units="K",
            acc_units="g",
            gyr_units="deg/s",
        )
    )


def test_plausibility_can_be_switched_off_and_nan_is_ignored():
    acc, gyr = moving_sensor(600)
    rec = schema.make_recording(
        acc * 9.80665, gyr, FS, check_units=False, acc_units="g", gyr_units="deg/s"
    )
    assert [f.check for f in quality.assess(rec)] == ["acc_units"]
    gappy = acc.copy()
    gappy[::7] = np.nan
    quiet_validate(
        schema.make_recording(
            gappy, gyr, FS, allow_nan=True, acc_units="g", gyr_units="deg/s"
        ),
        allow_nan=True,
    )


# --------------------------------------------------------------------------- real data


@pytest.mark.realdata
@pytest.mark.parametrize("source", ["broad:2", "fayat:example"])
def test_real_recordings_are_clean(data_mirror, source):
    with warnings.catch_warnings():
        warnings.simplefilter("error", QualityWarning)
        rec = datasets.load(source)
    quiet_validate(rec, allow_nan=True)
    assert quality.assess(rec) == []


@pytest.mark.realdata
def test_tumble_test_clips_while_turned_over(data_mirror):
    with pytest.warns(QualityWarning) as record:
        rec = datasets.load("fayat:tumble")
    messages = [str(w.message) for w in record]
    assert any(m.startswith("acc: 5 of 30543 samples") for m in messages)
    assert any(m.startswith("gyr: 6 of 30543 samples") for m in messages)
    assert rec.acc.attrs["range"] == 4.0 and rec.gyr.attrs["range"] == 1000.0
    assert not any(f.is_error for f in quality.assess(rec))
    gyr = quality.saturation(rec, var="gyr")
    np.testing.assert_array_equal(np.flatnonzero(gyr), np.arange(20861, 20867))
    # without the range attribute, the 6-sample run at -1000 deg/s still shows the rail
    rec["gyr"].attrs.pop("range")
    np.testing.assert_array_equal(quality.saturation(rec, var="gyr"), gyr)


# --------------------------------------------------------------------------- aliasing


def test_to_units_and_extra_do_not_share_memory():
    acc, gyr = moving_sensor(300)
    counter = np.arange(300)
    flags = np.zeros(300, bool)
    time = np.arange(300) / FS
    rec = schema.make_recording(
        acc,
        gyr,
        FS,
        time=time,
        extra={"counter": ("time", counter, {"long_name": "c"}), "flags": flags},
        acc_units="g",
        gyr_units="deg/s",
    )
    assert not np.shares_memory(rec.counter.values, counter)
    assert not np.shares_memory(rec.flags.values, flags)
    assert not np.shares_memory(rec.time.values, time)
    rec["counter"][:] = -1
    assert counter[5] == 5
    for out in (schema.to_units(rec), schema.to_units(rec, acc="m/s^2")):
        for v in ("acc", "gyr", "counter", "flags"):
            assert not np.shares_memory(out[v].values, rec[v].values), v


# --------------------------------------------------------------------------- CLI


def test_cli_validate_prints_warnings_and_exits_0(tmp_path, capsys):
    acc, gyr = moving_sensor(1000)
    rec = schema.make_recording(
        acc,
        np.clip(gyr, -90, 90),
        FS,
        gyr_range=90.0,
        check_saturation=False,
        acc_units="g",
        gyr_units="deg/s",
    )
    path = io.save_netcdf(rec, tmp_path / "clipped.nc")
    assert cli.main(["validate", str(path)]) == 0
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert (
        lines[0].startswith("warning: gyr: ")
        and "clipped at its full scale" in lines[0]
    )
    assert lines[-1] == f"{path}: valid Recording (1 warning)"
    assert len(lines) == 2 and err == ""


def test_cli_validate_plausibility_error_is_one_line(tmp_path, capsys):
    acc, gyr = moving_sensor(600)
    bad = schema.make_recording(
        acc * 9.80665, gyr, FS, validate_result=False, acc_units="g", gyr_units="deg/s"
    )
    path = io.save_netcdf(bad, tmp_path / "bad.nc")
    assert cli.main(["validate", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("tiltlab: acc is labelled g but its median magnitude is 9.8")
    assert err.count("\n") == 1 and "Traceback" not in err


def test_cli_validate_csv_with_range(tmp_path, capsys):
    acc, gyr = moving_sensor(600)
    gyr = np.clip(gyr, -90, 90)
    csv = tmp_path / "s.csv"
    rows = ["t_ms,ax,ay,az,gx,gy,gz"] + [
        ",".join(f"{v:.10g}" for v in (10.0 * i, *acc[i], *gyr[i])) for i in range(600)
    ]
    csv.write_text("\n".join(rows) + "\n")
    mapping = {
        "columns": {"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]},
        "units": {"acc": "g", "gyr": "deg/s"},
        "time_column": "t_ms",
        "time_units": "ms",
        "range": {"acc": 16, "gyr": 90},
    }
    mp = tmp_path / "m.json"
    mp.write_text(json.dumps(mapping))
    assert cli.main(["validate", str(csv), "--mapping", str(mp)]) == 0
    out = capsys.readouterr().out.splitlines()
    # once, although reading the CSV validates too
    assert len(out) == 2 and out[-1].endswith("valid Recording (1 warning)")
    assert (
        out[0].startswith("warning: gyr: ") and "±90 °/s (attribute 'range')" in out[0]
    )
    # info reports them on stderr
    assert cli.main(["info", str(csv), "--mapping", str(mp)]) == 0
    err = capsys.readouterr().err
    assert err.startswith("tiltlab: warning: gyr: ") and err.count("\n") == 1
