r"""The cohort feature table as a tidy CSV or Parquet file, for R, Excel and pandas.

:func:`~tiltlab.cohort.run_cohort` gives an :class:`xarray.Dataset` along ``session``
(saved as NetCDF by :func:`~tiltlab.cohort.save_features`). :func:`to_table` flattens
it into a :class:`pandas.DataFrame`, one row per session, with the columns in this
order:

* ids ``session, subject, group, timepoint`` — always strings: subject ``"007"`` stays
  ``"007"``, time point ``7`` becomes ``"7"``;
* the outcome ``status`` (``"ok"`` or ``"failed"``), ``error`` (why the session failed,
  empty when ok) and ``notes`` (why some features of a session that ran are NaN); a
  failed session stays a row, with NaN features;
* the features (float64, in the Dataset's order);
* ``file``, ``reader`` and the manifest's covariates (numbers stay numbers).

``df.attrs["units"]``, ``df.attrs["long_name"]`` and ``df.attrs["role"]`` map each
column to its unit, its description and its role (``id``, ``outcome``, ``feature``,
``source`` or ``covariate``); ``df.attrs["dataset"]`` holds the Dataset's attributes
(``feature_config``, ``config_hash``, ``tiltlab_version`` …).

:func:`save_table` writes the table atomically (a temporary file beside it, renamed
into place), in the format its suffix names:

``.csv``
    UTF-8 (no byte-order mark), comma-separated, one header row, ``.`` as the decimal
    mark, ``\n`` line ends; floats written with the shortest text that reads back to
    the same float64; a missing value (NaN) is an empty cell. A CSV file has no place
    for units, so they travel in a sidecar, the table's data dictionary
    ``<stem>.columns.csv`` (``features.csv`` → ``features.columns.csv``): one row per
    column of the table, with the columns ``column, units, long_name, dtype, role``
    (``dtype`` is ``string``, ``float64``, ``int64``, ``bool`` or ``datetime64``).
    The Dataset's attributes (the feature configuration) are not in the CSV files:
    they stay in the NetCDF and the Parquet file.
``.parquet``
    Column types kept; each field's metadata holds ``units``, ``long_name`` and
    ``role``; the file's key–value metadata holds each Dataset attribute under its own
    name (strings as they are, other values as JSON) and ``tiltlab:columns``, the data
    dictionary as JSON (for readers that show only file metadata). Needs ``pyarrow``.

:func:`load_table` reads either back: ids as strings, floats exact, NaN kept, units and
long names restored into ``df.attrs``.

Reading the files without tiltlab (ids named as text, or ``"007"`` becomes ``7``)::

    # Python (pandas only)
    df = pd.read_csv("features.csv", dtype={"session": str, "subject": str,
                                            "group": str, "timepoint": str})
    units = pd.read_csv("features.columns.csv", keep_default_na=False)
    df = pd.read_parquet("features.parquet")
    pyarrow.parquet.read_schema("features.parquet").field("dba_mean").metadata

    # R
    df <- read.csv("features.csv", colClasses = c(session = "character",
                   subject = "character", group = "character", timepoint = "character"))
    units <- read.csv("features.columns.csv")
    df <- arrow::read_parquet("features.parquet")

In Excel, open the CSV with Data › From Text/CSV (file origin UTF-8) and set the id
columns to Text so that leading zeros stay.

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
.. [2] H. Wickham, "Tidy Data", Journal of Statistical Software 59(10), 2014.
   doi:10.18637/jss.v059.i10
"""

from __future__ import annotations

import json
import os
import re
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from .._stack import user_stacklevel
from .run import _write_atomically

__all__ = [
    "TABLE_SUFFIXES",
    "SIDECAR_COLUMNS",
    "to_table",
    "save_table",
    "load_table",
    "sidecar_path",
]

#: File suffixes :func:`save_table` and :func:`load_table` know.
TABLE_SUFFIXES = (".csv", ".parquet")
#: Columns of the CSV sidecar ``<stem>.columns.csv`` (one row per column of the table).
SIDECAR_COLUMNS = ("column", "units", "long_name", "dtype", "role")

ID_COLUMNS = ("session", "subject", "group", "timepoint")
OUTCOME_COLUMNS = ("status", "error", "notes")
SOURCE_COLUMNS = ("file", "reader")
#: columns that are always strings
_STRING_COLUMNS = ID_COLUMNS + OUTCOME_COLUMNS + SOURCE_COLUMNS
_ROLES = {
    **dict.fromkeys(ID_COLUMNS, "id"),
    **dict.fromkeys(OUTCOME_COLUMNS, "outcome"),
    **dict.fromkeys(SOURCE_COLUMNS, "source"),
}
#: descriptions of the columns that come from the manifest (they have no attrs)
_LONG_NAMES = {
    "session": "session id",
    "subject": "subject (animal) id",
    "group": "experimental group",
    "timepoint": "time point",
    "status": "ok or failed",
    "error": "why the session failed (empty when ok)",
    "notes": "why features of a session that ran are NaN (feature: reason)",
    "file": "session file as named in the manifest (relative to its folder)",
    "reader": "reader of the session file",
}
_DTYPES = ("string", "float64", "int64", "bool", "datetime64")
#: Parquet file metadata written by pyarrow/pandas, not Dataset attributes
_ARROW_KEYS = ("pandas", "ARROW:schema")
_SUPPORTED = ".csv (UTF-8, units in the sidecar <stem>.columns.csv) and .parquet"


# ------------------------------------------------------------------ Dataset → table


def to_table(features: xr.Dataset) -> pd.DataFrame:
    """Convert the cohort feature Dataset to a tidy table: one row per session.

    Parameters
    ----------
    features : xarray.Dataset
        A cohort feature table along ``session``, as returned by
        :func:`~tiltlab.cohort.run_cohort` or :func:`~tiltlab.cohort.load_features`.

    Returns
    -------
    pandas.DataFrame
        Columns ``session, subject, group, timepoint`` (strings), ``status, error,
        notes`` (strings), the features (float64, NaN for a failed session), then
        ``file, reader`` and the covariates; a default integer index. ``attrs``:
        ``"units"``, ``"long_name"`` and ``"role"`` (column → str) and ``"dataset"``
        (the Dataset's attributes, as plain Python values).

    Raises
    ------
    TypeError
        If ``features`` is not an :class:`xarray.Dataset`.
    ValueError
        If it is not a cohort feature table: no ``session`` dimension, no ``status``
        variable, or a variable along another dimension.

    Examples
    --------
    A two-session feature Dataset, as :func:`~tiltlab.cohort.run_cohort` makes (one
    feature here; :func:`~tiltlab.cohort.load_features` reads a saved one):

    >>> import xarray as xr
    >>> from tiltlab import cohort
    >>> feats = xr.Dataset(
    ...     {
    ...         "status": ("session", ["ok", "failed"]),
    ...         "dba_mean": ("session", [0.123, float("nan")], {"units": "g"}),
    ...     },
    ...     coords={
    ...         "session": ["rat1_d0", "rat2_d0"],
    ...         "subject": ("session", ["rat1", "rat2"]),
    ...         "group": ("session", ["sham", "lesion"]),
    ...     },
    ... )
    >>> df = cohort.to_table(feats)
    >>> list(df.columns)
    ['session', 'subject', 'group', 'status', 'dba_mean']
    >>> df["dba_mean"].tolist()
    [0.123, nan]
    >>> df.attrs["units"]["dba_mean"], df.attrs["role"]["dba_mean"]
    ('g', 'feature')
    """
    ds = _check_features(features)
    ids = [c for c in ID_COLUMNS if c in ds.variables]
    outcome = [c for c in OUTCOME_COLUMNS if c in ds.variables]
    named = set(ids) | set(outcome) | set(SOURCE_COLUMNS)
    feats = [str(v) for v in ds.data_vars if v not in named]
    source = [c for c in SOURCE_COLUMNS if c in ds.variables]
    covariates = [str(c) for c in ds.coords if c not in named]
    columns: dict[str, Any] = {}
    roles: dict[str, str] = {}
    for names, role in (
        (ids, "id"),
        (outcome, "outcome"),
        (feats, "feature"),
        (source, "source"),
        (covariates, "covariate"),
    ):
        for c in names:
            always_str = c in _STRING_COLUMNS
            columns[c] = _column(ds[c].values, strings=always_str)
            roles[c] = role
    df = pd.DataFrame(columns)
    df.attrs = {
        "units": {c: _text(ds[c].attrs.get("units", "")) for c in df.columns},
        "long_name": {
            c: _text(ds[c].attrs.get("long_name", "")) or _LONG_NAMES.get(c, "")
            for c in df.columns
        },
        "role": roles,
        "dataset": {str(k): _plain(v) for k, v in ds.attrs.items()},
    }
    return df


def _check_features(features: Any) -> xr.Dataset:
    """``features`` if it is a flat cohort feature Dataset, else a clear error."""
    if isinstance(features, pd.DataFrame):
        raise TypeError(
            "expected the cohort feature Dataset (xarray.Dataset); this is already a "
            "pandas.DataFrame (save it with save_table)"
        )
    if not isinstance(features, xr.Dataset):
        raise TypeError(
            "expected the cohort feature Dataset (xarray.Dataset) of run_cohort or "
            f"load_features, got {type(features).__name__}"
        )
    dims = [str(d) for d in features.dims]
    if "session" not in dims:
        hint = (
            "; this looks like a Recording: run_cohort (tiltlab cohort run) turns "
            "recordings into a feature table"
            if "time" in dims
            else ""
        )
        raise ValueError(
            f"not a cohort feature table: no 'session' dimension (dimensions: {dims})"
            + hint
        )
    if "status" not in features.data_vars:
        raise ValueError(
            "not a cohort feature table: no 'status' variable along 'session' "
            "(made by run_cohort)"
        )
    other = [
        f"{v!s} {tuple(map(str, features[v].dims))}"
        for v in features.variables
        if features[v].dims != ("session",)
    ]
    if other:
        raise ValueError(
            "not a flat cohort feature table: every variable must lie along 'session' "
            f"alone, but got {', '.join(other)}"
        )
    return features


def _column(values: np.ndarray, *, strings: bool) -> pd.Series:
    """One column: strings when asked (or text values), else the numbers as they are."""
    arr = np.asarray(values)
    if strings or arr.dtype.kind in "OSU":
        return pd.Series([_text(v) for v in arr.tolist()], dtype=str)
    return pd.Series(arr.copy())


def _text(value: Any) -> str:
    if isinstance(value, bytes):
        return value.decode("utf-8")
    return str(value)


def _plain(value: Any) -> Any:
    """Convert a Dataset attribute to a plain Python (JSON-able) value."""
    if isinstance(value, bytes):
        return value.decode("utf-8")
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


# ------------------------------------------------------------------ files


def sidecar_path(path: str | os.PathLike) -> Path:
    """Name the data dictionary written beside a CSV table: ``<stem>.columns.csv``.

    Parameters
    ----------
    path : path-like
        The CSV table, e.g. ``features.csv``.

    Returns
    -------
    pathlib.Path
        ``features.columns.csv`` for ``features.csv`` (same folder).

    Examples
    --------
    >>> sidecar_path("out/features.csv").as_posix()
    'out/features.columns.csv'
    """
    path = Path(path)
    return path.with_name(f"{path.stem}.columns.csv")


def _format(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix in TABLE_SUFFIXES:
        return suffix
    hint = (
        " (a NetCDF feature file is read with load_features)"
        if suffix in (".nc", ".nc4", ".netcdf")
        else ""
    )
    raise ValueError(
        f"{path}: unknown table format {suffix or '(no suffix)'!r}; supported: "
        f"{_SUPPORTED}{hint}"
    )


def save_table(features: xr.Dataset | pd.DataFrame, path: str | os.PathLike) -> Path:
    """Write the cohort feature table as CSV (with its data dictionary) or Parquet.

    The format follows the suffix of ``path``; the file (and the CSV's sidecar) is
    written to a temporary file beside it and renamed into place, so a reader never
    sees half a file. See the module documentation for the layout of each format.

    Parameters
    ----------
    features : xarray.Dataset or pandas.DataFrame
        The cohort feature Dataset (:func:`~tiltlab.cohort.run_cohort`,
        :func:`~tiltlab.cohort.load_features`), or a table made from one by
        :func:`to_table` or :func:`load_table` (its ``attrs`` give the units).
    path : path-like
        ``*.csv`` (UTF-8; units, long names, types and roles in the sidecar
        ``<stem>.columns.csv``, see :func:`sidecar_path`) or ``*.parquet`` (units and
        long names in the field metadata, the Dataset's attributes in the file
        metadata).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        An unknown suffix (naming the supported ones), a folder as ``path``, or
        ``features`` that is not a cohort feature table.
    TypeError
        If ``features`` is neither a Dataset nor a DataFrame.
    ImportError
        For ``.parquet`` without ``pyarrow``.

    Examples
    --------
    >>> from tiltlab import cohort                                   # doctest: +SKIP
    >>> feats = cohort.load_features("features.nc")                  # doctest: +SKIP
    >>> cohort.save_table(feats, "features.csv")   # + features.columns.csv  # doctest: +SKIP
    >>> cohort.save_table(feats, "features.parquet")                 # doctest: +SKIP
    """
    path = Path(path)
    fmt = _format(path)
    if path.is_dir():
        raise ValueError(f"{path} is a folder; give a file such as features{fmt}")
    if isinstance(features, pd.DataFrame):
        df = _check_frame(features)
    else:
        df = to_table(features)
    dictionary = _dictionary(df)
    if fmt == ".csv":
        _write_atomically(sidecar_path(path), lambda tmp: _write_csv(dictionary, tmp))
        _write_atomically(path, lambda tmp: _write_csv(df, tmp))
    else:
        pq = _pyarrow()[1]
        table = _arrow_table(df, dictionary, df.attrs.get("dataset", {}))
        _write_atomically(path, lambda tmp: pq.write_table(table, tmp))
    return path


def _check_frame(df: pd.DataFrame, where: str = "the table") -> pd.DataFrame:
    """Copy a cohort table given as a DataFrame, its string columns as strings."""
    columns = [str(c) for c in df.columns]
    missing = [c for c in ("session", "status") if c not in columns]
    if missing:
        hint = ""
        if {"column", "units"} <= set(columns):
            hint = "; this is the column sidecar (data dictionary) of a table"
        raise ValueError(
            f"{where}: not a cohort feature table (no {' or '.join(map(repr, missing))} "
            f"column; columns: {columns[:8]}{' ...' if len(columns) > 8 else ''}){hint}"
        )
    if len(set(columns)) != len(columns):
        dup = sorted({c for c in columns if columns.count(c) > 1})
        raise ValueError(f"{where}: duplicate column name(s) {dup}")
    out = df.copy()
    out.columns = columns
    for c in _STRING_COLUMNS:
        if c in out.columns and not _is_text(out[c]):
            out[c] = pd.Series(
                ["" if _missing(v) else _text(v) for v in out[c].tolist()],
                dtype=str,
                index=out.index,
            )
    out.attrs = dict(df.attrs)
    return out


def _is_text(col: pd.Series) -> bool:
    if pd.api.types.is_string_dtype(col.dtype) and col.dtype != object:
        return not col.isna().any()
    return col.dtype == object and all(isinstance(v, str) for v in col.tolist())


def _missing(value: Any) -> bool:
    return (
        value is None
        or value is pd.NA
        or (isinstance(value, float) and np.isnan(value))
    )


def _dtype_name(col: pd.Series) -> str:
    t = pd.api.types
    if t.is_bool_dtype(col.dtype):
        return "bool"
    if t.is_integer_dtype(col.dtype):
        return "int64"
    if t.is_float_dtype(col.dtype):
        return "float64"
    if t.is_datetime64_any_dtype(col.dtype):
        return "datetime64"
    return "string"


def _dictionary(df: pd.DataFrame) -> pd.DataFrame:
    """Make the data dictionary of a table: one row per column."""
    units = df.attrs.get("units", {}) or {}
    long_name = df.attrs.get("long_name", {}) or {}
    role = df.attrs.get("role", {}) or {}
    rows = []
    for c in df.columns:
        dtype = _dtype_name(df[c])
        rows.append(
            {
                "column": c,
                "units": _text(units.get(c, "") or ""),
                "long_name": _text(long_name.get(c, "") or _LONG_NAMES.get(c, "")),
                "dtype": dtype,
                "role": _text(
                    role.get(c)
                    or _ROLES.get(c, "feature" if dtype == "float64" else "covariate")
                ),
            }
        )
    return pd.DataFrame(rows, columns=list(SIDECAR_COLUMNS), dtype=str)


def _write_csv(df: pd.DataFrame, tmp: Path) -> None:
    with open(tmp, "w", encoding="utf-8", newline="") as f:
        df.to_csv(f, index=False, lineterminator="\n")
        f.flush()
        os.fsync(f.fileno())


def _pyarrow():
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        raise ImportError(
            "Parquet tables need pyarrow: pip install 'pyarrow>=15' (or write .csv)"
        ) from None
    return pa, pq


def _arrow_table(df: pd.DataFrame, dictionary: pd.DataFrame, attrs: Mapping):
    pa = _pyarrow()[0]
    table = pa.Table.from_pandas(df, preserve_index=False)
    records = dictionary.to_dict("records")
    fields = [
        field.with_metadata({k: rec[k] for k in ("units", "long_name", "role")})
        for field, rec in zip(table.schema, records, strict=True)
    ]
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    as_json = []
    for key, value in attrs.items():
        key = str(key)
        if key in _ARROW_KEYS or key.startswith("tiltlab:"):
            continue
        value = _plain(value)
        if isinstance(value, str):
            meta[key] = value
        else:
            meta[key] = json.dumps(value)
            as_json.append(key)
    meta["tiltlab:json_attrs"] = json.dumps(as_json)
    meta["tiltlab:columns"] = json.dumps(records)
    return pa.Table.from_arrays(table.columns, schema=pa.schema(fields, metadata=meta))


# ------------------------------------------------------------------ file → table


def load_table(path: str | os.PathLike) -> pd.DataFrame:
    """Read a table written by :func:`save_table` (``.csv`` or ``.parquet``).

    Parameters
    ----------
    path : path-like
        ``*.csv`` (its sidecar ``<stem>.columns.csv`` gives the units and column
        types; without it a warning is issued and the types are guessed) or
        ``*.parquet``.

    Returns
    -------
    pandas.DataFrame
        As :func:`to_table` gives it: ids and other text columns as strings (``"007"``
        stays ``"007"``; empty errors are ``""``), floats exact, NaN kept; ``attrs``
        ``"units"``, ``"long_name"``, ``"role"`` (column → str) and ``"dataset"`` (the
        Dataset's attributes: from a Parquet file; empty for a CSV file).

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        An unknown suffix (naming the supported ones), a file that cannot be parsed,
        a table without ``session`` and ``status`` columns (not a cohort table), or a
        value that does not fit its column's type in the sidecar.

    Examples
    --------
    >>> from tiltlab import cohort                                 # doctest: +SKIP
    >>> df = cohort.load_table("features.csv")                     # doctest: +SKIP
    >>> df.loc[df["status"] == "failed", ["session", "error"]]     # doctest: +SKIP
    >>> df.attrs["units"]["tilt_immobile_sagittal_deg"]            # doctest: +SKIP
    'deg'
    """
    path = Path(path)
    fmt = _format(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such table file")
    return _read_csv(path) if fmt == ".csv" else _read_parquet(path)


def _read_raw_csv(path: Path, what: str) -> pd.DataFrame:
    try:
        return pd.read_csv(path, dtype=str, keep_default_na=False, encoding="utf-8")
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as e:
        msg = " ".join(str(e).split())
        raise ValueError(f"{path}: not a readable CSV {what} ({msg})") from None


def _read_csv(path: Path) -> pd.DataFrame:
    raw = _read_raw_csv(path, "table")
    _check_frame(raw, str(path))
    side = sidecar_path(path)
    if side.is_file():
        dictionary = _read_dictionary(side)
    else:
        warnings.warn(
            f"{path}: no data dictionary {side.name} beside it; units and long names "
            "are unknown and the column types are guessed",
            UserWarning,
            stacklevel=user_stacklevel(),
        )
        dictionary = {}
    columns = {}
    attrs: dict[str, dict[str, str]] = {"units": {}, "long_name": {}, "role": {}}
    for c in raw.columns:
        entry = dictionary.get(c, {})
        dtype = entry.get("dtype") or ("string" if c in _STRING_COLUMNS else None)
        columns[c] = _parse(raw[c], dtype, c, path, side)
        attrs["units"][c] = entry.get("units", "")
        attrs["long_name"][c] = entry.get("long_name", "") or _LONG_NAMES.get(c, "")
        attrs["role"][c] = entry.get("role", "") or _ROLES.get(
            c, "feature" if _dtype_name(columns[c]) == "float64" else "covariate"
        )
    df = pd.DataFrame(columns)
    df.attrs = {**attrs, "dataset": {}}
    return df


def _read_dictionary(side: Path) -> dict[str, dict[str, str]]:
    table = _read_raw_csv(side, "data dictionary")
    missing = [c for c in ("column", "units") if c not in table.columns]
    if missing:
        raise ValueError(
            f"{side}: not a column sidecar (no {missing} column; expected the columns "
            f"{list(SIDECAR_COLUMNS)})"
        )
    out = {}
    for i, row in enumerate(table.to_dict("records")):
        dtype = row.get("dtype", "")
        if dtype and dtype not in _DTYPES:
            raise ValueError(
                f"{side}, line {i + 2}: unknown dtype {dtype!r} for column "
                f"{row['column']!r}; known: {list(_DTYPES)}"
            )
        out[row["column"]] = row
    return out


_INT = re.compile(r"^[+-]?\d+$")


def _parse(
    col: pd.Series, dtype: str | None, name: str, path: Path, side: Path
) -> pd.Series:
    """Parse a CSV column of strings as ``dtype`` (guessed if None)."""
    values = [v.strip() for v in col.tolist()]
    if dtype is None:  # no data dictionary: numbers where every cell is one
        filled = [v for v in values if v]
        if filled and len(filled) == len(values) and all(_INT.match(v) for v in values):
            dtype = "int64"
        elif filled and all(_is_float(v) for v in filled):
            dtype = "float64"
        else:
            dtype = "string"
    if dtype == "int64" and any(not v for v in values):
        dtype = "float64"  # an empty cell: NaN, which int64 cannot hold
    try:
        if dtype == "float64":
            return pd.Series(
                [float(v) if v else np.nan for v in values], dtype="float64"
            )
        if dtype == "int64":
            return pd.Series([int(v) for v in values], dtype="int64")
        if dtype == "bool":
            flags = {"True": True, "False": False, "true": True, "false": False}
            return pd.Series([flags[v] for v in values], dtype=bool)
        if dtype == "datetime64":
            return pd.Series(pd.to_datetime(values))
    except (ValueError, KeyError):
        bad = next((i, v) for i, v in enumerate(values) if not _fits(v, dtype))
        raise ValueError(
            f"{path}, line {bad[0] + 2}: column {name!r} holds {bad[1]!r}, not a "
            f"{dtype} value ({side.name} gives its type)"
        ) from None
    return pd.Series(col.tolist(), dtype=str)


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _fits(text: str, dtype: str) -> bool:
    if dtype == "float64":
        return not text or _is_float(text)
    if dtype == "int64":
        return bool(_INT.match(text))
    if dtype == "bool":
        return text in ("True", "False", "true", "false")
    try:
        pd.to_datetime([text])
    except ValueError:
        return False
    return True


def _read_parquet(path: Path) -> pd.DataFrame:
    pa, pq = _pyarrow()
    try:
        table = pq.read_table(path)
    except (pa.ArrowException, OSError) as exc:
        msg = " ".join(str(exc).split())
        raise ValueError(f"{path}: not a readable Parquet file ({msg})") from None
    df = _check_frame(table.to_pandas(), str(path))
    attrs: dict[str, dict[str, str]] = {"units": {}, "long_name": {}, "role": {}}
    for field in table.schema:
        meta = {k.decode(): v.decode() for k, v in (field.metadata or {}).items()}
        c = field.name
        attrs["units"][c] = meta.get("units", "")
        attrs["long_name"][c] = meta.get("long_name", "") or _LONG_NAMES.get(c, "")
        attrs["role"][c] = meta.get("role", "") or _ROLES.get(
            c, "feature" if _dtype_name(df[c]) == "float64" else "covariate"
        )
    file_meta = {
        k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()
    }
    as_json = set(json.loads(file_meta.get("tiltlab:json_attrs", "[]")))
    dataset = {}
    for key, value in file_meta.items():
        if key in _ARROW_KEYS or key.startswith(("tiltlab:", "ARROW:")):
            continue
        dataset[key] = json.loads(value) if key in as_json else value
    df.attrs = {**attrs, "dataset": dataset}
    return df
