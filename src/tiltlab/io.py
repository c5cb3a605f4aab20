"""Readers and writers. I/O only: each reader parses a file into a Recording
(:mod:`tiltlab.schema`) without any processing beyond unit labelling, and each
writer stores one losslessly.

Supported formats
-----------------
* Fayat et al. 2021 CSV files: the freely-moving example (``read_fayat_imu``) and
  the tumble test (``read_fayat_tumble``).
* BROAD benchmark trials, ``.hdf5`` and MATLAB ``.mat`` layouts (``read_broad``).
* A generic CSV with a column/unit mapping (``read_csv``).
* NetCDF via h5netcdf (``save_netcdf`` / ``load_netcdf``), exact round trip
  including attributes of any JSON-serialisable type.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from . import schema

__all__ = [
    "ReadError",
    "read_fayat_imu",
    "read_fayat_tumble",
    "read_broad",
    "read_csv",
    "save_netcdf",
    "load_netcdf",
]

PathLike = str | os.PathLike


class ReadError(OSError):
    """A file is missing, truncated, corrupt or not in the expected layout."""


def _read_table(
    path: PathLike, required: Sequence[str], *, final_newline: bool = False, **kwargs
) -> pd.DataFrame:
    path = Path(path)
    if not path.is_file():
        raise ReadError(f"{path}: no such file")
    if final_newline:
        # files written line by line end with a newline; a missing one means the copy was cut short
        with open(path, "rb") as f:
            f.seek(0, os.SEEK_END)
            if f.tell() == 0:
                raise ReadError(f"{path}: empty file")
            f.seek(-1, os.SEEK_END)
            if f.read(1) not in (b"\n", b"\r"):
                raise ReadError(
                    f"{path}: last line is incomplete (no final newline): truncated file?"
                )
    try:
        df = pd.read_csv(path, **kwargs)
    except (
        pd.errors.ParserError,
        pd.errors.EmptyDataError,
        UnicodeDecodeError,
        ValueError,
    ) as exc:
        raise ReadError(f"{path}: not a readable CSV table ({exc})") from None
    missing = [c for c in required if c not in df.columns]
    if missing:
        raise ReadError(
            f"{path}: missing column(s) {missing}; found {list(df.columns)}"
        )
    sub = df[list(required)]
    numeric = sub.apply(pd.to_numeric, errors="coerce")
    bad = numeric.isna() & ~sub.isna()
    if bad.to_numpy().any():
        row, col = np.argwhere(bad.to_numpy())[0]
        raise ReadError(
            f"{path}: non-numeric value {sub.iat[row, col]!r} in column {required[col]!r}, data row {row}"
        )
    if numeric.isna().to_numpy().any():
        row, col = np.argwhere(numeric.isna().to_numpy())[0]
        raise ReadError(
            f"{path}: empty field in column {required[col]!r}, data row {row} (truncated file?)"
        )
    if len(numeric) < 2:
        raise ReadError(f"{path}: fewer than two samples")
    return numeric


def read_fayat_imu(
    path: PathLike, *, counter_rate: float = 300.0, fs: float = 100.0, **attrs
) -> xr.Dataset:
    """Read Fayat et al.'s freely-moving rat example (``example_imu.csv``).

    Columns ``counter, ax, ay, az, gx, gy, gz``: acceleration in g, angular velocity in
    °/s, ``counter`` the acquisition board's sample counter at ``counter_rate`` Hz. The
    file is down-sampled to ``fs`` = 100 Hz, so sample times are ``(counter − counter₀) /
    counter_rate``; 27 of its intervals are 2/300 s instead of 3/300 s (left as they are,
    and kept in the ``counter`` variable).

    Axes: x points forward (nose), y to the animal's left, z up (dorsal) [1]_.

    References
    ----------
    .. [1] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
    """
    df = _read_table(
        path, ["counter", "ax", "ay", "az", "gx", "gy", "gz"], final_newline=True
    )
    counter = df["counter"].to_numpy(np.int64)
    time = (counter - counter[0]) / float(counter_rate)
    return schema.make_recording(
        df[["ax", "ay", "az"]].to_numpy(),
        df[["gx", "gy", "gz"]].to_numpy(),
        fs,
        acc_units="g",
        gyr_units="deg/s",
        time=time,
        extra={
            "counter": (
                "time",
                counter,
                {"long_name": f"acquisition counter at {counter_rate:g} Hz"},
            )
        },
        attrs={
            "source": str(Path(path).name),
            "sensor": "MPU9250 (wired head IMU)",
            "subject": "rat",
            "session": "example",
            "axes": "x forward (nose), y left, z up (dorsal)",
            **attrs,
        },
    )


def read_fayat_tumble(path: PathLike, *, fs: float = 300.0, **attrs) -> xr.Dataset:
    """Read Fayat et al.'s tumble-test recording (``example_sensor_calibration.csv``).

    Columns: an unnamed index, ``ax, ay, az`` (g), ``gx, gy, gz`` (°/s), ``time`` (s);
    300 Hz. The sensor is held still in several orientations; there is no trigger
    channel.
    """
    df = _read_table(
        path,
        ["ax", "ay", "az", "gx", "gy", "gz", "time"],
        final_newline=True,
        index_col=0,
    )
    return schema.make_recording(
        df[["ax", "ay", "az"]].to_numpy(),
        df[["gx", "gy", "gz"]].to_numpy(),
        fs,
        acc_units="g",
        gyr_units="deg/s",
        time=df["time"].to_numpy(),
        attrs={
            "source": str(Path(path).name),
            "sensor": "MPU9250",
            "subject": "none",
            "session": "tumble test",
            **attrs,
        },
    )


_BROAD_VARS = ("imu_acc", "imu_gyr", "imu_mag", "opt_quat", "opt_pos", "movement")


def _read_broad_hdf5(path: Path) -> tuple[dict[str, np.ndarray], float, str]:
    import h5py

    try:
        with h5py.File(path, "r") as f:
            missing = [k for k in _BROAD_VARS if k not in f]
            if missing:
                raise ReadError(f"{path}: not a BROAD trial, missing {missing}")
            data = {k: np.asarray(f[k][()]) for k in _BROAD_VARS}
            if "sampling_rate" in f.attrs:
                fs = float(np.asarray(f.attrs["sampling_rate"]).ravel()[0])
            elif "sampling_rate" in f:
                fs = float(np.asarray(f["sampling_rate"][()]).ravel()[0])
            else:
                raise ReadError(f"{path}: no sampling_rate")
            info = f.attrs.get("info", "")
            info = info.decode() if isinstance(info, bytes) else str(info)
    except (OSError, KeyError) as exc:
        if isinstance(exc, ReadError):
            raise
        raise ReadError(
            f"{path}: cannot read HDF5 file ({exc}); truncated or corrupt?"
        ) from None
    return data, fs, info


def _read_broad_mat(path: Path) -> tuple[dict[str, np.ndarray], float, str]:
    import scipy.io

    try:
        m = scipy.io.loadmat(path)
    except Exception as exc:  # scipy raises several types for damaged files
        raise ReadError(
            f"{path}: cannot read MATLAB file ({type(exc).__name__}: {exc}); truncated or corrupt?"
        ) from None
    missing = [k for k in _BROAD_VARS + ("sampling_rate",) if k not in m]
    if missing:
        raise ReadError(f"{path}: not a BROAD trial, missing {missing}")
    data = {k: np.asarray(m[k]) for k in _BROAD_VARS}
    data["movement"] = data["movement"].reshape(-1)
    fs = float(np.asarray(m["sampling_rate"]).ravel()[0])
    info = m.get("info", "")
    info = str(np.asarray(info).ravel()[0]) if np.size(info) else ""
    return data, fs, info


def read_broad(path: PathLike, **attrs) -> xr.Dataset:
    """Read a BROAD benchmark trial (``.hdf5`` or ``.mat``) into a Recording.

    Units are kept as published: acceleration m/s², angular velocity rad/s,
    magnetic field µT. ``q_ref`` is the optical orientation (w, x, y, z, sensor → ENU,
    already aligned to the IMU frame), ``movement`` the boolean mask of samples to score
    and ``opt_pos`` the optical position (m).

    References
    ----------
    .. [1] D. Laidig, M. Caruso, A. Cereatti, T. Seel, Data 6(7):72, 2021.
       doi:10.3390/data6070072
    """
    path = Path(path)
    if not path.is_file():
        raise ReadError(f"{path}: no such file")
    suffix = path.suffix.lower()
    if suffix in (".hdf5", ".h5"):
        data, fs, info = _read_broad_hdf5(path)
    elif suffix == ".mat":
        data, fs, info = _read_broad_mat(path)
    else:
        raise ReadError(
            f"{path}: unknown BROAD file type {suffix!r} (expected .hdf5 or .mat)"
        )
    n = data["imu_acc"].shape[0]
    for k in _BROAD_VARS:
        if data[k].shape[0] != n:
            raise ReadError(
                f"{path}: {k} has {data[k].shape[0]} samples, imu_acc has {n}"
            )
    q = data["opt_quat"].astype(float)
    # the optical reference has NaN where tracking was lost; keep NaN, validate with allow_nan
    trial = path.stem
    return schema.make_recording(
        data["imu_acc"],
        data["imu_gyr"],
        fs,
        acc_units="m/s^2",
        gyr_units="rad/s",
        mag=data["imu_mag"],
        mag_units="uT",
        q_ref=q,
        extra={
            "movement": (
                "time",
                data["movement"].astype(bool),
                {"long_name": "samples scored by BROAD (movement phase)"},
            ),
            "opt_pos": (
                ("time", "axis"),
                data["opt_pos"].astype(float),
                {"units": "m", "long_name": "optical position", "frame": "world (ENU)"},
            ),
        },
        attrs={
            "source": path.name,
            "sensor": "myon aktos-t",
            "subject": "hand-held IMU",
            "session": trial,
            "trial": trial,
            "world_frame": "ENU",
            "info": info,
            **attrs,
        },
        allow_nan=True,
    )


def read_csv(
    path: PathLike,
    columns: Mapping[str, Sequence[str] | str],
    units: Mapping[str, str],
    *,
    fs: float | None = None,
    time_column: str | None = None,
    time_scale: float = 1.0,
    attrs: Mapping[str, Any] | None = None,
    **read_kwargs,
) -> xr.Dataset:
    """Read any CSV with a column/unit mapping.

    Parameters
    ----------
    path : path-like
        CSV file.
    columns : mapping
        Variable → column names, e.g. ``{"acc": ["AccX", "AccY", "AccZ"], "gyr": [...],
        "temp": "T"}``. ``acc`` and ``gyr`` are required; ``mag``, ``temp`` and ``q_ref``
        (four columns, scalar first) are optional.
    units : mapping
        Variable → unit string, e.g. ``{"acc": "m/s^2", "gyr": "rad/s"}``; required for
        every physical variable in ``columns`` (no unit is assumed).
    fs : float, optional
        Sampling rate (Hz). If omitted, ``time_column`` is required and ``fs`` is
        estimated as 1 / median interval (recorded in ``attrs['fs_source']``).
    time_column : str, optional
        Column with sample times; multiplied by ``time_scale`` to obtain seconds.
    attrs : mapping, optional
        Extra dataset attributes (provenance).
    **read_kwargs
        Passed to :func:`pandas.read_csv` (e.g. ``sep=';'``).
    """
    cols = {k: [v] if isinstance(v, str) else list(v) for k, v in columns.items()}
    for k in ("acc", "gyr"):
        if k not in cols:
            raise ValueError(f"columns must map {k!r}")
    for k in cols:
        if k not in ("acc", "gyr", "mag", "temp", "q_ref"):
            raise ValueError(
                f"unknown variable {k!r} in columns (acc, gyr, mag, temp, q_ref)"
            )
        if k != "q_ref" and k not in units:
            raise ValueError(
                f"units must give the unit of {k!r}; tiltlab does not assume one"
            )
    required = [c for v in cols.values() for c in v] + (
        [time_column] if time_column else []
    )
    df = _read_table(path, required, **read_kwargs)
    get = {k: df[v].to_numpy(float) for k, v in cols.items()}
    time = df[time_column].to_numpy(float) * time_scale if time_column else None
    extra_attrs = dict(attrs or {})
    if fs is None:
        if time is None:
            raise ValueError(
                "give fs, or a time_column from which to estimate it; tiltlab never assumes a sampling rate"
            )
        fs = 1.0 / float(np.median(np.diff(time)))
        extra_attrs["fs_source"] = f"estimated from column {time_column!r}"
    return schema.make_recording(
        get["acc"],
        get["gyr"],
        fs,
        acc_units=units["acc"],
        gyr_units=units["gyr"],
        mag=get.get("mag"),
        mag_units=units.get("mag", "uT"),
        temp=get["temp"][:, 0] if "temp" in get else None,
        temp_units=units.get("temp", "degC"),
        q_ref=get.get("q_ref"),
        time=time,
        attrs={"source": Path(path).name, **extra_attrs},
    )


_ATTRS_KEY = "_tiltlab_attrs_json"


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return {"__ndarray__": o.tolist(), "dtype": str(o.dtype)}
    raise TypeError(
        f"attribute value {o!r} of type {type(o).__name__} cannot be stored"
    )


def _json_hook(d):
    if "__ndarray__" in d:
        return np.asarray(d["__ndarray__"], dtype=d["dtype"])
    return d


def save_netcdf(ds: xr.Dataset, path: PathLike) -> Path:
    """Write a Dataset to NetCDF-4 (h5netcdf engine) so that :func:`load_netcdf` returns it exactly.

    NetCDF attributes cannot hold booleans, dicts or None, so every attribute (of the
    dataset, its variables and coordinates) is also stored as JSON and restored on load.
    """
    path = Path(path)
    out = ds.copy()
    record = {"__dataset__": dict(ds.attrs)}
    for name, var in ds.variables.items():
        record[str(name)] = dict(var.attrs)
    try:
        blob = json.dumps(record, default=_json_default)
    except TypeError as exc:
        raise ValueError(f"cannot save attributes: {exc}") from None
    out.attrs = {
        k: v
        for k, v in ds.attrs.items()
        if isinstance(v, (str, int, float, np.number)) and not isinstance(v, bool)
    }
    out.attrs[_ATTRS_KEY] = blob
    for name in out.variables:
        out[name].attrs = {
            k: v
            for k, v in ds[name].attrs.items()
            if isinstance(v, (str, int, float, np.number)) and not isinstance(v, bool)
        }
    path.parent.mkdir(parents=True, exist_ok=True)
    out.to_netcdf(path, engine="h5netcdf", invalid_netcdf=False)
    return path


def load_netcdf(
    path: PathLike, *, validate: bool = False, **validate_kwargs
) -> xr.Dataset:
    """Load a Dataset written by :func:`save_netcdf` (fully into memory).

    Parameters
    ----------
    validate : bool
        Also run :func:`tiltlab.schema.validate` (for Recordings).
    **validate_kwargs
        Passed to :func:`tiltlab.schema.validate` (``allow_nan`` defaults to whether the
        file holds NaN).
    """
    path = Path(path)
    if not path.is_file():
        raise ReadError(f"{path}: no such file")
    try:
        with xr.open_dataset(path, engine="h5netcdf") as f:
            ds = f.load()
    except Exception as exc:
        raise ReadError(
            f"{path}: cannot read NetCDF file ({type(exc).__name__}: {exc}); truncated or corrupt?"
        ) from None
    blob = ds.attrs.pop(_ATTRS_KEY, None)
    if blob is not None:
        record = json.loads(blob, object_hook=_json_hook)
        ds.attrs = record.pop("__dataset__")
        for name, a in record.items():
            if name in ds.variables:
                ds[name].attrs = a
    for name in ds.variables:
        ds[name].encoding = {}
    if validate:
        allow_nan = any(
            bool(np.isnan(ds[v].values).any())
            for v in ds.data_vars
            if ds[v].dtype.kind == "f"
        )
        schema.validate(ds, **{"allow_nan": allow_nan, **validate_kwargs})
    return ds
