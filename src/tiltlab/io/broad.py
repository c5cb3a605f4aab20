"""BROAD benchmark trials (``.hdf5`` and MATLAB ``.mat``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from .. import schema
from ._common import PathLike, ReadError


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


def read_broad(path: PathLike, *, check_units: bool = True, **attrs) -> xr.Dataset:
    """Read a BROAD benchmark trial (``.hdf5`` or ``.mat``) into a Recording.

    Units are kept as published: acceleration m/s², angular velocity rad/s,
    magnetic field µT. ``q_ref`` is the optical orientation (w, x, y, z, sensor → ENU,
    already aligned to the IMU frame), ``movement`` the boolean mask of samples to score
    and ``opt_pos`` the optical position (m). ``check_units=False`` skips the unit
    plausibility check (:func:`tiltlab.schema.make_recording`), as for every reader.

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
        check_units=check_units,
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
