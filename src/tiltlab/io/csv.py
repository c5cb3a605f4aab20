"""Read a generic CSV through a column/unit mapping (:func:`read_csv`)."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from .. import _validate
from .. import quality as _quality
import tiltlab.io.clock as _clock
from ._common import (
    PathLike,
    ReadError,
    _missing_columns_message,
    no_file,
    read_table_or_fail,
    sensor_recording,
)
from .clock import CLOCK_POLICIES, MAX_GAP, READ_GAP_POLICIES, TIME_UNITS
from .mapping import FS_RANGE, MAPPING_KEYS, CsvMapping, check_mapping, load_mapping

__all__ = [
    "read_csv",
    "read_csv_mapping",
    "CsvMapping",
    "TIME_UNITS",
    "FS_RANGE",
    "READ_GAP_POLICIES",
    "CLOCK_POLICIES",
    "MAX_GAP",
]


def read_csv_mapping(mapping: Mapping[str, Any] | PathLike | CsvMapping) -> CsvMapping:
    """Load and check a column/unit mapping for :func:`read_csv`.

    Parameters
    ----------
    mapping : dict, CsvMapping or path-like
        The mapping itself, or the path of a JSON file holding it::

            {
              "columns": {"acc": ["AccX", "AccY", "AccZ"],
                          "gyr": ["GyrX", "GyrY", "GyrZ"], "temp": "T"},
              "units": {"acc": "m/s^2", "gyr": "deg/s", "temp": "degC"},
              "time_column": "t_ms", "time_units": "ms",
              "sep": ";"
            }

        Keys:

        * ``columns`` (required): variable → column name(s). ``acc`` is required;
          ``gyr``, ``mag``, ``temp`` and ``q_ref`` (four columns, scalar first) are
          optional. With a header of several rows (``"header": [0, 1]``) a column is
          named by its levels joined with ``/``, e.g. ``"left_sensor/acc_x"``.
        * ``units`` (required): variable → unit, for every mapped variable but
          ``q_ref``; tiltlab never assumes one.
        * ``fs`` (Hz) or ``time_column`` (or both).
        * ``time_units``: ``"s"`` (default), ``"ms"``, ``"us"``, ``"ns"``, or
          ``"datetime"`` for date-time text; also accepted as ``units["time"]``, or
          ``time_scale`` (factor to seconds). Epoch times are recognised (see
          :func:`read_csv`).
        * ``clock``: ``"grid"`` (default) or ``"resample"``; ``max_gap`` (sample
          periods, default 5); ``gaps``: ``"raise"`` (default) or ``"nan"`` (see
          :func:`read_csv`).
        * ``fs_range``: [low, high] Hz of a plausible rate (``null`` disables).
        * ``range``: variable → full scale in its units (``r`` for ±r, or
          ``[low, high]``; acc, gyr, mag), used to find clipped samples.
        * ``scale``: variable → positive factor from the column's numbers to
          ``units`` (acc, gyr, mag, temp), e.g. ``{"acc": 0.001}`` for a column in mg
          with ``units["acc"] = "g"``, or 1/16384 g per count for raw counts at ±2 g.
        * ``check_units`` (true/false), ``axes``, ``preset``, ``axis_labels``: passed
          to :func:`tiltlab.schema.make_recording` (device axes and sign conventions,
          :mod:`tiltlab.axes`).
        * ``attrs``: extra Recording attributes.
        * any other key is a :func:`pandas.read_csv` option (``sep``, ``decimal``,
          ``skiprows``, ``comment``, ``encoding``, ``header`` …), or put them under
          ``read_csv``.

    Returns
    -------
    CsvMapping
        The checked mapping, a frozen record whose fields are ``columns`` (variable
        → list of names), ``units`` (canonical spellings), ``time_column``,
        ``time_scale`` (factor to seconds; None for date-times), ``time_units`` (the
        unit's name, or None for another factor), ``range``, ``scale``, ``fs`` (float
        or None), ``fs_range``, ``gaps``, ``clock``, ``max_gap``, ``check_units``,
        ``axes``, ``preset``, ``axis_labels``, ``attrs`` and ``read_csv`` (options for
        :func:`pandas.read_csv`); ``m["units"]`` reads a field too.

    Raises
    ------
    ReadError
        If the file is missing or unreadable.
    ValueError
        If the JSON is invalid or the mapping is incomplete or inconsistent; the
        message names the key.

    Examples
    --------
    >>> from tiltlab import io
    >>> m = io.read_csv_mapping({"columns": {"acc": ["ax", "ay", "az"]},
    ...                          "units": {"acc": "g"}, "fs": 50})
    >>> m.columns["acc"], m.clock, m.gaps
    (['ax', 'ay', 'az'], 'grid', 'raise')
    """
    return CsvMapping.load(mapping)


def _flat(name: Any) -> str:
    """Name a column, joining the levels of a multi-row header with ``/``."""
    if isinstance(name, tuple):
        return "/".join(str(level) for level in name)
    return str(name)


def _numeric(values: pd.Series, name: str, path: Path, raw_text=None) -> np.ndarray:
    """Convert a column to numbers, refusing text, missing values and empty fields.

    The error names the data row. ``raw_text(row)``, if given, returns the field as
    written in the file (pandas has already turned markers such as ``NaN`` or ``NA``
    into NaN).
    """
    num = pd.to_numeric(values, errors="coerce")
    bad = num.isna().to_numpy()
    if bad.any():
        row = int(np.argmax(bad))
        text = values.iat[row]
        if pd.isna(text) and raw_text is not None:
            text = raw_text(row)
        if text is None or pd.isna(text) or str(text).strip() == "":
            raise ReadError(
                f"{path}: empty field in column {name!r}, data row {row} (truncated file?)"
            )
        if pd.isna(pd.to_numeric(pd.Series([str(text).strip()]), errors="coerce")[0]):
            if str(text).strip().lower().lstrip("+-#") in _NA_MARKERS:
                n_bad = int(bad.sum())
                raise ReadError(
                    f"{path}: missing value {str(text)!r} in column {name!r}, data row "
                    f"{row} ({n_bad} missing value{'s' if n_bad != 1 else ''} in the "
                    "column): read_csv takes every row as a measured sample. Drop the "
                    "rows without a measurement (with a time column, the gap they "
                    "leave can be kept as NaN rows: gaps='nan')"
                )
        raise ReadError(
            f"{path}: non-numeric value {text!r} in column {name!r}, data row {row}"
        )
    return num.to_numpy()


#: Texts that pandas reads as a missing value (lower case, sign and '#' stripped).
_NA_MARKERS = frozenset(
    {"nan", "na", "n/a", "null", "none", "nat", "<na>", "1.#ind", "1.#qnan", "ind"}
)


def _raw_field(path: Path, kwargs: Mapping[str, Any], column: str):
    """Make a function ``row -> str`` giving the field of ``column`` as written.

    The file is read again without missing-value conversion; used for error messages
    only.
    """

    def get(row: int):
        try:
            df = pd.read_csv(
                path,
                **{
                    **kwargs,
                    "dtype": str,
                    "keep_default_na": False,
                    "na_filter": False,
                },
            )
        except (pd.errors.ParserError, ValueError, TypeError, UnicodeDecodeError):
            return None
        df.columns = [_flat(c) for c in df.columns]
        if column not in df.columns or row >= len(df):
            return None
        return df[column].iat[row]

    return get


def read_frame(
    path: Path,
    wanted: Sequence[str],
    roles: Mapping[str, str],
    text: Sequence[str] = (),
    **read_kwargs,
) -> dict[str, np.ndarray]:
    """Read the ``wanted`` columns of a CSV as numbers, or as text for ``text``.

    Integers are kept as integers. A header of several rows is flattened (levels joined
    with ``/``).

    Parameters
    ----------
    path : Path
        CSV file.
    wanted : sequence of str
        Columns to read.
    roles : mapping
        Column → what it is mapped to, for messages about missing columns.
    text : sequence of str, optional
        Columns returned as read (date-time text).
    **read_kwargs
        Options for :func:`pandas.read_csv`.

    Returns
    -------
    dict
        Column name → values.

    Raises
    ------
    ReadError
        If the file is missing or unreadable, lacks a column, holds fewer than two
        samples, or a column is not numeric.
    """
    if not path.is_file():
        raise ReadError(no_file(path))
    header = read_kwargs.get("header", "infer")
    multi = isinstance(header, (list, tuple)) and len(header) > 1
    want = set(wanted)
    kwargs = dict(read_kwargs)
    if not multi and not kwargs.get("index_col"):
        kwargs["usecols"] = lambda c: str(c) in want
    df = read_table_or_fail(path, **kwargs)
    df.columns = [_flat(c) for c in df.columns]
    missing = [c for c in wanted if c not in df.columns]
    if missing:
        if "usecols" in kwargs:  # name every column of the file in the message
            kwargs.pop("usecols")
            try:
                df = pd.read_csv(path, **{**kwargs, "nrows": 0})
            except (pd.errors.ParserError, pd.errors.EmptyDataError, ValueError):
                pass
            df.columns = [_flat(c) for c in df.columns]
        msg = _missing_columns_message(path, df, missing, roles)
        if not multi and any("/" in c for c in missing):
            msg += (
                " (a name written 'level1/level2' is a column of a header of several "
                "rows: give header=[0, 1])"
            )
        raise ReadError(msg)
    if len(df) < 2:
        raise ReadError(f"{path}: fewer than two samples")
    out = {}
    for c in wanted:
        col = df[c]
        if isinstance(col, pd.DataFrame):
            raise ReadError(f"{path}: column {c!r} appears more than once")
        out[c] = (
            col.to_numpy()
            if c in text
            else _numeric(col, c, path, _raw_field(path, kwargs, c))
        )
    return out


#: Keys of a mapping that :func:`read_csv` takes as keywords in ``**options``.
_MAPPING_OPTIONS = frozenset(MAPPING_KEYS) - {"columns", "units", "read_csv"}


def _raw_mapping(
    columns: Any,
    units: Mapping[str, str] | None,
    mapping: Mapping[str, Any] | PathLike | CsvMapping | None,
    explicit: Mapping[str, Any],
    options: dict[str, Any],
) -> tuple[dict[str, Any], str]:
    """Merge the keywords of a :func:`read_csv` call into its raw mapping (they win)."""
    raw: dict[str, Any] = {}
    where = ""
    if mapping is not None:
        raw, where = load_mapping(mapping)
    elif columns is not None and (
        isinstance(columns, (str, os.PathLike, CsvMapping))
        or (isinstance(columns, Mapping) and "columns" in columns)
    ):
        # read_csv(path, "mapping.json") or read_csv(path, {"columns": ..., "units": ...})
        raw, where = load_mapping(columns)
        columns = None
    if columns is not None:
        raw["columns"] = columns
    if units is not None:
        raw["units"] = {**(raw.get("units") or {}), **units}
    given = {k: options.pop(k) for k in list(options) if k in _MAPPING_OPTIONS}
    given.update(explicit)
    if given.get("time_scale") is not None or given.get("time_units") is not None:
        for k in ("time_scale", "time_units"):
            raw.pop(k, None)
        if isinstance(raw.get("units"), Mapping):
            raw["units"] = {k: v for k, v in raw["units"].items() if k != "time"}
    if "fs_range" in given:  # None disables the check
        raw["fs_range"] = given.pop("fs_range")
    attrs = given.pop("attrs", None)
    if attrs:
        raw["attrs"] = {**(raw.get("attrs") or {}), **attrs}
    raw.update({k: v for k, v in given.items() if v is not None})
    nested = options.pop("read_csv", None) or {}
    if not isinstance(nested, Mapping):
        raise ValueError("read_csv must be a mapping of pandas.read_csv options")
    if options or nested:
        raw["read_csv"] = {**(raw.get("read_csv") or {}), **nested, **options}
    return raw, where


def read_columns(
    path: Path,
    columns: Mapping[str, Sequence[str]],
    time_column: str | None,
    time_units: str | None,
    read_options: Mapping[str, Any],
) -> dict[str, np.ndarray]:
    """Read the mapped columns and the time column of a CSV (:func:`read_frame`).

    Parameters
    ----------
    path : Path
        CSV file.
    columns : mapping
        Variable → column names.
    time_column : str or None
        Column of sample times (read as text for date-times).
    time_units : str or None
        The time unit's name; ``"datetime"`` keeps the time column as text.
    read_options : mapping
        Options for :func:`pandas.read_csv`.

    Returns
    -------
    dict
        Column name → values.
    """
    roles = {c: var for var, names in columns.items() for c in names}
    if time_column:
        roles.setdefault(time_column, "time_column")
    return read_frame(
        path,
        list(roles),
        roles,
        text=[time_column] if time_units == _clock.DATETIME else (),
        **read_options,
    )


def read_csv(
    path: PathLike,
    columns: Mapping[str, Sequence[str] | str] | None = None,
    units: Mapping[str, str] | None = None,
    *,
    mapping: Mapping[str, Any] | PathLike | CsvMapping | None = None,
    fs: float | None = None,
    time_column: str | None = None,
    time_units: str | None = None,
    clock: str | None = None,
    gaps: str | None = None,
    **options: Any,
) -> xr.Dataset:
    r"""Read any CSV with a column/unit mapping.

    Parameters
    ----------
    path : path-like
        CSV file.
    columns : mapping, optional
        Variable → column names, e.g. ``{"acc": ["AccX", "AccY", "AccZ"], "gyr": [...],
        "temp": "T"}``. ``acc`` is required; ``gyr``, ``mag``, ``temp`` and ``q_ref``
        (four columns, scalar first) are optional (a tag without gyroscope gives a
        valid Recording). With a header of several rows (``header=[0, 1]``) name a
        column by its levels joined with ``/``: ``"left_sensor/acc_x"``. Not needed
        when ``mapping`` gives them.
    units : mapping, optional
        Variable → unit string, e.g. ``{"acc": "m/s^2", "gyr": "rad/s"}``; required for
        every physical variable in ``columns`` (no unit is assumed). ``"time"`` may give
        the unit of the time column (as ``time_units``).
    mapping : dict, CsvMapping or path-like, optional
        A whole mapping (:class:`CsvMapping`, :func:`read_csv_mapping`), a dict, or
        the path of a JSON file holding one. Arguments given explicitly override it
        (``units`` and ``attrs`` are merged). When the options come from a mapping,
        error messages name the fix as a JSON key (``"clock": "resample"``), else as a
        keyword (``clock='resample'``).
    fs : float, optional
        Sampling rate (Hz). If omitted, ``time_column`` is required and ``fs`` is
        estimated (recorded in ``attrs['fs_source']``): with ``clock="grid"`` as
        1 / median step, with ``clock="resample"`` as (samples − 1) / duration leaving
        out the real gaps; to 7 significant digits.
    time_column : str, optional
        Column with sample times.
    time_units : {"s", "ms", "us", "ns", "datetime"}, optional
        Unit of the time column; an alternative to ``time_scale``. Default seconds.
        ``"datetime"`` parses date-time text (:func:`pandas.to_datetime`; read as UTC
        when no zone is written). Epoch times (numbers whose first sample, in the given
        unit, falls between 1980 and 2100) and date-times are made relative to the first
        sample, whose absolute time is kept in ``attrs['time_origin']`` (ISO 8601, UTC).
    clock : {"grid", "resample"}, optional
        ``"grid"`` (default): the samples must sit on a ``k / fs`` grid, and steps of
        several periods are dropped samples, handled by ``gaps``. ``"resample"``: for
        real clocks that jitter, drift or arrive in bursts; every variable is
        interpolated linearly onto the uniform grid ``t0 + k / fs`` spanning the time
        column, and ``attrs['resampled']`` says so (original sample count, median and
        longest step). Linear interpolation is used because it never overshoots,
        needs no assumption on the signal beyond its samples and keeps a still sensor
        exactly still; it attenuates high frequencies (a sine at f sampled every T
        loses up to ``1 − sinc²(f T)`` of its amplitude between samples, about 3 % at
        f T = 0.1) and does not remove aliasing: when ``fs`` is much lower than the
        clock's rate a :class:`~tiltlab.quality.QualityWarning` says to low-pass
        filter first.
    gaps : {"raise", "nan"}, optional
        What to do with samples missing from the time column (a logger that dropped
        samples: steps longer than 1.5 periods on a grid clock, longer than
        ``max_gap`` periods on a resampled one). ``"raise"`` (default) refuses the file
        with the gaps located; ``"nan"`` puts NaN rows on the grid in their place, keeps
        a description in ``attrs['gaps']`` and validates with ``allow_nan``. A grid
        that would be more than half missing
        (:data:`tiltlab.io.clock.MAX_MISSING_FRACTION`, 50 %) is refused with the
        longest time jump and its data rows named: such a grid comes from a
        corrupted timestamp or a reset clock, not from dropped samples.
    **options
        Any other key of a mapping (:func:`read_csv_mapping`), as a keyword; they
        override the mapping's:

        time_scale : float, optional
            Factor converting the time column to seconds (e.g. ``1e-3`` for ms).
        fs_range : (float, float) or None
            Plausible sampling rates (Hz). A rate outside it — estimated, or given and
            contradicted by the time column — is an error that suggests the time unit that
            would fit. ``None`` disables the check.
        max_gap : float, optional
            With ``clock="resample"``: the longest step, in sample periods of the time
            column's own rate, that is interpolated across (default 5). A longer step is a
            real gap, handled by ``gaps``.
        range : mapping, optional
            Variable → the sensor's full scale (``r`` for ±r, or ``[low, high]``; acc,
            gyr, mag), used to find clipped samples.
        scale : mapping, optional
            Variable → factor from the column's numbers to its ``units``, e.g.
            ``{"acc": 0.001}`` for mg; kept in ``attrs['csv_scale']``.
        check_units : bool, optional
            Passed to :func:`tiltlab.schema.make_recording` (default True). A
            :class:`~tiltlab.quality.UnitCheckError` names the switch as the options were
            given (``"check_units": false`` in a mapping, ``check_units=False`` here).
        axes, preset, axis_labels : optional
            Device axes and sign conventions, passed to
            :func:`tiltlab.schema.make_recording` (e.g. ``axes={"acc": ["-x", "-y", "-z"]}``
            for a logger that reports gravity instead of specific force).
        attrs : mapping, optional
            Extra dataset attributes (provenance).

        Any other keyword is passed to :func:`pandas.read_csv` (e.g. ``sep=';'``,
        ``header=[0, 1]``), as are the options under ``read_csv={...}``.

    Returns
    -------
    xarray.Dataset
        The validated Recording, with ``attrs['source']`` the file name.

    Raises
    ------
    ReadError
        If the file is missing (or is a directory) or unreadable, or lacks a mapped
        column (the message names it and lists the file's columns), or a mapped
        column holds text, an empty field or a missing-value marker such as ``NaN``
        (named as such, with its data row).
    ValueError
        If the mapping is incomplete or inconsistent, or the sampling rate implausible.
    RecordingError
        If the data break the Recording contract, if the time column skips samples
        (unless ``gaps="nan"``; with it, if more than half of the grid would be
        missing), or if it is not on a regular grid with ``clock="grid"`` (the
        message suggests ``clock="resample"``).

    Examples
    --------
    >>> import numpy as np, tempfile, pathlib
    >>> from tiltlab import io
    >>> t = np.cumsum(np.r_[0, np.full(199, 0.01) * (1 + 0.2 * np.sin(np.arange(199)))])
    >>> rows = ["t,ax,ay,az"] + [f"{x:.6f},0,0,1" for x in t]
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "log.csv"
    >>> _ = p.write_text("\n".join(rows))
    >>> rec = io.read_csv(p, {"acc": ["ax", "ay", "az"]}, {"acc": "g"},
    ...                   time_column="t", clock="resample", fs=100)
    >>> rec.attrs["fs"], bool(np.allclose(np.diff(rec.time), 0.01))
    (100.0, True)
    """
    path = Path(path)
    explicit = {
        "fs": fs,
        "time_column": time_column,
        "time_units": time_units,
        "clock": clock,
        "gaps": gaps,
    }
    raw, where = _raw_mapping(columns, units, mapping, explicit, dict(options))
    style = "mapping" if where else "python"
    m = check_mapping(raw, where)
    data = read_columns(path, m.columns, m.time_column, m.time_units, m.read_csv)
    get = {
        k: np.column_stack([data[c] for c in v]).astype(float) * m.scale.get(k, 1.0)
        for k, v in m.columns.items()
    }
    extra_attrs = dict(m.attrs)
    if m.scale:
        extra_attrs["csv_scale"] = dict(m.scale)
    fs, time, allow_nan = m.fs, None, False
    if m.time_column:
        time, fs, allow_nan = _apply_clock(
            data[m.time_column], get, m, path, extra_attrs, style
        )
    lo_hi = m.fs_range
    if lo_hi is not None and not lo_hi[0] <= fs <= lo_hi[1]:
        raise ValueError(
            f"{path}: fs = {fs:g} Hz is outside the plausible range {lo_hi[0]:g}–{lo_hi[1]:g} Hz "
            "(give fs_range to accept it)"
        )
    return build_recording(
        get,
        fs,
        m,
        time=time,
        attrs={"source": path.name, **extra_attrs},
        allow_nan=allow_nan,
        style=style,
    )


def _apply_clock(
    raw_time: np.ndarray,
    get: dict[str, np.ndarray],
    m: CsvMapping,
    path: Path,
    extra_attrs: dict[str, Any],
    style: str,
) -> tuple[np.ndarray, float, bool]:
    """Put the samples on a uniform (or exact) grid in seconds; ``get`` is updated."""
    tcol, scale = m.time_column, m.time_scale
    where = f"{path}: "
    time, origin = _clock.to_seconds(
        raw_time, _clock.DATETIME if scale is None else scale, where
    )
    if origin is not None:
        extra_attrs["time_origin"] = _clock.iso_utc(origin)
    _clock.check_increasing(time, tcol, where)
    unit = m.time_units or _clock.unit_name(scale)
    raw_scale = 1.0 if scale is None else scale
    fs, lo_hi = m.fs, m.fs_range
    resample = m.clock == "resample"
    if resample:
        fs_est, n_gaps = _clock.estimate_rate(time, m.max_gap)
        how = f"(samples − 1) / duration of column {tcol!r} ({unit})" + (
            f", leaving out {n_gaps} gap{'s' * (n_gaps != 1)}" if n_gaps else ""
        )
    else:
        fs_est = 1.0 / float(np.median(np.diff(time)))
        how = f"1 / median step of column {tcol!r} ({unit})"
    raw_step = 1.0 / (fs_est * raw_scale)

    def hint(rates: tuple[float, float] | None) -> str:
        if scale is None:  # date-times: no other unit to suggest
            return ""
        return _clock.unit_hint(raw_step, rates, scale, style)

    if fs is None or resample:
        if lo_hi is not None and not lo_hi[0] <= fs_est <= lo_hi[1]:
            raise ValueError(
                f"{path}: sampling rate estimated from time column {tcol!r} ({unit}) is "
                f"{fs_est:.6g} Hz, outside the plausible range {lo_hi[0]:g}–{lo_hi[1]:g} Hz"
                + (hint(lo_hi) or "; give fs, or widen fs_range")
            )
    if fs is None:
        # 7 significant digits: the estimate carries the rounding noise of the column
        fs = float(f"{fs_est:.7g}")
        extra_attrs["fs_source"] = f"estimated as {how}"
    elif not resample and not np.isclose(fs_est, fs, rtol=0.02):
        raise ValueError(
            f"{path}: fs = {fs:g} Hz but time column {tcol!r} ({unit}) gives "
            f"{fs_est:.6g} Hz (median interval {raw_step:g} {unit})"
            + hint((0.98 * fs, 1.02 * fs))
        )
    allow_nan = False
    if not resample:
        time, new, missing = _clock.place_on_grid(
            time, get, fs, tcol, where, m.gaps, style
        )
        get.update(new)
        if missing:
            allow_nan = True
            extra_attrs["gaps"] = (
                f"{missing} missing sample{'s' if missing != 1 else ''} filled with NaN; "
                + _validate.describe_gaps(
                    time, fs, _validate.segments(time, fs, values=get["acc"])
                )
            )
        return time, fs, allow_nan
    gap_idx = _clock.gap_steps(time, fs_est, m.max_gap)
    if gap_idx.size and m.gaps == "raise":
        _clock.raise_gaps(time, gap_idx, fs_est, m.max_gap, tcol, where, style)
    grid = _clock.uniform_grid(time[0], time[-1], fs)
    if gap_idx.size:  # grid samples strictly inside the gaps become NaN
        inside = np.searchsorted(
            grid, time[gap_idx + 1], side="left"
        ) - np.searchsorted(grid, time[gap_idx], side="right")
        _clock.check_missing_fraction(
            time, grid.size, int(inside.sum()), fs, tcol, where, gap_idx
        )
    _clock.warn_if_downsampled(fs, fs_est, str(path))
    for var, v in get.items():
        get[var] = _clock.interpolate(time, v, grid, gap_idx, quaternion=var == "q_ref")
    extra_attrs["resampled"] = _clock.describe_resampling(time, grid.size, fs)
    if gap_idx.size:
        allow_nan = True
        n_nan = int(np.isnan(get["acc"][:, 0]).sum())
        extra_attrs["gaps"] = (
            f"{n_nan} grid sample{'s' if n_nan != 1 else ''} in {gap_idx.size} gap"
            f"{'s' if gap_idx.size != 1 else ''} longer than {m.max_gap:g} periods "
            "filled with NaN; "
            + _validate.describe_gaps(
                grid, fs, _validate.segments(grid, fs, values=get["acc"])
            )
        )
    return grid, fs, allow_nan


def build_recording(
    get: Mapping[str, np.ndarray],
    fs: float,
    m: CsvMapping | Mapping[str, Any],
    *,
    time: np.ndarray | None,
    attrs: Mapping[str, Any],
    allow_nan: bool,
    style: str,
) -> xr.Dataset:
    """Build a Recording with a mapping's options (``schema.make_recording``).

    A unit-check error names the switch in the form the options were given.

    Parameters
    ----------
    get : mapping
        Variable → samples.
    fs : float
        Sampling rate (Hz).
    m : CsvMapping or mapping
        The checked options: ``units``, ``range``, ``axes``, ``preset``,
        ``axis_labels`` and ``check_units``.
    time : numpy.ndarray or None
        Sample times (s), or None for ``k / fs``.
    attrs : mapping
        Recording attributes.
    allow_nan : bool
        Whether NaN samples (gaps) are accepted.
    style : {"mapping", "python"}
        How the options were given, for error messages.

    Returns
    -------
    xarray.Dataset
        The validated Recording.
    """
    full = m["range"]
    try:
        return sensor_recording(
            get,
            fs,
            m["units"],
            acc_range=full.get("acc"),
            gyr_range=full.get("gyr"),
            mag_range=full.get("mag"),
            q_ref=get.get("q_ref"),
            time=time,
            axes=m["axes"],
            preset=m["preset"],
            axis_labels=m["axis_labels"],
            attrs=attrs,
            check_units=m["check_units"],
            allow_nan=allow_nan,
        )
    except _quality.UnitCheckError as err:
        raise err.for_switch(style) from None
