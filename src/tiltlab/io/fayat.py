"""Fayat et al. 2021 CSV files: the freely-moving example and the tumble test."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .. import _validate, schema
from ._common import PathLike, ReadError, _read_table


def _mpu9250_recording(
    path: PathLike,
    df,
    fs: float,
    check_units: bool,
    attrs: dict[str, Any],
    **options: Any,
) -> xr.Dataset:
    """Build a Recording from the ``ax..gz`` columns (g, °/s) of a Fayat et al. table."""
    return schema.make_recording(
        df[["ax", "ay", "az"]].to_numpy(),
        df[["gx", "gy", "gz"]].to_numpy(),
        fs,
        acc_units="g",
        gyr_units="deg/s",
        check_units=check_units,
        attrs={"source": str(Path(path).name), **attrs},
        **options,
    )


def _counter(path: PathLike, column) -> np.ndarray:
    """Read the acquisition counter as int64.

    A non-integer value (a corrupted row) is an error naming the row, never cut to an
    integer.
    """
    values = column.to_numpy()
    if values.dtype.kind == "f":
        frac = values != np.floor(values)
        if frac.any():
            i = int(np.argmax(frac))
            raise ReadError(
                f"{path}: counter must hold whole sample counts, got {values[i].item()!r} at "
                f"data row {i} ({int(frac.sum())} non-integer value"
                f"{'s' if frac.sum() != 1 else ''}): a corrupted row? Repair or "
                "remove it"
            )
    return values.astype(np.int64)


def read_fayat_imu(
    path: PathLike,
    *,
    counter_rate: float = 300.0,
    fs: float = 100.0,
    check_units: bool = True,
    **attrs,
) -> xr.Dataset:
    """Read Fayat et al.'s freely-moving rat example (``example_imu.csv``).

    Columns ``counter, ax, ay, az, gx, gy, gz``: acceleration in g, angular velocity in
    °/s, ``counter`` the acquisition board's sample counter at ``counter_rate`` Hz. The
    file is down-sampled to ``fs`` = 100 Hz, so sample times are ``(counter − counter₀) /
    counter_rate``; 27 of its intervals are 2/300 s instead of 3/300 s (left as they are,
    and kept in the ``counter`` variable). ``check_units=False`` skips the unit
    plausibility check, as for every reader.

    Axes: x points forward (nose), y to the animal's left, z up (dorsal) [1]_.

    Parameters
    ----------
    path : path-like
        ``example_imu.csv``.
    counter_rate : float, optional
        Rate of the acquisition counter (Hz).
    fs : float, optional
        Nominal sampling rate of the file (Hz).
    check_units : bool, optional
        False skips the plausibility check of the g and °/s columns.
    **attrs
        Attributes that replace the defaults (``sensor``, ``subject``, ``session``,
        ``axes``) or add to them.

    Returns
    -------
    xarray.Dataset
        The Recording, with the ``counter`` variable.

    Raises
    ------
    ReadError
        A missing file (or a directory), a truncated or unreadable table, or a
        ``counter`` value that is not a whole number (the data row is named; it is
        never cut to an integer).

    References
    ----------
    .. [1] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
    """
    df = _read_table(
        path, ["counter", "ax", "ay", "az", "gx", "gy", "gz"], final_newline=True
    )
    counter_rate = _validate.positive(counter_rate, "counter_rate")
    counter = _counter(path, df["counter"])
    time = (counter - counter[0]) / counter_rate
    return _mpu9250_recording(
        path,
        df,
        fs,
        check_units,
        {
            "sensor": "MPU9250 (wired head IMU)",
            "subject": "rat",
            "session": "example",
            "axes": "x forward (nose), y left, z up (dorsal)",
            **attrs,
        },
        preset="rat_head",
        time=time,
        extra={
            "counter": (
                "time",
                counter,
                {"long_name": f"acquisition counter at {counter_rate:g} Hz"},
            )
        },
    )


def read_fayat_tumble(
    path: PathLike, *, fs: float = 300.0, check_units: bool = True, **attrs
) -> xr.Dataset:
    """Read Fayat et al.'s tumble-test recording (``example_sensor_calibration.csv``).

    Columns: an unnamed index, ``ax, ay, az`` (g), ``gx, gy, gz`` (°/s), ``time`` (s);
    300 Hz. The sensor is held still in several orientations; there is no trigger
    channel. ``check_units=False`` skips the unit plausibility check.

    The MPU9250 was set to ±4 g and ±1000 °/s: every value is a multiple of 1/8192 g and
    1/32.768 °/s, and the file holds the rails −4 g, 32767/8192 g and −1000 °/s. Both are
    recorded as the variables' ``range`` attribute (the full scale), so that the samples
    clipped while the sensor was turned over are found
    (:func:`tiltlab.quality.saturation`).

    Parameters
    ----------
    path : path-like
        ``example_sensor_calibration.csv``.
    fs : float, optional
        Sampling rate (Hz).
    check_units : bool, optional
        False skips the unit check of the tumble test's g and °/s columns.
    **attrs
        Provenance for ``attrs``, replacing ``sensor="MPU9250"``, ``subject="none"``
        and ``session="tumble test"`` or adding to them.

    Returns
    -------
    xarray.Dataset
        The Recording, with the full scale in each variable's ``range``.

    Raises
    ------
    ReadError
        A missing file (or a directory), or a truncated or unreadable table.
    """
    df = _read_table(
        path,
        ["ax", "ay", "az", "gx", "gy", "gz", "time"],
        final_newline=True,
        index_col=0,
    )
    return _mpu9250_recording(
        path,
        df,
        fs,
        check_units,
        {"sensor": "MPU9250", "subject": "none", "session": "tumble test", **attrs},
        acc_range=4.0,
        gyr_range=1000.0,
        time=df["time"].to_numpy(),
    )
