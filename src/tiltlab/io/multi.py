"""Exports with one file per sensor, each on its own clock (:func:`read_multi`)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .. import _validate
import tiltlab.io.clock as _clock
from ._common import PathLike, ReadError
from .csv import build_recording, read_columns
from .mapping import (
    COMMON_KEYS,
    WIDTH,
    check_common,
    check_range,
    check_read_options,
    check_time_unit,
    check_unit,
    load_mapping,
    read_csv_params,
)

__all__ = ["read_multi", "STREAM_KEYS", "MAT_LAYOUTS"]

#: Keys of one entry of ``files`` (besides pandas.read_csv options for a CSV).
STREAM_KEYS = (
    "path",
    "columns",
    "variable",
    "layout",
    "units",
    "scale",
    "range",
    "time_column",
    "time_units",
    "time_scale",
    "read_csv",
)
#: How a MATLAB matrix holds [t, x, y, z]: as its rows (4 × N) or its columns (N × 4).
MAT_LAYOUTS = ("rows", "columns")


def _check_stream(
    var: str, entry: Any, where: str, allowed: frozenset[str]
) -> dict[str, Any]:
    """One entry of ``files``, checked: where the file is, its unit, scale and clock."""
    here = f"{where}files[{var!r}]: "
    if var not in WIDTH:
        raise ValueError(
            f"{where}unknown variable {var!r} in 'files' (known: {', '.join(WIDTH)})"
        )
    if isinstance(entry, str) or not isinstance(entry, Mapping):
        raise ValueError(
            f"{here}give a mapping with 'path', 'units' and the time, e.g. "
            '{"path": "Accelerometer.csv", "columns": ["x", "y", "z"], '
            '"time_column": "seconds_elapsed", "time_units": "s", "units": "m/s^2"}'
        )
    path = entry.get("path")
    if not isinstance(path, str) or not path:
        raise ValueError(f"{here}'path' must name the file, got {path!r}")
    is_mat = Path(path).suffix.lower() == ".mat"
    unknown = [
        k for k in entry if k not in STREAM_KEYS and (is_mat or k not in allowed)
    ]
    if unknown:
        raise ValueError(
            f"{here}unknown key(s) {unknown}; an entry has {', '.join(STREAM_KEYS)}"
            + ("" if is_mat else " and pandas.read_csv options")
        )
    out: dict[str, Any] = {
        "path": path,
        "mat": is_mat,
        "units": _stream_unit(var, entry.get("units"), here),
        "scale": _stream_scale(var, entry.get("scale"), here),
        "range": check_range(
            {var: entry["range"]} if entry.get("range") is not None else None,
            [var],
            here,
        ).get(var),
    }
    if is_mat:
        out.update(_check_mat_entry(entry, WIDTH[var], here))
    else:
        out.update(_check_csv_entry(entry, WIDTH[var], here, allowed))
    return out


def _stream_unit(var: str, units: Any, here: str) -> str:
    """Check a stream's unit (q_ref is unitless; every other variable states one)."""
    if var == "q_ref":
        if units not in (None, "1"):
            raise ValueError(f"{here}q_ref is unitless: give no 'units'")
        return "1"
    if units is None:
        raise ValueError(
            f"{here}'units' must give the unit of {var!r}; tiltlab does not assume one"
        )
    return check_unit(var, units, here)


def _stream_scale(var: str, scale: Any, here: str) -> float:
    """Check a stream's factor from the file's numbers to its unit (default 1)."""
    if scale is None:
        return 1.0
    if var == "q_ref":
        raise ValueError(f"{here}q_ref takes no scale")
    return float(_validate.positive(scale, f"{here}scale"))


def _check_mat_entry(entry: Mapping[str, Any], width: int, here: str) -> dict[str, Any]:
    """``variable``, ``layout`` and the time unit of a MATLAB entry."""
    for key in ("columns", "time_column", "read_csv"):
        if key in entry:
            raise ValueError(
                f"{here}{key!r} is for CSV files; a .mat entry has 'variable' and "
                "'layout' (time in the first row or column)"
            )
    layout = entry.get("layout")
    if layout is not None and layout not in MAT_LAYOUTS:
        raise ValueError(
            f"{here}layout must be 'rows' ({width + 1} × N: t, then the values) or "
            f"'columns' (N × {width + 1}), got {layout!r}"
        )
    variable = entry.get("variable")
    if variable is not None and not isinstance(variable, str):
        raise ValueError(f"{here}'variable' must be a name, got {variable!r}")
    time_scale, time_unit = check_time_unit(entry, "first row/column", here)
    if time_scale is None:
        raise ValueError(f"{here}a .mat time row is numeric: give 's', 'ms' …")
    return {
        "variable": variable,
        "layout": layout,
        "time_scale": time_scale,
        "time_units": time_unit,
    }


def _check_csv_entry(
    entry: Mapping[str, Any], width: int, here: str, allowed: frozenset[str]
) -> dict[str, Any]:
    """Check ``columns``, ``time_column``, time unit and read options of a CSV entry."""
    names = entry.get("columns")
    names = [names] if isinstance(names, str) else names
    if (
        not isinstance(names, (list, tuple))
        or len(names) != width
        or not all(isinstance(c, str) for c in names)
    ):
        raise ValueError(
            f"{here}'columns' must list {width} column name(s), got {names!r}"
        )
    tcol = entry.get("time_column")
    if not isinstance(tcol, str):
        raise ValueError(
            f"{here}'time_column' must name the column of this file's clock "
            "(each file of a multi-file export has its own)"
        )
    time_scale, time_unit = check_time_unit(entry, tcol, here)
    return {
        "columns": list(names),
        "time_column": tcol,
        "read_csv": check_read_options(entry, here, allowed),
        "time_scale": time_scale,
        "time_units": time_unit,
    }


def _read_stream(
    var: str, s: Mapping[str, Any], base: Path, where: str
) -> tuple[np.ndarray, np.ndarray, str]:
    """Read one stream: its raw time column, values (N, width) and source name."""
    path = Path(s["path"])
    if not path.is_absolute():
        path = base / path
    here = f"{where}files[{var!r}]: "
    width = WIDTH[var]
    if s["mat"]:
        from .mat import read_matrix

        a = np.asarray(read_matrix(path, s["variable"]))
        layout = s["layout"]
        if a.ndim != 2:
            raise ReadError(f"{path}: expected a matrix, got shape {a.shape}")
        if layout is None:
            rows, cols = a.shape[0] == width + 1, a.shape[1] == width + 1
            if rows == cols:
                raise ReadError(
                    f"{here}{path.name} has shape {a.shape}: give layout 'rows' "
                    f"([t, values] as {width + 1} rows) or 'columns'"
                )
            layout = "rows" if rows else "columns"
        shape = a.shape
        a = a if layout == "columns" else a.T
        if a.shape[1] != width + 1:
            raise ReadError(
                f"{here}{path.name} has shape {shape}; layout {layout!r} needs "
                f"{width + 1} {layout} (time, then {width} value{'s' * (width > 1)})"
            )
        if a.shape[0] < 2:
            raise ReadError(f"{path}: fewer than two samples")
        name = _clock.source_name(path, s["variable"])
        return a[:, 0], a[:, 1:].astype(float), name
    tcol = s["time_column"]
    data = read_columns(path, {var: s["columns"]}, tcol, s["time_units"], s["read_csv"])
    values = np.column_stack([data[c] for c in s["columns"]]).astype(float)
    return data[tcol], values, path.name


def read_multi(
    mapping: Mapping[str, Any] | PathLike,
    *,
    base: PathLike | None = None,
    **overrides: Any,
) -> xr.Dataset:
    r"""Read an export of one file per sensor, each on its own clock, into a Recording.

    Every stream is interpolated linearly onto one uniform grid at ``fs`` over the
    interval where all streams overlap (as :func:`tiltlab.io.read_csv` with
    ``clock="resample"``, whose docstring says what linear interpolation does to high
    frequencies); steps longer than ``max_gap`` periods of a stream's own rate are real
    gaps, never interpolated across, and handled by ``gaps``.

    Parameters
    ----------
    mapping : dict or path-like
        The mapping, or the path of a JSON file holding it::

            {
              "files": {
                "acc": {"path": "Accelerometer.csv", "columns": ["x", "y", "z"],
                        "time_column": "seconds_elapsed", "time_units": "s",
                        "units": "m/s^2"},
                "gyr": {"path": "gyro.mat", "variable": "gyroBuffer",
                        "layout": "rows", "units": "deg/s"},
                "mag": {...}
              },
              "fs": 100, "check_units": true, "axes": {"acc": ["-x", "-y", "-z"]}
            }

        ``files`` maps each variable (``acc`` required; ``gyr``, ``mag``, ``temp``,
        ``q_ref`` optional) to one file: ``path`` (relative paths are resolved against
        ``base``, else the mapping file's folder, else the working directory) and
        ``units`` (required; ``scale``, a factor from the file's numbers to the units,
        and ``range``, the full scale, optional). A CSV entry gives ``columns``, its own
        ``time_column`` and ``time_units`` (``"s"``, ``"ms"``, ``"us"``, ``"ns"``,
        ``"datetime"``; epoch times are made relative, see :func:`read_csv`) and any
        :func:`pandas.read_csv` option. A MATLAB entry (``.mat``, v5 or v7.3) gives
        ``variable`` (optional when the file holds one) and ``layout``: ``"rows"`` for
        a (1 + width) × N matrix ``[t; x; y; z]``, ``"columns"`` for N × (1 + width)
        (guessed from the shape when omitted); its time is in seconds unless
        ``time_units`` says otherwise. The other keys apply to the Recording: ``fs``
        (Hz; default the accelerometer stream's rate, estimated as in
        ``clock="resample"``), ``fs_range``, ``max_gap`` (default 5), ``gaps``
        (``"raise"`` or ``"nan"``), ``check_units``, ``axes``, ``preset``,
        ``axis_labels`` and ``attrs``.
    base : path-like, optional
        Folder against which relative paths are resolved.
    **overrides
        Any key of the mapping other than ``files`` (``fs=200``, ``gaps="nan"`` …);
        they win over the mapping's.

    Returns
    -------
    xarray.Dataset
        The validated Recording. ``attrs['streams']`` gives, for each variable, its
        source file, sample count, rate and median and longest step;
        ``attrs['merge']`` says how the streams were put on the grid;
        ``attrs['source']`` lists the files.

    Raises
    ------
    ReadError
        A file is missing or unreadable, or lacks a column or variable.
    ValueError
        The mapping is incomplete or inconsistent, a rate is implausible, or the
        streams do not overlap.
    RecordingError
        A clock is not increasing, or has real gaps (unless ``gaps="nan"``), or the
        data break the Recording contract.

    Examples
    --------
    >>> import numpy as np, tempfile, pathlib
    >>> from tiltlab import io
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> for name, rate, z in (("acc", 100, 9.81), ("gyr", 90, 0.0)):
    ...     t = np.arange(0, 2, 1 / rate)
    ...     rows = ["t,x,y,z"] + [f"{x:.6f},0,0,{z}" for x in t]
    ...     _ = (d / f"{name}.csv").write_text("\n".join(rows))
    >>> files = {v: {"path": f"{v}.csv", "columns": ["x", "y", "z"],
    ...              "time_column": "t", "units": u}
    ...          for v, u in (("acc", "m/s^2"), ("gyr", "rad/s"))}
    >>> rec = io.read_multi({"files": files, "fs": 100}, base=d)
    >>> sorted(rec.data_vars), rec.attrs["fs"]
    (['acc', 'gyr'], 100.0)
    """
    raw, where = load_mapping(mapping)
    if base is None:
        base = Path(mapping).parent if not isinstance(mapping, Mapping) else Path.cwd()
    files = _check_multi_keys(raw, overrides, where)
    common = check_common(raw, where)
    allowed = read_csv_params()
    streams = {v: _check_stream(v, e, where, allowed) for v, e in files.items()}
    read = {
        var: _read_clock(var, s, Path(base), where, common)
        for var, s in streams.items()
    }
    extra = _align_origins(read, where)
    fs = common["fs"]
    if fs is None:
        fs = read["acc"]["info"]["rate_hz"]
        extra["fs_source"] = (
            "the accelerometer stream's rate, (samples − 1) / duration leaving out gaps"
        )
    grid = _overlap_grid(read, fs, where)
    get = {var: _resample(var, r, grid, fs, where) for var, r in read.items()}
    allow_nan = any(r["gaps"].size for r in read.values())
    if allow_nan:
        extra["gaps"] = _describe_nan_rows(get, grid, fs)
    names = list(read)
    extra["streams"] = {v: r["info"] for v, r in read.items()}
    extra["merge"] = (
        f"{len(names)} stream{'s' * (len(names) > 1)} ({', '.join(names)}) interpolated "
        f"linearly onto one uniform {fs:.7g} Hz grid over their overlap, t = "
        f"{grid[0]:.6g}–{grid[-1]:.6g} s ({grid.size} samples)"
    )
    m = {
        **common,
        "units": {v: s["units"] for v, s in streams.items()},
        "range": {v: s["range"] for v, s in streams.items() if s["range"] is not None},
    }
    return build_recording(
        get,
        fs,
        m,
        time=grid,
        attrs={
            "source": ", ".join(dict.fromkeys(r["name"] for r in read.values())),
            **extra,
            **common["attrs"],
        },
        allow_nan=allow_nan,
        style="mapping",
    )


def _check_multi_keys(
    raw: dict[str, Any], overrides: Mapping[str, Any], where: str
) -> Mapping[str, Any]:
    """Merge the overrides into the mapping, check its keys and return ``files``."""
    bad = [k for k in overrides if k not in COMMON_KEYS]
    if bad:
        raise TypeError(
            f"read_multi got unknown option(s) {bad}; it takes {', '.join(COMMON_KEYS)}"
        )
    raw.update({k: v for k, v in overrides.items() if v is not None})
    unknown = [k for k in raw if k not in ("files", *COMMON_KEYS)]
    if unknown:
        raise ValueError(
            f"{where}unknown key(s) {unknown}; a multi-file mapping has 'files' and "
            f"{', '.join(COMMON_KEYS)} (CSV options go in each file's entry)"
        )
    files = raw.get("files")
    if not isinstance(files, Mapping) or "acc" not in files:
        raise ValueError(
            f"{where}'files' must map each variable to its file, 'acc' at least, e.g. "
            '{"acc": {"path": "Accelerometer.csv", ...}, "gyr": {...}}'
        )
    if raw.get("clock") not in (None, "resample"):
        raise ValueError(
            f"{where}a multi-file export is always resampled onto one grid: give no "
            "'clock' or 'resample'"
        )
    return files


def _read_clock(
    var: str,
    s: Mapping[str, Any],
    base: Path,
    where: str,
    common: Mapping[str, Any],
) -> dict[str, Any]:
    """Read one stream and check its clock: times (s), values, gaps and a summary."""
    max_gap, lo_hi = common["max_gap"], common["fs_range"]
    raw_time, values, name = _read_stream(var, s, base, where)
    here = f"{where}files[{var!r}] ({name}): "
    scale = s["time_scale"]
    t, origin = _clock.to_seconds(
        raw_time, _clock.DATETIME if scale is None else scale, here
    )
    _clock.check_increasing(t, "time", here)
    rate, n_gaps = _clock.estimate_rate(t, max_gap)
    if lo_hi is not None and not lo_hi[0] <= rate <= lo_hi[1]:
        hint = (
            _clock.unit_hint(1.0 / (rate * scale), lo_hi, scale, "mapping")
            if scale is not None
            else ""
        )
        raise ValueError(
            f"{here}its clock gives {rate:.6g} Hz, outside the plausible range "
            f"{lo_hi[0]:g}–{lo_hi[1]:g} Hz"
            + (hint or "; check the time unit, or widen fs_range")
        )
    gap_idx = _clock.gap_steps(t, rate, max_gap)
    if gap_idx.size and common["gaps"] == "raise":
        _clock.raise_gaps(t, gap_idx, rate, max_gap, "time", here, "mapping")
    steps = np.diff(t)
    return {
        "time": t,
        "origin": origin,
        "values": values * s["scale"],
        "gaps": gap_idx,
        "name": name,
        "info": {
            "source": name,
            "samples": int(t.size),
            "rate_hz": float(f"{rate:.7g}"),
            "median_step_s": float(f"{np.median(steps):.6g}"),
            "max_step_s": float(f"{steps.max():.6g}"),
            **({"gaps": int(gap_idx.size)} if gap_idx.size else {}),
        },
    }


def _align_origins(read: Mapping[str, dict[str, Any]], where: str) -> dict[str, Any]:
    """Shift absolute clocks onto the earliest one; ``time_origin`` if any."""
    origins = {v: r["origin"] for v, r in read.items()}
    if all(o is None for o in origins.values()):
        return {}
    if any(o is None for o in origins.values()):
        raise ValueError(
            f"{where}some clocks hold absolute (epoch or date-time) times and others "
            f"do not ({', '.join(v for v, o in origins.items() if o is None)}): "
            "the streams cannot be aligned"
        )
    first = min(origins.values())
    for r in read.values():
        shift = (r["origin"] - first) / np.timedelta64(1, "ns") * 1e-9
        r["time"] = r["time"] + shift
    return {"time_origin": _clock.iso_utc(first)}


def _overlap_grid(
    read: Mapping[str, Mapping[str, Any]], fs: float, where: str
) -> np.ndarray:
    """Build the uniform grid at ``fs`` over the interval every stream covers."""
    start = max(float(r["time"][0]) for r in read.values())
    stop = min(float(r["time"][-1]) for r in read.values())
    if stop <= start:
        spans = ", ".join(
            f"{v} {r['time'][0]:.6g}–{r['time'][-1]:.6g} s" for v, r in read.items()
        )
        raise ValueError(
            f"{where}the streams do not overlap in time ({spans}): are they from the "
            "same session, on the same clock?"
        )
    grid = _clock.uniform_grid(start, stop, fs)
    if grid.size < 2:
        raise ValueError(
            f"{where}the streams overlap for {stop - start:.3g} s only: fewer than two "
            f"samples at {fs:g} Hz"
        )
    return grid


def _resample(
    var: str, r: Mapping[str, Any], grid: np.ndarray, fs: float, where: str
) -> np.ndarray:
    """One stream interpolated onto the grid, NaN inside its real gaps."""
    _clock.warn_if_downsampled(fs, r["info"]["rate_hz"], f"{where}files[{var!r}]")
    if r["gaps"].size:  # refuse a grid that would be mostly NaN (a corrupt clock)
        t, gi = r["time"], r["gaps"]
        inside = np.searchsorted(grid, t[gi + 1], side="left") - np.searchsorted(
            grid, t[gi], side="right"
        )
        _clock.check_missing_fraction(
            t,
            grid.size,
            int(inside.sum()),
            fs,
            "time",
            f"{where}files[{var!r}]: ",
            gi,
        )
    return _clock.interpolate(
        r["time"], r["values"], grid, r["gaps"], quaternion=var == "q_ref"
    )


def _describe_nan_rows(
    get: Mapping[str, np.ndarray], grid: np.ndarray, fs: float
) -> str:
    """``attrs['gaps']``: how many grid rows hold NaN, and where."""
    bad_rows = np.zeros(grid.size, dtype=bool)
    for v in get.values():
        bad_rows |= np.isnan(v.reshape(grid.size, -1)).any(axis=1)
    segs = _validate.segments(grid, fs, values=np.where(bad_rows, np.nan, 0.0)[:, None])
    return (
        f"{int(bad_rows.sum())} grid samples inside real gaps filled with NaN; "
        + _validate.describe_gaps(grid, fs, segs)
    )
