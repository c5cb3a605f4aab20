"""tag-tools (animaltags) NetCDF archives, written here in the tag-tools layout.

The sensor values are the real TWLogger calibration session (foreign/tag_twlogger):
raw LSM303 counts turned into m/s² and µT the way its processing script does (y
flipped into tag-tools' [forward, right, up] frame, then the published per-axis scale
and offset). They are stored as tag-tools stores them — one variable per sensor, the
sample dimension named "<name> samples", the rate and unit as attributes — in both
NetCDF-4 and NetCDF-3, and read back.
"""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from tiltlab import io
from tiltlab.quality import UnitCheckError

FS = 50.0  # the logger's nominal rate (settings file: "Sampling Rate: 50Hz")
N = 3000


@pytest.fixture(scope="module")
def twlogger(foreign) -> dict[str, np.ndarray]:
    d = foreign / "tag_twlogger"
    raw = pd.read_csv(d / "T1D0711-00.CSV", nrows=N)
    cal = pd.read_csv(d / "Tag1_LSM303cal.csv")
    flip = np.array([1.0, -1.0, 1.0])
    acc = raw[["ACCELX", "ACCELY", "ACCELZ"]].to_numpy(float) * flip
    mag = raw[["MAGX", "MAGY", "MAGZ"]].to_numpy(float) * flip
    acc = acc * cal["AccPoly1"].to_numpy() + cal["AccPoly2"].to_numpy()
    mag = mag * cal["MagPoly1"].to_numpy() + cal["MagPoly2"].to_numpy()
    # a depth trace for the layout (the tag was not on an animal): slow dive to 10 m
    depth = 5.0 * (1 - np.cos(2 * np.pi * np.arange(N) / N))
    return {"A": acc, "M": mag, "P": depth}


def _sensor(name, values, unit, fs=FS, axes="FRU", samples_first=False, **extra):
    values = np.asarray(values, float)
    attrs = {
        "sampling_rate": fs,
        "sampling_rate_unit": "Hz",
        "unit": unit,
        "depid": "tw18_192a",
        "full_name": {"A": "Acceleration", "M": "Magnetometer"}.get(name, name),
        "frame": "tag",
        **extra,
    }
    if values.ndim == 1:
        return xr.DataArray(values, dims=(f"{name} samples",), attrs=attrs)
    attrs["axes"] = axes
    dims = (f"{name} samples", f"{name} axes")
    if samples_first:
        return xr.DataArray(values, dims=dims, attrs=attrs)
    # R's ncdf4 writes column-major: the file shows (axes, samples)
    return xr.DataArray(values.T, dims=dims[::-1], attrs=attrs)


def _write(path: Path, variables: dict, engine: str) -> Path:
    ds = xr.Dataset(variables, attrs={"depid": "tw18_192a", "creation_date": "2018"})
    fmt = "NETCDF3_64BIT" if engine == "scipy" else "NETCDF4"
    ds.to_netcdf(path, engine=engine, format=fmt)
    return path


@pytest.mark.parametrize("engine", ["h5netcdf", "scipy"])
def test_read_back_acc_mag_depth(tmp_path, twlogger, engine):
    p = _write(
        tmp_path / f"tw_{engine}.nc",
        {
            "A": _sensor("A", twlogger["A"], "m/s2"),
            "M": _sensor("M", twlogger["M"], "uT", samples_first=True),
            "P": _sensor("P", twlogger["P"], "m H2O"),
        },
        engine,
    )
    assert io.netcdf_format(p) == (
        "NetCDF-4" if engine == "h5netcdf" else "NetCDF-3 64-bit offset"
    )
    what = io.detect(p)
    assert what.startswith("tag-tools NetCDF (variables A, M, P; 50 Hz")
    rec = io.read_tagtools(p)
    assert rec.attrs["fs"] == FS
    assert "gyr" not in rec  # accelerometer + magnetometer tag: valid without gyroscope
    assert rec["acc"].attrs["units"] == "m/s^2" and rec["mag"].attrs["units"] == "uT"
    assert rec.attrs["axis_labels"] == ["forward", "left", "up"]
    # FRU (left-handed) → forward, left, up: only y changes sign
    np.testing.assert_allclose(rec["acc"].values, twlogger["A"] * [1, -1, 1])
    np.testing.assert_allclose(rec["mag"].values, twlogger["M"] * [1, -1, 1])
    # physical check of the calibrated real data: |A| ≈ 1 g, |M| of Earth's field
    assert abs(np.median(np.linalg.norm(rec["acc"].values, axis=1)) - 9.8) < 0.5
    assert 15 < np.median(np.linalg.norm(rec["mag"].values, axis=1)) < 60
    np.testing.assert_allclose(rec["depth"].values, twlogger["P"])
    assert rec["depth"].attrs["units"] == "m H2O"
    assert rec.attrs["deployment"] == "tw18_192a"
    # the generic reader and the converter's dispatcher agree
    again = io.read(p)
    np.testing.assert_array_equal(again["acc"].values, rec["acc"].values)


def test_acc_only_and_other_axes(tmp_path, twlogger):
    # accelerometer only, in g, with an axes code other than FRU: x back, y left, z up
    a_g = twlogger["A"] / 9.80665
    code = np.array([-1.0, -1.0, 1.0])  # FRU → BLU
    p = _write(
        tmp_path / "acc_only.nc",
        {"A": _sensor("A", a_g * code, "g", axes="BLU")},
        "h5netcdf",
    )
    rec = io.read_tagtools(p)
    assert list(rec.data_vars) == ["acc"]
    assert rec["acc"].attrs["units"] == "g"
    np.testing.assert_allclose(rec["acc"].values, a_g * [1, -1, 1])
    bad = _write(
        tmp_path / "ned.nc", {"A": _sensor("A", a_g, "g", axes="NED")}, "h5netcdf"
    )
    with pytest.raises(io.ReadError, match="axes 'NED'.*axes="):
        io.read_tagtools(bad)
    # an explicit axes override reads it anyway
    rec = io.read_tagtools(bad, axes=["x", "-y", "z"])
    np.testing.assert_allclose(rec["acc"].values, a_g * [1, -1, 1])


def test_rates_differ_is_refused_by_name(tmp_path, twlogger):
    p = _write(
        tmp_path / "rates.nc",
        {
            "A": _sensor("A", twlogger["A"], "m/s2"),
            "P": _sensor("P", twlogger["P"][::10], "m H2O", fs=FS / 10),
        },
        "scipy",
    )
    assert "A 50 Hz, P 5 Hz" in io.detect(p)
    with pytest.raises(io.ReadError, match=r"A 50 Hz, P 5 Hz.*variables=\['A'\]"):
        io.read_tagtools(p)
    rec = io.read_tagtools(p, variables=["A"])
    assert "depth" not in rec and rec.sizes["time"] == N


def test_unit_check_and_switch(tmp_path, twlogger):
    # m/s² values labelled g: decisively wrong, refused; the switch accepts the label
    p = _write(
        tmp_path / "mislabel.nc", {"A": _sensor("A", twlogger["A"], "g")}, "h5netcdf"
    )
    with pytest.raises(UnitCheckError):
        io.read_tagtools(p)
    rec = io.read_tagtools(p, check_units=False)
    assert rec["acc"].attrs["units"] == "g"
    # no unit at all: refused, naming the option
    q = _write(
        tmp_path / "nounit.nc",
        {"A": _sensor("A", twlogger["A"], "m/s2").drop_attrs()},
        "h5netcdf",
    )
    q2 = tmp_path / "nounit2.nc"
    ds = xr.open_dataset(q, engine="h5netcdf").load()
    ds["A"].attrs = {"sampling_rate": FS, "axes": "FRU"}
    ds.to_netcdf(q2, engine="h5netcdf")
    with pytest.raises(io.ReadError, match="acc_units="):
        io.read_tagtools(q2)
    assert io.read_tagtools(q2, acc_units="m/s^2").attrs["fs"] == FS


def test_load_netcdf_names_foreign_files(tmp_path, twlogger):
    for engine in ("scipy", "h5netcdf"):
        p = _write(
            tmp_path / f"f_{engine}.nc",
            {"A": _sensor("A", twlogger["A"], "m/s2")},
            engine,
        )
        with pytest.raises(io.NotRecordingError) as err:
            io.load_netcdf(p)
        text = str(err.value)
        assert "tag-tools NetCDF" in text and "tiltlab convert" in text
        assert "corrupt" not in text
    plain = tmp_path / "plain3.nc"
    xr.Dataset({"x": ("n", np.arange(4.0))}).to_netcdf(plain, engine="scipy")
    with pytest.raises(
        io.NotRecordingError, match=r"NetCDF-3 .*file with variables x.*make_recording"
    ):
        io.load_netcdf(plain)


@pytest.mark.parametrize("fmt", ["NETCDF4", "NETCDF3_64BIT"])
@pytest.mark.parametrize("letters", ["FRU", "BLD", "LUF"])
def test_write_tagtools_round_trip(tmp_path, fmt, letters):
    """Any tag-tools axes letters and both NetCDF formats read back to the same
    Recording values (gaps kept as NaN), units unchanged, the input untouched."""
    from tiltlab import io, simulate

    rec = simulate.simulate_session(
        4.0, 50.0, seed=2, sensor=simulate.SensorModel(magnetometer=True)
    )
    rec["acc"][20:23] = np.nan
    before = rec.copy(deep=True)
    path = io.write_tagtools(rec, tmp_path / "tag.nc", axes=letters, format=fmt)
    assert rec.identical(before)
    back = io.read_tagtools(path)
    for v in ("acc", "gyr", "mag"):
        np.testing.assert_array_equal(back[v].values, rec[v].values)
        assert back[v].attrs["units"] == rec[v].attrs["units"]
    assert back.attrs["fs"] == rec.attrs["fs"]


def test_write_tagtools_refuses_unplaceable_axes(tmp_path):
    from tiltlab import io, simulate

    rec = simulate.simulate_session(2.0, 50.0, seed=2)
    with pytest.raises(ValueError, match="one of F/B, one of L/R"):
        io.write_tagtools(rec, tmp_path / "tag.nc", axes="FFU")
    with pytest.raises(ValueError, match="format"):
        io.write_tagtools(rec, tmp_path / "tag.nc", format="HDF5")
