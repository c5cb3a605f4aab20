r"""The cohort manifest: a plain CSV naming every session of a study.

One row per session, with the columns

=================  =====================================================================
``session``        unique session id
``subject``        animal (or participant) id
``group``          experimental group
``timepoint``      time relative to the intervention (e.g. ``7d`` or a number of days;
                   may be empty for cross-sectional data)
``file``           the session's recording, relative to the manifest's folder or absolute
``reader``         ``netcdf``, ``fayat_csv``, ``fayat_tumble``, ``broad``, ``csv``,
                   ``tagtools`` (tag-tools NetCDF) or ``auto`` (:func:`tiltlab.io.read`
                   chooses from the file's content)
``reader_options`` optional: a JSON object of keyword arguments for the reader, e.g. the
                   generic CSV's ``{"columns": {...}, "units": {...}, "fs": 100}``;
                   empty for most readers. ``{"check_units": false}`` accepts the unit
                   labels as they are, for the session's file and its calibration
``calibration``    optional: the subject's tumble-test recording (``.nc`` read with
                   :func:`tiltlab.io.load_netcdf`, ``.csv`` with
                   :func:`tiltlab.io.read_fayat_tumble`)
=================  =====================================================================

Any other column is a covariate and travels to the feature table as a coordinate.
:func:`read_manifest` rejects a malformed manifest before any work starts, naming the
line (1-based, the header being line 1) and the session; a session file that is
missing or unreadable is *not* a manifest error: :func:`tiltlab.cohort.run_cohort`
records it as a failed session.

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
"""

from __future__ import annotations

import inspect
import json
import os
import re
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd
import xarray as xr

from .. import io as _io
from ..quality import UnitCheckError

__all__ = [
    "REQUIRED_COLUMNS",
    "OPTIONAL_COLUMNS",
    "READERS",
    "ManifestError",
    "Manifest",
    "read_manifest",
    "init_manifest",
    "load_session",
    "load_calibration",
    "session_path",
]

REQUIRED_COLUMNS: tuple[str, ...] = (
    "session",
    "subject",
    "group",
    "timepoint",
    "file",
    "reader",
)
OPTIONAL_COLUMNS: tuple[str, ...] = ("reader_options", "calibration")


def _read_netcdf(
    path,
    *,
    allow_nan: bool | None = None,
    max_jitter: float = 0.35,
    quat_atol: float = 1e-6,
    check_units: bool = True,
) -> xr.Dataset:
    """A NetCDF Recording (:func:`tiltlab.io.load_netcdf`), validated with these
    options of :func:`tiltlab.schema.validate`."""
    kw = {"max_jitter": max_jitter, "quat_atol": quat_atol, "check_units": check_units}
    if allow_nan is not None:
        kw["allow_nan"] = allow_nan
    return _io.load_netcdf(path, validate=True, **kw)


#: reader name → function ``reader(path, **reader_options)`` returning a Recording
READERS: dict[str, Callable[..., xr.Dataset]] = {
    "netcdf": _read_netcdf,
    "fayat_csv": _io.read_fayat_imu,
    "fayat_tumble": _io.read_fayat_tumble,
    "broad": _io.read_broad,
    "csv": _io.read_csv,
    "tagtools": _io.read_tagtools,
    "auto": _io.read,
}
#: calibration file suffix → reader
_CALIBRATION_READERS = {".nc": "netcdf", ".netcdf": "netcdf", ".csv": "fayat_tumble"}


class ManifestError(ValueError):
    """A manifest is malformed; the message names the line and the session."""


@dataclass(frozen=True)
class Manifest:
    """A validated cohort manifest.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per session: the required columns, ``reader_options`` (JSON text),
        ``calibration`` (``""`` when none) and the covariates.
    root : pathlib.Path
        Folder against which relative ``file`` and ``calibration`` paths are resolved.
    path : pathlib.Path or None
        The manifest file (None for a manifest built in memory and not written).
    """

    table: pd.DataFrame
    root: Path
    path: Path | None = None

    def __len__(self) -> int:
        return len(self.table)

    @property
    def sessions(self) -> list[str]:
        """Session ids, in manifest order."""
        return list(self.table["session"])

    @property
    def covariates(self) -> list[str]:
        """Names of the covariate columns."""
        known = set(REQUIRED_COLUMNS) | set(OPTIONAL_COLUMNS)
        return [c for c in self.table.columns if c not in known]

    def rows(self) -> Iterator[dict[str, Any]]:
        """Yield each session's row as a dict (a copy)."""
        yield from self.table.to_dict("records")

    def row(self, session: str) -> dict[str, Any]:
        """The row of one session."""
        sel = self.table[self.table["session"] == session]
        if len(sel) != 1:
            raise KeyError(f"no session {session!r} in the manifest")
        return sel.iloc[0].to_dict()

    def to_csv(self, path) -> Path:
        """Write the manifest (paths are written as they are in ``table``)."""
        path = Path(path)
        self.table.to_csv(path, index=False)
        return path


# ------------------------------------------------------------------ validation


def _where(name: str, line: int, session: str | None = None) -> str:
    s = f"{name}, line {line}"
    return f"{s} (session {session!r})" if session else s


def _options(text: str, reader: str, where: str) -> dict[str, Any]:
    text = "" if text is None else str(text).strip()
    if not text:
        opts: Any = {}
    else:
        try:
            opts = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ManifestError(
                f"{where}: reader_options is not valid JSON ({exc.msg} at character "
                f"{exc.pos}): {text!r}"
            ) from None
    if not isinstance(opts, dict):
        raise ManifestError(
            f"{where}: reader_options must be a JSON object, got {type(opts).__name__}"
        )
    if reader == "csv":
        missing = [k for k in ("columns", "units") if k not in opts]
        if missing:
            raise ManifestError(
                f"{where}: the csv reader needs reader_options {missing} (a column and "
                "unit mapping, and fs or time_column)"
            )
        if "fs" not in opts and "time_column" not in opts:
            raise ManifestError(
                f"{where}: the csv reader needs 'fs' or 'time_column' in "
                "reader_options: tiltlab never assumes a sampling rate"
            )
    else:
        params = inspect.signature(READERS[reader]).parameters
        if not any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values()):
            unknown = [k for k in opts if k not in params or k == "path"]
            if unknown:
                raise ManifestError(
                    f"{where}: reader {reader!r} does not accept option(s) {unknown}"
                )
    return opts


def _maybe_numeric(col: pd.Series) -> pd.Series:
    if (col == "").any():
        return col
    try:
        return pd.to_numeric(col)
    except (ValueError, TypeError):
        return col


def _check_table(
    df: pd.DataFrame, root: Path, name: str, groups: Sequence[str] | None
) -> pd.DataFrame:
    """Validate and normalise a manifest table (all cells strings); returns a new one."""
    missing = [c for c in REQUIRED_COLUMNS if c not in df.columns]
    if missing:
        raise ManifestError(
            f"{name}, line 1 (header): missing required column(s) {missing}; "
            f"found {list(df.columns)}"
        )
    if len(df) == 0:
        raise ManifestError(f"{name}: no sessions (the manifest has no data rows)")
    df = df.copy()
    for c in OPTIONAL_COLUMNS:
        if c not in df.columns:
            df[c] = ""
    df = df.fillna("").astype(str)
    for c in df.columns:
        df[c] = df[c].str.strip()
    groups = None if groups is None else [str(g) for g in groups]
    seen_session: dict[str, int] = {}
    seen_file: dict[str, int] = {}
    for i, row in enumerate(df.to_dict("records")):
        line = i + 2
        sid = row["session"] or None
        where = _where(name, line, sid)
        for c in ("session", "subject", "group", "file", "reader"):
            if not row[c]:
                raise ManifestError(f"{where}: empty {c!r}")
        if row["session"] in seen_session:
            raise ManifestError(
                f"{where}: session id {row['session']!r} already used on line "
                f"{seen_session[row['session']]}"
            )
        seen_session[row["session"]] = line
        if row["reader"] not in READERS:
            raise ManifestError(
                f"{where}: unknown reader {row['reader']!r}; known: {sorted(READERS)}"
            )
        _options(row["reader_options"], row["reader"], where)
        key = os.path.normcase(os.path.abspath(session_path(row["file"], root)))
        if key in seen_file:
            raise ManifestError(
                f"{where}: file {row['file']!r} is already named on line "
                f"{seen_file[key]}"
            )
        seen_file[key] = line
        cal = row["calibration"]
        if cal and Path(cal).suffix.lower() not in _CALIBRATION_READERS:
            raise ManifestError(
                f"{where}: calibration file {cal!r} must be .nc (NetCDF) or .csv "
                "(Fayat tumble test)"
            )
        if groups is not None and row["group"] not in groups:
            raise ManifestError(
                f"{where}: unknown group {row['group']!r}; expected one of {groups}"
            )
    known = set(REQUIRED_COLUMNS) | set(OPTIONAL_COLUMNS)
    for c in ["timepoint"] + [c for c in df.columns if c not in known]:
        df[c] = _maybe_numeric(df[c])
    order = list(REQUIRED_COLUMNS) + list(OPTIONAL_COLUMNS)
    return df[order + [c for c in df.columns if c not in order]].reset_index(drop=True)


def read_manifest(path, *, groups: Sequence[str] | None = None) -> Manifest:
    """Read and validate a cohort manifest.

    Parameters
    ----------
    path : path-like
        The manifest CSV (see the module docstring for its columns).
    groups : sequence of str, optional
        The expected group names; a row with another group is rejected.

    Returns
    -------
    Manifest
        With ``root`` the manifest's folder.

    Raises
    ------
    FileNotFoundError
        If the manifest does not exist.
    ManifestError
        A missing required column, an empty required field, a duplicate session id or
        file, an unknown reader, ``reader_options`` that are not a JSON object (or lack
        what the reader needs), a calibration file of unknown type, or an unknown group;
        the message names the line and the session. Session files are not opened here.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such manifest")
    try:
        df = pd.read_csv(path, dtype=str, keep_default_na=False, skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as e:
        raise ManifestError(f"{path.name}: not a readable CSV table ({e})") from None
    root = path.parent.resolve()
    table = _check_table(df, root, path.name, groups)
    return Manifest(table=table, root=root, path=path.resolve())


# ------------------------------------------------------------------ loading


def session_path(file, root) -> Path:
    """``file`` if absolute, else ``root / file``."""
    p = Path(str(file)).expanduser()
    return p if p.is_absolute() else Path(root) / p


def _takes(func: Callable[..., Any], name: str) -> bool:
    """True if ``func`` accepts the keyword ``name`` (explicitly or through ``**``)."""
    try:
        params = inspect.signature(func).parameters
    except (TypeError, ValueError):
        return False
    if name in params:
        return True
    # **attrs of a reader are dataset attributes, not options: only io.read forwards
    return func is _io.read


def load_session(row: Mapping[str, Any], root) -> xr.Dataset:
    """Read one session's Recording with the reader its manifest row names.

    Parameters
    ----------
    row : mapping
        A manifest row (a dict from :meth:`Manifest.rows` or a pandas Series) with
        ``file``, ``reader`` and optionally ``reader_options`` (JSON text or a dict).
    root : path-like
        Folder of the manifest (:attr:`Manifest.root`).

    Returns
    -------
    xarray.Dataset
        The Recording, validated by its reader (:func:`tiltlab.schema.validate`), with
        the manifest's ``session``, ``subject`` and ``group`` added to its attrs as
        ``cohort_session``, ``cohort_subject`` and ``cohort_group``.

    Raises
    ------
    tiltlab.io.ReadError
        A missing, truncated or unreadable file.
    tiltlab._validate.RecordingError
        A recording that breaks the Recording contract.
    """
    reader = str(row["reader"])
    if reader not in READERS:
        raise ManifestError(f"unknown reader {reader!r}; known: {sorted(READERS)}")
    opts = row.get("reader_options", "")
    if not isinstance(opts, Mapping):
        opts = _options(opts, reader, f"session {row.get('session')!r}")
    opts = dict(opts)
    func = READERS[reader]
    try:
        rec = func(session_path(row["file"], root), **opts)
    except UnitCheckError as err:
        # name the switch as a manifest gives it
        raise err.for_switch("manifest") from None
    extra = {
        f"cohort_{k}": str(row[k]) for k in ("session", "subject", "group") if k in row
    }
    return rec.assign_attrs(extra) if extra else rec


def load_calibration(row: Mapping[str, Any], root) -> xr.Dataset | None:
    """The tumble-test Recording named in a manifest row's ``calibration``, or None.

    ``.nc`` files are read with :func:`tiltlab.io.load_netcdf` (validated), ``.csv``
    files with :func:`tiltlab.io.read_fayat_tumble`.
    """
    cal = str(row.get("calibration", "") or "").strip()
    if not cal or cal == "nan":
        return None
    reader = _CALIBRATION_READERS.get(Path(cal).suffix.lower())
    if reader is None:
        raise ManifestError(f"calibration file {cal!r} must be .nc or .csv")
    opts = row.get("reader_options", "")
    if not isinstance(opts, Mapping):
        try:
            opts = json.loads(str(opts)) if str(opts or "").strip() else {}
        except json.JSONDecodeError:
            opts = {}
    kw = {}
    if isinstance(opts, Mapping) and opts.get("check_units") is False:
        if _takes(READERS[reader], "check_units"):
            kw["check_units"] = False
    try:
        return READERS[reader](session_path(cal, root), **kw)
    except UnitCheckError as err:
        raise err.for_switch("manifest") from None


# ------------------------------------------------------------------ init_manifest

_FIELD = re.compile(r"\{(\w+)\}")


def _pattern_regex(pattern: str) -> tuple[re.Pattern, list[str]]:
    parts, fields, pos = [], [], 0
    for m in _FIELD.finditer(pattern):
        parts.append(re.escape(pattern[pos : m.start()]))
        f = m.group(1)
        parts.append(f"(?P={f})" if f in fields else f"(?P<{f}>[^/]+?)")
        if f not in fields:
            fields.append(f)
        pos = m.end()
    parts.append(re.escape(pattern[pos:]))
    return re.compile("".join(parts)), fields


def init_manifest(
    folder,
    pattern: str,
    *,
    reader: str = "netcdf",
    group: str | Mapping[str, str] | None = None,
    reader_options: Mapping[str, Any] | None = None,
    calibration: str | Mapping[str, str] | None = None,
    out=None,
) -> Manifest:
    """Build a manifest from the files of a folder whose relative paths match a pattern.

    Parameters
    ----------
    folder : path-like
        Folder searched recursively.
    pattern : str
        Relative path with named fields, e.g. ``"{group}/{subject}_{timepoint}.nc"``;
        a field matches one or more characters other than ``/``. Fields ``session``,
        ``subject``, ``group`` and ``timepoint`` fill those columns, any other field
        becomes a covariate. ``subject`` (or ``session``) is required. The session id
        is ``{subject}_{timepoint}`` (``{subject}`` without a timepoint) unless the
        pattern has ``{session}``.
    reader : str
        Reader of every file (see :data:`READERS`).
    group : str or mapping, optional
        The group when the pattern has no ``{group}`` field: one name for all, or a
        mapping subject → group.
    reader_options : mapping, optional
        Reader options for every row (stored as JSON).
    calibration : str or mapping, optional
        Each subject's tumble test: a path pattern formatted with the row's fields
        (e.g. ``"calibration/{subject}_tumble.nc"``) or a mapping subject → path.
    out : path-like, optional
        Write the manifest there (paths relative to its folder).

    Returns
    -------
    Manifest
        Validated as :func:`read_manifest` would.
    """
    folder = Path(folder).resolve()
    if not folder.is_dir():
        raise FileNotFoundError(f"{folder}: no such folder")
    if reader not in READERS:
        raise ValueError(f"unknown reader {reader!r}; known: {sorted(READERS)}")
    regex, fields = _pattern_regex(str(pattern))
    if "subject" not in fields and "session" not in fields:
        raise ValueError(
            f"pattern {pattern!r} needs a {{subject}} or {{session}} field"
        )
    if "group" not in fields and group is None:
        raise ValueError(
            f"pattern {pattern!r} has no {{group}} field: give group= (a name or a "
            "mapping subject → group)"
        )
    rows = []
    for p in sorted(folder.rglob("*")):
        m = regex.fullmatch(p.relative_to(folder).as_posix()) if p.is_file() else None
        if m is None:
            continue
        f = m.groupdict()
        subject = f.get("subject", f.get("session"))
        tp = f.get("timepoint", "")
        session = f.get("session") or (f"{subject}_{tp}" if tp else subject)
        if "group" in f:
            grp = f["group"]
        elif isinstance(group, Mapping):
            if subject not in group:
                raise ValueError(f"group mapping has no entry for subject {subject!r}")
            grp = group[subject]
        else:
            grp = str(group)
        cal = ""
        if isinstance(calibration, Mapping):
            cal = str(calibration.get(subject, ""))
        elif calibration is not None:
            cal = str(calibration).format(**{**f, "subject": subject, "group": grp})
        row = {
            "session": session,
            "subject": subject,
            "group": grp,
            "timepoint": tp,
            "file": str(p),
            "reader": reader,
            "reader_options": json.dumps(dict(reader_options or {}), sort_keys=True),
            "calibration": str(session_path(cal, folder)) if cal else "",
        }
        row.update({k: v for k, v in f.items() if k not in row})
        rows.append(row)
    if not rows:
        raise ValueError(f"no file under {folder} matches {pattern!r}")
    df = pd.DataFrame(rows)
    base = Path(out).resolve().parent if out is not None else folder
    for c in ("file", "calibration"):
        df[c] = [Path(os.path.relpath(v, base)).as_posix() if v else "" for v in df[c]]
    name = Path(out).name if out is not None else "manifest"
    table = _check_table(df.astype(str), base, name, None)
    manifest = Manifest(table=table, root=base, path=None)
    if out is not None:
        out = manifest.to_csv(Path(out).resolve())
        manifest = Manifest(table=table, root=base, path=out)
    return manifest
