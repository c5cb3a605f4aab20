"""A catalogue of bad inputs: every public function gives a right answer or a clear error.

Each case is ``(id, call, exception type(s), regex)``: ``call(tmp)`` performs one bad call
(``tmp`` is a fresh temporary folder), and the error must be of the given type with a
message matching the regex, which names the argument or variable (and, where possible,
its value). Cases for modules whose owner has not fixed them yet are marked
``xfail(strict=True, reason="owner: <module>")``.

The last part fuzzes the Recording constructor and :func:`tiltlab.filters.estimate` with
hypothesis: a valid result, or a RecordingError/ValueError naming the problem — never
another exception, never a silent NaN.
"""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from hypothesis import HealthCheck, Phase, given, note, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tiltlab import (
    behavior,
    calibration,
    cohort,
    datasets,
    dsp,
    evaluate,
    filters,
    frames,
    intervals,
    io,
    quaternion,
    schema,
    sphere,
    stats,
    trig,
)
from tiltlab._validate import RecordingError
from tiltlab.cli import main as cli_main

NAN, INF = float("nan"), float("inf")

# --------------------------------------------------------------------------- small inputs

FS = 100.0
N = 1000
_t = np.arange(N) / FS
_theta = 0.5 * np.sin(2 * np.pi * 0.5 * _t)  # rad, rotation about x
_dtheta = 0.5 * 2 * np.pi * 0.5 * np.cos(2 * np.pi * 0.5 * _t)  # rad/s
_noise = np.random.default_rng(42)
ACC = np.column_stack([np.zeros(N), np.sin(_theta), np.cos(_theta)])  # g
ACC = ACC + _noise.normal(0.0, 1e-3, ACC.shape)
GYR = np.column_stack([np.degrees(_dtheta), np.zeros(N), np.zeros(N)]) + [
    0.5,
    -0.3,
    0.2,
]
GYR = GYR + _noise.normal(0.0, 0.05, GYR.shape)
_mw = 48.0 * np.array([0.0, np.cos(1.1), -np.sin(1.1)])  # ENU field, uT
MAG = np.column_stack(
    [
        np.full(N, _mw[0]),
        np.cos(_theta) * _mw[1] + np.sin(_theta) * _mw[2],
        -np.sin(_theta) * _mw[1] + np.cos(_theta) * _mw[2],
    ]
)
REC = schema.make_recording(
    ACC,
    GYR,
    FS,
    mag=MAG,
    attrs={"session": "s1"},
    acc_units="g",
    gyr_units="deg/s",
    mag_units="uT",
)
REC6 = schema.make_recording(ACC, GYR, FS, acc_units="g", gyr_units="deg/s")
Q = filters.estimate(REC6, "lowpass").values
G = quaternion.gravity(Q)  # unit tilt vectors
RNG = np.random.default_rng(0)
UNIT = sphere.vmf_sample([0.0, 0.0, 1.0], 5.0, 200, rng=1)
SPEED = np.linalg.norm(GYR, axis=1)  # deg/s
STILL_IV = np.array([[0, 100], [300, 400]])
CUBE = np.array(
    [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1.0]]
)  # six tumble poses (g)
SPHERE_PTS = frames.fibonacci_lattice(30)


def _with(ds: xr.Dataset, **attrs) -> xr.Dataset:
    """A copy of ``ds`` with dataset attrs replaced."""
    out = ds.copy()
    out.attrs = {**ds.attrs, **attrs}
    return out


def _var_attrs(ds: xr.Dataset, var: str, **attrs) -> xr.Dataset:
    out = ds.copy(deep=True)
    out[var].attrs = {**ds[var].attrs, **attrs}
    return out


def _drop_fs(ds: xr.Dataset) -> xr.Dataset:
    out = ds.copy()
    out.attrs = {k: v for k, v in ds.attrs.items() if k != "fs"}
    return out


def _nan_acc(ds: xr.Dataset) -> xr.Dataset:
    out = ds.copy(deep=True)
    out["acc"][5, 1] = np.nan
    return out


def _csv(tmp: Path, text: str, name: str = "data.csv") -> Path:
    p = tmp / name
    p.write_text(text)
    return p


_GOOD_CSV = "t,ax,ay,az,gx,gy,gz\n" + "".join(
    f"{i / 100:.2f},0,0,1,0.1,0,0\n" for i in range(50)
)
_FAYAT_IMU = "counter,ax,ay,az,gx,gy,gz\n" + "".join(
    f"{1000 + 3 * i},0,0,1,0.1,0,0\n" for i in range(50)
)
_FAYAT_TUMBLE = ",ax,ay,az,gx,gy,gz,time\n" + "".join(
    f"{i},0,0,1,0.1,0,0,{i / 300:.6f}\n" for i in range(50)
)
_MAPPING = {
    "columns": {"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]},
    "units": {"acc": "g", "gyr": "deg/s"},
    "time_column": "t",
}


def _mapping_file(tmp: Path, mapping) -> Path:
    p = tmp / "mapping.json"
    p.write_text(json.dumps(mapping))
    return p


_MANIFEST_COLS = "session,subject,group,timepoint,file,reader\n"


def _manifest(tmp: Path, rows: str, header: str = _MANIFEST_COLS) -> Path:
    return _csv(tmp, header + rows, "manifest.csv")


# --------------------------------------------------------------------------- the catalogue

CASES: list = []


def case(id_, call, exc, match, owner: str | None = None, strict: bool = True):
    """Register one bad call. ``owner`` marks a case that the module's owner must fix."""
    marks = []
    if owner is not None:
        marks.append(pytest.mark.xfail(strict=strict, reason=f"owner: {owner}"))
    CASES.append(pytest.param(call, exc, match, id=id_, marks=marks))


# ----------------------------------------------------------------------------- schema
case(
    "schema-fs-none",
    lambda t: schema.make_recording(ACC, GYR, None, acc_units="g", gyr_units="deg/s"),
    ValueError,
    r"\bfs\b",
)
case(
    "schema-fs-zero",
    lambda t: schema.make_recording(ACC, GYR, 0, acc_units="g", gyr_units="deg/s"),
    ValueError,
    r"\bfs\b.*\b0",
)
case(
    "schema-fs-negative",
    lambda t: schema.make_recording(ACC, GYR, -100, acc_units="g", gyr_units="deg/s"),
    ValueError,
    r"\bfs\b.*-100",
)
case(
    "schema-fs-nan",
    lambda t: schema.make_recording(ACC, GYR, NAN, acc_units="g", gyr_units="deg/s"),
    ValueError,
    r"\bfs\b.*nan",
)
case(
    "schema-fs-inf",
    lambda t: schema.make_recording(ACC, GYR, INF, acc_units="g", gyr_units="deg/s"),
    ValueError,
    r"\bfs\b.*inf",
)
case(
    "schema-fs-string",
    lambda t: schema.make_recording(ACC, GYR, "fast", acc_units="g", gyr_units="deg/s"),
    ValueError,
    r"\bfs\b.*fast",
)
case(
    "schema-acc-shape",
    lambda t: schema.make_recording(
        ACC[:, :2], GYR, FS, acc_units="g", gyr_units="deg/s"
    ),
    RecordingError,
    r"\bacc\b.*shape",
)
case(
    "schema-gyr-1d",
    lambda t: schema.make_recording(
        ACC, GYR[:, 0], FS, acc_units="g", gyr_units="deg/s"
    ),
    RecordingError,
    r"\bgyr\b.*shape",
)
case(
    "schema-length-mismatch",
    lambda t: schema.make_recording(
        ACC, GYR[:-1], FS, acc_units="g", gyr_units="deg/s"
    ),
    RecordingError,
    r"acc and gyr",
)
case(
    "schema-acc-nan",
    lambda t: schema.make_recording(
        np.where(ACC > 0.99, NAN, ACC), GYR, FS, acc_units="g", gyr_units="deg/s"
    ),
    RecordingError,
    r"\bacc\b.*non-finite",
)
case(
    "schema-gyr-inf",
    lambda t: schema.make_recording(
        ACC, np.where(GYR > 40, INF, GYR), FS, acc_units="g", gyr_units="deg/s"
    ),
    RecordingError,
    r"\bgyr\b.*non-finite",
)
case(
    "schema-acc-units-unknown",
    lambda t: schema.make_recording(
        ACC, GYR, FS, acc_units="furlong", gyr_units="deg/s"
    ),
    ValueError,
    r"furlong",
)
case(
    "schema-gyr-units-wrong-quantity",
    lambda t: schema.make_recording(ACC, GYR, FS, gyr_units="g", acc_units="g"),
    RecordingError,
    r"\bgyr\b.*units",
)
case(
    "schema-gyr-units-implausible",
    lambda t: schema.make_recording(
        ACC, np.radians(GYR), FS, acc_units="g", gyr_units="deg/s"
    ),
    RecordingError,
    r"\bgyr\b.*(units|rad/s)",
)
case(
    "schema-time-shape",
    lambda t: schema.make_recording(
        ACC, GYR, FS, time=_t[:-1], acc_units="g", gyr_units="deg/s"
    ),
    RecordingError,
    r"\btime\b.*shape",
)
case(
    "schema-time-decreasing",
    lambda t: schema.make_recording(
        ACC, GYR, FS, time=_t[::-1], acc_units="g", gyr_units="deg/s"
    ),
    RecordingError,
    r"\btime\b.*increasing",
)
case(
    "schema-time-contradicts-fs",
    lambda t: schema.make_recording(
        ACC, GYR, 2 * FS, time=_t, acc_units="g", gyr_units="deg/s"
    ),
    RecordingError,
    r"time is irregular|fs",
)
case(
    "schema-t0-nan",
    lambda t: schema.make_recording(
        ACC, GYR, FS, t0=NAN, acc_units="g", gyr_units="deg/s"
    ),
    RecordingError,
    r"\bt0\b|time",
)
case(
    "schema-q_ref-non-unit",
    lambda t: schema.make_recording(
        ACC, GYR, FS, q_ref=2 * Q, acc_units="g", gyr_units="deg/s"
    ),
    RecordingError,
    r"q_ref.*non-unit",
)
case(
    "schema-q_ref-shape",
    lambda t: schema.make_recording(
        ACC, GYR, FS, q_ref=Q[:, :3], acc_units="g", gyr_units="deg/s"
    ),
    ValueError,
    r"q_ref",
)
case(
    "schema-mag-shape",
    lambda t: schema.make_recording(
        ACC, GYR, FS, mag=MAG[:, :2], acc_units="g", gyr_units="deg/s", mag_units="uT"
    ),
    ValueError,
    r"\bmag\b",
)
case(
    "schema-temp-length",
    lambda t: schema.make_recording(
        ACC,
        GYR,
        FS,
        temp=np.zeros(N - 1),
        acc_units="g",
        gyr_units="deg/s",
        temp_units="degC",
    ),
    ValueError,
    r"\btemp\b",
)
case(
    "schema-mag-nan",
    lambda t: schema.make_recording(
        ACC, GYR, FS, mag=MAG * NAN, acc_units="g", gyr_units="deg/s", mag_units="uT"
    ),
    RecordingError,
    r"\bmag\b.*non-finite",
)
case(
    "schema-extra-shape",
    lambda t: schema.make_recording(
        ACC,
        GYR,
        FS,
        extra={"flags": np.zeros((N, 2))},
        acc_units="g",
        gyr_units="deg/s",
    ),
    RecordingError,
    r"flags",
)
case(
    "schema-validate-not-dataset",
    lambda t: schema.validate(ACC),
    RecordingError,
    r"xarray\.Dataset",
)
case(
    "schema-validate-no-fs",
    lambda t: schema.validate(_drop_fs(REC6)),
    RecordingError,
    r"'fs'",
)
case(
    "schema-validate-fs-negative",
    lambda t: schema.validate(_with(REC6, fs=-5.0)),
    RecordingError,
    r"'fs'.*-5",
)
case(
    "schema-validate-no-units",
    lambda t: schema.validate(
        _var_attrs(REC6, "acc", units=None).pipe(
            lambda d: d.assign(acc=d["acc"].drop_attrs())
        )
    ),
    RecordingError,
    r"'acc'.*units",
)
case(
    "schema-validate-max_jitter-negative",
    lambda t: schema.validate(REC6, max_jitter=-1.0),
    ValueError,
    r"max_jitter must.*-1",
)
case(
    "schema-validate-quat_atol-nan",
    lambda t: schema.validate(REC6, quat_atol=NAN),
    ValueError,
    r"quat_atol.*nan",
)
case(
    "schema-to_units-wrong-quantity",
    lambda t: schema.to_units(REC6, acc="deg/s"),
    ValueError,
    r"deg/s",
)
case(
    "schema-to_units-unknown-variable",
    lambda t: schema.to_units(REC6, foo="g"),
    RecordingError,
    r"'foo'",
)
case(
    "schema-to_units-unknown-unit",
    lambda t: schema.to_units(REC6, gyr="rpm?"),
    ValueError,
    r"rpm\?",
)

# ----------------------------------------------------------------------------- io
case(
    "io-read_csv-missing-file",
    lambda t: io.read_csv(t / "nope.csv", mapping=_MAPPING),
    OSError,
    r"nope\.csv",
)
case(
    "io-read_csv-missing-column",
    lambda t: io.read_csv(
        _csv(t, _GOOD_CSV),
        mapping={
            **_MAPPING,
            "columns": {"acc": ["ax", "ay", "AZ"], "gyr": ["gx", "gy", "gz"]},
        },
    ),
    OSError,
    r"AZ",
)
case(
    "io-read_csv-no-fs-no-time",
    lambda t: io.read_csv(
        _csv(t, _GOOD_CSV),
        {"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]},
        {"acc": "g", "gyr": "deg/s"},
    ),
    ValueError,
    r"\bfs\b|time_column",
)
case(
    "io-read_csv-fs-negative",
    lambda t: io.read_csv(
        _csv(t, _GOOD_CSV),
        {"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]},
        {"acc": "g", "gyr": "deg/s"},
        fs=-100,
    ),
    ValueError,
    r"\bfs\b.*-100",
)
case(
    "io-read_csv-fs-nan",
    lambda t: io.read_csv(
        _csv(t, _GOOD_CSV),
        {"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]},
        {"acc": "g", "gyr": "deg/s"},
        fs=NAN,
    ),
    ValueError,
    r"\bfs\b.*nan",
)
case(
    "io-read_csv-missing-units",
    lambda t: io.read_csv(
        _csv(t, _GOOD_CSV),
        {"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]},
        {"acc": "g"},
        time_column="t",
    ),
    ValueError,
    r"\bgyr\b",
)
case(
    "io-read_csv-bad-time_units",
    lambda t: io.read_csv(
        _csv(t, _GOOD_CSV), mapping={**_MAPPING, "time_units": "fortnight"}
    ),
    ValueError,
    r"time_units.*fortnight",
)
case(
    "io-read_csv-non-numeric",
    lambda t: io.read_csv(
        _csv(t, _GOOD_CSV.replace("0.1,0,0\n", "abc,0,0\n", 1)), mapping=_MAPPING
    ),
    OSError,
    r"abc.*'gx'",
)
case(
    "io-read_csv-wrong-acc-width",
    lambda t: io.read_csv(
        _csv(t, _GOOD_CSV),
        mapping={
            **_MAPPING,
            "columns": {"acc": ["ax", "ay"], "gyr": ["gx", "gy", "gz"]},
        },
    ),
    ValueError,
    r"\bacc\b",
)
case(
    "io-mapping-not-dict",
    lambda t: io.read_csv_mapping(42),
    (TypeError, ValueError),
    r"mapping",
)
case(
    "io-mapping-no-columns",
    lambda t: io.read_csv_mapping({"units": {"acc": "g"}}),
    ValueError,
    r"'columns'",
)
case(
    "io-mapping-unknown-variable",
    lambda t: io.read_csv_mapping(
        {**_MAPPING, "columns": {**_MAPPING["columns"], "baro": "p"}}
    ),
    ValueError,
    r"baro",
)
case(
    "io-mapping-unknown-key",
    lambda t: io.read_csv_mapping({**_MAPPING, "colums": {}}),
    ValueError,
    r"colums",
)
case(
    "io-mapping-bad-unit",
    lambda t: io.read_csv_mapping(
        {**_MAPPING, "units": {"acc": "furlong", "gyr": "deg/s"}}
    ),
    ValueError,
    r"furlong",
)
case(
    "io-mapping-missing-file",
    lambda t: io.read_csv_mapping(t / "m.json"),
    OSError,
    r"m\.json",
)
case(
    "io-mapping-bad-json",
    lambda t: io.read_csv_mapping(_csv(t, "{not json", "m.json")),
    ValueError,
    r"m\.json.*JSON",
)
case(
    "io-mapping-fs-zero",
    lambda t: io.read_csv_mapping({**_MAPPING, "fs": 0}),
    ValueError,
    r"\bfs\b.*0",
)
case(
    "io-read_broad-not-hdf5",
    lambda t: io.read_broad(_csv(t, "hello", "x.hdf5")),
    (OSError, ValueError),
    r"x\.hdf5",
)
case("io-read_broad-missing", lambda t: io.read_broad(t / "x.mat"), OSError, r"x\.mat")
case(
    "io-read_fayat_imu-wrong-columns",
    lambda t: io.read_fayat_imu(_csv(t, _GOOD_CSV)),
    OSError,
    r"column",
)
case(
    "io-read_fayat_imu-fs-zero",
    lambda t: io.read_fayat_imu(_csv(t, _FAYAT_IMU), fs=0),
    ValueError,
    r"\bfs\b",
)
case(
    "io-read_fayat_imu-counter_rate-zero",
    lambda t: io.read_fayat_imu(_csv(t, _FAYAT_IMU), counter_rate=0.0),
    ValueError,
    r"counter_rate.*0",
)
case(
    "io-read_fayat_tumble-fs-nan",
    lambda t: io.read_fayat_tumble(_csv(t, _FAYAT_TUMBLE), fs=NAN),
    ValueError,
    r"\bfs\b",
)
case("io-load_netcdf-missing", lambda t: io.load_netcdf(t / "r.nc"), OSError, r"r\.nc")
case(
    "io-load_netcdf-not-netcdf",
    lambda t: io.load_netcdf(_csv(t, "garbage", "r.nc")),
    (OSError, ValueError),
    r"r\.nc",
)
case(
    "io-save_netcdf-not-recording",
    lambda t: io.save_netcdf(ACC, t / "r.nc"),
    (TypeError, ValueError),
    r"Dataset|Recording|ds",
)

# ----------------------------------------------------------------------------- datasets
case(
    "datasets-load-unknown-scheme",
    lambda t: datasets.load("fayat:nope"),
    datasets.DataError,
    r"fayat:nope",
)
case(
    "datasets-load-unknown-suffix",
    lambda t: datasets.load("session.xyz"),
    datasets.DataError,
    r"session\.xyz",
)
case(
    "datasets-load-missing-nc",
    lambda t: datasets.load(str(t / "missing.nc")),
    datasets.DataError,
    r"missing\.nc",
)
case(
    "datasets-load-missing-mat",
    lambda t: datasets.load(str(t / "missing.mat")),
    datasets.DataError,
    r"missing\.mat",
)
case(
    "datasets-load-broad-number",
    lambda t: datasets.load("broad:999"),
    datasets.DataError,
    r"999",
)
case(
    "datasets-load-broad-name",
    lambda t: datasets.load("broad:nonsense"),
    datasets.DataError,
    r"nonsense",
)
case(
    "datasets-load-empty", lambda t: datasets.load(""), datasets.DataError, r"''|source"
)
case(
    "datasets-load-not-a-string",
    lambda t: datasets.load(42),
    (datasets.DataError, TypeError),
    r"source.*42",
)
case(
    "datasets-load-none",
    lambda t: datasets.load(None),
    (datasets.DataError, TypeError),
    r"source.*None",
)
case(
    "datasets-fetch-unknown",
    lambda t: datasets.fetch("no/such/file.csv"),
    datasets.DataError,
    r"no/such/file\.csv",
)
case(
    "datasets-citation-unknown",
    lambda t: datasets.citation("nope"),
    (datasets.DataError, KeyError, ValueError),
    r"nope",
)
case(
    "datasets-broad_trial-zero",
    lambda t: datasets.load_broad_trial(0),
    datasets.DataError,
    r"\b0\b",
)

# ----------------------------------------------------------------------------- filters
est = filters.estimate
case(
    "filters-unknown-method",
    lambda t: est(REC6, "kalman9000"),
    ValueError,
    r"kalman9000",
)
case("filters-method-not-string", lambda t: est(REC6, 3), ValueError, r"\b3\b")
case(
    "filters-unknown-parameter",
    lambda t: est(REC6, "madgwick", gain=1.0),
    ValueError,
    r"gain",
)
case(
    "filters-not-a-recording",
    lambda t: est(ACC, "madgwick"),
    RecordingError,
    r"recording",
)
case(
    "filters-madgwick-beta-negative",
    lambda t: est(REC6, "madgwick", beta=-0.1),
    ValueError,
    r"beta.*-0\.1",
)
case(
    "filters-madgwick-beta-nan",
    lambda t: est(REC6, "madgwick", beta=NAN),
    ValueError,
    r"beta.*nan",
)
case(
    "filters-mahony-kp-negative",
    lambda t: est(REC6, "mahony", kp=-1.0),
    ValueError,
    r"kp.*-1",
)
case(
    "filters-mahony-ki-nan",
    lambda t: est(REC6, "mahony", ki=NAN),
    ValueError,
    r"ki.*nan",
)
case(
    "filters-complementary-tau-zero",
    lambda t: est(REC6, "complementary", tau_acc_s=0.0),
    ValueError,
    r"tau_acc_s.*0",
)
case(
    "filters-complementary-tau-nan",
    lambda t: est(REC6, "complementary", tau_acc_s=NAN),
    ValueError,
    r"tau_acc_s.*nan",
)
case(
    "filters-lowpass-cutoff-zero",
    lambda t: est(REC6, "lowpass", cutoff_hz=0.0),
    ValueError,
    r"cutoff_hz.*0",
)
case(
    "filters-lowpass-cutoff-nyquist",
    lambda t: est(REC6, "lowpass", cutoff_hz=60.0),
    ValueError,
    r"cutoff_hz.*Nyquist|cutoff_hz.*60",
)
case(
    "filters-lowpass-order-zero",
    lambda t: est(REC6, "lowpass", order=0),
    ValueError,
    r"order.*0",
)
case(
    "filters-ekf-var_acc-negative",
    lambda t: est(REC6, "ekf", var_acc=-1.0),
    ValueError,
    r"var_acc.*-1",
)
case(
    "filters-ekf-var_gyr-nan",
    lambda t: est(REC6, "ekf", var_gyr=NAN),
    ValueError,
    r"var_gyr.*nan",
)
case(
    "filters-ekf-P0-nan",
    lambda t: est(REC6, "ekf", P0=np.full((4, 4), NAN)),
    ValueError,
    r"P0",
)
case(
    "filters-eskf-acc_noise-negative",
    lambda t: est(REC6, "eskf", acc_noise=-0.05),
    ValueError,
    r"acc_noise.*-0\.05",
)
case(
    "filters-smoother-cutoff-negative",
    lambda t: est(REC6, "smoother", cutoff_hz=-0.1),
    ValueError,
    r"cutoff_hz.*-0\.1",
)
case(
    "filters-init_window-negative",
    lambda t: est(REC6, "madgwick", init_window_s=-1.0),
    ValueError,
    r"init_window_s.*-1",
)
case(
    "filters-init_window-nan",
    lambda t: est(REC6, "mahony", init_window_s=NAN),
    ValueError,
    r"init_window_s.*nan",
)
case(
    "filters-q0-zero",
    lambda t: est(REC6, "madgwick", q0=[0, 0, 0, 0]),
    ValueError,
    r"q0",
)
case(
    "filters-q0-shape", lambda t: est(REC6, "madgwick", q0=[1, 0, 0]), ValueError, r"q0"
)
case(
    "filters-use_mag-without-mag",
    lambda t: est(REC6, "madgwick", use_mag=True),
    RecordingError,
    r"'mag'",
)
case(
    "filters-use_mag-6d-method",
    lambda t: est(REC, "lowpass", use_mag=True),
    ValueError,
    r"magnetometer|use_mag",
)
case(
    "filters-acc-units-unknown",
    lambda t: est(_var_attrs(REC6, "acc", units="furlong"), "madgwick"),
    ValueError,
    r"furlong",
)
case(
    "filters-acc-units-wrong-quantity",
    lambda t: est(_var_attrs(REC6, "acc", units="deg/s"), "madgwick"),
    ValueError,
    r"deg/s",
)
case(
    "filters-fs-contradicts-time",
    lambda t: est(_with(REC6, fs=200.0), "madgwick"),
    RecordingError,
    r"\bfs\b.*200",
)
case(
    "filters-fs-missing",
    lambda t: est(_drop_fs(REC6), "madgwick"),
    RecordingError,
    r"\bfs\b",
)
case(
    "filters-acc-nan", lambda t: est(_nan_acc(REC6), "madgwick"), ValueError, r"\bacc\b"
)
case(
    "filters-gravity-bad-shape",
    lambda t: filters.gravity(np.zeros((5, 3))),
    ValueError,
    r"\bq\b",
)
case(
    "filters-madgwick_batch-negative-beta",
    lambda t: filters.madgwick_batch(ACC, np.radians(GYR), FS, betas=[0.1, -0.1]),
    ValueError,
    r"betas?.*-0\.1",
)
case(
    "filters-initial_orientation-zero-acc",
    lambda t: filters.initial_orientation(np.zeros((5, 3))),
    ValueError,
    r"acc",
)
case(
    "filters-initial_orientation-mag-parallel",
    lambda t: filters.initial_orientation([[0, 0, 1.0]], [[0, 0, 5.0]]),
    ValueError,
    r"magnetometer.*parallel",
)
case(
    "filters-rest_gyro_bias-window-zero",
    lambda t: filters.rest_gyro_bias(ACC, np.radians(GYR), FS, window_s=0.0),
    ValueError,
    r"window_s",
)
case(
    "filters-davenport-weights-negative",
    lambda t: filters.davenport(ACC, MAG, dip=1.1, weights=(1.0, -1.0)),
    ValueError,
    r"weights",
)


# ----------------------------------------------------------------------------- calibration
cal = calibration
case(
    "cal-detect_static-no-fs",
    lambda t: cal.detect_static(GYR),
    RecordingError,
    r"\bfs\b",
)
case(
    "cal-detect_static-threshold-negative",
    lambda t: cal.detect_static(REC6, threshold_deg_s=-3.0),
    ValueError,
    r"threshold_deg_s.*-3",
)
case(
    "cal-detect_static-threshold-nan",
    lambda t: cal.detect_static(REC6, threshold_deg_s=NAN),
    ValueError,
    r"threshold_deg_s.*nan",
)
case(
    "cal-detect_static-smooth-negative",
    lambda t: cal.detect_static(REC6, smooth_s=-0.1),
    ValueError,
    r"smooth_s.*-0\.1",
)
case(
    "cal-detect_static-min_duration-nan",
    lambda t: cal.detect_static(REC6, min_duration_s=NAN),
    ValueError,
    r"min_duration_s.*nan",
)
case(
    "cal-detect_static-acc_std-negative",
    lambda t: cal.detect_static(REC6, acc_std_threshold_g=-0.01),
    ValueError,
    r"acc_std_threshold_g.*-0\.01",
)
case(
    "cal-detect_static-offset-shape",
    lambda t: cal.detect_static(REC6, gyr_offset=[1.0, 2.0]),
    ValueError,
    r"offset",
)
case(
    "cal-detect_static-trigger-window-zero",
    lambda t: cal.detect_static(REC6, trigger=np.zeros(N), trigger_window_s=0.0),
    ValueError,
    r"window_s.*0",
)
case(
    "cal-robust_gyro_offset-quantile-zero",
    lambda t: cal.robust_gyro_offset(REC6, quantile=0.0),
    ValueError,
    r"quantile.*0",
)
case(
    "cal-robust_gyro_offset-window-negative",
    lambda t: cal.robust_gyro_offset(REC6, window_s=-1.0),
    ValueError,
    r"window_s.*-1",
)
case(
    "cal-trigger-level-nan",
    lambda t: cal.static_intervals_from_trigger(np.zeros(N), FS, level=NAN),
    ValueError,
    r"level.*nan",
)
case(
    "cal-static_means-intervals-out-of-range",
    lambda t: cal.static_means(ACC, [[0, N + 5]]),
    ValueError,
    r"intervals",
)
case(
    "cal-static_means-full_scale-negative",
    lambda t: cal.static_means(ACC, STILL_IV, full_scale=-2.0),
    ValueError,
    r"full_scale.*-2",
)
case(
    "cal-static_means-min_periods",
    lambda t: cal.static_means(ACC, STILL_IV, min_periods=3),
    cal.CalibrationError,
    r"still periods.*3",
)
case(
    "cal-gyro_offset-no-intervals",
    lambda t: cal.gyro_offset(GYR, np.zeros((0, 2), int)),
    cal.CalibrationError,
    r"still period",
)
case(
    "cal-fit_offsets-too-few",
    lambda t: cal.fit_offsets(CUBE[:2]),
    cal.CalibrationError,
    r"at least 3",
)
case(
    "cal-fit_offsets-collinear",
    lambda t: cal.fit_offsets(
        np.array([[0, 0, 1.0], [0, 0, -1.0], [0, 0, 1.0], [0, 0, -1.0]])
    ),
    cal.CalibrationError,
    r"condition|collinear",
)
case(
    "cal-fit_offsets-radius-zero",
    lambda t: cal.fit_offsets(CUBE, radius=0.0),
    ValueError,
    r"radius.*0",
)
case(
    "cal-fit_offsets-points-nan",
    lambda t: cal.fit_offsets(np.where(CUBE == 1, NAN, CUBE)),
    ValueError,
    r"points",
)
case(
    "cal-fit_offsets-points-far-from-radius",
    lambda t: cal.fit_offsets(CUBE * 9.81),
    cal.CalibrationError,
    r"norm.*radius|away from",
)
case(
    "cal-fit_offsets-sem-shape",
    lambda t: cal.fit_offsets(CUBE, sem=np.ones((2, 3))),
    ValueError,
    r"sem",
)
case(
    "cal-fit_ellipsoid-structure",
    lambda t: cal.fit_ellipsoid(SPHERE_PTS, structure="diagonal"),
    ValueError,
    r"structure.*diagonal",
)
case(
    "cal-fit_ellipsoid-max_condition-negative",
    lambda t: cal.fit_ellipsoid(SPHERE_PTS, max_condition=-1.0),
    ValueError,
    r"max_condition.*-1",
)
case(
    "cal-fit_ellipsoid-too-few",
    lambda t: cal.fit_ellipsoid(CUBE),
    cal.CalibrationError,
    r"at least 9",
)
case(
    "cal-fit_offsets_batch-iterations-zero",
    lambda t: cal.fit_offsets_batch(CUBE[None], iterations=0),
    ValueError,
    r"iterations.*0",
)
case(
    "cal-fit_known_directions-mismatch",
    lambda t: cal.fit_known_directions(CUBE, CUBE[:5]),
    ValueError,
    r"directions|points",
)
case(
    "cal-norm_error-radius-negative",
    lambda t: cal.norm_error(CUBE, radius=-1.0),
    ValueError,
    r"radius.*-1",
)
case(
    "cal-lattice_subset-k-zero",
    lambda t: cal.lattice_subset(SPHERE_PTS, 0),
    ValueError,
    r"\bk\b.*0",
)
case(
    "cal-lattice_subset-k-too-large",
    lambda t: cal.lattice_subset(SPHERE_PTS, 31),
    ValueError,
    r"\bk\b.*31",
)
case(
    "cal-all_subsets-n-negative",
    lambda t: cal.all_subsets(-1, 2),
    ValueError,
    r"\bn\b.*-1",
)
case(
    "cal-offset_systematic-n_draws",
    lambda t: cal.offset_systematic_uncertainty(CUBE, n_draws=1),
    ValueError,
    r"n_draws.*1",
)
case(
    "cal-offset_systematic-scale_sd-nan",
    lambda t: cal.offset_systematic_uncertainty(CUBE, scale_sd=NAN),
    ValueError,
    r"scale_sd.*nan",
)
case(
    "cal-mag-ellipsoid-field-negative",
    lambda t: cal.fit_mag_ellipsoid(SPHERE_PTS * 40, field=-40.0),
    ValueError,
    r"field.*-40",
)
case(
    "cal-mag-ellipsoid-field-zero",
    lambda t: cal.fit_mag_ellipsoid(SPHERE_PTS * 40, field=0.0),
    ValueError,
    r"field.*0",
)
case(
    "cal-mag-ellipsoid-constant",
    lambda t: cal.fit_mag_ellipsoid(np.ones((20, 3))),
    cal.CalibrationError,
    r"do not vary",
)
case(
    "cal-mag-ellipsoid-mag-nan",
    lambda t: cal.fit_mag_ellipsoid(SPHERE_PTS * NAN),
    ValueError,
    r"\bmag\b",
)
case(
    "cal-minmax-zero-range",
    lambda t: cal.minmax_mag_calibration(np.ones((20, 3))),
    cal.CalibrationError,
    r"zero range",
)
case(
    "cal-four_point-shape",
    lambda t: cal.four_point_mag_calibration(np.ones((3, 3)), np.ones((4, 3))),
    ValueError,
    r"bottom",
)
case(
    "cal-four_point-flank",
    lambda t: cal.four_point_mag_calibration(
        np.ones((4, 3)), np.ones((4, 3)), flank_on="up"
    ),
    ValueError,
    r"flank_on.*up",
)
case(
    "cal-four_point-degenerate",
    lambda t: cal.four_point_mag_calibration(np.ones((4, 3)), np.ones((4, 3))),
    cal.CalibrationError,
    r"axis U",
)
case(
    "cal-apply_mag-offset-shape",
    lambda t: cal.apply_mag_calibration(MAG, [1.0, 2.0]),
    ValueError,
    r"offset",
)
case(
    "cal-apply_mag-matrix-nan",
    lambda t: cal.apply_mag_calibration(MAG, [0, 0, 0], np.full((3, 3), NAN)),
    ValueError,
    r"matrix",
)
case(
    "cal-temperature-degree-negative",
    lambda t: cal.fit_temperature_model(np.arange(6.0), np.zeros((6, 3)), degree=-1),
    ValueError,
    r"degree.*-1",
)
case(
    "cal-temperature-too-few",
    lambda t: cal.fit_temperature_model(np.arange(3.0), np.zeros((3, 3))),
    cal.CalibrationError,
    r"distinct",
)
case(
    "cal-temperature-temp-nan",
    lambda t: cal.fit_temperature_model(
        np.array([1, 2, NAN, 4, 5, 6.0]), np.zeros((6, 3))
    ),
    ValueError,
    r"\btemp\b",
)
case(
    "cal-temperature-temp-length",
    lambda t: cal.fit_temperature_model(np.arange(5.0), np.zeros((6, 3))),
    ValueError,
    r"\btemp\b",
)
case(
    "cal-temperature-extrapolate-negative",
    lambda t: cal.fit_temperature_model(np.arange(6.0), np.zeros((6, 3)), degree=1)(
        np.ones(3), extrapolate_degc=-1.0
    ),
    ValueError,
    r"extrapolate_degc.*-1",
)
case(
    "cal-temperature-outside-range",
    lambda t: cal.fit_temperature_model(np.arange(6.0), np.zeros((6, 3)), degree=1)(
        np.array([40.0])
    ),
    cal.CalibrationError,
    r"outside the calibrated range",
)
case(
    "cal-offsets_vs_temperature-no-temp",
    lambda t: cal.offsets_vs_temperature(GYR, fs=FS),
    ValueError,
    r"\btemp\b",
)
case(
    "cal-correct_drift-method",
    lambda t: cal.correct_drift(REC6, method="magic"),
    ValueError,
    r"method.*magic",
)
case(
    "cal-correct_drift-window-zero",
    lambda t: cal.correct_drift(REC6, window_s=0.0),
    ValueError,
    r"window_s.*0",
)
case(
    "cal-correct_drift-prior-missing",
    lambda t: cal.correct_drift(REC6, method="prior"),
    ValueError,
    r"prior_deg_s",
)
case(
    "cal-correct_drift-too-short",
    lambda t: cal.correct_drift(REC6, window_s=60.0),
    cal.CalibrationError,
    r"window_s",
)
case(
    "cal-drift_slope-start-negative",
    lambda t: cal.drift_slope(np.zeros((N, 3)), FS, start_s=-1.0),
    ValueError,
    r"start_s.*-1",
)
case(
    "cal-integrate_rate-no-fs",
    lambda t: cal.integrate_rate(GYR),
    RecordingError,
    r"\bfs\b",
)
case(
    "cal-allan-taus-negative",
    lambda t: cal.allan_deviation(GYR, FS, taus_s=[-1.0, 1.0]),
    ValueError,
    r"taus_s",
)
case(
    "cal-allan-n_taus-zero",
    lambda t: cal.allan_deviation(GYR, FS, n_taus=0),
    ValueError,
    r"n_taus.*0",
)
case(
    "cal-allan-too-short",
    lambda t: cal.allan_deviation(GYR[:10], FS),
    cal.CalibrationError,
    r"too short",
)
case(
    "cal-allan_noise-adev-shape",
    lambda t: cal.allan_noise_parameters([0.1, 1.0], [1.0]),
    ValueError,
    r"adev",
)
case(
    "cal-estimate_lag-max_lag-negative",
    lambda t: cal.estimate_lag(ACC, ACC, FS, max_lag_s=-1.0),
    ValueError,
    r"max_lag_s.*-1",
)
case(
    "cal-estimate_lag-channels",
    lambda t: cal.estimate_lag(ACC, ACC[:, :2], FS),
    ValueError,
    r"channels",
)
case(
    "cal-estimate_lag-fs_y-zero",
    lambda t: cal.estimate_lag(ACC, ACC, FS, fs_y=0.0),
    ValueError,
    r"\bfs(_y)?\b.*0",
)
case(
    "cal-ttl-cycle-zero",
    lambda t: cal.repair_ttl_slips(np.zeros(100), [0, 6, 12], cycle=0),
    ValueError,
    r"cycle.*0",
)
case(
    "cal-ttl-not-increasing",
    lambda t: cal.repair_ttl_slips(np.zeros(100), [0, 6, 6]),
    cal.CalibrationError,
    r"increasing",
)
case(
    "cal-marker_qc-drop_fraction",
    lambda t: cal.marker_distance_qc(ACC, GYR, drop_fraction=1.0),
    ValueError,
    r"drop_fraction.*1",
)
case(
    "cal-optical-median-zero",
    lambda t: cal.optical_tilt_uncertainty(0.1, 0.0),
    ValueError,
    r"median_distance.*0",
)
case(
    "cal-head_frame-coincident",
    lambda t: cal.head_frame_from_markers(ACC, ACC, GYR),
    ValueError,
    r"coincident",
)
case(
    "cal-imu_to_head-cutoff-negative",
    lambda t: cal.imu_to_head_alignment(REC6, ACC, cutoff_hz=-2.0),
    ValueError,
    r"cutoff_hz.*-2",
)
case(
    "cal-imu_to_head-still-shape",
    lambda t: cal.imu_to_head_alignment(REC6, ACC, still=np.ones(5, bool)),
    ValueError,
    r"still",
)
case(
    "cal-mounting_rotation-zero",
    lambda t: cal.mounting_rotation([0.0, 0.0, 0.0]),
    ValueError,
    r"acc_rest",
)
case(
    "cal-Calibration-offset-shape",
    lambda t: cal.Calibration(acc_offset=[1.0, 2.0]),
    ValueError,
    r"acc_offset",
)
case(
    "cal-Calibration-matrix-nan",
    lambda t: cal.Calibration(gyr_matrix=np.full((3, 3), NAN)),
    ValueError,
    r"gyr_matrix",
)
case(
    "cal-Calibration-reflection",
    lambda t: cal.Calibration(rotation=np.diag([1.0, 1.0, -1.0]), target_frame="head"),
    ValueError,
    r"rotation",
)
case(
    "cal-Calibration-rotation-no-frame",
    lambda t: cal.Calibration(rotation=np.eye(3)),
    ValueError,
    r"target_frame",
)
case(
    "cal-calibrate-not-calibration",
    lambda t: cal.calibrate(REC6, {"acc_offset": [0, 0, 0]}),
    (TypeError, ValueError),
    r"calibration",
)
case(
    "cal-calibrate-twice",
    lambda t: cal.calibrate(
        cal.calibrate(REC6, cal.Calibration(acc_offset=[0.01, 0, 0])),
        cal.Calibration(acc_offset=[0.01, 0, 0]),
    ),
    cal.CalibrationError,
    r"already|twice",
)
case(
    "cal-tumble-model",
    lambda t: cal.tumble_calibration(REC6, model="quadric"),
    ValueError,
    r"model.*quadric",
)
case(
    "cal-tumble-threshold-negative",
    lambda t: cal.tumble_calibration(REC6, threshold_deg_s=-1.0),
    ValueError,
    r"threshold_deg_s.*-1",
)

# ----------------------------------------------------------------------------- sphere
case("sphere-kde-h-zero", lambda t: sphere.kde(UNIT, h=0.0), ValueError, r"\bh\b.*0")
case(
    "sphere-kde-h-negative",
    lambda t: sphere.kde(UNIT, h=-0.1),
    ValueError,
    r"\bh\b.*-0\.1",
)
case("sphere-kde-h-nan", lambda t: sphere.kde(UNIT, h=NAN), ValueError, r"\bh\b.*nan")
case(
    "sphere-kde-identical-samples",
    lambda t: sphere.kde(np.tile([0.0, 0.0, 1.0], (50, 1))),
    ValueError,
    r"vectors.*(identical|spread)|identical",
)
case(
    "sphere-kde-weights-negative",
    lambda t: sphere.kde(UNIT, h=0.2, weights=-np.ones(len(UNIT))),
    ValueError,
    r"weights",
)
case(
    "sphere-kde-kernel",
    lambda t: sphere.kde(UNIT, h=0.2, kernel="box"),
    ValueError,
    r"kernel.*box",
)
case(
    "sphere-kde-cell-zero",
    lambda t: sphere.kde(UNIT, h=0.2, cell_deg=0.0),
    ValueError,
    r"cell_deg.*0",
)
case(
    "sphere-kde-zero-vectors",
    lambda t: sphere.kde(np.zeros((10, 3)), h=0.2),
    ValueError,
    r"vectors",
)
case(
    "sphere-grid-cell-negative",
    lambda t: sphere.equal_area_grid(cell_deg=-1.0),
    ValueError,
    r"cell_deg.*-1",
)
case(
    "sphere-grid-pole-zero",
    lambda t: sphere.equal_area_grid(pole=(0.0, 0.0, 0.0)),
    ValueError,
    r"pole",
)
case(
    "sphere-mkde-no-fs",
    lambda t: sphere.mkde(UNIT, h=0.2),
    (ValueError, RecordingError),
    r"\bfs\b|times",
)
case(
    "sphere-mkde-diffusion-negative",
    lambda t: sphere.mkde(UNIT, fs=10.0, h=0.2, diffusion=-1.0),
    ValueError,
    r"diffusion.*-1",
)
case(
    "sphere-reference_bandwidth-method",
    lambda t: sphere.reference_bandwidth(UNIT, method="silverman"),
    ValueError,
    r"method.*silverman",
)
case(
    "sphere-vmf_pdf-kappa-negative",
    lambda t: sphere.vmf_pdf(UNIT, [0, 0, 1.0], -1.0),
    ValueError,
    r"kappa.*-1",
)
case(
    "sphere-vmf_pdf-kappa-nan",
    lambda t: sphere.vmf_pdf(UNIT, [0, 0, 1.0], NAN),
    ValueError,
    r"kappa.*nan",
)
case(
    "sphere-vmf_pdf-mu-zero",
    lambda t: sphere.vmf_pdf(UNIT, [0, 0, 0.0], 1.0),
    ValueError,
    r"\bmu\b",
)
case(
    "sphere-vmf_sample-kappa-negative",
    lambda t: sphere.vmf_sample([0, 0, 1.0], -2.0, 10),
    ValueError,
    r"kappa.*-2",
)
case(
    "sphere-vmf_sample-kappa-nan",
    lambda t: sphere.vmf_sample([0, 0, 1.0], NAN, 10),
    ValueError,
    r"kappa.*nan",
)
case(
    "sphere-vmf_sample-n-negative",
    lambda t: sphere.vmf_sample([0, 0, 1.0], 1.0, -3),
    ValueError,
    r"\bn\b.*-3",
)
case(
    "sphere-vmf_fit-weights-negative",
    lambda t: sphere.vmf_fit(UNIT, weights=-np.ones(len(UNIT))),
    ValueError,
    r"weights",
)
case(
    "sphere-vmf_fit-weights-length",
    lambda t: sphere.vmf_fit(UNIT, weights=np.ones(3)),
    ValueError,
    r"weights",
)
case(
    "sphere-vmf_fit-zero-vectors",
    lambda t: sphere.vmf_fit(np.zeros((10, 3))),
    ValueError,
    r"\bx\b|vectors",
)
case(
    "sphere-vmf_bootstrap-level",
    lambda t: sphere.vmf_bootstrap(UNIT, level=1.5, n_boot=10),
    ValueError,
    r"level.*1\.5",
)
case(
    "sphere-vmf_bootstrap-n_boot-zero",
    lambda t: sphere.vmf_bootstrap(UNIT, n_boot=0),
    ValueError,
    r"n_boot.*0",
)
case(
    "sphere-vmf_cap_area-level",
    lambda t: sphere.vmf_cap_area(5.0, 2.0),
    ValueError,
    r"level.*2",
)
case(
    "sphere-a3_inverse-rbar",
    lambda t: sphere.a3_inverse(1.5),
    ValueError,
    r"rbar.*1\.5",
)
case(
    "sphere-mesh-n-small",
    lambda t: sphere.sphere_mesh(3),
    ValueError,
    r"\bn\b.*3",
)
case(
    "sphere-tilt_map-zero-vectors",
    lambda t: sphere.tilt_map(np.zeros((10, 3))),
    ValueError,
    r"vectors",
)
case(
    "sphere-visited-min_count-zero",
    lambda t: sphere.visited(
        sphere.tilt_map(UNIT, mesh=sphere.sphere_mesh(100)), min_count=0
    ),
    ValueError,
    r"min_count.*0",
)
case(
    "sphere-isopleths-levels",
    lambda t: sphere.isopleths(np.ones(10), np.ones(10), levels=(0.5, 1.5)),
    ValueError,
    r"level",
)
case(
    "sphere-residence-radius-negative",
    lambda t: sphere.residence(UNIT, UNIT[:2], -0.1, 1.0, fs=10.0),
    ValueError,
    r"radius.*-0\.1",
)
case(
    "sphere-residence-t_out-nan",
    lambda t: sphere.residence(UNIT, UNIT[:2], 0.1, NAN, fs=10.0),
    ValueError,
    r"t_out.*nan",
)
case(
    "sphere-sagittal-lesion_side",
    lambda t: sphere.sagittal_angle([0, 0, 1.0], lesion_side="up"),
    ValueError,
    r"lesion_side.*up",
)
case(
    "sphere-histogram-weights-negative",
    lambda t: sphere.histogram(
        UNIT, sphere.sphere_mesh(100), weights=-np.ones(len(UNIT))
    ),
    ValueError,
    r"weights",
)

# ----------------------------------------------------------------------------- trig
ACC1 = ACC[:10]
case(
    "trig-posture-convention",
    lambda t: trig.posture(ACC1, convention="nasa"),
    ValueError,
    r"convention.*nasa",
)
case(
    "trig-heading-shape-mismatch",
    lambda t: trig.heading(ACC1, MAG[:5]),
    ValueError,
    r"\bmag\b|acc",
)
case(
    "trig-azimuth-declination-nan",
    lambda t: trig.azimuth(ACC1, MAG[:10], declination=NAN),
    ValueError,
    r"declination",
)
case(
    "trig-body_rotations-window-zero",
    lambda t: trig.body_rotations(REC6, window_s=0.0),
    ValueError,
    r"window_s.*0",
)
case(
    "trig-body_rotations-no-fs",
    lambda t: trig.body_rotations(GYR, window_s=1.0, units="deg/s"),
    RecordingError,
    r"\bfs\b",
)
case(
    "trig-oscillation-window-negative",
    lambda t: trig.oscillation_stats(np.sin(_t), FS, level=0.0, window_s=-1.0),
    ValueError,
    r"window_s.*-1",
)
case(
    "trig-crossing-level-nan",
    lambda t: trig.crossing_times(np.sin(_t), FS, level=NAN),
    ValueError,
    r"level.*nan",
)
case(
    "trig-correct_tangential-g-zero",
    lambda t: trig.correct_tangential(0.1, 0.5, g=0.0),
    ValueError,
    r"\bg\b.*0",
)
case(
    "trig-correct_centripetal-g-nan",
    lambda t: trig.correct_centripetal(0.1, 1.0, 0.2, g=NAN),
    ValueError,
    r"\bg\b.*nan",
)
case(
    "trig-lonlat-radius-negative",
    lambda t: trig.lonlat_to_local(0.0, 0.0, 0.1, 0.1, radius=-1.0),
    ValueError,
    r"radius.*-1",
)
case(
    "trig-sub_arc-k-zero",
    lambda t: trig.sub_arc_rotations(0.5, 0.1, 0.0, 0),
    ValueError,
    r"\bk\b.*0",
)
case(
    "trig-step_body_rates-duration-zero",
    lambda t: trig.step_body_rates(0.5, 0.1, 0.0, 0.0, 10),
    ValueError,
    r"duration_s.*0",
)
case(
    "trig-step_body_rates-n-zero",
    lambda t: trig.step_body_rates(0.5, 0.1, 0.0, 1.0, 0),
    ValueError,
    r"\bn\b.*0",
)
case(
    "trig-dead_reckon-lengths",
    lambda t: trig.dead_reckon_2d(np.ones(10), np.zeros(9), np.zeros((2, 2)), [0, 9]),
    ValueError,
    r"speed|\baz\b",
)
case(
    "trig-rotations-method",
    lambda t: trig.rotations_from_orientations(0, 0, 0, 1, 0, 0, method="best"),
    ValueError,
    r"method.*best",
)
case(
    "trig-magnetic_loop-inclination-nan",
    lambda t: trig.posture_from_magnetic_loop(MAG[:50], NAN),
    ValueError,
    r"inclination.*nan",
)

# ----------------------------------------------------------------------------- frames
case(
    "frames-angles_from_quaternion-non-unit",
    lambda t: frames.angles_from_quaternion([2.0, 0, 0, 0]),
    ValueError,
    r"\bq\b.*unit",
)
case(
    "frames-angles_from_quaternion-zero",
    lambda t: frames.angles_from_quaternion([0.0, 0, 0, 0]),
    ValueError,
    r"\bq\b",
)
case(
    "frames-angles_from_quaternion-nan-tol",
    lambda t: frames.angles_from_quaternion([1.0, 0, 0, 0], singular_tol=NAN),
    ValueError,
    r"singular_tol.*nan",
)
case(
    "frames-angles_from_matrix-reflection",
    lambda t: frames.angles_from_matrix(np.diag([1.0, 1.0, -1.0])),
    ValueError,
    r"matrix.*(rotation|reflection)",
)
case(
    "frames-angles_from_matrix-not-orthogonal",
    lambda t: frames.angles_from_matrix(2 * np.eye(3)),
    ValueError,
    r"matrix.*rotation",
)
case(
    "frames-angles_from_matrix-shape",
    lambda t: frames.angles_from_matrix(np.eye(2)),
    ValueError,
    r"matrix.*shape",
)
case(
    "frames-mounting_angles-zero",
    lambda t: frames.mounting_angles([0.0, 0.0, 0.0]),
    ValueError,
    r"acc_rest",
)
case(
    "frames-mounting_angles-convention",
    lambda t: frames.mounting_angles([0.0, 0.0, 1.0], convention="ned"),
    ValueError,
    r"convention.*ned",
)
case(
    "frames-acc_from_angles-convention",
    lambda t: frames.acc_from_angles(0.1, 0.2, convention="ned"),
    ValueError,
    r"convention.*ned",
)
case(
    "frames-acc_from_angles-g-nan",
    lambda t: frames.acc_from_angles(0.1, 0.2, g=NAN),
    ValueError,
    r"\bg\b.*nan",
)
case(
    "frames-device_to_body_eq1-vertical",
    lambda t: frames.device_to_body_eq1(ACC1, [1.0, 0.0, 0.0]),
    ValueError,
    r"acc_rest",
)
case(
    "frames-geomagnetic-intensity-negative",
    lambda t: frames.geomagnetic_field(intensity=-48.0),
    ValueError,
    r"intensity.*-48",
)
case(
    "frames-geomagnetic-inclination-nan",
    lambda t: frames.geomagnetic_field(inclination=NAN),
    ValueError,
    r"inclination.*nan",
)
case(
    "frames-mag_from_angles-field-shape",
    lambda t: frames.mag_from_angles(0, 0, 0, field=[1.0, 2.0]),
    ValueError,
    r"field",
)
case(
    "frames-fibonacci-n-zero",
    lambda t: frames.fibonacci_lattice(0),
    ValueError,
    r"\bn\b.*0",
)
case(
    "frames-fibonacci-n-float",
    lambda t: frames.fibonacci_lattice(2.5),
    ValueError,
    r"\bn\b.*2\.5",
)
case(
    "frames-stage_angles-zero",
    lambda t: frames.stage_angles([0.0, 0.0, 0.0]),
    ValueError,
    r"\bg\b",
)
case(
    "frames-stage_angles-scalar",
    lambda t: frames.stage_angles(1.0),
    ValueError,
    r"\bg\b",
)
case(
    "frames-head_frame-coincident",
    lambda t: frames.head_frame_from_markers(ACC1, ACC1, GYR[:10]),
    ValueError,
    r"m1|m2|marker",
)
case(
    "frames-spherical_coords-shape",
    lambda t: frames.spherical_coords([1.0, 2.0]),
    ValueError,
    r"\bv\b",
)
case(
    "frames-device_to_body-vectors-shape",
    lambda t: frames.device_to_body(np.ones((4, 2)), 0.1, 0.1),
    ValueError,
    r"vectors",
)

# ----------------------------------------------------------------------------- quaternion
case(
    "quat-normalize-zero",
    lambda t: quaternion.normalize([0.0, 0, 0, 0]),
    ValueError,
    r"\bq\b|quaternion",
)
case(
    "quat-mul-shape",
    lambda t: quaternion.mul([1.0, 0, 0], [1.0, 0, 0, 0]),
    ValueError,
    r"\bp\b",
)
case(
    "quat-rotate-v-shape",
    lambda t: quaternion.rotate([1.0, 0, 0, 0], [1.0, 0]),
    ValueError,
    r"\bv\b",
)
case(
    "quat-from_matrix-shape",
    lambda t: quaternion.from_matrix(np.eye(2)),
    ValueError,
    r"\bm\b",
)
case(
    "quat-from_matrix-reflection",
    lambda t: quaternion.from_matrix(np.diag([1.0, 1.0, -1.0])),
    ValueError,
    r"\bm\b.*(rotation|reflection)",
)
case(
    "quat-from_matrix-inf",
    lambda t: quaternion.from_matrix(np.full((3, 3), INF)),
    ValueError,
    r"\bm\b",
)
case(
    "quat-to_rotvec-non-unit",
    lambda t: quaternion.to_rotvec([2.0, 0, 0, 0]),
    ValueError,
    r"\bq\b.*unit",
)
case(
    "quat-integrate-fs-zero",
    lambda t: quaternion.integrate_gyro(np.zeros((5, 3)), 0.0),
    ValueError,
    r"\bfs\b.*0",
)
case(
    "quat-integrate-fs-string",
    lambda t: quaternion.integrate_gyro(np.zeros((5, 3)), "fast"),
    ValueError,
    r"\bfs\b.*fast",
)
case(
    "quat-integrate-omega-nan",
    lambda t: quaternion.integrate_gyro(np.full((5, 3), NAN), FS),
    ValueError,
    r"omega",
)
case(
    "quat-integrate-q0-zero",
    lambda t: quaternion.integrate_gyro(np.zeros((5, 3)), FS, q0=[0.0, 0, 0, 0]),
    ValueError,
    r"q0",
)
case(
    "quat-identity-n-negative",
    lambda t: quaternion.identity(-1),
    ValueError,
    r"\bn\b.*-1",
)
case(
    "quat-random-n-negative",
    lambda t: quaternion.random_quaternions(-1),
    ValueError,
    r"\bn\b.*-1",
)
case(
    "quat-error_angles-broadcast",
    lambda t: quaternion.tilt_error(Q[:5], Q[:4]),
    ValueError,
    r"q_est.*q_ref|q_ref.*q_est",
)
case(
    "quat-angle_between-zero",
    lambda t: quaternion.angle_between([0.0, 0, 0], [0.0, 0, 1]),
    ValueError,
    r"\bu\b",
)

# ----------------------------------------------------------------------------- intervals
case(
    "intervals-mask-2d",
    lambda t: intervals.mask_to_intervals(np.ones((3, 3), bool)),
    ValueError,
    r"mask.*1-D",
)
case(
    "intervals-min_length-negative",
    lambda t: intervals.mask_to_intervals(np.ones(5, bool), min_length=-1),
    ValueError,
    r"min_length.*-1",
)
case(
    "intervals-merge_gap-negative",
    lambda t: intervals.mask_to_intervals(np.ones(5, bool), merge_gap=-2),
    ValueError,
    r"merge_gap.*-2",
)
case(
    "intervals-mask-nan",
    lambda t: intervals.mask_to_intervals(np.array([0.0, NAN, 1.0])),
    ValueError,
    r"mask",
)
case(
    "intervals-to_mask-out-of-range",
    lambda t: intervals.intervals_to_mask([[0, 20]], 10),
    ValueError,
    r"intervals",
)
case(
    "intervals-to_mask-n-negative",
    lambda t: intervals.intervals_to_mask(np.zeros((0, 2), int), -1),
    ValueError,
    r"\bn\b.*-1",
)
case(
    "intervals-samples_below-negative",
    lambda t: intervals.samples_below(-1.0, FS),
    ValueError,
    r"duration_s.*-1",
)
case(
    "intervals-samples_below-fs-nan",
    lambda t: intervals.samples_below(1.0, NAN),
    ValueError,
    r"\bfs\b.*nan",
)

# ----------------------------------------------------------------------------- dsp
case(
    "dsp-lowpass-nyquist",
    lambda t: dsp.lowpass(ACC, FS, 60.0),
    ValueError,
    r"cutoff_hz.*Nyquist",
)
case(
    "dsp-lowpass-order-zero",
    lambda t: dsp.lowpass(ACC, FS, 2.0, order=0),
    ValueError,
    r"order.*0",
)
case(
    "dsp-lowpass-order-huge",
    lambda t: dsp.lowpass(ACC, FS, 2.0, order=1e300),
    ValueError,
    r"order must be at most",
)
case(
    "dsp-lowpass-cutoff-nan",
    lambda t: dsp.lowpass(ACC, FS, NAN),
    ValueError,
    r"cutoff_hz.*nan",
)
case(
    "dsp-lowpass-fs-zero",
    lambda t: dsp.lowpass(ACC, 0.0, 2.0),
    ValueError,
    r"\bfs\b.*0",
)
case(
    "dsp-lowpass-x-nan",
    lambda t: dsp.lowpass(np.where(ACC > 0.99, NAN, ACC), FS, 2.0),
    ValueError,
    r"\bx\b",
)
case(
    "dsp-moving_mean-n-zero", lambda t: dsp.moving_mean(ACC, 0), ValueError, r"\bn\b.*0"
)
case(
    "dsp-moving_mean-x-nan",
    lambda t: dsp.moving_mean(np.array([1.0, NAN, 2.0]), 2),
    ValueError,
    r"\bx\b",
)
case("dsp-moving_std-x-2d", lambda t: dsp.moving_std(ACC, 3), ValueError, r"\bx\b")
case(
    "dsp-still_mask-threshold-negative",
    lambda t: dsp.still_mask(SPEED, FS, threshold=-1.0),
    ValueError,
    r"threshold.*-1",
)
case(
    "dsp-still_mask-acc_norm-length",
    lambda t: dsp.still_mask(
        SPEED, FS, threshold=5.0, acc_norm=np.ones(5), acc_std_threshold=0.1
    ),
    ValueError,
    r"acc_norm",
)
case(
    "dsp-window_samples-zero",
    lambda t: dsp.window_samples(0.0, FS),
    ValueError,
    r"window_s.*0",
)
case(
    "dsp-window_samples-minimum",
    lambda t: dsp.window_samples(1.0, FS, minimum=-1),
    ValueError,
    r"minimum.*-1",
)

# ----------------------------------------------------------------------------- behavior
case(
    "behavior-immobility-threshold-negative",
    lambda t: behavior.detect_immobility(SPEED, FS, threshold_deg_s=-12.0),
    ValueError,
    r"threshold_deg_s.*-12",
)
case(
    "behavior-immobility-threshold-nan",
    lambda t: behavior.detect_immobility(SPEED, FS, threshold_deg_s=NAN),
    ValueError,
    r"threshold_deg_s.*nan",
)
case(
    "behavior-immobility-threshold-string",
    lambda t: behavior.immobility(REC6, threshold_deg_s="automatic"),
    ValueError,
    r"threshold_deg_s.*automatic",
)
case(
    "behavior-immobility-merge-negative",
    lambda t: behavior.detect_immobility(SPEED, FS, merge_gap_s=-0.1),
    ValueError,
    r"merge_gap_s.*-0\.1",
)
case(
    "behavior-immobility-min_duration-nan",
    lambda t: behavior.immobility(REC6, min_duration_s=NAN),
    ValueError,
    r"min_duration_s.*nan",
)
case(
    "behavior-immobility-no-fs",
    lambda t: behavior.detect_immobility(SPEED),
    RecordingError,
    r"\bfs\b",
)
case(
    "behavior-immobility-speed-nan",
    lambda t: behavior.detect_immobility(np.where(SPEED > 40, NAN, SPEED), FS),
    ValueError,
    r"speed",
)
case(
    "behavior-immobility-gyr_offset-shape",
    lambda t: behavior.immobility(REC6, gyr_offset=[1.0]),
    ValueError,
    r"gyr_offset",
)
case(
    "behavior-angular_speed-no-units",
    lambda t: behavior.angular_speed(GYR),
    RecordingError,
    r"units",
)
case(
    "behavior-angular_speed-units-wrong",
    lambda t: behavior.angular_speed(GYR, units="g"),
    ValueError,
    r"\bg\b|units",
)
case(
    "behavior-speed_modes-bins",
    lambda t: behavior.speed_modes(SPEED, bins=1),
    ValueError,
    r"bins.*1",
)
case(
    "behavior-speed_modes-log_range",
    lambda t: behavior.speed_modes(SPEED, log_range=(2.0, 1.0)),
    ValueError,
    r"log_range",
)
case(
    "behavior-speed_modes-prominence",
    lambda t: behavior.speed_modes(SPEED, min_prominence=2.0),
    ValueError,
    r"min_prominence.*2",
)
case(
    "behavior-valley-unimodal",
    lambda t: behavior.valley_threshold(np.full(500, 10.0)),
    ValueError,
    r"bimodal",
)
case(
    "behavior-recording_speed-offset",
    lambda t: behavior.recording_speed(REC6, gyr_offset="median"),
    ValueError,
    r"offset.*median",
)
case(
    "behavior-gyro_spectrum-nperseg-zero",
    lambda t: behavior.gyro_spectrum(REC6, nperseg_s=0.0),
    ValueError,
    r"nperseg_s.*0",
)
case(
    "behavior-realism-threshold-negative",
    lambda t: behavior.realism_table({"a": REC6}, threshold_deg_s=-1.0),
    ValueError,
    r"threshold_deg_s.*-1",
)
case(
    "behavior-static_acc-window-zero",
    lambda t: behavior.static_acceleration(REC6, window_s=0.0),
    ValueError,
    r"window_s.*0",
)
case(
    "behavior-static_acc-mode",
    lambda t: behavior.static_acceleration(REC6, window_s=1.0, mode="rolling"),
    ValueError,
    r"mode.*rolling",
)
case(
    "behavior-dba-window-nan",
    lambda t: behavior.dba(REC6, window_s=NAN),
    ValueError,
    r"window_s.*nan",
)
case(
    "behavior-odba-no-fs",
    lambda t: behavior.odba(ACC, window_s=1.0),
    RecordingError,
    r"\bfs\b",
)
case(
    "behavior-step_summary-window-inf",
    lambda t: behavior.step_summary(REC6, window_s=INF),
    ValueError,
    r"window_s.*inf",
)
case(
    "behavior-window_length-fs-zero",
    lambda t: behavior.window_length(1.0, 0.0),
    ValueError,
    r"\bfs\b.*0",
)
case(
    "behavior-circling-moving-shape",
    lambda t: behavior.circling_index(REC6, G, moving=np.ones(5, bool)),
    ValueError,
    r"moving",
)
case(
    "behavior-circling-no-movement",
    lambda t: behavior.circling_index(REC6, G, moving=np.zeros(N, bool)),
    ValueError,
    r"movement",
)
case(
    "behavior-azimuthal-g-shape",
    lambda t: behavior.azimuthal_speed(REC6, G[:5]),
    ValueError,
    r"\bg\b",
)
case(
    "behavior-azimuthal-g-zero",
    lambda t: behavior.azimuthal_speed(REC6, np.zeros((N, 3))),
    ValueError,
    r"\bg\b",
)

# ----------------------------------------------------------------------------- cohort
FC = cohort.FeatureConfig
case(
    "cohort-config-method",
    lambda t: FC(method="kalman9000"),
    ValueError,
    r"method.*kalman9000",
)
case(
    "cohort-config-method-param-unknown",
    lambda t: FC(method="lowpass", method_params={"beta": 1.0}),
    ValueError,
    r"method_params.*beta",
)
case(
    "cohort-config-method-param-nan",
    lambda t: FC(method="lowpass", method_params={"cutoff_hz": NAN}),
    ValueError,
    r"cutoff_hz.*nan",
)
case(
    "cohort-config-method-param-negative",
    lambda t: FC(method="lowpass", method_params={"cutoff_hz": -2.0}),
    ValueError,
    r"cutoff_hz.*-2",
)
case(
    "cohort-config-use_mag-6d",
    lambda t: FC(method="lowpass", use_mag=True),
    ValueError,
    r"use_mag",
)
case(
    "cohort-config-threshold-negative",
    lambda t: FC(threshold_deg_s=-12.0),
    ValueError,
    r"threshold_deg_s.*-12",
)
case(
    "cohort-config-threshold-nan",
    lambda t: FC(threshold_deg_s=NAN),
    ValueError,
    r"threshold_deg_s.*nan",
)
case(
    "cohort-config-merge-negative",
    lambda t: FC(merge_gap_s=-0.1),
    ValueError,
    r"merge_gap_s.*-0\.1",
)
case("cohort-config-mesh_n", lambda t: FC(mesh_n=3), ValueError, r"mesh_n.*3")
case(
    "cohort-config-visited_min_count",
    lambda t: FC(visited_min_count=0),
    ValueError,
    r"visited_min_count.*0",
)
case(
    "cohort-config-dba_window",
    lambda t: FC(dba_window_s=0.0),
    ValueError,
    r"dba_window_s.*0",
)
case(
    "cohort-config-tilt_thresholds",
    lambda t: FC(tilt_thresholds_deg=(20.0, 200.0)),
    ValueError,
    r"tilt_thresholds_deg.*200",
)
case(
    "cohort-config-speed_quantiles",
    lambda t: FC(speed_quantiles=(0.5, 1.5)),
    ValueError,
    r"speed_quantiles.*1\.5",
)
case(
    "cohort-config-lesion_side",
    lambda t: FC(lesion_side="up"),
    ValueError,
    r"lesion_side.*up",
)
case(
    "cohort-config-gyr_offset",
    lambda t: FC(gyr_offset="median"),
    ValueError,
    r"gyr_offset.*median",
)
case("cohort-config-bool", lambda t: FC(use_mag="yes"), ValueError, r"use_mag.*yes")
case(
    "cohort-config-from_dict-unknown",
    lambda t: FC.from_dict({"threshold": 12.0}),
    ValueError,
    r"threshold",
)
case(
    "cohort-manifest-missing",
    lambda t: cohort.read_manifest(t / "m.csv"),
    OSError,
    r"m\.csv",
)
case(
    "cohort-manifest-missing-column",
    lambda t: cohort.read_manifest(
        _manifest(t, "s1,a,g,0,x.nc\n", "session,subject,group,timepoint,file\n")
    ),
    cohort.ManifestError,
    r"reader",
)
case(
    "cohort-manifest-duplicate-session",
    lambda t: cohort.read_manifest(
        _manifest(t, "s1,a,g,0,x.nc,netcdf\ns1,b,g,0,y.nc,netcdf\n")
    ),
    cohort.ManifestError,
    r"s1",
)
case(
    "cohort-manifest-bad-reader",
    lambda t: cohort.read_manifest(_manifest(t, "s1,a,g,0,x.nc,parquet\n")),
    cohort.ManifestError,
    r"parquet",
)
case(
    "cohort-manifest-empty",
    lambda t: cohort.read_manifest(_manifest(t, "")),
    cohort.ManifestError,
    r"no sessions",
)
case(
    "cohort-manifest-unknown-group",
    lambda t: cohort.read_manifest(
        _manifest(t, "s1,a,g,0,x.nc,netcdf\n"), groups=["sham"]
    ),
    cohort.ManifestError,
    r"\bg\b|group",
)
case(
    "cohort-init-no-folder",
    lambda t: cohort.init_manifest(t / "nope", "{subject}.nc"),
    OSError,
    r"nope",
)
case(
    "cohort-init-reader",
    lambda t: cohort.init_manifest(t, "{subject}.nc", reader="parquet"),
    ValueError,
    r"parquet",
)
case(
    "cohort-init-pattern-no-field",
    lambda t: cohort.init_manifest(t, "data.nc"),
    ValueError,
    r"pattern|subject",
)
case(
    "cohort-load_session-missing-file",
    lambda t: cohort.load_session(
        {"session": "s1", "file": "x.nc", "reader": "netcdf"}, t
    ),
    OSError,
    r"x\.nc",
)
case(
    "cohort-run-workers-zero",
    lambda t: cohort.run_cohort(cohort.read_manifest(_manifest_ok(t)), workers=0),
    ValueError,
    r"workers.*0",
)
case(
    "cohort-run-not-config",
    lambda t: cohort.run_cohort(
        cohort.read_manifest(_manifest_ok(t)), {"method": "lowpass"}
    ),
    (TypeError, ValueError),
    r"config",
)
case(
    "cohort-session_features-not-recording",
    lambda t: cohort.session_features(ACC),
    (RecordingError, TypeError),
    r"recording|Recording",
)
case(
    "cohort-session_features-not-config",
    lambda t: cohort.session_features(REC6, {"method": "lowpass"}),
    (TypeError, ValueError),
    r"config",
)


def _manifest_ok(tmp: Path) -> Path:
    io.save_netcdf(REC6, tmp / "a.nc")
    return _manifest(tmp, "s1,a,g,0,a.nc,netcdf\n")


# ----------------------------------------------------------------------------- stats
case(
    "stats-mwu-empty",
    lambda t: stats.mann_whitney([], [1.0, 2.0], alternative="two-sided"),
    ValueError,
    r"\bx\b.*empty",
)
case(
    "stats-mwu-nan",
    lambda t: stats.mann_whitney([1.0, NAN], [1.0, 2.0], alternative="two-sided"),
    ValueError,
    r"\bx\b",
)
case(
    "stats-mwu-alternative",
    lambda t: stats.mann_whitney([1.0, 2.0], [3.0, 4.0], alternative="bigger"),
    ValueError,
    r"alternative.*bigger",
)
case(
    "stats-mwu-method",
    lambda t: stats.mann_whitney(
        [1.0, 2.0], [3.0, 4.0], alternative="less", method="magic"
    ),
    ValueError,
    r"method.*magic",
)
case(
    "stats-mwu-2d",
    lambda t: stats.mann_whitney(np.ones((2, 2)), [3.0, 4.0], alternative="less"),
    ValueError,
    r"\bx\b.*one-dimensional",
)
case(
    "stats-mwu-exact_max_n",
    lambda t: stats.mann_whitney(
        [1.0, 2.0], [3.0, 4.0], alternative="less", exact_max_n=-1
    ),
    ValueError,
    r"exact_max_n.*-1",
)
case(
    "stats-wilcoxon-lengths",
    lambda t: stats.wilcoxon_signed_rank(
        [1.0, 2.0, 3.0], [1.0, 2.0], alternative="less"
    ),
    ValueError,
    r"\bx\b.*\by\b|length",
)
case(
    "stats-wilcoxon-zero_method",
    lambda t: stats.wilcoxon_signed_rank(
        [1.0, 2.0, 3.0], alternative="less", zero_method="drop"
    ),
    ValueError,
    r"zero_method.*drop",
)
case(
    "stats-wilcoxon-inf",
    lambda t: stats.wilcoxon_signed_rank([1.0, INF, 3.0], alternative="less"),
    ValueError,
    r"\bx\b",
)
case(
    "stats-hl-conf-high",
    lambda t: stats.hodges_lehmann([1.0, 2.0, 3.0], [2.0, 3.0, 4.0], conf_level=1.5),
    ValueError,
    r"conf_level.*1\.5",
)
case(
    "stats-hl-conf-zero",
    lambda t: stats.hodges_lehmann([1.0, 2.0, 3.0], [2.0, 3.0, 4.0], conf_level=0.0),
    ValueError,
    r"conf_level.*0",
)
case(
    "stats-hl-conf-nan",
    lambda t: stats.hodges_lehmann([1.0, 2.0, 3.0], [2.0, 3.0, 4.0], conf_level=NAN),
    ValueError,
    r"conf_level.*nan",
)
case(
    "stats-hl-alternative",
    lambda t: stats.hodges_lehmann([1.0, 2.0, 3.0], [2.0, 3.0, 4.0], alternative="up"),
    ValueError,
    r"alternative.*up",
)
case(
    "stats-ps-conf-one",
    lambda t: stats.prob_superiority([1.0, 2.0], [2.0, 3.0], conf_level=1.0),
    ValueError,
    r"conf_level.*1",
)
case(
    "stats-ps-empty-y",
    lambda t: stats.prob_superiority([1.0, 2.0], []),
    ValueError,
    r"\by\b.*empty",
)
case(
    "stats-paired-ps-conf",
    lambda t: stats.paired_prob_superiority([1.0, 2.0], [2.0, 3.0], conf_level=-0.5),
    ValueError,
    r"conf_level.*-0\.5",
)
case(
    "stats-paired-rb-zero_method",
    lambda t: stats.paired_rank_biserial([1.0, 2.0], [2.0, 3.0], zero_method="x"),
    ValueError,
    r"zero_method",
)
case(
    "stats-adjust-p-above-one",
    lambda t: stats.adjust([0.01, 1.5]),
    ValueError,
    r"\bp\b.*1\.5|\bp\b",
)
case("stats-adjust-p-nan", lambda t: stats.adjust([0.01, NAN]), ValueError, r"\bp\b")
case(
    "stats-adjust-method",
    lambda t: stats.adjust([0.01, 0.02], method="sidak2"),
    ValueError,
    r"method.*sidak2",
)
case(
    "stats-adjust-family-small",
    lambda t: stats.adjust([0.01, 0.02], family=1),
    ValueError,
    r"family.*1",
)
case(
    "stats-bonferroni-negative-p",
    lambda t: stats.paper_bonferroni([-0.1]),
    ValueError,
    r"\bp\b",
)
case(
    "stats-add_adjustments-family-column",
    lambda t: stats.add_adjustments(pd.DataFrame({"p": [0.1]}), family=["nope"]),
    ValueError,
    r"nope",
)
case(
    "stats-mwu_null-n1-negative",
    lambda t: stats.mwu_null_distribution(-1, 3),
    ValueError,
    r"n1.*-1",
)
case(
    "stats-signed_rank_null-n-float",
    lambda t: stats.signed_rank_null_distribution(2.5),
    ValueError,
    r"\bn\b.*2\.5",
)
case(
    "stats-noether-p",
    lambda t: stats.noether_n_per_group(0.5),
    ValueError,
    r"p_superiority.*0\.5",
)
case(
    "stats-noether-alpha",
    lambda t: stats.noether_n_per_group(0.8, alpha=2.0),
    ValueError,
    r"alpha.*2",
)
case(
    "stats-noether-power",
    lambda t: stats.noether_n_per_group(0.8, power=NAN),
    ValueError,
    r"power.*nan",
)
case(
    "stats-normal_shift-sd",
    lambda t: stats.normal_shift(1.0, sd=-1.0),
    ValueError,
    r"\bsd\b.*-1",
)
case(
    "stats-normal_shift-shift-nan",
    lambda t: stats.normal_shift(NAN),
    ValueError,
    r"shift.*nan",
)
case(
    "stats-normal_shift_superiority-sd",
    lambda t: stats.normal_shift_superiority(1.0, sd=0.0),
    ValueError,
    r"\bsd\b.*0",
)
case(
    "stats-power-n_sim",
    lambda t: stats.power_by_simulation(stats.normal_shift(1.0), 5, n_sim=0),
    ValueError,
    r"n_sim.*0",
)
case(
    "stats-power-alpha",
    lambda t: stats.power_by_simulation(
        stats.normal_shift(1.0), 5, alpha=NAN, n_sim=10
    ),
    ValueError,
    r"alpha.*nan",
)
case(
    "stats-power-test",
    lambda t: stats.power_by_simulation(
        stats.normal_shift(1.0), 5, test="t-test", n_sim=10
    ),
    ValueError,
    r"test.*t-test",
)
case(
    "stats-power-n-small",
    lambda t: stats.power_by_simulation(stats.normal_shift(1.0), 0, n_sim=10),
    ValueError,
    r"n_per_group.*0",
)
case(
    "stats-animals_needed-range",
    lambda t: stats.animals_needed(
        stats.normal_shift(1.0), n_min=10, n_max=5, n_sim=10
    ),
    ValueError,
    r"n_min|n_max",
)
case(
    "stats-animals_needed-target",
    lambda t: stats.animals_needed(stats.normal_shift(1.0), target_power=1.2, n_sim=10),
    ValueError,
    r"target_power.*1\.2",
)
case(
    "stats-fayat_table-name",
    lambda t: stats.fayat_table("A99"),
    (KeyError, ValueError),
    r"A99",
)
case(
    "stats-format_table-output",
    lambda t: stats.format_table(pd.DataFrame({"p_paper": [0.1]}), output="pdf"),
    ValueError,
    r"output.*pdf",
)
case(
    "stats-format_table-decimals",
    lambda t: stats.format_table(pd.DataFrame({"p_paper": [0.1]}), decimals=-1),
    ValueError,
    r"decimals.*-1",
)

# ----------------------------------------------------------------------------- evaluate
case(
    "evaluate-tilt_errors-shape",
    lambda t: evaluate.tilt_errors(Q[:5], Q[:4]),
    ValueError,
    r"q_est|ref",
)
case(
    "evaluate-tilt_errors-width",
    lambda t: evaluate.tilt_errors(Q[:, :3], Q),
    ValueError,
    r"q_est",
)
case(
    "evaluate-error_stats-mask-shape",
    lambda t: evaluate.error_stats(np.ones(10), mask=np.ones(5, bool)),
    ValueError,
    r"mask",
)
case(
    "evaluate-ecdf-empty",
    lambda t: evaluate.ecdf([]),
    ValueError,
    r"values.*empty|values",
)
case(
    "evaluate-table1-statistic",
    lambda t: evaluate.table1(
        {"a": np.ones(10)}, np.zeros(10, bool), statistics=("mode",)
    ),
    ValueError,
    r"mode",
)
case(
    "evaluate-table1-immobile-shape",
    lambda t: evaluate.table1({"a": np.ones(10)}, np.zeros(5, bool)),
    ValueError,
    r"immobile",
)
case(
    "evaluate-binned-edges",
    lambda t: evaluate.binned_by_speed({"a": np.ones(10)}, np.ones(10), [10.0, 5.0]),
    ValueError,
    r"edges",
)
case(
    "evaluate-shift-samples-nan",
    lambda t: evaluate.shift_quaternions(Q, NAN),
    ValueError,
    r"samples.*nan",
)
case(
    "evaluate-state_scores-stat",
    lambda t: evaluate.state_scores(Q, REC6, stat="mode"),
    (ValueError, RecordingError),
    r"stat.*mode|tilt_ref",
)
case(
    "evaluate-tilt_rmse-no-ref",
    lambda t: evaluate.tilt_rmse(Q, REC6),
    (ValueError, RecordingError),
    r"q_ref",
)
case(
    "evaluate-grid_search-method",
    lambda t: evaluate.grid_search([REC6], "kalman9000", {"beta": [0.1]}),
    ValueError,
    r"kalman9000",
)
case(
    "evaluate-grid_search-param",
    lambda t: evaluate.grid_search([REC6], "madgwick", {"gain": [0.1]}),
    ValueError,
    r"gain",
)
case(
    "evaluate-grid_search-n_jobs",
    lambda t: evaluate.grid_search([REC6], "madgwick", {"beta": [0.1]}, n_jobs=0),
    ValueError,
    r"n_jobs.*0",
)
case(
    "evaluate-optimum-dim",
    lambda t: evaluate.optimum(
        xr.DataArray(np.ones((2, 3)), dims=("beta", "trial")), dim="recording"
    ),
    ValueError,
    r"recording",
)


# ----------------------------------------------------------------------------- more geometry
Q1 = np.array([1.0, 0, 0, 0])
case(
    "frames-wrap_angle-inf",
    lambda t: frames.wrap_angle([0.0, INF]),
    ValueError,
    r"angle.*infinite",
)
case("frames-R1-inf", lambda t: frames.R1(-INF), ValueError, r"angle.*infinite")
case(
    "frames-angles_to_quaternion-inf",
    lambda t: frames.angles_to_quaternion(INF, 0.0, 0.0),
    ValueError,
    r"azimuth.*infinite",
)
case(
    "frames-angles_to_matrix-inf",
    lambda t: frames.angles_to_matrix(0.0, 0.0, INF),
    ValueError,
    r"angle.*infinite",
)
case(
    "frames-unit_vector-inf",
    lambda t: frames.unit_vector(INF, 0.0),
    ValueError,
    r"\bxi\b.*infinite",
)
case(
    "frames-stage_quaternion-inf",
    lambda t: frames.stage_quaternion(0.1, INF),
    ValueError,
    r"roll.*infinite",
)
case(
    "quat-from_rotvec-inf",
    lambda t: quaternion.from_rotvec([INF, 0, 0]),
    ValueError,
    r"\br\b.*infinite",
)
case(
    "quat-from_rotvec-huge",
    lambda t: quaternion.from_rotvec([1e300, 1e300, 0]),
    ValueError,
    r"\br\b.*too large",
)
case(
    "quat-gravity-zero",
    lambda t: quaternion.gravity([0.0, 0, 0, 0]),
    ValueError,
    r"\bq\b.*zero",
)
case(
    "quat-gravity-inf",
    lambda t: quaternion.gravity([INF, 0, 0, 0]),
    ValueError,
    r"\bq\b.*infinite",
)
case(
    "quat-inv-zero",
    lambda t: quaternion.inv([0.0, 0, 0, 0]),
    ValueError,
    r"\bq\b.*zero",
)
case(
    "quat-mul-inf",
    lambda t: quaternion.mul([INF, 0, 0, 0], Q1),
    ValueError,
    r"\bp\b.*infinite",
)
case(
    "quat-mul-broadcast",
    lambda t: quaternion.mul(Q[:3], Q[:2]),
    ValueError,
    r"\bp\b and \bq\b",
)
case(
    "quat-rotate-broadcast",
    lambda t: quaternion.rotate(Q[:3], G[:2]),
    ValueError,
    r"\bq\b and \bv\b",
)
case(
    "quat-tilt_error-zero",
    lambda t: quaternion.tilt_error([0.0, 0, 0, 0], Q1),
    ValueError,
    r"q_est.*zero",
)
case(
    "quat-integrate-omega-huge",
    lambda t: quaternion.integrate_gyro(np.full((3, 3), 1e300), FS),
    ValueError,
    r"omega.*too large",
)
case(
    "cal-identifiable_matrix-singular",
    lambda t: cal.identifiable_matrix(np.zeros((3, 3))),
    ValueError,
    r"matrix.*singular",
)
case(
    "cal-triplet_orthogonality-zero",
    lambda t: cal.triplet_orthogonality(np.zeros((3, 3))),
    ValueError,
    r"directions.*zero",
)
case(
    "cal-apply_mag-singular",
    lambda t: cal.apply_mag_calibration(MAG, [0, 0, 0], np.zeros((3, 3))),
    ValueError,
    r"matrix.*singular",
)
case(
    "cal-allan_noise-negative",
    lambda t: cal.allan_noise_parameters([0.1, 1.0, 10.0], [-1.0, -1.0, -1.0]),
    ValueError,
    r"adev.*negative",
)
case(
    "cal-compensate-not-model",
    lambda t: cal.compensate_temperature(np.zeros((3, 3)), np.zeros(3), "cubic"),
    TypeError,
    r"model.*TemperatureModel",
)
case(
    "cal-ttl-first_frame-negative",
    lambda t: cal.repair_ttl_slips(np.zeros(30), [0, 6, 12], first_frame=-1),
    ValueError,
    r"first_frame.*-1",
)
case(
    "cal-fit_offsets-x0-nan",
    lambda t: cal.fit_offsets(CUBE, x0=[NAN, 0, 0]),
    ValueError,
    r"x0",
)
case(
    "evaluate-binned-edges-nan",
    lambda t: evaluate.binned_by_speed({"a": np.ones(5)}, np.ones(5), [0.0, NAN, 2.0]),
    ValueError,
    r"edges.*nan",
)
case(
    "evaluate-pairwise-mask-shape",
    lambda t: evaluate.pairwise_tilt_rms({"a": Q, "b": Q}, mask=np.ones(3, bool)),
    ValueError,
    r"mask",
)
case(
    "dsp-still_mask-negative-speed",
    lambda t: dsp.still_mask(-SPEED, FS, threshold=5.0),
    ValueError,
    r"speed.*negative",
)
case(
    "intervals-to_mask-fractional",
    lambda t: intervals.intervals_to_mask([[0.5, 3.7]], 10),
    ValueError,
    r"intervals.*whole",
)
case(
    "stats-hl-paired-lengths",
    lambda t: stats.hodges_lehmann([1.0, 2.0, 3.0], [1.0, 2.0], paired=True),
    ValueError,
    r"\bx\b and \by\b",
)
case(
    "stats-exact_p_lattice-n1",
    lambda t: stats.exact_p_lattice(-1, 2),
    ValueError,
    r"n1.*-1",
)
case(
    "stats-power-n-list-negative",
    lambda t: stats.power_by_simulation(stats.normal_shift(1.0), [3, -2], n_sim=5),
    ValueError,
    r"n_per_group.*-2",
)
case(
    "stats-noether-family-zero",
    lambda t: stats.noether_n_per_group(0.8, family=0),
    ValueError,
    r"family.*0",
)


@pytest.mark.parametrize(("call", "exc", "match"), CASES)
def test_bad_input(call, exc, match, tmp_path):
    with pytest.raises(exc) as info:
        call(tmp_path)
    message = str(info.value)
    assert re.search(match, message), (
        f"{type(info.value).__name__}: {message!r} does not match {match!r}"
    )


def test_catalogue_size():
    assert len(CASES) >= 130


# --------------------------------------------------------------------------- degenerate, not errors

GOOD_EDGES = []


def good(id_, call, check, owner=None):
    marks = [pytest.mark.xfail(strict=True, reason=f"owner: {owner}")] if owner else []
    GOOD_EDGES.append(pytest.param(call, check, id=id_, marks=marks))


def _finite(x):
    return np.all(np.isfinite(np.asarray(x, float)))


good(
    "vmf_pdf-kappa-zero-is-uniform",
    lambda: sphere.vmf_pdf(UNIT, [0, 0, 1.0], 0.0),
    lambda p: np.allclose(p, 1 / (4 * np.pi)),
)
good(
    "vmf_pdf-kappa-tiny",
    lambda: sphere.vmf_pdf(UNIT, [0, 0, 1.0], 1e-300),
    lambda p: np.allclose(p, 1 / (4 * np.pi)),
)
good(
    "vmf_logpdf-kappa-huge", lambda: sphere.vmf_logpdf(UNIT, [0, 0, 1.0], 1e6), _finite
)
good(
    "vmf_sample-kappa-zero",
    lambda: sphere.vmf_sample([0, 0, 1.0], 0.0, 50, rng=0),
    lambda x: _finite(x) and np.allclose(np.linalg.norm(x, axis=1), 1),
)
good(
    "vmf_sample-kappa-tiny",
    lambda: sphere.vmf_sample([0, 0, 1.0], 1e-12, 50, rng=0),
    lambda x: _finite(x) and np.allclose(np.linalg.norm(x, axis=1), 1),
)
good(
    "vmf_sample-kappa-huge",
    lambda: sphere.vmf_sample([0, 0, 1.0], 1e8, 50, rng=0),
    lambda x: _finite(x) and np.allclose(x, [0, 0, 1], atol=1e-3),
)
good(
    "a3-kappa-zero",
    lambda: sphere.a3(0.0),
    lambda v: _finite(v) and abs(float(v)) < 1e-12,
)
good(
    "vmf_cap_area-kappa-zero",
    lambda: sphere.vmf_cap_area(0.0, 0.5),
    _finite,
)
good(
    "quat-angle_between-antiparallel",
    lambda: quaternion.angle_between([0, 0, 1.0], [0, 0, -1.0]),
    lambda a: np.isclose(a, np.pi),
)
good(
    "frames-angles-gimbal",
    lambda: frames.angles_from_quaternion(
        frames.angles_to_quaternion(0.3, np.pi / 2, 0.0)
    ),
    lambda o: all(_finite(v) for v in o),
)
good(
    "dsp-lowpass-one-sample",
    lambda: dsp.lowpass(np.ones((1, 3)), FS, 2.0),
    lambda y: np.array_equal(y, np.ones((1, 3))),
)
good(
    "intervals-empty-mask",
    lambda: intervals.mask_to_intervals(np.zeros(0, bool)),
    lambda iv: iv.shape == (0, 2),
)
good(
    "stats-mwu-all-tied",
    lambda: stats.mann_whitney([1.0, 1.0, 1.0], [1.0, 1.0], alternative="two-sided"),
    lambda r: np.isfinite(r.p) and r.p == 1.0,
)


good(
    "quat-from_matrix-nan-propagates",
    lambda: quaternion.from_matrix(np.full((2, 3, 3), NAN)),
    lambda q: q.shape == (2, 4) and np.all(np.isnan(q)),
)
good(
    "frames-head_frame-missing-marker-is-nan",
    lambda: frames.head_frame_from_markers(
        [[NAN, 0, 0], [1.0, 0, 0]], [[0, 0, 0], [0, 0, 0.0]], [[0, 1.0, 0], [0, 1.0, 0]]
    ),
    lambda m: np.all(np.isnan(m[0])) and _finite(m[1]),
)
good(
    "quat-integrate-empty",
    lambda: quaternion.integrate_gyro(np.zeros((0, 3)), FS),
    lambda q: q.shape == (0, 4),
)


@pytest.mark.parametrize(("call", "check"), GOOD_EDGES)
def test_degenerate_but_valid(call, check):
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # no silent overflow / 0/0
        out = call()
    assert check(out), out


UNDEFINED = []


def undefined(id_, call, match, owner=None):
    """A quantity undefined for the input: NaN with a warning naming the variable, or an
    error naming it (the policy of :mod:`tiltlab._validate`) — never a silent number."""
    marks = [pytest.mark.xfail(strict=True, reason=f"owner: {owner}")] if owner else []
    UNDEFINED.append(pytest.param(call, match, id=id_, marks=marks))


_UP = np.tile([0.0, 0.0, 1.0], (5, 1))
undefined("trig-posture-zero-acc", lambda: trig.posture(np.zeros((5, 3))), r"\bacc\b")
undefined(
    "trig-azimuth-zero-field", lambda: trig.azimuth(_UP, np.zeros((5, 3))), r"\bmag\b"
)
undefined(
    "trig-azimuth-zero-acc", lambda: trig.azimuth(np.zeros((5, 3)), MAG[:5]), r"\bacc\b"
)
undefined(
    "trig-azimuth-field-parallel-to-gravity",
    lambda: trig.azimuth(_UP, np.tile([0.0, 0.0, -40.0], (5, 1))),
    r"\bmag\b",
)
undefined(
    "trig-heading-field-parallel-to-gravity",
    lambda: trig.heading(_UP, np.tile([0.0, 0.0, 40.0], (5, 1))).azimuth,
    r"\bmag\b",
)


@pytest.mark.parametrize(("call", "match"), UNDEFINED)
def test_undefined_is_nan_with_warning_or_error(call, match):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            out = call()
        except ValueError as exc:
            assert re.search(match, str(exc)), exc
            return
    values = np.concatenate(
        [np.ravel(np.asarray(v, float)) for v in np.atleast_1d(out)]
    )
    assert np.all(np.isnan(values)), f"an undefined result must be NaN, got {out}"
    messages = [str(w.message) for w in caught]
    assert any(re.search(match, m) for m in messages), (
        f"no warning naming it: {messages}"
    )


# --------------------------------------------------------------------------- the CLI

CLI_CASES = []


def cli(id_, args, match, *, usage=False, owner=None):
    marks = [pytest.mark.xfail(strict=True, reason=f"owner: {owner}")] if owner else []
    CLI_CASES.append(pytest.param(args, match, usage, id=id_, marks=marks))


def _cli_files(tmp: Path) -> dict[str, str]:
    csv = _csv(tmp, _GOOD_CSV, "mine.csv")
    bad_json = _csv(tmp, "{oops", "bad.json")
    bad_map = _mapping_file(
        tmp, {**_MAPPING, "units": {"acc": "furlong", "gyr": "deg/s"}}
    )
    rec = REC6.copy()
    rec.attrs = {**REC6.attrs, "fs": 50.0}
    wrong_fs = tmp / "wrong_fs.nc"
    rec.to_netcdf(wrong_fs)
    io.save_netcdf(REC6, tmp / "a.nc")
    manifest = _manifest(tmp, "s1,a,g,0,a.nc,netcdf\n")
    bad_manifest = _csv(tmp, "session,file\ns1,a.nc\n", "bad_manifest.csv")
    config = _csv(tmp, json.dumps({"threshold_deg_s": -1}), "config.json")
    return {
        "csv": str(csv),
        "bad_json": str(bad_json),
        "bad_map": str(bad_map),
        "wrong_fs": str(wrong_fs),
        "manifest": str(manifest),
        "bad_manifest": str(bad_manifest),
        "config": str(config),
        "tmp": str(tmp),
    }


cli("no-command", [], r"COMMAND|required", usage=True)
cli("unknown-command", ["bogus"], r"bogus", usage=True)
cli("info-missing-source", ["info"], r"source", usage=True)
cli("info-missing-file", ["info", "{tmp}/nope.nc"], r"nope\.nc")
cli("info-unknown-suffix", ["info", "{tmp}/session.xyz"], r"session\.xyz")
cli("info-broad-unknown", ["info", "broad:999"], r"999")
cli("info-csv-without-mapping", ["info", "{csv}"], r"mapping")
cli("info-mapping-missing", ["info", "{csv}", "--mapping", "{tmp}/m.json"], r"m\.json")
cli(
    "info-mapping-bad-json",
    ["info", "{csv}", "--mapping", "{bad_json}"],
    r"bad\.json.*JSON",
)
cli("info-mapping-bad-unit", ["info", "{csv}", "--mapping", "{bad_map}"], r"furlong")
cli("validate-fs-contradicts-time", ["validate", "{wrong_fs}"], r"\bfs\b|irregular")
cli("fetch-unknown", ["fetch", "no/such/file.csv"], r"no/such/file\.csv")
cli(
    "cohort-run-missing-manifest",
    ["cohort", "run", "{tmp}/none.csv", "--out", "{tmp}/f.nc"],
    r"none\.csv",
)
cli(
    "cohort-run-bad-manifest",
    ["cohort", "run", "{bad_manifest}", "--out", "{tmp}/f.nc"],
    r"subject|group|reader|column",
)
cli(
    "cohort-run-workers-zero",
    ["cohort", "run", "{manifest}", "--out", "{tmp}/f.nc", "--workers", "0"],
    r"--workers.*0",
    usage=True,
)
cli(
    "cohort-run-bad-config",
    ["cohort", "run", "{manifest}", "--out", "{tmp}/f.nc", "--config", "{config}"],
    r"threshold_deg_s.*-1",
)
cli(
    "cohort-run-missing-config",
    ["cohort", "run", "{manifest}", "--out", "{tmp}/f.nc", "--config", "{tmp}/c.json"],
    r"c\.json",
)
cli(
    "cohort-init-no-folder",
    [
        "cohort",
        "init",
        "{tmp}/nofolder",
        "--pattern",
        "{{subject}}.nc",
        "--out",
        "{tmp}/m2.csv",
    ],
    r"nofolder",
)
cli(
    "cohort-init-bad-reader",
    [
        "cohort",
        "init",
        "{tmp}",
        "--pattern",
        "{{subject}}.nc",
        "--reader",
        "parquet",
        "--out",
        "{tmp}/m2.csv",
    ],
    r"--reader: invalid choice: 'parquet'",
    usage=True,
)
cli("cohort-show-missing", ["cohort", "show", "{tmp}/none.nc"], r"none\.nc")
cli(
    "cohort-show-max-features",
    ["cohort", "show", "{tmp}/a.nc", "--max-features", "-1"],
    r"--max-features",
    usage=True,
)


@pytest.mark.parametrize(("args", "match", "usage"), CLI_CASES)
def test_cli_bad_arguments(args, match, usage, tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("TILTLAB_DEBUG", raising=False)
    files = _cli_files(tmp_path)
    argv = [a.format(**files) for a in args]
    capsys.readouterr()
    status = cli_main(argv)
    err = capsys.readouterr().err
    assert status != 0, f"exit status 0 for {argv}"
    assert "Traceback" not in err, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert lines, "nothing on stderr"
    if usage:  # argparse: usage line(s), then one "tiltlab ...: error: ..." line
        assert re.match(r"tiltlab( \w+)*: error: ", lines[-1]), err
        assert re.search(match, lines[-1]), err
    else:
        assert len(lines) == 1, f"expected one line on stderr, got:\n{err}"
        assert lines[0].startswith("tiltlab: "), err
        assert "unexpected error" not in lines[0], err
        assert re.search(match, lines[0]), err


# --------------------------------------------------------------------------- hypothesis fuzzing

_NAMES = re.compile(
    r"\b(acc|gyr|mag|temp|q_ref|fs|time|t0|units?|acc_units|gyr_units|mag_units|"
    r"attribute 'fs'|sampling rate|recording|beta|kp|ki|tau_acc_s|cutoff_hz|order|"
    r"init_window_s|accelerometer|magnetometer|gyroscope)\b",
    re.IGNORECASE,
)
_SPECIAL = [NAN, INF, -INF, 0.0, 1e300, -1e300, 1e-300, 1e6]
_FS_BAD = [0.0, -1.0, NAN, INF, -INF, 1e-300, 1e300, "100", "fast", None, True, [100]]
_FS_GOOD = [1.0, 50.0, 100.0, 200.0, 1000.0]
_fuzz = settings(
    max_examples=50,
    deadline=None,
    phases=[Phase.explicit, Phase.reuse, Phase.generate, Phase.shrink],
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)


@st.composite
def _signal(draw, n, width=3, bad_shape=False):
    """Moderate values (half the time clean), with a few special values injected."""
    shape = (n, width)
    if bad_shape:
        shape = draw(
            st.sampled_from([(n, 2), (n,), (n, 3, 1), (max(n - 1, 0), 3), (n, 4)])
        )
    a = draw(
        hnp.arrays(
            np.float64, shape, elements=st.floats(-50, 50, allow_nan=False, width=32)
        )
    )
    if a.size and draw(st.booleans()):
        for _ in range(draw(st.integers(1, 3))):
            a.flat[draw(st.integers(0, a.size - 1))] = draw(st.sampled_from(_SPECIAL))
    return a


def _outcome(kind: str) -> None:
    from hypothesis import event

    event(kind)


@_fuzz
@given(data=st.data())
def test_fuzz_make_recording(data):
    """make_recording: a valid Recording, or a RecordingError/ValueError naming the
    problem — never another exception."""
    n = data.draw(st.integers(0, 40), label="n")
    acc = data.draw(_signal(n, bad_shape=data.draw(st.booleans())), label="acc")
    gyr = data.draw(
        _signal(n, bad_shape=data.draw(st.integers(0, 4)) == 0), label="gyr"
    )
    fs = data.draw(
        st.one_of(
            st.sampled_from(_FS_GOOD),
            st.sampled_from(_FS_BAD),
            st.floats(-1e3, 1e6),
        ),
        label="fs",
    )
    kw = {
        "acc_units": data.draw(st.sampled_from(["g", "m/s^2", "furlong", "deg/s"])),
        "gyr_units": data.draw(st.sampled_from(["deg/s", "rad/s", "g", ""])),
    }
    if data.draw(st.booleans(), label="with mag"):
        kw["mag"] = data.draw(_signal(n, bad_shape=data.draw(st.integers(0, 4)) == 0))
    if data.draw(st.integers(0, 4), label="with temp") == 0:
        kw["temp"] = data.draw(_signal(n, width=1))[:, 0]
    if data.draw(st.integers(0, 4), label="with time") == 0:
        kw["time"] = data.draw(_signal(n, width=1))[:, 0]
    dtype = data.draw(
        st.sampled_from([np.float64, np.float32, np.int16]), label="dtype"
    )
    if (
        dtype is not np.float64
        and np.all(np.isfinite(acc))
        and np.abs(acc).max(initial=0) < 3e4
    ):
        acc = acc.astype(dtype)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            units = {
                "acc_units": "g",
                "gyr_units": "deg/s",
                "mag_units": "uT",
                "temp_units": "degC",
            }
            rec = schema.make_recording(acc, gyr, fs, **{**units, **kw})
    except (RecordingError, ValueError) as exc:
        _outcome(f"error {type(exc).__name__}")
        assert _NAMES.search(str(exc)), f"{type(exc).__name__}: {exc}"
        return
    _outcome("valid recording")
    schema.validate(rec)
    assert rec.sizes["time"] == np.asarray(acc).shape[0]
    for name in ("acc", "gyr"):
        assert np.all(np.isfinite(rec[name].values))


_FAST = ("mahony", "madgwick", "complementary", "lowpass")
_BAD_PARAM = st.sampled_from([NAN, INF, -1.0, 0.0, -1e-9, 1e300])
_PARAMS = {
    "mahony": {"kp": st.floats(0, 10), "ki": st.floats(0, 1)},
    "madgwick": {"beta": st.floats(0, 2)},
    "complementary": {"tau_acc_s": st.floats(0.01, 100)},
    "lowpass": {"cutoff_hz": st.floats(0.01, 0.49), "order": st.integers(1, 6)},
}
_COMMON = {"init_window_s": st.floats(0, 1)}


@st.composite
def _recordings(draw):
    n = draw(st.integers(1, 40))
    fs = draw(st.sampled_from([1.0, 10.0, 100.0, 1000.0, 1e-3, 1e6]))
    acc = draw(_signal(n))
    gyr = draw(_signal(n))
    if draw(st.booleans()):  # a plausible recording: 1 g up, modest rates
        acc = acc / 50.0 + [0.0, 0.0, 1.0]
    acc_units = draw(st.sampled_from(["g", "m/s^2"]))
    gyr_units = draw(st.sampled_from(["deg/s", "rad/s"]))
    # built without validation: estimate() must make its own checks
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return schema.make_recording(
            acc,
            gyr,
            fs,
            acc_units=acc_units,
            gyr_units=gyr_units,
            validate_result=False,
        )


@_fuzz
@given(rec=_recordings(), data=st.data(), method=st.sampled_from(_FAST))
def test_fuzz_estimate(rec, data, method):
    """estimate(): finite unit quaternions, or a RecordingError/ValueError naming the
    problem — never another exception, never NaN."""
    params = {}
    for name, good_values in {**_PARAMS[method], **_COMMON}.items():
        choice = data.draw(st.integers(0, 3), label=f"{name} choice")
        if choice == 1:
            params[name] = data.draw(good_values, label=name)
        elif choice == 2:
            params[name] = data.draw(_BAD_PARAM, label=name)
    if method == "lowpass" and "cutoff_hz" in params and params["cutoff_hz"] < 0.5:
        params["cutoff_hz"] *= rec.attrs["fs"]  # a fraction of fs, below Nyquist
    note(
        f"fs={rec.attrs['fs']!r} acc [{rec['acc'].attrs['units']}]="
        f"{rec['acc'].values.tolist()!r} gyr [{rec['gyr'].attrs['units']}]="
        f"{rec['gyr'].values.tolist()!r}"
    )
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            q = filters.estimate(rec, method, **params)
    except (RecordingError, ValueError) as exc:
        _outcome(f"error {type(exc).__name__}")
        assert _NAMES.search(str(exc)), f"{type(exc).__name__}: {exc}"
        return
    _outcome("estimate")
    v = np.asarray(q.values)
    assert v.shape == (rec.sizes["time"], 4)
    assert np.all(np.isfinite(v)), f"non-finite output of {method} with {params}"
    assert np.allclose(np.linalg.norm(v, axis=1), 1.0, atol=1e-6)
