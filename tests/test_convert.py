"""`tiltlab convert`, `--no-check-units` and foreign-file recognition on the CLI."""

import json

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from tiltlab import cli, cohort, io, schema


def _tagtools_file(path, acc, unit, engine="h5netcdf", fs=25.0):
    attrs = {
        "sampling_rate": fs,
        "sampling_rate_unit": "Hz",
        "unit": unit,
        "axes": "FRU",
        "frame": "tag",
    }
    ds = xr.Dataset(
        {"A": xr.DataArray(acc.T, dims=("A axes", "A samples"), attrs=attrs)},
        attrs={"depid": "sim01"},
    )
    fmt = "NETCDF3_CLASSIC" if engine == "scipy" else "NETCDF4"
    ds.to_netcdf(path, engine=engine, format=fmt)
    return path


def _still_acc(n=500, g=9.80665, seed=0):
    rng = np.random.default_rng(seed)
    return np.tile([0.0, 0.0, g], (n, 1)) + rng.normal(0, 0.05 * g / 9.8, (n, 3))


@pytest.mark.parametrize("engine", ["h5netcdf", "scipy"])
def test_convert_tagtools_roundtrip(tmp_path, capsys, engine):
    src = _tagtools_file(tmp_path / "dep.nc", _still_acc(), "m/s2", engine)
    # info names the file and the command that converts it, and summarises it
    assert cli.main(["info", str(src)]) == 0
    out = capsys.readouterr().out
    assert "tag-tools NetCDF (variables A; 25 Hz" in out and "tiltlab convert" in out
    # validate refuses it in one line that says what it is, not "corrupt"
    assert cli.main(["validate", str(src)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "tag-tools" in err and "corrupt" not in err
    out_nc = tmp_path / "session.nc"
    assert cli.main(["convert", str(src), "--out", str(out_nc)]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    assert line.startswith(f"wrote {out_nc}: 500 samples at 25 Hz")
    rec = io.load_netcdf(out_nc, validate=True)
    assert rec.attrs["axis_labels"] == ["forward", "left", "up"]
    assert "gyr" not in rec
    assert cli.main(["validate", str(out_nc)]) == 0
    # refuses to overwrite without --force
    assert cli.main(["convert", str(src), "--out", str(out_nc)]) == 1
    assert "--force" in capsys.readouterr().err


def test_no_check_units_everywhere(tmp_path, capsys):
    # m/s² values labelled g: refused, naming the CLI switch; accepted with it
    src = _tagtools_file(tmp_path / "bad.nc", _still_acc(), "g")
    for argv in (
        ["info", str(src)],
        ["convert", str(src), "--out", str(tmp_path / "o.nc")],
    ):
        assert cli.main(argv) == 1
        err = capsys.readouterr().err
        assert err.startswith("tiltlab: ") and "--no-check-units" in err
        assert err.count("\n") == 1
        assert cli.main([*argv, "--no-check-units"]) == 0
        capsys.readouterr()
    rec = schema.make_recording(_still_acc(), fs=25.0, acc_units="g", check_units=False)
    saved = io.save_netcdf(rec, tmp_path / "mislabelled.nc")
    assert cli.main(["validate", str(saved)]) == 1
    assert "--no-check-units" in capsys.readouterr().err
    assert cli.main(["validate", str(saved), "--no-check-units"]) == 0


def test_cohort_manifest_check_units_switch(tmp_path):
    rec = schema.make_recording(
        _still_acc(2000),
        _still_acc(2000) * 0,
        25.0,
        acc_units="g",
        gyr_units="deg/s",
        check_units=False,
    )
    io.save_netcdf(rec, tmp_path / "a.nc")
    table = pd.DataFrame(
        {
            "session": ["s1"],
            "subject": ["m1"],
            "group": ["ctl"],
            "timepoint": [""],
            "file": ["a.nc"],
            "reader": ["netcdf"],
            "reader_options": [""],
        }
    )
    table.to_csv(tmp_path / "m.csv", index=False)
    assert len(cohort.read_manifest(tmp_path / "m.csv")) == 1
    from tiltlab.cohort.manifest import load_session
    from tiltlab.quality import UnitCheckError

    row = dict(table.iloc[0])
    with pytest.raises(UnitCheckError, match="manifest row"):
        load_session(row, tmp_path)
    row["reader_options"] = json.dumps({"check_units": False})
    assert load_session(row, tmp_path)["acc"].attrs["units"] == "g"


def test_detect_foreign_recordings(foreign):
    d = foreign
    mat = (
        d
        / "board_sunsided"
        / "unmoved-with-x-pointing-forward"
        / "mpu6050_accelerometer.mat"
    )
    assert (
        io.detect(mat) == "MATLAB v7.3 file with variables accelBuffer(12243×4 double)"
    )
    with pytest.raises(io.ReadError, match="read_multi|read_matrix"):
        io.read(mat)
    csv = d / "tag_twlogger" / "T1D0711-00.CSV"
    assert io.detect(csv).startswith("CSV with columns Date(MM/DD/YYYY)")
