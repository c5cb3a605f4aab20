"""Readers and writers: real files, generic CSV, NetCDF round trip, damaged files."""

import shutil

import numpy as np
import pytest
import xarray as xr

from tiltlab import io, schema
from tiltlab import quaternion as Q
from tiltlab.io import ReadError
from tiltlab.quality import QualityWarning


@pytest.fixture(scope="module")
def fayat_dir(data_mirror):
    return data_mirror / "fayat2021"


def test_read_fayat_example(fayat_dir):
    rec = io.read_fayat_imu(fayat_dir / "example_imu.csv")
    assert rec.sizes["time"] == 4893 and rec.attrs["fs"] == 100.0
    assert rec.acc.attrs["units"] == "g" and rec.gyr.attrs["units"] == "deg/s"
    # time comes from the 300 Hz counter: mostly 3-count steps, some 2-count steps
    steps = np.round(np.diff(rec.time.values) * 300).astype(int)
    assert set(np.unique(steps)) == {2, 3}
    # a head IMU in g: the mean norm is close to 1 g
    assert 0.95 < float(np.linalg.norm(rec.acc.values, axis=1).mean()) < 1.05


def test_read_fayat_tumble(fayat_dir):
    # the MPU9250 was set to ±4 g, ±1000 deg/s, and clipped while turned over
    with pytest.warns(QualityWarning, match="clipped at its full scale"):
        rec = io.read_fayat_tumble(fayat_dir / "example_sensor_calibration.csv")
    assert rec.attrs["fs"] == 300.0 and rec.sizes["time"] == 30543
    assert rec.acc.attrs["range"] == 4.0 and rec.gyr.attrs["range"] == 1000.0
    np.testing.assert_allclose(np.diff(rec.time.values), 1 / 300, rtol=1e-6)


@pytest.mark.parametrize(
    "name",
    ["02_undisturbed_slow_rotation_B.hdf5", "01_undisturbed_slow_rotation_A.mat"],
)
def test_read_broad_both_layouts(data_mirror, name):
    rec = io.read_broad(data_mirror / "broad" / name)
    assert rec.attrs["fs"] == pytest.approx(285.714285714, rel=1e-9)
    assert rec.movement.dtype == bool and 0 < rec.movement.sum() < rec.sizes["time"]
    assert rec.acc.attrs["units"] == "m/s^2" and rec.gyr.attrs["units"] == "rad/s"
    q = rec.q_ref.values
    ok = np.isfinite(q).all(axis=1)
    np.testing.assert_allclose(np.linalg.norm(q[ok], axis=1), 1.0, atol=1e-6)
    # optical ground truth is aligned to the IMU: at rest, acc points along the tilt g_s = R(q)^T e_z
    still = ok & (np.linalg.norm(rec.gyr.values, axis=1) < 0.02)
    ang = Q.angle_between(rec.acc.values[still], Q.gravity(q[still]))
    assert np.median(np.degrees(ang)) < 2.0


def test_mat_and_hdf5_layouts_agree(tmp_path, data_mirror):
    """Write the .mat layout from an hdf5 trial and check both readers give the same Recording."""
    import scipy.io

    rec = io.read_broad(data_mirror / "broad" / "02_undisturbed_slow_rotation_B.hdf5")
    scipy.io.savemat(
        tmp_path / "02.mat",
        {
            "imu_acc": rec.acc.values,
            "imu_gyr": rec.gyr.values,
            "imu_mag": rec.mag.values,
            "opt_quat": rec.q_ref.values,
            "opt_pos": rec.opt_pos.values,
            "movement": rec.movement.values.astype(np.uint8)[:, None],
            "sampling_rate": np.array([[rec.attrs["fs"]]]),
            "info": np.array([rec.attrs["info"]]),
        },
    )
    back = io.read_broad(tmp_path / "02.mat")
    for v in ("acc", "gyr", "mag", "q_ref", "opt_pos", "movement"):
        np.testing.assert_array_equal(back[v].values, rec[v].values)
    assert back.attrs["info"] == rec.attrs["info"]


def test_generic_csv(tmp_path):
    rng = np.random.default_rng(2)
    n, fs = 400, 50.0
    acc = rng.normal(0, 0.01, (n, 3)) + [0, 0, 9.81]
    gyr = rng.normal(0, 0.01, (n, 3))
    t = 10.0 + np.arange(n) / fs
    lines = ["T;AX;AY;AZ;GX;GY;GZ;TEMP"] + [
        ";".join(f"{v:.17g}" for v in (t[i], *acc[i], *gyr[i], 25.0 + i * 0.001))
        for i in range(n)
    ]
    p = tmp_path / "log.csv"
    p.write_text("\n".join(lines))
    rec = io.read_csv(
        p,
        {"acc": ["AX", "AY", "AZ"], "gyr": ["GX", "GY", "GZ"], "temp": "TEMP"},
        {"acc": "m/s^2", "gyr": "rad/s", "temp": "degC"},
        time_column="T",
        sep=";",
    )
    assert rec.attrs["fs"] == pytest.approx(fs) and "fs_source" in rec.attrs
    np.testing.assert_array_equal(rec.acc.values, acc)
    np.testing.assert_array_equal(rec.time.values, t)
    assert rec.temp.attrs["units"] == "degC"
    with pytest.raises(ValueError, match="units must give the unit of 'gyr'"):
        io.read_csv(
            p,
            {"acc": ["AX", "AY", "AZ"], "gyr": ["GX", "GY", "GZ"]},
            {"acc": "g"},
            fs=fs,
            sep=";",
        )
    with pytest.raises(ValueError, match="never assumes a sampling rate"):
        io.read_csv(
            p,
            {"acc": ["AX", "AY", "AZ"], "gyr": ["GX", "GY", "GZ"]},
            {"acc": "g", "gyr": "rad/s"},
            sep=";",
        )
    with pytest.raises(ReadError, match="missing column"):
        io.read_csv(
            p,
            {"acc": ["AX", "AY", "Q"], "gyr": ["GX", "GY", "GZ"]},
            {"acc": "g", "gyr": "rad/s"},
            fs=fs,
            sep=";",
        )


def test_truncated_and_corrupt_files(tmp_path, data_mirror):
    src = data_mirror / "fayat2021" / "example_imu.csv"
    text = src.read_text()
    cut = tmp_path / "cut.csv"
    cut.write_text(text[: len(text) // 2 - 7])  # ends mid-line
    with pytest.raises(ReadError, match="incomplete.*truncated"):
        io.read_fayat_imu(cut)
    garbage = tmp_path / "garbage.csv"
    garbage.write_text(text.replace("0.4", "zz", 1))
    with pytest.raises(ReadError, match="non-numeric value"):
        io.read_fayat_imu(garbage)
    h5 = data_mirror / "broad" / "02_undisturbed_slow_rotation_B.hdf5"
    bad_h5 = tmp_path / "bad.hdf5"
    bad_h5.write_bytes(h5.read_bytes()[:100_000])
    with pytest.raises(ReadError, match="truncated or corrupt"):
        io.read_broad(bad_h5)
    mat = data_mirror / "broad" / "01_undisturbed_slow_rotation_A.mat"
    bad_mat = tmp_path / "bad.mat"
    bad_mat.write_bytes(mat.read_bytes()[:100_000])
    with pytest.raises(ReadError, match="truncated or corrupt"):
        io.read_broad(bad_mat)
    with pytest.raises(ReadError, match="no such file"):
        io.read_broad(tmp_path / "nothing.hdf5")
    other = tmp_path / "x.txt"
    shutil.copy(src, other)
    with pytest.raises(ReadError, match="unknown BROAD file type"):
        io.read_broad(other)


def test_netcdf_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(5)
    n = 500
    q = Q.random_quaternions(n, rng)
    rec = schema.make_recording(
        Q.gravity(q),
        rng.normal(0, 1, (n, 3)),
        200.0,
        acc_units="g",
        gyr_units="rad/s",
        q_ref=q,
        mag=rng.normal(0, 30, (n, 3)),
        mag_units="uT",
        temp=25 + rng.normal(0, 0.1, n),
        temp_units="degC",
        extra={
            "moving": ("time", rng.random(n) > 0.5, {"long_name": "a mask"}),
            "state": (
                "time",
                rng.integers(0, 4, n).astype(np.int8),
                {"legend": {"0": "still", "1": "walk"}},
            ),
        },
        attrs={
            "subject": "rat 7",
            "flag": True,
            "none": None,
            "offsets": [0.1, -0.2, 0.05],
            "nested": {"a": 1, "b": [1, 2]},
            "arr": np.arange(3.0),
            "n": np.int64(4),
        },
        check_units=False,
    )
    path = io.save_netcdf(rec, tmp_path / "sub" / "r.nc")
    back = io.load_netcdf(path, validate=True, check_units=False)  # random gyro data
    xr.testing.assert_identical(back, rec.assign_attrs(arr=back.attrs["arr"]))
    np.testing.assert_array_equal(back.attrs["arr"], rec.attrs["arr"])
    assert back.attrs["flag"] is True and back.attrs["none"] is None
    assert back.state.attrs["legend"] == {"0": "still", "1": "walk"}
    assert back.moving.dtype == bool and back.state.dtype == np.int8
    bad = tmp_path / "bad.nc"
    bad.write_bytes(path.read_bytes()[:2000])
    with pytest.raises(ReadError, match="truncated or corrupt"):
        io.load_netcdf(bad)


def test_netcdf_round_trip_real_trial(tmp_path, data_mirror):
    rec = io.read_broad(data_mirror / "broad" / "02_undisturbed_slow_rotation_B.hdf5")
    back = io.load_netcdf(io.save_netcdf(rec, tmp_path / "t.nc"), validate=True)
    xr.testing.assert_identical(back, rec)


# --------------------------------------------------------------------------- generic CSV with a mapping


def _lab_csv(path, *, n=600, fs=300.0, time_factor=1e3, sep=","):
    """A lab's own CSV: time in ms (by default), acc in g, gyro in deg/s, temperature."""
    rng = np.random.default_rng(7)
    acc = rng.normal(0, 0.01, (n, 3)) + [0, 0, 1.0]
    gyr = rng.normal(0, 1.0, (n, 3))
    t = 1234.5 + np.arange(n) / fs * time_factor
    head = sep.join(["t_ms", "AccX", "AccY", "AccZ", "GyrX", "GyrY", "GyrZ", "T"])
    rows = [
        sep.join(f"{v:.17g}" for v in (t[i], *acc[i], *gyr[i], 30.0)) for i in range(n)
    ]
    path.write_text("\n".join([head, *rows]) + "\n")
    return acc, gyr, t


MAPPING = {
    "columns": {
        "acc": ["AccX", "AccY", "AccZ"],
        "gyr": ["GyrX", "GyrY", "GyrZ"],
        "temp": "T",
    },
    "units": {"acc": "g", "gyr": "deg/s", "temp": "degC"},
    "time_column": "t_ms",
    "time_units": "ms",
}


def test_csv_mapping_from_json_file(tmp_path):
    import json

    p = tmp_path / "session.csv"
    acc, gyr, t = _lab_csv(p, sep=";")
    mp = tmp_path / "mapping.json"
    mp.write_text(json.dumps({**MAPPING, "sep": ";", "attrs": {"subject": "rat 3"}}))
    checked = io.read_csv_mapping(mp)
    assert checked["time_scale"] == 1e-3 and checked["read_csv"] == {"sep": ";"}
    assert checked["columns"]["temp"] == ["T"]
    for rec in (io.read_csv(p, mapping=mp), io.read_csv(p, mapping=str(mp))):
        assert rec.attrs["fs"] == pytest.approx(300.0)
        assert rec.attrs["subject"] == "rat 3" and "ms" in rec.attrs["fs_source"]
        np.testing.assert_array_equal(rec.acc.values, acc)
        np.testing.assert_allclose(rec.time.values, t / 1e3, rtol=1e-15)
        assert rec.gyr.attrs["units"] == "deg/s"
    # explicit arguments override the mapping
    rec = io.read_csv(p, mapping=mp, fs=300.0, attrs={"subject": "rat 4"})
    assert rec.attrs["fs"] == 300.0 and rec.attrs["subject"] == "rat 4"
    assert "fs_source" not in rec.attrs


@pytest.mark.parametrize(
    "time_spec",
    [
        {"time_units": "ms"},
        {"time_scale": 1e-3},
        {"units": {"acc": "g", "gyr": "deg/s", "temp": "degC", "time": "ms"}},
    ],
)
def test_csv_time_column_in_ms(tmp_path, time_spec):
    p = tmp_path / "s.csv"
    _lab_csv(p)
    m = {k: v for k, v in MAPPING.items() if k != "time_units"} | time_spec
    rec = io.read_csv(p, mapping=m)
    assert rec.attrs["fs"] == pytest.approx(300.0)
    assert rec.time.values[0] == pytest.approx(1.2345)


def test_csv_time_in_us_and_keyword_arguments(tmp_path):
    p = tmp_path / "s.csv"
    _lab_csv(p, fs=100.0, time_factor=1e6)
    rec = io.read_csv(
        p,
        MAPPING["columns"],
        MAPPING["units"],
        time_column="t_ms",
        time_units="us",
    )
    assert rec.attrs["fs"] == pytest.approx(100.0)


def test_csv_implausible_fs_suggests_the_time_unit(tmp_path):
    p = tmp_path / "s.csv"
    _lab_csv(p)
    m = {k: v for k, v in MAPPING.items() if k != "time_units"}
    # time column read as seconds: 0.3 Hz, and the message says it is probably ms
    with pytest.raises(ValueError, match=r'0\.3 Hz.*"time_units": "ms".*300 Hz'):
        io.read_csv(p, mapping=m)
    # an fs that the time column contradicts
    with pytest.raises(ValueError, match="fs = 300 Hz but time column 't_ms'"):
        io.read_csv(p, mapping={**m, "fs": 300})
    with pytest.raises(ValueError, match="outside the plausible range"):
        io.read_csv(p, mapping={**MAPPING, "fs_range": [1000, 5000]})
    # the check can be switched off
    rec = io.read_csv(p, mapping=m, fs_range=None)
    assert rec.attrs["fs"] == pytest.approx(0.3)
    with pytest.raises(ValueError, match="time unit is given twice"):
        io.read_csv(p, mapping={**MAPPING, "time_scale": 1e-6})
    with pytest.raises(ValueError, match="time_units must be one of"):
        io.read_csv(p, mapping={**MAPPING, "time_units": "minutes"})


def test_csv_missing_column_is_named_with_the_available_ones(tmp_path):
    p = tmp_path / "s.csv"
    _lab_csv(p)
    m = {**MAPPING, "columns": {**MAPPING["columns"], "acc": ["AccX", "AccY", "Acc_Z"]}}
    with pytest.raises(ReadError) as err:
        io.read_csv(p, mapping=m)
    msg = str(err.value)
    assert "'Acc_Z' (mapped to acc)" in msg and "did you mean 'AccZ'" in msg
    assert "available columns: 't_ms', 'AccX'" in msg
    with pytest.raises(ReadError, match=r"'time' \(time_column\)"):
        io.read_csv(p, mapping={**MAPPING, "time_column": "time"})
    # a wrong separator leaves one column: the message says so
    with pytest.raises(ReadError, match="is the separator right"):
        io.read_csv(p, mapping={**MAPPING, "sep": ";"})


def test_csv_mapping_errors(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"columns": {"acc": ["a", "b"}')
    with pytest.raises(ValueError, match=r"bad.json: not valid JSON \(line 1"):
        io.read_csv_mapping(bad)
    with pytest.raises(ReadError, match="no such mapping file"):
        io.read_csv_mapping(tmp_path / "nothing.json")
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['colums'\]"):
        io.read_csv_mapping({"colums": {}, **MAPPING})
    with pytest.raises(ValueError, match=r"columns\['acc'\] needs 3 column"):
        io.read_csv_mapping({**MAPPING, "columns": {"acc": ["a", "b"], "gyr": "g"}})
    with pytest.raises(ValueError, match=r"units\['gyr'\]: unknown unit 'rpm'"):
        io.read_csv_mapping({**MAPPING, "units": {"acc": "g", "gyr": "rpm"}})
    with pytest.raises(ValueError, match="never assumes a sampling rate"):
        io.read_csv_mapping({"columns": MAPPING["columns"], "units": MAPPING["units"]})
    with pytest.raises(ValueError, match="pandas.read_csv does not take"):
        io.read_csv_mapping({**MAPPING, "read_csv": {"nope": 1}})


@pytest.mark.parametrize(
    ("factor", "unit", "name", "given"),
    [
        (1e3, "ms", "milliseconds", None),
        (1e6, "us", "microseconds", None),
        (1.0, "s", "seconds", "ms"),  # seconds declared as ms: 30 kHz
    ],
)
def test_csv_time_unit_hint_names_the_unit(tmp_path, factor, unit, name, given):
    p = tmp_path / "s.csv"
    _lab_csv(p, fs=100.0, time_factor=factor)
    m = {k: v for k, v in MAPPING.items() if k != "time_units"}
    if given:
        m["time_units"] = given
    # the options come from a mapping: the fix is named as its JSON key
    expected = f'the time column looks like {name}: give "time_units": "{unit}"'
    with pytest.raises(ValueError, match=rf"outside the plausible range.*{expected}"):
        io.read_csv(p, mapping=m)
    with pytest.raises(ValueError, match=rf"fs = 100 Hz but .*{expected}"):
        io.read_csv(p, mapping={**m, "fs": 100})
    rec = io.read_csv(p, mapping={**m, "time_units": unit})
    assert rec.attrs["fs"] == pytest.approx(100.0)


def test_csv_full_scale_from_the_mapping(tmp_path):
    p = tmp_path / "s.csv"
    _lab_csv(p)
    rec = io.read_csv(
        p, mapping={**MAPPING, "range": {"acc": 16, "gyr": [-2000, 2000]}}
    )
    assert rec.acc.attrs["range"] == 16.0 and rec.gyr.attrs["range"] == 2000.0
    rec = io.read_csv(p, mapping=MAPPING, range={"gyr": 250})
    assert rec.gyr.attrs["range"] == 250.0 and "range" not in rec.acc.attrs
    with pytest.raises(
        ValueError, match=r"range\['gyr'\] must be a positive full scale"
    ):
        io.read_csv_mapping({**MAPPING, "range": {"gyr": -1}})
    with pytest.raises(ValueError, match=r"range\['temp'\]: a full scale is given for"):
        io.read_csv_mapping({**MAPPING, "range": {"temp": 100}})
    with pytest.raises(ValueError, match=r"range\['mag'\] is given but 'mag' is not"):
        io.read_csv_mapping({**MAPPING, "range": {"mag": 4900}})
    with pytest.raises(ValueError, match="'range' must map variables"):
        io.read_csv_mapping({**MAPPING, "range": 16})


def test_csv_scale_reads_columns_in_mg_or_counts(tmp_path):
    p = tmp_path / "s.csv"
    acc, gyr, _ = _lab_csv(p)
    # a factor from the column's numbers to the units (here: gyroscope counts of 2 °/s)
    rec = io.read_csv(p, mapping=MAPPING, scale={"gyr": 2.0})
    np.testing.assert_allclose(rec.gyr.values, 2.0 * gyr)
    np.testing.assert_array_equal(rec.acc.values, acc)
    assert rec.attrs["csv_scale"] == {"gyr": 2.0}
    checked = io.read_csv_mapping({**MAPPING, "scale": {"acc": 0.5}})
    assert checked["scale"] == {"acc": 0.5}
    assert io.read_csv_mapping(MAPPING)["scale"] == {}
    # a prefixed or raw unit is refused with the scale that reads it
    with pytest.raises(
        ValueError,
        match=r"'mg' looks like milli-g: give units \{'acc': 'g'\} and scale",
    ):
        io.read_csv_mapping({**MAPPING, "units": {"acc": "mg", "gyr": "deg/s"}})
    with pytest.raises(ValueError, match="'mdps' looks like milli-deg/s"):
        io.read_csv_mapping({**MAPPING, "units": {"acc": "g", "gyr": "mdps"}})
    with pytest.raises(ValueError, match="for raw ADC counts give the physical unit"):
        io.read_csv_mapping({**MAPPING, "units": {"acc": "LSB", "gyr": "deg/s"}})
    with pytest.raises(ValueError, match=r"scale\['acc'\] must be"):
        io.read_csv_mapping({**MAPPING, "scale": {"acc": 0}})
    with pytest.raises(
        ValueError, match=r"scale\['mag'\]: a factor is given for a mapped"
    ):
        io.read_csv_mapping({**MAPPING, "scale": {"mag": 0.1}})
    with pytest.raises(ValueError, match="'scale' must map variables to factors"):
        io.read_csv_mapping({**MAPPING, "scale": 0.001})


def test_csv_dropped_samples_are_refused_or_kept_as_nan(tmp_path):
    p = tmp_path / "s.csv"
    acc, gyr, t = _lab_csv(p, fs=100.0)
    lines = p.read_text().splitlines(keepends=True)
    # the logger lost samples 200–204 (five rows of data, after the header)
    p.write_text("".join(lines[:201] + lines[206:]))
    with pytest.raises(
        schema.RecordingError,
        match=r'skips samples \(1 gap: 0\.05 s at t = .*"gaps": "nan"',
    ):
        io.read_csv(p, mapping=MAPPING)
    # the same hint as a keyword when the options are keywords
    with pytest.raises(schema.RecordingError, match=r"skips samples .*gaps='nan'"):
        io.read_csv(
            p,
            MAPPING["columns"],
            MAPPING["units"],
            time_column="t_ms",
            time_units="ms",
        )
    rec = io.read_csv(p, mapping={**MAPPING, "gaps": "nan"})
    assert rec.sizes["time"] == 600 and rec.attrs["fs"] == pytest.approx(100.0)
    assert np.isnan(rec.acc.values[200:205]).all()
    np.testing.assert_array_equal(rec.acc.values[205:], acc[205:])
    np.testing.assert_allclose(rec.time.values, t / 1e3, rtol=1e-12)
    assert rec.attrs["gaps"].startswith("5 missing samples filled with NaN; 1 gap")
    schema.validate(rec, allow_nan=True)
    # a gap-free file is unchanged by gaps="nan"
    q = tmp_path / "q.csv"
    _lab_csv(q, fs=100.0)
    assert "gaps" not in io.read_csv(q, mapping=MAPPING, gaps="nan").attrs
    with pytest.raises(ValueError, match="gaps must be one of 'raise', 'nan'"):
        io.read_csv_mapping({**MAPPING, "gaps": "fill"})
    # samples off the 1/fs grid cannot be placed
    r = tmp_path / "r.csv"
    lines = [lines[0]] + [
        ",".join(
            [f"{1234.5 + 10 * i + (15 if i > 300 else 0):.17g}", *row.split(",")[1:]]
        )
        for i, row in enumerate(lines[1:])
    ]
    r.write_text("".join(lines))
    with pytest.raises(schema.RecordingError, match="not on a regular grid"):
        io.read_csv(r, mapping=MAPPING, fs=100.0, gaps="nan")
