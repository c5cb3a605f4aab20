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
``session``, ``subject`` and ``group`` are always text (``007`` stays ``007``); the
time point and the covariates become numbers when every value is a number written
without a leading zero (``0``, ``7``, ``14``), and stay text otherwise (``d7``,
``007``).

:func:`read_manifest` rejects a malformed manifest before any work starts, naming the
line (1-based, the header being line 1) and the session: a missing column, an empty
field, an unknown reader or malformed ``reader_options``; a session id used twice; a
subject in two groups (if subject ids restart in each group, prefix them with the
group: ``tiltlab cohort init --nested-subjects`` writes them so); two sessions of one
subject at one time point (one animal counted twice in the statistics); one recording
listed twice — the same path, the same file through a link, or the same content (only
files of equal size are compared, by sampled blocks and then by SHA-256); and, when
the study declares them (``groups=``, ``timepoints=``), a group or time point it does
not declare (a typo). A session file that is missing or unreadable is *not* a manifest
error: :func:`tiltlab.cohort.run_cohort` records it as a failed session.

:func:`init_manifest` writes a manifest from the files of a folder whose paths match a
pattern (:data:`PATTERN_HELP` states its grammar) or an explicit regular expression.

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
"""

from __future__ import annotations

import difflib
import hashlib
import inspect
import json
import os
import re
import warnings
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
    "PATTERN_HELP",
    "ManifestError",
    "ManifestWarning",
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


class ManifestWarning(UserWarning):
    """A manifest that is valid but looks wrong (e.g. two group labels one letter
    apart)."""


class ManifestError(ValueError):
    """A manifest is malformed; the message names the line (or, for
    :func:`init_manifest`, the file) and the session."""


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
        """Write the manifest to a CSV file.

        Relative ``file`` and ``calibration`` paths are rewritten relative to the new
        file's folder (absolute ones are kept), so that the written manifest names the
        same files as this one wherever it is written. Missing folders are created.
        """
        path = Path(path)
        table = self.table.copy()
        new_root = path.resolve().parent
        if new_root != Path(self.root).resolve():
            for c in ("file", "calibration"):
                if c in table.columns:
                    table[c] = [_rebase(v, self.root, new_root) for v in table[c]]
        path.parent.mkdir(parents=True, exist_ok=True)
        table.to_csv(path, index=False)
        return path


def _portable(path, base) -> str:
    """``path`` relative to the folder ``base`` (POSIX separators), or absolute when no
    relative path exists (another drive)."""
    try:
        return Path(os.path.relpath(path, base)).as_posix()
    except ValueError:
        return Path(path).as_posix()


def _rebase(value: Any, root, new_root) -> Any:
    text = "" if value is None else str(value)
    if not text.strip() or Path(text).expanduser().is_absolute():
        return value
    return _portable(Path(root) / text, new_root)


# ------------------------------------------------------------------ validation

#: how a subject id that restarts in each group is made unique (both contexts)
_RESTART_MANIFEST = (
    "If subject ids restart in each group (two different animals), make them unique, "
    "e.g. prefix them with the group ({example!r}), as 'tiltlab cohort init "
    "--nested-subjects' writes them"
)
_RESTART_INIT = (
    "If subject ids restart in each group (two different animals), give "
    "nested_subjects=True ('tiltlab cohort init --nested-subjects') to name them "
    "<group>-<subject> ({example!r})"
)
#: bytes per sampled block when comparing the content of files of equal size
_BLOCK = 1 << 16
#: a number written with a leading zero: kept as text (an id such as 007)
_LEADING_ZERO = re.compile(r"^[+-]?0\d")


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
    """Numbers when every value is a number without a leading zero, else the text."""
    text = col.astype(str)
    if (text == "").any() or text.str.match(_LEADING_ZERO).any():
        return col
    try:
        return pd.to_numeric(col)
    except (ValueError, TypeError):
        return col


def _declared_names(names, what: str) -> list[str] | None:
    """A study's declared groups or time points: a sequence, or one comma-separated
    string; None when not declared."""
    if names is None:
        return None
    if isinstance(names, str):
        names = names.split(",")
    out = [str(n).strip() for n in names]
    if not out or any(not n for n in out):
        raise ValueError(
            f"declared {what}s {list(names)!r}: give non-empty names, e.g. "
            f"{'A,B' if what == 'group' else 'd0,d7'}"
        )
    return list(dict.fromkeys(out))


def _check_declared(value: str, declared: list[str] | None, what: str, where: str):
    if declared is None or value in declared:
        return
    close = difflib.get_close_matches(value, declared, n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    shown = f"unknown {what} {value!r}" if value else f"no {what}"
    raise ManifestError(
        f"{where}: {shown}; the study declares the {what}s "
        f"{', '.join(map(repr, declared))}{hint}"
    )


def _fingerprint(path: str, size: int) -> bytes:
    """SHA-256 of three sampled blocks (start, middle, end) of a file."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for offset in sorted(
            {0, max(0, size // 2 - _BLOCK // 2), max(0, size - _BLOCK)}
        ):
            f.seek(offset)
            h.update(f.read(_BLOCK))
    return h.digest()


def _sha256(path: str) -> bytes:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.digest()


def _same_content(paths: Sequence[str]) -> tuple[int, int] | None:
    """The first ``(j, i)``, ``j < i``, of two existing files with the same bytes.

    Only files of equal size are read: first three sampled blocks, and the whole file
    (SHA-256) only where those agree. Files that cannot be read are left out."""
    by_size: dict[int, list[int]] = {}
    for i, p in enumerate(paths):
        try:
            if os.path.isfile(p):
                by_size.setdefault(os.path.getsize(p), []).append(i)
        except OSError:
            continue
    twins: list[tuple[int, int]] = []
    for size, idx in by_size.items():
        if len(idx) < 2:
            continue
        for digest in (lambda p: _fingerprint(p, size), _sha256):
            groups: dict[bytes, list[int]] = {}
            for i in idx:
                try:
                    groups.setdefault(digest(paths[i]), []).append(i)
                except OSError:
                    continue
            idx = [i for g in groups.values() if len(g) > 1 for i in g]
            if len(idx) < 2:
                break
        else:
            for g in groups.values():
                if len(g) > 1:
                    g = sorted(g)
                    twins.append((g[0], g[1]))
    return min(twins, key=lambda t: t[1]) if twins else None


def _check_table(
    df: pd.DataFrame,
    root: Path,
    name: str,
    groups: Sequence[str] | str | None = None,
    *,
    timepoints: Sequence[str] | str | None = None,
    labels: Sequence[str] | None = None,
    restart_hint: str = _RESTART_MANIFEST,
) -> pd.DataFrame:
    """Validate and normalise a manifest table (all cells strings); returns a new one.

    Rows are named ``"<name>, line N"`` (``N`` 1-based with the header as line 1), or
    by ``labels[i]`` when given (a table that is not a file yet)."""
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
    groups = _declared_names(groups, "group")
    timepoints = _declared_names(timepoints, "time point")

    def ref(i: int) -> str:  # another row, after "is also ..."
        return f"on line {i + 2}" if labels is None else f"in {labels[i]}"

    def where(i: int, session: str | None) -> str:
        head = _where(name, i + 2) if labels is None else str(labels[i])
        return f"{head} (session {session!r})" if session else head

    def this_file(i: int) -> str:
        return f"file {records[i]['file']!r}" if labels is None else "this file"

    def other(j: int) -> str:  # another row's file
        sid = records[j]["session"]
        if labels is None:
            return f"{records[j]['file']!r} {ref(j)} (session {sid!r})"
        return f"{labels[j]} (session {sid!r})"

    records = df.to_dict("records")
    group_of: dict[str, tuple[str, int]] = {}
    seen_session: dict[str, int] = {}
    seen_cell: dict[tuple[str, str], int] = {}
    seen_file: dict[str, int] = {}
    seen_real: dict[str, int] = {}
    real_paths: list[str] = []
    for i, row in enumerate(records):
        sid = row["session"] or None
        at = where(i, sid)
        for c in ("session", "subject", "group", "file", "reader"):
            if not row[c]:
                raise ManifestError(f"{at}: empty {c!r}")
        if row["reader"] not in READERS:
            raise ManifestError(
                f"{at}: unknown reader {row['reader']!r}; known: {sorted(READERS)}"
            )
        _options(row["reader_options"], row["reader"], at)
        cal = row["calibration"]
        if cal and Path(cal).suffix.lower() not in _CALIBRATION_READERS:
            raise ManifestError(
                f"{at}: calibration file {cal!r} must be .nc (NetCDF) or .csv "
                "(Fayat tumble test)"
            )
        _check_declared(row["group"], groups, "group", at)
        _check_declared(row["timepoint"], timepoints, "time point", at)
        subject, group, tp = row["subject"], row["group"], row["timepoint"]
        if subject in group_of and group_of[subject][0] != group:
            first_group, j = group_of[subject]
            hint = restart_hint.format(example=f"{group}-{subject}")
            raise ManifestError(
                f"{at}: subject {subject!r} is in group {group!r} here and in group "
                f"{first_group!r} {ref(j)} (session {records[j]['session']!r}); a "
                f"subject belongs to one group. {hint}"
            )
        group_of.setdefault(subject, (group, i))
        if row["session"] in seen_session:
            raise ManifestError(
                f"{at}: session id {row['session']!r} already used "
                f"{ref(seen_session[row['session']])}"
            )
        seen_session[row["session"]] = i
        path = session_path(row["file"], root)
        key = os.path.normcase(os.path.abspath(path))
        if key in seen_file:
            raise ManifestError(
                f"{at}: file {row['file']!r} is already named {ref(seen_file[key])}"
            )
        seen_file[key] = i
        real = os.path.normcase(os.path.realpath(path))
        if real in seen_real:
            j = seen_real[real]
            raise ManifestError(
                f"{at}: {this_file(i)} is the same file as {other(j)}, through a link "
                "or another spelling of its path: one recording listed twice"
            )
        seen_real[real] = i
        real_paths.append(real)
        if (subject, tp) in seen_cell:
            j = seen_cell[(subject, tp)]
            when = f"at time point {tp!r}" if tp else "without a time point"
            raise ManifestError(
                f"{at}: subject {subject!r} already has a session {when} (session "
                f"{records[j]['session']!r} {ref(j)}); one session per subject and "
                "time point, or the statistics count one animal twice: give the "
                "sessions distinct time points (e.g. 'd7' and 'd7b'), or leave one out"
            )
        seen_cell[(subject, tp)] = i
    twins = _same_content(real_paths)
    if twins is not None:
        j, i = twins
        raise ManifestError(
            f"{where(i, records[i]['session'])}: {this_file(i)} has the same content "
            f"as {other(j)}: one recording listed twice (a copy?)"
        )
    known = set(REQUIRED_COLUMNS) | set(OPTIONAL_COLUMNS)
    for c in ["timepoint"] + [c for c in df.columns if c not in known]:
        df[c] = _maybe_numeric(df[c])
    order = list(REQUIRED_COLUMNS) + list(OPTIONAL_COLUMNS)
    return df[order + [c for c in df.columns if c not in order]].reset_index(drop=True)


def read_manifest(
    path,
    *,
    groups: Sequence[str] | str | None = None,
    timepoints: Sequence[str] | str | None = None,
) -> Manifest:
    """Read and validate a cohort manifest.

    Parameters
    ----------
    path : path-like
        The manifest CSV (see the module docstring for its columns).
    groups : sequence of str, or str, optional
        The study's groups (a sequence, or one comma-separated string such as
        ``"sham,lesion"``); a row with another group (a typo) is rejected, naming the
        row, the declared groups and the closest one.
    timepoints : sequence of str, or str, optional
        The study's time points, likewise (compared as text: ``"0"``, ``"d7"``).

    Returns
    -------
    Manifest
        With ``root`` the manifest's folder. ``session``, ``subject`` and ``group``
        are text (``007`` stays ``007``).

    Raises
    ------
    FileNotFoundError
        If the manifest does not exist.
    ManifestError
        A missing required column, an empty required field, a duplicate session id, an
        unknown reader, ``reader_options`` that are not a JSON object (or lack what the
        reader needs), a calibration file of unknown type, a subject in two groups, two
        sessions of one subject at one time point, one recording listed twice (the same
        path, the same file through a link, or the same content), or a group or time
        point the study does not declare; the message names the line and the session.
        Session files are not read here, except to compare files of equal size.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such manifest")
    try:
        df = pd.read_csv(path, dtype=str, keep_default_na=False, skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as e:
        raise ManifestError(f"{path.name}: not a readable CSV table ({e})") from None
    root = path.parent.resolve()
    table = _check_table(df, root, path.name, groups, timepoints=timepoints)
    if groups is None:
        _warn_near_duplicates(table["group"], "groups", "groups=", path.name)
    if timepoints is None:
        _warn_near_duplicates(
            table["timepoint"], "time points", "timepoints=", path.name
        )
    return Manifest(table=table, root=root, path=path.resolve())


def _warn_near_duplicates(column, what: str, keyword: str, where: str) -> None:
    """Warn when two labels of a column differ by a letter or two (``translaton`` next
    to ``translation``): likely a typo that would make a group or time point of its
    own. Only a warning: labels such as ``d1``/``d7`` are close on purpose; declaring
    the labels (``keyword``) makes an undeclared one an error."""
    counts = column.astype(str).value_counts()
    labels = list(counts.index)
    for i, a in enumerate(labels):
        for b in labels[i + 1 :]:
            if min(len(a), len(b)) < 5:  # short labels (d1, d7, A, B) differ by design
                continue
            if difflib.SequenceMatcher(None, a.lower(), b.lower()).ratio() >= 0.85:
                warnings.warn(
                    f"{where}: {what} {a!r} ({counts[a]} sessions) and {b!r} "
                    f"({counts[b]} sessions) differ by a letter or two: a typo? "
                    f"Declare the study's {what} ({keyword}, or --{keyword[:-1]} on "
                    "the command line) to make an undeclared label an error",
                    ManifestWarning,
                    stacklevel=3,
                )


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

#: The grammar of :func:`init_manifest`'s patterns, in words (also ``--help``).
PATTERN_HELP = (
    "A pattern is a file's path relative to FOLDER, with '/' between folders, in which "
    "{name} fields stand for parts of the path. A field matches one or more "
    "characters other than '/'; fields are read from left to right, each taking as "
    "much as it can, so where a separator (such as '_') stands between two fields "
    "the path is split at the separator's LAST occurrence: with "
    "'{group}/{subject}_{timepoint}.nc', 'A/rat_01_d0.nc' is subject 'rat_01' at "
    "time point 'd0'. Only the last field of a path segment must therefore be free "
    "of the separator that comes before it (time points such as d0, 7d, baseline). "
    "Two fields must be separated by some text ('{subject}{timepoint}' is refused), "
    "and a field named twice must match the same text both times. Fields session, "
    "subject, group and timepoint fill those columns; any other field is a "
    "covariate. Where the rule does not fit (time points such as 'day_7'), give a "
    "regular expression with named groups instead, matched against the whole "
    "relative path, e.g. '(?P<group>[^/]+)/(?P<subject>[^/]+)_(?P<timepoint>day_\\d+)"
    "\\.nc'."
)

_FIELD = re.compile(r"\{(\w+)\}")


def _pattern_regex(pattern: str) -> tuple[re.Pattern, list[str]]:
    """The regular expression of a pattern (see :data:`PATTERN_HELP`) and its fields.

    Each field becomes a greedy ``[^/]+`` (a field named again, a back-reference)."""
    if not pattern.strip():
        raise ValueError("the pattern is empty; give e.g. '{group}/{subject}.nc'")
    if pattern.startswith("/"):
        raise ValueError(
            f"pattern {pattern!r} starts with '/': a pattern is a path relative to "
            "the folder searched, e.g. '{group}/{subject}_{timepoint}.nc'"
        )
    parts: list[str] = []
    fields: list[str] = []
    pos, prev = 0, None
    for m in _FIELD.finditer(pattern):
        literal = pattern[pos : m.start()]
        if "{" in literal or "}" in literal:
            raise ValueError(
                f"pattern {pattern!r}: {literal!r} has a brace that is not a field; "
                "a field is {name} with letters, digits and '_' only"
            )
        f = m.group(1)
        if prev is not None and not literal:
            raise ValueError(
                f"pattern {pattern!r}: fields {{{prev}}} and {{{f}}} touch, so "
                "nothing says where one ends; put a separator between them, or give "
                "a regular expression with named groups (regex=, --regex)"
            )
        parts.append(re.escape(literal))
        parts.append(f"(?P={f})" if f in fields else f"(?P<{f}>[^/]+)")
        if f not in fields:
            fields.append(f)
        pos, prev = m.end(), f
    tail = pattern[pos:]
    if "{" in tail or "}" in tail:
        raise ValueError(
            f"pattern {pattern!r}: {tail!r} has a brace that is not a field; a field "
            "is {name} with letters, digits and '_' only"
        )
    parts.append(re.escape(tail))
    return re.compile("".join(parts)), fields


def _user_regex(regex: str | re.Pattern) -> tuple[re.Pattern, list[str]]:
    """A user's regular expression and its named groups (the fields)."""
    if isinstance(regex, re.Pattern):
        compiled = regex
    else:
        try:
            compiled = re.compile(str(regex))
        except re.error as exc:
            raise ValueError(
                f"regex {regex!r} is not a valid regular expression ({exc})"
            ) from None
    fields = list(compiled.groupindex)
    if not fields:
        raise ValueError(
            f"regex {compiled.pattern!r} has no named group; name the parts, e.g. "
            "(?P<subject>[^/]+)_(?P<timepoint>[^/_]+)\\.nc"
        )
    return compiled, fields


def _broad_layout(path: Path) -> bool:
    """True for an HDF5 file with the variables of a BROAD trial (which
    :func:`tiltlab.io.detect` may describe as a NetCDF-4 file, h5netcdf opening any
    HDF5 file)."""
    import h5py

    from ..io.broad import _BROAD_VARS

    try:
        with h5py.File(path, "r") as f:
            names = set(map(str, f.keys()))
    except OSError:
        return False
    return all(k in names for k in _BROAD_VARS)


def _reader_from_content(path: Path, label: str) -> str:
    """The reader of a file, chosen from its content (:func:`tiltlab.io.detect`);
    a file of another kind is refused, listing the readers to choose from."""
    choices = ", ".join(r for r in READERS if r != "auto")
    try:
        with warnings.catch_warnings():  # a probe: the reader warns when it reads
            warnings.simplefilter("ignore")
            what = _io.detect(path)
    except (OSError, ValueError) as exc:
        raise ValueError(
            f"{label}: cannot tell what it is ({' '.join(str(exc).split())}), so no "
            f"reader can be chosen from its content; give reader= (--reader): one of "
            f"{choices}, or auto (chosen when each session is read)"
        ) from None
    if what.startswith("tiltlab Recording"):
        return "netcdf"
    if what.startswith("tag-tools NetCDF"):
        return "tagtools"
    if what.startswith("BROAD trial"):
        return "broad"
    if what.startswith(("NetCDF-4 file", "HDF5 file")) and _broad_layout(path):
        return "broad"
    extra = ""
    if what.startswith(("CSV", "TSV")):
        extra = (
            " (your own CSV: reader csv with reader_options, a column/unit mapping; "
            "Fayat et al.'s CSV: fayat_csv or fayat_tumble)"
        )
    raise ValueError(
        f"{label} looks like a {what}, for which tiltlab does not choose a reader; "
        f"give reader= (--reader): one of {choices}{extra}"
    )


def init_manifest(
    folder,
    pattern: str | None = None,
    *,
    regex: str | re.Pattern | None = None,
    reader: str | None = None,
    group: str | Mapping[str, str] | None = None,
    nested_subjects: bool = False,
    groups: Sequence[str] | str | None = None,
    timepoints: Sequence[str] | str | None = None,
    reader_options: Mapping[str, Any] | None = None,
    calibration: str | Mapping[str, str] | None = None,
    out=None,
) -> Manifest:
    r"""Build a manifest from the files of a folder whose relative paths match a pattern.

    Parameters
    ----------
    folder : path-like
        Folder searched recursively.
    pattern : str, optional
        Relative path with named fields, e.g. ``"{group}/{subject}_{timepoint}.nc"``.
        A field matches one or more characters other than ``/``; fields are read left
        to right, each taking as much as it can, so a separator between two fields
        splits the path at its *last* occurrence: ``A/rat_01_d0.nc`` is subject
        ``rat_01`` at time point ``d0`` (the full grammar: :data:`PATTERN_HELP`).
        Fields ``session``, ``subject``, ``group`` and ``timepoint`` fill those
        columns, any other field becomes a covariate. ``subject`` (or ``session``) is
        required. The session id is ``{subject}_{timepoint}`` (``{subject}`` without
        a timepoint) unless the pattern has ``{session}``.
    regex : str or re.Pattern, optional
        Instead of ``pattern``: a regular expression matched against the whole relative
        path (``/`` separators), whose named groups are the fields, e.g.
        ``r"(?P<group>[^/]+)/(?P<subject>[^/]+)_(?P<timepoint>day_\d+)\.nc"``.
    reader : str, optional
        Reader of every file (see :data:`READERS`). Default: chosen for each file from
        its content (:func:`tiltlab.io.detect`): ``netcdf`` for a tiltlab Recording,
        ``tagtools`` for a tag-tools NetCDF, ``broad`` for a BROAD trial; any other
        file is refused, naming it and the readers to choose from.
    group : str or mapping, optional
        The group when the pattern has no ``{group}`` field: one name for all, or a
        mapping subject → group.
    nested_subjects : bool
        Subject ids restart in each group (``A/rat1_d0.nc`` and ``B/rat1_d0.nc`` are
        two animals): name each subject ``<group>-<subject>`` (``A-rat1``), and a
        ``{session}`` field's id likewise. Without it a subject found in two groups is
        refused.
    groups, timepoints : sequence of str, or str, optional
        The study's declared groups and time points (a sequence, or a comma-separated
        string); a file whose group or time point is not declared (a typo) is
        refused, as by :func:`read_manifest`.
    reader_options : mapping, optional
        Reader options for every row (stored as JSON).
    calibration : str or mapping, optional
        Each subject's tumble test: a path pattern formatted with the row's fields
        as found in the path (e.g. ``"calibration/{subject}_tumble.nc"``) or a mapping
        subject → path; relative paths are relative to ``folder``.
    out : path-like, optional
        Write the manifest there (paths relative to its folder).

    Returns
    -------
    Manifest
        Validated as :func:`read_manifest` would; ``file`` and ``calibration`` relative
        to the manifest's folder (``out``'s, else ``folder``) wherever a relative path
        exists.

    Raises
    ------
    FileNotFoundError
        If ``folder`` does not exist.
    ValueError
        A bad pattern or regex, an unknown reader, a file whose reader cannot be
        chosen from its content, no matching file.
    ManifestError
        What :func:`read_manifest` rejects (a subject in two groups, a session id or a
        subject and time point twice, one recording twice, an undeclared group or time
        point …), naming the file, as the manifest is not written yet.
    """
    folder = Path(folder).resolve()
    if not folder.is_dir():
        raise FileNotFoundError(f"{folder}: no such folder")
    if reader is not None and reader not in READERS:
        raise ValueError(f"unknown reader {reader!r}; known: {sorted(READERS)}")
    if (pattern is None) == (regex is None):
        raise ValueError(
            "give a pattern (e.g. '{group}/{subject}_{timepoint}.nc') or a regex with "
            "named groups, not both"
            if pattern is not None
            else "give a pattern (e.g. '{group}/{subject}_{timepoint}.nc') or a regex "
            "with named groups"
        )
    if pattern is not None:
        compiled, fields = _pattern_regex(str(pattern))
        shown = repr(str(pattern))
    else:
        compiled, fields = _user_regex(regex)
        shown = f"regex {compiled.pattern!r}"
    if "subject" not in fields and "session" not in fields:
        raise ValueError(f"pattern {shown} needs a {{subject}} or {{session}} field")
    if "group" not in fields and group is None:
        raise ValueError(
            f"pattern {shown} has no {{group}} field: give group= (a name or a "
            "mapping subject → group)"
        )
    rows, labels = [], []
    for p in sorted(folder.rglob("*")):
        if not p.is_file():
            continue
        rel = p.relative_to(folder).as_posix()
        m = compiled.fullmatch(rel)
        if m is None:
            continue
        label = f"file {rel!r}"
        f = {k: ("" if v is None else str(v)) for k, v in m.groupdict().items()}
        found = f.get("subject") or f.get("session", "")
        tp = f.get("timepoint", "")
        if "group" in f:
            grp = f["group"]
        elif isinstance(group, Mapping):
            if found not in group:
                raise ValueError(
                    f"{label}: the group mapping has no entry for subject {found!r}"
                )
            grp = str(group[found])
        else:
            grp = str(group)
        subject = f"{grp}-{found}" if nested_subjects else found
        session = f.get("session", "")
        if session and nested_subjects:
            session = f"{grp}-{session}"
        session = session or (f"{subject}_{tp}" if tp else subject)
        cal = ""
        if isinstance(calibration, Mapping):
            cal = str(calibration.get(subject, calibration.get(found, "")))
        elif calibration is not None:
            try:
                cal = str(calibration).format(**{**f, "subject": found, "group": grp})
            except (KeyError, IndexError) as exc:
                raise ValueError(
                    f"calibration pattern {calibration!r} names {exc}, which is not a "
                    f"field of the pattern ({', '.join(fields)})"
                ) from None
        row = {
            "session": session,
            "subject": subject,
            "group": grp,
            "timepoint": tp,
            "file": str(p),
            "reader": reader or _reader_from_content(p, label),
            "reader_options": json.dumps(dict(reader_options or {}), sort_keys=True),
            "calibration": str(session_path(cal, folder)) if cal else "",
        }
        row.update({k: v for k, v in f.items() if k not in row})
        rows.append(row)
        labels.append(label)
    if not rows:
        raise ValueError(f"no file under {folder} matches {shown}")
    df = pd.DataFrame(rows)
    base = Path(out).resolve().parent if out is not None else folder
    for c in ("file", "calibration"):
        df[c] = [_portable(v, base) if v else "" for v in df[c]]
    name = Path(out).name if out is not None else "manifest"
    table = _check_table(
        df.astype(str),
        base,
        name,
        groups,
        timepoints=timepoints,
        labels=labels,
        restart_hint=_RESTART_INIT,
    )
    manifest = Manifest(table=table, root=base, path=None)
    if out is not None:
        out = manifest.to_csv(Path(out).resolve())
        manifest = Manifest(table=table, root=base, path=out)
    return manifest
