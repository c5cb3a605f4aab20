"""A Recording written the way a phone logging app exports it (:func:`phone_export`).

One CSV per sensor, each on its own jittery clock with nanosecond epoch times.
"""

from __future__ import annotations

from os import PathLike
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from .. import _validate as _v
from .. import units as _units
from .._deprecate import renamed

__all__ = ["PHONE_FILES", "phone_export"]

#: file name, the phone's unit and the variable's name in a phone export
PHONE_FILES = {
    "acc": ("TotalAcceleration.csv", "m/s^2"),
    "gyr": ("Gyroscope.csv", "rad/s"),
    "mag": ("Magnetometer.csv", "uT"),
}


def _stream_times(t0: float, t1: float, fs: float, rng, drift: float, jitter: float):
    """Draw the sample times of one stream in [t0, t1].

    The stream has its own rate (``fs`` off by up to ``drift``), its own start within
    the first period, and Gaussian jitter of ``jitter`` periods (kept increasing).
    """
    rate = fs * (1.0 + rng.uniform(-drift, drift))
    start = t0 + rng.uniform(0.0, 1.0 / rate)
    n = int(np.floor((t1 - start) * rate)) + 1
    t = start + np.arange(n) / rate + rng.normal(0.0, jitter / rate, n)
    t = np.clip(np.maximum.accumulate(t), t0, t1)
    keep = np.r_[True, np.diff(t) > 0]  # strictly increasing, as a logger writes
    return t[keep], rate


@renamed(recording="rec")
def phone_export(
    rec: xr.Dataset,
    folder: str | PathLike,
    *,
    drift: float = 0.01,
    jitter: float = 0.2,
    start_ns: int = 1_700_000_000_000_000_000,
    seed: int = 0,
) -> dict[str, Path]:
    """Write a Recording as a phone sensor-logger export: one CSV per sensor.

    Each sensor gets its own clock (rate off the Recording's ``fs`` by up to ``drift``,
    its own start, Gaussian jitter), its values linearly interpolated from the
    Recording at those times, and is written with columns ``time`` (integer
    nanoseconds since the Unix epoch, from ``start_ns``), ``seconds_elapsed`` (s since
    the Recording's first sample, to the microsecond) and ``z``, ``y``, ``x`` (the axis order of some
    phone apps), in the phone's units (m/s², rad/s, µT). The axes are written as they
    are: a simulated recording in the sensor frame becomes a phone whose (right, top,
    out of screen) axes are the sensor's (x, y, z). It is a test input for
    :func:`tiltlab.io.read_multi` with ``"time_units": "ns"`` and the ``android``
    preset.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording; ``acc`` and whichever of ``gyr`` and ``mag`` it has are written
        (formerly ``recording``, which still works with a ``FutureWarning``).
    folder : path-like
        Folder to write into (created if needed).
    drift : float
        Largest relative rate error of a stream's clock (0.01: 1 %).
    jitter : float
        Standard deviation of the sample-time jitter, in sample periods.
    start_ns : int
        Epoch time (ns) of the Recording's first sample.
    seed : int
        Seed of the clocks.

    Returns
    -------
    dict
        Variable name → path of its CSV file.

    Examples
    --------
    >>> import tempfile
    >>> from tiltlab import simulate
    >>> rec = simulate.simulate_session(5.0, 100.0, seed=1)
    >>> files = phone_export(rec, tempfile.mkdtemp())
    >>> sorted(p.name for p in files.values())
    ['Gyroscope.csv', 'TotalAcceleration.csv']
    """
    if not isinstance(rec, xr.Dataset) or "acc" not in rec:
        raise _v.RecordingError("phone_export needs a Recording with acc")
    if rec.attrs.get("fs") is None:
        raise _v.RecordingError("phone_export: the Recording has no fs attribute")
    fs = _v.check_fs(rec.attrs["fs"])
    if not 0.0 <= drift < 0.5 or not 0.0 <= jitter < 0.5:
        raise ValueError(
            f"drift must be in [0, 0.5) and jitter in [0, 0.5) periods, got "
            f"drift={drift}, jitter={jitter}"
        )
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    t = rec["time"].values.astype(float)
    t0, t1 = float(t[0]), float(t[-1])
    files = {}
    for var, (name, unit) in PHONE_FILES.items():
        if var not in rec:
            continue
        values = _units.convert(rec[var].values, rec[var].attrs["units"], unit)
        times, _ = _stream_times(t0, t1, fs, rng, drift, jitter)
        table = pd.DataFrame(
            {
                "time": start_ns + np.round((times - t0) * 1e9).astype(np.int64),
                "seconds_elapsed": np.round(times - t0, 6),  # µs, as apps print it
            }
        )
        for k, axis in ((2, "z"), (1, "y"), (0, "x")):
            table[axis] = np.interp(times, t, values[:, k])
        files[var] = out / name
        table.to_csv(files[var], index=False, float_format="%.7g")
    return files
