"""A generic CSV with a column/unit mapping (:func:`read_csv`)."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from .. import _validate, schema
from .. import quality as _quality
from .. import units as _units
from ._common import PathLike, ReadError, _read_table


#: Units accepted for a CSV time column, as factors to seconds.
TIME_UNITS: dict[str, float] = {"s": 1.0, "ms": 1e-3, "us": 1e-6}
_TIME_ALIASES = {"s": "s", "sec": "s", "ms": "ms", "us": "us", "µs": "us", "μs": "us"}

#: Sampling rates (Hz) accepted by :func:`read_csv` unless told otherwise: a value
#: outside this range almost always means a time column in the wrong unit.
FS_RANGE: tuple[float, float] = (1.0, 20_000.0)

#: What :func:`read_csv` does with samples missing from the time column (dropped by a
#: logger): refuse the file, or put NaN rows in their place.
GAP_POLICIES: tuple[str, ...] = ("raise", "nan")

#: Number of columns each Recording variable takes from a CSV.
_WIDTH = {"acc": 3, "gyr": 3, "mag": 3, "temp": 1, "q_ref": 4}
_MAPPING_KEYS = (
    "columns",
    "units",
    "fs",
    "time_column",
    "time_scale",
    "time_units",
    "fs_range",
    "range",
    "scale",
    "gaps",
    "attrs",
    "read_csv",
)
_NOT_READ_KWARGS = {"filepath_or_buffer", "usecols", "dtype"}


def _read_csv_params() -> frozenset[str]:
    import inspect

    return frozenset(inspect.signature(pd.read_csv).parameters) - _NOT_READ_KWARGS


def _time_factor(time_units: str, where: str) -> float:
    key = _TIME_ALIASES.get(str(time_units).strip())
    if key is None:
        raise ValueError(
            f"{where}time_units must be one of 's', 'ms', 'us', got {time_units!r}"
        )
    return TIME_UNITS[key]


_RAW_UNITS = {"counts", "count", "lsb", "raw", "adc", "digits", "bits"}


def _scaled_unit_hint(var: str, unit: object) -> str:
    """A hint for a unit that is a known one with a prefix (``mg``, ``mdps``) or raw
    ADC counts: read the column with a ``scale`` factor instead."""
    if not isinstance(unit, str):
        return ""
    key = unit.strip()
    if key.lower() in _RAW_UNITS:
        example = {"acc": ("g", "1/16384 (±2 g)"), "gyr": ("deg/s", "1/131 (±250 °/s)")}
        u, f = example.get(var, ("its physical unit", "1/sensitivity"))
        return (
            f"; for raw ADC counts give the physical unit and a factor, e.g. "
            f"units {{{var!r}: {u!r}}} and scale {{{var!r}: {f}}}"
        )
    for prefix, factor in (("m", "0.001"), ("milli", "0.001"), ("milli-", "0.001")):
        rest = key[len(prefix) :]
        if key.startswith(prefix) and rest:
            try:
                canon = _units.normalise_unit(rest)
            except _units.UnitsError:
                continue
            return (
                f"; {unit!r} looks like milli-{canon}: give units {{{var!r}: {canon!r}}} "
                f"and scale {{{var!r}: {factor}}}"
            )
    return ""


def _load_mapping(mapping: Mapping[str, Any] | PathLike) -> tuple[dict[str, Any], str]:
    """The raw mapping as a dict, and a prefix naming it in messages."""
    if isinstance(mapping, Mapping):
        return dict(mapping), "mapping: "
    if not isinstance(mapping, (str, os.PathLike)):
        raise TypeError(
            f"mapping must be a dict or the path of a JSON file, got {type(mapping).__name__}"
        )
    path = Path(mapping)
    if not path.is_file():
        raise ReadError(f"{path}: no such mapping file")
    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError as exc:
        raise ReadError(f"{path}: not a text (JSON) file ({exc.reason})") from None
    except json.JSONDecodeError as exc:
        raise ValueError(
            f"{path}: not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})"
        ) from None
    if not isinstance(raw, dict):
        raise ValueError(
            f"{path}: a mapping is a JSON object with keys 'columns' and 'units', "
            f"got a JSON {type(raw).__name__}"
        )
    return raw, f"mapping {path}: "


def _check_mapping(raw: Mapping[str, Any], where: str) -> dict[str, Any]:
    """Check a raw mapping and return it normalised (see :func:`read_csv_mapping`)."""
    allowed_read = _read_csv_params()
    unknown = [k for k in raw if k not in _MAPPING_KEYS and k not in allowed_read]
    if unknown:
        raise ValueError(
            f"{where}unknown key(s) {unknown}; a mapping has {', '.join(_MAPPING_KEYS)} "
            "and pandas.read_csv options (sep, decimal, skiprows, comment, encoding, ...)"
        )
    columns = raw.get("columns")
    if not isinstance(columns, Mapping) or not columns:
        raise ValueError(
            f"{where}'columns' must map variables to column names, e.g. "
            '{"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]}'
        )
    cols: dict[str, list[str]] = {}
    for var, names in columns.items():
        if var not in _WIDTH:
            raise ValueError(
                f"{where}unknown variable {var!r} in 'columns' (known: {', '.join(_WIDTH)})"
            )
        names = [names] if isinstance(names, str) else names
        if not isinstance(names, Sequence) or not all(
            isinstance(c, str) for c in names
        ):
            raise ValueError(
                f"{where}columns[{var!r}] must be a column name or a list of names, got {names!r}"
            )
        if len(names) != _WIDTH[var]:
            raise ValueError(
                f"{where}columns[{var!r}] needs {_WIDTH[var]} column(s), got {len(names)}: {list(names)}"
            )
        cols[var] = list(names)
    for var in ("acc", "gyr"):
        if var not in cols:
            raise ValueError(f"{where}'columns' must map {var!r}")
    units_in = raw.get("units") or {}
    if not isinstance(units_in, Mapping):
        raise ValueError(f"{where}'units' must map variables to unit strings")
    units: dict[str, str] = {}
    for var, unit in units_in.items():
        if var == "time":
            continue
        if var not in _WIDTH:
            raise ValueError(
                f"{where}unknown variable {var!r} in 'units' (known: {', '.join(_WIDTH)}, time)"
            )
        try:
            units[var] = _units.normalise_unit(unit)
        except _units.UnitsError as exc:
            raise ValueError(
                f"{where}units[{var!r}]: {exc}{_scaled_unit_hint(var, unit)}"
            ) from None
    for var in cols:
        if var != "q_ref" and var not in units:
            raise ValueError(
                f"{where}units must give the unit of {var!r}; tiltlab does not assume one"
            )
    # time: a column, and its unit as time_units ("s", "ms", "us"), units["time"] or time_scale
    time_column = raw.get("time_column")
    if time_column is not None and not isinstance(time_column, str):
        raise ValueError(
            f"{where}time_column must be a column name, got {time_column!r}"
        )
    unit_sources = {
        k: v
        for k, v in (
            ("time_units", raw.get("time_units")),
            ("units['time']", units_in.get("time")),
        )
        if v is not None
    }
    factors = {k: _time_factor(v, where) for k, v in unit_sources.items()}
    if raw.get("time_scale") is not None:
        factors["time_scale"] = _validate.positive(
            raw["time_scale"], f"{where}time_scale"
        )
    if len(set(factors.values())) > 1:
        raise ValueError(
            f"{where}the time unit is given twice and disagrees: {factors} (factors to seconds)"
        )
    if factors and time_column is None:
        raise ValueError(f"{where}a time unit is given but no time_column")
    time_scale = next(iter(factors.values()), 1.0)
    fs = raw.get("fs")
    if fs is not None:
        fs = _validate.check_fs(fs, f"{where}fs")
    elif time_column is None:
        raise ValueError(
            f"{where}give fs, or a time_column from which to estimate it; "
            "tiltlab never assumes a sampling rate"
        )
    fs_range = raw.get("fs_range", FS_RANGE)
    if fs_range is not None:
        if not isinstance(fs_range, Sequence) or len(fs_range) != 2:
            raise ValueError(
                f"{where}fs_range must be [low, high] in Hz, got {fs_range!r}"
            )
        lo = _validate.positive(fs_range[0], f"{where}fs_range[0]")
        hi = _validate.positive(fs_range[1], f"{where}fs_range[1]", allow_inf=True)
        if lo >= hi:
            raise ValueError(f"{where}fs_range must be [low, high], got {fs_range!r}")
        fs_range = (lo, hi)
    full: dict[str, Any] = {}
    range_in = raw.get("range") or {}
    if not isinstance(range_in, Mapping):
        raise ValueError(
            f"{where}'range' must map variables to their full scale, e.g. "
            '{"acc": 16, "gyr": 2000}'
        )
    for var, value in range_in.items():
        if var not in ("acc", "gyr", "mag"):
            raise ValueError(
                f"{where}range[{var!r}]: a full scale is given for acc, gyr or mag only"
            )
        if var not in cols:
            raise ValueError(
                f"{where}range[{var!r}] is given but {var!r} is not mapped"
            )
        try:
            lo, hi = _quality.limits(value, f"{where}range[{var!r}]")
        except ValueError as exc:
            raise ValueError(str(exc)) from None
        full[var] = hi if np.isclose(-lo, hi) else [lo, hi]
    scale: dict[str, float] = {}
    scale_in = raw.get("scale") or {}
    if not isinstance(scale_in, Mapping):
        raise ValueError(
            f"{where}'scale' must map variables to factors, e.g. "
            '{"acc": 0.001} for a column in mg read as g'
        )
    for var, value in scale_in.items():
        if var not in cols or var == "q_ref":
            raise ValueError(
                f"{where}scale[{var!r}]: a factor is given for a mapped acc, gyr, mag "
                "or temp only"
            )
        scale[var] = _validate.positive(value, f"{where}scale[{var!r}]")
    gaps = raw.get("gaps") or "raise"
    if gaps not in GAP_POLICIES:
        raise ValueError(
            f"{where}gaps must be one of {', '.join(map(repr, GAP_POLICIES))}, got {gaps!r}"
        )
    attrs = raw.get("attrs") or {}
    if not isinstance(attrs, Mapping):
        raise ValueError(
            f"{where}'attrs' must be a mapping of attribute names to values"
        )
    read_kwargs = {k: v for k, v in raw.items() if k in allowed_read}
    nested = raw.get("read_csv") or {}
    if not isinstance(nested, Mapping):
        raise ValueError(
            f"{where}'read_csv' must be a mapping of pandas.read_csv options"
        )
    bad = [k for k in nested if k not in allowed_read]
    if bad:
        raise ValueError(
            f"{where}'read_csv' has option(s) pandas.read_csv does not take or tiltlab sets itself: {bad}"
        )
    read_kwargs.update(nested)
    return {
        "columns": cols,
        "units": units,
        "fs": fs,
        "time_column": time_column,
        "time_scale": float(time_scale),
        "fs_range": fs_range,
        "range": full,
        "scale": scale,
        "gaps": gaps,
        "attrs": dict(attrs),
        "read_csv": read_kwargs,
    }


def read_csv_mapping(mapping: Mapping[str, Any] | PathLike) -> dict[str, Any]:
    """Load and check a column/unit mapping for :func:`read_csv`.

    Parameters
    ----------
    mapping : dict or path-like
        The mapping itself, or the path of a JSON file holding it::

            {
              "columns": {"acc": ["AccX", "AccY", "AccZ"],
                          "gyr": ["GyrX", "GyrY", "GyrZ"], "temp": "T"},
              "units": {"acc": "m/s^2", "gyr": "deg/s", "temp": "degC"},
              "time_column": "t_ms", "time_units": "ms",
              "sep": ";"
            }

        Keys: ``columns`` (variable → column name(s); ``acc`` and ``gyr`` required,
        ``mag``, ``temp`` and ``q_ref`` optional) and ``units`` (variable → unit) are
        required; ``fs`` (Hz) or ``time_column`` (or both) must be given;
        ``time_units`` (``"s"``, ``"ms"``, ``"us"``; also accepted as
        ``units["time"]``) or ``time_scale`` (factor to seconds) give the unit of the
        time column (default seconds); ``fs_range`` ([low, high] Hz, ``null`` to
        disable) bounds a plausible sampling rate; ``range`` (variable → full scale in
        its units, ``r`` for ±r or ``[low, high]``, for ``acc``, ``gyr``, ``mag``) is the
        sensor's measurement range, used to find clipped samples; ``scale`` (variable →
        positive factor from the column's numbers to ``units``, for ``acc``, ``gyr``,
        ``mag``, ``temp``; e.g. ``{"acc": 0.001}`` for a column in mg with
        ``units["acc"] = "g"``, or 1/16384 g per count for raw counts at ±2 g) converts
        columns in units tiltlab does not name; ``gaps`` (``"raise"`` or ``"nan"``,
        see :func:`read_csv`) handles samples missing from the time column; ``attrs``
        are extra
        Recording attributes; any other key is a :func:`pandas.read_csv` option (``sep``,
        ``decimal``, ``skiprows``, ``comment``, ``encoding``…), or put them under
        ``read_csv``.

    Returns
    -------
    dict
        Keys ``columns`` (variable → list of names), ``units`` (canonical spellings),
        ``fs`` (float or None), ``time_column``, ``time_scale`` (factor to seconds),
        ``fs_range``, ``range`` (variable → full scale), ``scale`` (variable →
        factor), ``gaps``, ``attrs`` and ``read_csv`` (options for :func:`pandas.read_csv`).

    Raises
    ------
    ReadError
        If the file is missing or unreadable.
    ValueError
        If the JSON is invalid or the mapping is incomplete or inconsistent; the
        message names the key.
    """
    raw, where = _load_mapping(mapping)
    return _check_mapping(raw, where)


def _check_time(time: np.ndarray, column: str, path: Path) -> None:
    if not np.all(np.isfinite(time)):
        raise schema.RecordingError(
            f"{path}: time column {column!r} has non-finite values"
        )
    step = np.diff(time)
    if np.any(step <= 0):
        i = int(np.argmax(step <= 0))
        raise schema.RecordingError(
            f"{path}: time column {column!r} is not strictly increasing "
            f"(data row {i + 1}: {time[i + 1]!r} after {time[i]!r})"
        )


_TIME_NAMES = {"s": "seconds", "ms": "milliseconds", "us": "microseconds"}


def _unit_hint(
    raw_step: float, fs_range: tuple[float, float] | None, scale: float | None = None
) -> str:
    """Which time unit (other than the one in use, factor ``scale`` to seconds) would
    make the median step a plausible sampling interval."""
    lo, hi = fs_range or FS_RANGE
    for unit, factor in TIME_UNITS.items():
        if scale is not None and np.isclose(factor, scale):
            continue
        f = 1.0 / (raw_step * factor)
        if lo <= f <= hi:
            return (
                f"; the time column looks like {_TIME_NAMES[unit]}: give "
                f"time_units={unit!r} (fs would be {f:.6g} Hz)"
            )
    return ""


def read_csv(
    path: PathLike,
    columns: Mapping[str, Sequence[str] | str] | None = None,
    units: Mapping[str, str] | None = None,
    *,
    mapping: Mapping[str, Any] | PathLike | None = None,
    fs: float | None = None,
    time_column: str | None = None,
    time_scale: float | None = None,
    time_units: str | None = None,
    fs_range: tuple[float, float] | None = FS_RANGE,
    attrs: Mapping[str, Any] | None = None,
    **read_kwargs,
) -> xr.Dataset:
    """Read any CSV with a column/unit mapping.

    Parameters
    ----------
    path : path-like
        CSV file.
    columns : mapping, optional
        Variable → column names, e.g. ``{"acc": ["AccX", "AccY", "AccZ"], "gyr": [...],
        "temp": "T"}``. ``acc`` and ``gyr`` are required; ``mag``, ``temp`` and ``q_ref``
        (four columns, scalar first) are optional. Not needed when ``mapping`` gives them.
    units : mapping, optional
        Variable → unit string, e.g. ``{"acc": "m/s^2", "gyr": "rad/s"}``; required for
        every physical variable in ``columns`` (no unit is assumed). ``"time"`` may give
        the unit of the time column (as ``time_units``).
    mapping : dict or path-like, optional
        A whole mapping (``columns``, ``units``, ``fs``, ``time_column``, ``time_units``
        …, see :func:`read_csv_mapping`), or the path of a JSON file holding one.
        Arguments given explicitly override it (``units`` and ``attrs`` are merged); its
        ``range`` (variable → the sensor's full scale) and ``scale`` (variable → factor
        from the column's numbers to its ``units``, e.g. ``{"acc": 0.001}`` for mg) may
        also be given as keywords. The factors are kept in ``attrs['csv_scale']``.
        So may ``gaps``: ``"raise"`` (default) refuses a time column that skips samples
        (steps longer than 1.5/fs, a logger that dropped samples); ``"nan"`` inserts
        NaN rows in their place, keeps a description in ``attrs['gaps']`` and
        validates with ``allow_nan``.
    fs : float, optional
        Sampling rate (Hz). If omitted, ``time_column`` is required and ``fs`` is
        estimated as 1 / median interval, to 7 significant digits (recorded in
        ``attrs['fs_source']``).
    time_column : str, optional
        Column with sample times.
    time_scale : float, optional
        Factor converting the time column to seconds (e.g. ``1e-3`` for ms).
    time_units : {"s", "ms", "us"}, optional
        Unit of the time column; an alternative to ``time_scale``. Default seconds.
    fs_range : (float, float) or None
        Plausible sampling rates (Hz). A rate outside it — estimated, or given and
        contradicted by the time column — is an error that suggests the time unit that
        would fit. ``None`` disables the check.
    attrs : mapping, optional
        Extra dataset attributes (provenance).
    **read_kwargs
        Passed to :func:`pandas.read_csv` (e.g. ``sep=';'``).

    Returns
    -------
    xarray.Dataset
        The validated Recording, with ``attrs['source']`` the file name.

    Raises
    ------
    ReadError
        If the file is missing or unreadable, or lacks a mapped column (the message
        names it and lists the file's columns).
    ValueError
        If the mapping is incomplete or inconsistent, or the sampling rate implausible.
    RecordingError
        If the data break the Recording contract, or the time column skips samples
        (unless ``gaps="nan"``).
    """
    path = Path(path)
    raw: dict[str, Any] = {}
    where = ""
    if mapping is not None:
        raw, where = _load_mapping(mapping)
    elif columns is not None and (
        isinstance(columns, (str, os.PathLike))
        or (isinstance(columns, Mapping) and "columns" in columns)
    ):
        # read_csv(path, "mapping.json") or read_csv(path, {"columns": ..., "units": ...})
        raw, where = _load_mapping(columns)
        columns = None
    if columns is not None:
        raw["columns"] = columns
    if units is not None:
        raw["units"] = {**(raw.get("units") or {}), **units}
    if fs is not None:
        raw["fs"] = fs
    if time_column is not None:
        raw["time_column"] = time_column
    if time_scale is not None or time_units is not None:
        for k in ("time_scale", "time_units"):
            raw.pop(k, None)
        if isinstance(raw.get("units"), Mapping):
            raw["units"] = {k: v for k, v in raw["units"].items() if k != "time"}
        raw["time_scale"], raw["time_units"] = time_scale, time_units
    if fs_range != FS_RANGE or "fs_range" not in raw:
        raw["fs_range"] = fs_range
    if attrs:
        raw["attrs"] = {**(raw.get("attrs") or {}), **attrs}
    if "range" in read_kwargs:  # the sensor's full scale, as in a mapping
        raw["range"] = read_kwargs.pop("range")
    if "scale" in read_kwargs:  # factors from the columns' numbers to the units
        raw["scale"] = read_kwargs.pop("scale")
    if "gaps" in read_kwargs:  # what to do with samples the logger dropped
        raw["gaps"] = read_kwargs.pop("gaps")
    nested = read_kwargs.pop("read_csv", None) or {}
    if not isinstance(nested, Mapping):
        raise ValueError("read_csv must be a mapping of pandas.read_csv options")
    if read_kwargs or nested:
        raw["read_csv"] = {**(raw.get("read_csv") or {}), **nested, **read_kwargs}
    m = _check_mapping(raw, where)
    cols, tcol = m["columns"], m["time_column"]
    roles = {c: var for var, names in cols.items() for c in names}
    if tcol:
        roles.setdefault(tcol, "time_column")
    df = _read_table(path, list(roles), roles=roles, **m["read_csv"])
    get = {k: df[v].to_numpy(float) * m["scale"].get(k, 1.0) for k, v in cols.items()}
    time = None
    extra_attrs = dict(m["attrs"])
    if m["scale"]:
        extra_attrs["csv_scale"] = dict(m["scale"])
    fs, lo_hi = m["fs"], m["fs_range"]
    if tcol:
        raw_time = df[tcol].to_numpy(float)
        time = raw_time * m["time_scale"]
        _check_time(time, tcol, path)
        raw_step = float(np.median(np.diff(raw_time)))
        fs_est = 1.0 / (raw_step * m["time_scale"])
        unit = next(
            (u for u, f in TIME_UNITS.items() if np.isclose(f, m["time_scale"])),
            f"× {m['time_scale']:g} s",
        )
        if fs is None:
            if lo_hi is not None and not lo_hi[0] <= fs_est <= lo_hi[1]:
                raise ValueError(
                    f"{path}: sampling rate estimated from time column {tcol!r} ({unit}) is "
                    f"{fs_est:.6g} Hz, outside the plausible range {lo_hi[0]:g}–{lo_hi[1]:g} Hz"
                    + (
                        _unit_hint(raw_step, lo_hi, m["time_scale"])
                        or "; give fs, or widen fs_range"
                    )
                )
            # 7 significant digits: the median of parsed intervals carries rounding noise
            fs = float(f"{fs_est:.7g}")
            extra_attrs["fs_source"] = f"estimated from column {tcol!r} ({unit})"
        elif not np.isclose(fs_est, fs, rtol=0.02):
            raise ValueError(
                f"{path}: fs = {fs:g} Hz but time column {tcol!r} ({unit}) gives "
                f"{fs_est:.6g} Hz (median interval {raw_step:g} {unit})"
                + _unit_hint(raw_step, (0.98 * fs, 1.02 * fs), m["time_scale"])
            )
    if lo_hi is not None and not lo_hi[0] <= fs <= lo_hi[1]:
        raise ValueError(
            f"{path}: fs = {fs:g} Hz is outside the plausible range {lo_hi[0]:g}–{lo_hi[1]:g} Hz "
            "(give fs_range to accept it)"
        )
    allow_nan = False
    if time is not None:
        time, get, missing = _place_on_grid(time, get, fs, tcol, path, m["gaps"])
        if missing:
            allow_nan = True
            extra_attrs["gaps"] = (
                f"{missing} missing sample{'s' if missing != 1 else ''} filled with NaN; "
                + _validate.describe_gaps(
                    time, fs, _validate.segments(time, fs, values=get["acc"])
                )
            )
    return schema.make_recording(
        get["acc"],
        get["gyr"],
        fs,
        acc_units=m["units"]["acc"],
        gyr_units=m["units"]["gyr"],
        mag=get.get("mag"),
        mag_units=m["units"].get("mag", "uT"),
        acc_range=m["range"].get("acc"),
        gyr_range=m["range"].get("gyr"),
        mag_range=m["range"].get("mag"),
        temp=get["temp"][:, 0] if "temp" in get else None,
        temp_units=m["units"].get("temp", "degC"),
        q_ref=get.get("q_ref"),
        time=time,
        attrs={"source": path.name, **extra_attrs},
        allow_nan=allow_nan,
    )


def _place_on_grid(
    time: np.ndarray,
    get: dict[str, np.ndarray],
    fs: float,
    tcol: str,
    path: Path,
    gaps: str,
) -> tuple[np.ndarray, dict[str, np.ndarray], int]:
    """Find samples missing from a time column (steps of about k/fs, k ≥ 2): refuse
    them (``gaps="raise"``) or insert NaN rows in their place (``"nan"``); return the
    time, the columns and the number of samples inserted."""
    segs = _validate.segments(time, fs)
    if len(segs) <= 1:
        return time, get, 0
    pos = (time - time[0]) * fs
    k = np.rint(pos).astype(np.int64)
    n_missing = int(k[-1] + 1 - k.size)
    where = _validate.describe_gaps(time, fs, segs)
    if gaps == "raise":
        raise schema.RecordingError(
            f"{path}: time column {tcol!r} skips samples ({where}"
            + (f"; about {n_missing} samples missing" if n_missing > 0 else "")
            + "): the logger dropped samples, or fs is wrong. "
            "Read with gaps='nan' to keep the gaps as NaN rows (orientation filters "
            "then run on each gap-free segment, estimate(..., gaps='segments'))"
        )
    if np.any(np.abs(pos - k) > 0.35) or np.any(np.diff(k) < 1):
        i = int(np.argmax((np.abs(pos - k) > 0.35) | np.r_[False, np.diff(k) < 1]))
        raise schema.RecordingError(
            f"{path}: time column {tcol!r} is not on a regular grid of 1/fs = "
            f"{1 / fs:.6g} s (data row {i}: {pos[i]:.2f} sample periods after the "
            "first); cannot place the gaps, give the right fs"
        )
    n = int(k[-1] + 1)
    full_time = time[0] + np.arange(n) / fs
    full_time[k] = time
    out = {}
    for var, v in get.items():
        filled = np.full((n, *v.shape[1:]), np.nan)
        filled[k] = v
        out[var] = filled
    return full_time, out, n - k.size
