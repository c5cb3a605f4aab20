"""BROAD benchmark trials (``.hdf5`` and MATLAB ``.mat``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr


from ._common import PathLike, ReadError, no_file, sensor_recording


_BROAD_VARS = ("imu_acc", "imu_gyr", "imu_mag", "opt_quat", "opt_pos", "movement")
#: Columns of each variable (``movement`` is one flag per sample).
_WIDTH = {
    "imu_acc": 3,
    "imu_gyr": 3,
    "imu_mag": 3,
    "opt_quat": 4,
    "opt_pos": 3,
    "movement": 1,
}


def _check_layout(path: Path, data: dict[str, np.ndarray]) -> int:
    """Count the samples, refusing a transposed or mis-shaped variable by name."""
    transposed = [
        k
        for k, w in _WIDTH.items()
        if data[k].ndim == 2
        and data[k].shape[0] == w
        and data[k].shape[1] not in (w, 1)
        and w > 1
    ]
    if transposed:
        shapes = ", ".join(f"{k} {data[k].shape}" for k in transposed)
        raise ReadError(
            f"{path}: the variables are stored transposed, one column per sample "
            f"({shapes}; expected one row per sample, e.g. (N, 3), or (N, 4) for "
            "opt_quat), as MATLAB "
            "writes an array that was not transposed before saving: transpose them "
            "(e.g. save imu_acc.' in MATLAB, or arr.T in Python) and save again"
        )
    for k, w in _WIDTH.items():
        a = data[k]
        ok = (a.ndim == 1 and w == 1) or (a.ndim == 2 and a.shape[1] == w)
        if not ok:
            want = "(samples,)" if w == 1 else f"(samples, {w})"
            raise ReadError(f"{path}: {k} has shape {a.shape}, expected {want}")
    n = data["imu_acc"].shape[0]
    for k in _BROAD_VARS:
        if data[k].shape[0] != n:
            raise ReadError(
                f"{path}: {k} has {data[k].shape[0]} samples, imu_acc has {n}"
            )
    return n


def _movement_mask(path: Path, movement: np.ndarray) -> np.ndarray:
    """Read BROAD's ``movement`` flags as booleans.

    Anything but 0/1 (NaN included) is an error naming the rows, never a silent
    ``True``.
    """
    m = np.asarray(movement).reshape(-1)
    if m.dtype == bool:
        return m
    if m.dtype.kind not in "biuf":
        raise ReadError(f"{path}: movement must hold 0/1 flags, got dtype {m.dtype}")
    bad = ~np.isin(m, (0, 1))  # NaN is never in (0, 1)
    if bad.any():
        rows = np.flatnonzero(bad)
        nan = int(np.isnan(m[rows]).sum()) if m.dtype.kind == "f" else 0
        what = "NaN" if nan == rows.size else "values other than 0/1 (e.g. NaN or 2)"
        raise ReadError(
            f"{path}: movement (the mask of scored samples) has {rows.size} {what} at "
            f"rows {rows[:5].tolist()}{' …' if rows.size > 5 else ''} (first value "
            f"{m[rows[0]].item()!r}); a missing flag cannot be scored as movement or rest: "
            "repair the file's mask first"
        )
    return m.astype(bool)


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
    mv = data["movement"]
    if mv.ndim == 2 and 1 in mv.shape:  # MATLAB stores a vector as (N, 1) or (1, N)
        data["movement"] = mv.reshape(-1)
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

    Parameters
    ----------
    path : path-like
        The trial file.
    check_units : bool, optional
        False accepts the published units unchecked (they pass the check).
    **attrs
        Attributes to add to the Recording (provenance, e.g. ``subject="S01"``).

    Returns
    -------
    xarray.Dataset
        The Recording, with ``q_ref``, ``movement`` and ``opt_pos``.

    Raises
    ------
    ReadError
        A missing file (or a directory), an unreadable or incomplete trial, variables
        of different lengths, variables stored transposed (one column per sample, as
        MATLAB saves an array that was not transposed), or a ``movement`` mask with
        anything but 0/1 flags (a NaN flag is neither movement nor rest: the rows are
        named).

    References
    ----------
    .. [1] D. Laidig, M. Caruso, A. Cereatti, T. Seel, Data 6(7):72, 2021.
       doi:10.3390/data6070072
    """
    path = Path(path)
    if not path.is_file():
        raise ReadError(no_file(path))
    suffix = path.suffix.lower()
    if suffix in (".hdf5", ".h5"):
        data, fs, info = _read_broad_hdf5(path)
    elif suffix == ".mat":
        data, fs, info = _read_broad_mat(path)
    else:
        raise ReadError(
            f"{path}: unknown BROAD file type {suffix!r} (expected .hdf5 or .mat)"
        )
    _check_layout(path, data)
    movement = _movement_mask(path, data["movement"])
    q = data["opt_quat"].astype(float)
    # the optical reference has NaN where tracking was lost; keep NaN, validate with allow_nan
    trial = path.stem
    return sensor_recording(
        {"acc": data["imu_acc"], "gyr": data["imu_gyr"], "mag": data["imu_mag"]},
        fs,
        {"acc": "m/s^2", "gyr": "rad/s", "mag": "uT"},
        q_ref=q,
        check_units=check_units,
        extra={
            "movement": (
                "time",
                movement,
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
