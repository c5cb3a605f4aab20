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

Each session's recording is read by :func:`load_session` (with the reader registry
:data:`READERS`, in :mod:`~tiltlab.cohort.sessions`);
:func:`~tiltlab.cohort.init_manifest` (in :mod:`~tiltlab.cohort.initialize`) writes a
manifest from the files of a folder whose paths match a pattern or an explicit regular
expression.
"""

from __future__ import annotations

import difflib
import hashlib
import os
import re
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from .._stack import user_stacklevel
from ..datasets import file_sha256
from .sessions import (
    _CALIBRATION_READERS,
    READERS,
    ManifestError,
    _options,
    load_calibration,
    load_session,
    session_path,
)

__all__ = [
    "REQUIRED_COLUMNS",
    "OPTIONAL_COLUMNS",
    "READERS",
    "ManifestError",
    "ManifestWarning",
    "StudyLabels",
    "Manifest",
    "read_manifest",
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


@dataclass(frozen=True)
class StudyLabels:
    """The groups and time points a study declares (a label not among them is a typo).

    Attributes
    ----------
    groups : sequence of str, or str, optional
        The study's groups (a sequence, or one comma-separated string such as
        ``"sham,lesion"``); None declares none.
    timepoints : sequence of str, or str, optional
        The study's time points, likewise (compared as text: ``"0"``, ``"d7"``).
    """

    groups: Sequence[str] | str | None = None
    timepoints: Sequence[str] | str | None = None


class ManifestWarning(UserWarning):
    """Warn of a manifest that is valid but looks wrong.

    A manifest that is valid but looks wrong (e.g. two group labels one letter
    apart).
    """


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
        """Count the sessions."""
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
        """Return the row of one session."""
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
    """Make ``path`` relative to the folder ``base`` (POSIX separators) where possible.

    ``path`` relative to the folder ``base`` (POSIX separators), or absolute when no
    relative path exists (another drive).
    """
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
    """Parse a study's declared groups or time points.

    A study's declared groups or time points: a sequence, or one comma-separated
    string; None when not declared.
    """
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
    return bytes.fromhex(file_sha256(path))


def _same_content(paths: Sequence[str]) -> tuple[int, int] | None:
    """Find the first ``(j, i)``, ``j < i``, of two existing files with the same bytes.

    Only files of equal size are read: first three sampled blocks, and the whole file
    (SHA-256) only where those agree. Files that cannot be read are left out.
    """
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
    by ``labels[i]`` when given (a table that is not a file yet).
    """
    df = _normalised(df, name)
    groups = _declared_names(groups, "group")
    timepoints = _declared_names(timepoints, "time point")
    rows = _RowNames(df.to_dict("records"), name, labels)
    seen = _Seen(rows, root, restart_hint)
    for i, row in enumerate(rows.records):
        at = rows.where(i, row["session"] or None)
        _check_cells(row, at)
        _check_declared(row["group"], groups, "group", at)
        _check_declared(row["timepoint"], timepoints, "time point", at)
        seen.add(i, row, at)
    seen.check_contents()
    known = set(REQUIRED_COLUMNS) | set(OPTIONAL_COLUMNS)
    for c in ["timepoint"] + [c for c in df.columns if c not in known]:
        df[c] = _maybe_numeric(df[c])
    order = list(REQUIRED_COLUMNS) + list(OPTIONAL_COLUMNS)
    return df[order + [c for c in df.columns if c not in order]].reset_index(drop=True)


def _normalised(df: pd.DataFrame, name: str) -> pd.DataFrame:
    """Check the header and the rows; add the optional columns, strip cells."""
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
    return df


def _check_cells(row: dict[str, str], at: str) -> None:
    """Check one row's own cells: required fields, reader, its options, calibration."""
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


@dataclass(frozen=True)
class _RowNames:
    """How messages name a manifest's rows: by line, or by ``labels`` (no file yet)."""

    records: list[dict[str, str]]
    name: str
    labels: Sequence[str] | None

    def ref(self, i: int) -> str:
        """Name another row, after "is also ..."."""
        return f"on line {i + 2}" if self.labels is None else f"in {self.labels[i]}"

    def where(self, i: int, session: str | None) -> str:
        """Name a row at the head of a message."""
        if self.labels is None:
            head = _where(self.name, i + 2)
        else:
            head = str(self.labels[i])
        return f"{head} (session {session!r})" if session else head

    def this_file(self, i: int) -> str:
        """Name a row's file, in a message about that row."""
        if self.labels is None:
            return f"file {self.records[i]['file']!r}"
        return "this file"

    def other(self, j: int) -> str:
        """Name another row's file."""
        sid = self.records[j]["session"]
        if self.labels is None:
            return f"{self.records[j]['file']!r} {self.ref(j)} (session {sid!r})"
        return f"{self.labels[j]} (session {sid!r})"


class _Seen:
    """What the rows so far have used: a row that repeats one of them is refused."""

    def __init__(self, rows: _RowNames, root: Path, restart_hint: str):
        self.rows, self.root, self.restart_hint = rows, root, restart_hint
        self.group_of: dict[str, tuple[str, int]] = {}
        self.session: dict[str, int] = {}
        self.cell: dict[tuple[str, str], int] = {}
        self.file: dict[str, int] = {}
        self.real: dict[str, int] = {}
        self.real_paths: list[str] = []

    def add(self, i: int, row: dict[str, str], at: str) -> None:
        """Check row ``i`` against the rows before it, then record it."""
        self._subject(i, row, at)
        self._session(i, row, at)
        self._file(i, row, at)
        self._cell(i, row, at)

    def _subject(self, i: int, row: dict[str, str], at: str) -> None:
        """Refuse a subject in two groups."""
        subject, group = row["subject"], row["group"]
        if subject in self.group_of and self.group_of[subject][0] != group:
            first_group, j = self.group_of[subject]
            hint = self.restart_hint.format(example=f"{group}-{subject}")
            raise ManifestError(
                f"{at}: subject {subject!r} is in group {group!r} here and in group "
                f"{first_group!r} {self.rows.ref(j)} (session "
                f"{self.rows.records[j]['session']!r}); a subject belongs to one "
                f"group. {hint}"
            )
        self.group_of.setdefault(subject, (group, i))

    def _session(self, i: int, row: dict[str, str], at: str) -> None:
        """Refuse a session id used twice."""
        if row["session"] in self.session:
            raise ManifestError(
                f"{at}: session id {row['session']!r} already used "
                f"{self.rows.ref(self.session[row['session']])}"
            )
        self.session[row["session"]] = i

    def _file(self, i: int, row: dict[str, str], at: str) -> None:
        """Refuse a file named twice, by its path or through a link."""
        path = session_path(row["file"], self.root)
        key = os.path.normcase(os.path.abspath(path))
        if key in self.file:
            raise ManifestError(
                f"{at}: file {row['file']!r} is already named "
                f"{self.rows.ref(self.file[key])}"
            )
        self.file[key] = i
        real = os.path.normcase(os.path.realpath(path))
        if real in self.real:
            j = self.real[real]
            raise ManifestError(
                f"{at}: {self.rows.this_file(i)} is the same file as "
                f"{self.rows.other(j)}, through a link or another spelling of its "
                "path: one recording listed twice"
            )
        self.real[real] = i
        self.real_paths.append(real)

    def _cell(self, i: int, row: dict[str, str], at: str) -> None:
        """Refuse two sessions of one subject at one time point."""
        subject, tp = row["subject"], row["timepoint"]
        if (subject, tp) in self.cell:
            j = self.cell[(subject, tp)]
            when = f"at time point {tp!r}" if tp else "without a time point"
            raise ManifestError(
                f"{at}: subject {subject!r} already has a session {when} (session "
                f"{self.rows.records[j]['session']!r} {self.rows.ref(j)}); one "
                "session per subject and time point, or the statistics count one "
                "animal twice: give the sessions distinct time points (e.g. 'd7' and "
                "'d7b'), or leave one out"
            )
        self.cell[(subject, tp)] = i

    def check_contents(self) -> None:
        """Refuse two files with the same content (one recording copied)."""
        twins = _same_content(self.real_paths)
        if twins is not None:
            j, i = twins
            rows = self.rows
            raise ManifestError(
                f"{rows.where(i, rows.records[i]['session'])}: {rows.this_file(i)} "
                f"has the same content as {rows.other(j)}: one recording listed "
                "twice (a copy?)"
            )


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
    """Warn when two labels of a column differ by a letter or two.

    Warn when two labels of a column differ by a letter or two (``translaton`` next
    to ``translation``): likely a typo that would make a group or time point of its
    own. Only a warning: labels such as ``d1``/``d7`` are close on purpose; declaring
    the labels (``keyword``) makes an undeclared one an error.
    """
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
                    stacklevel=user_stacklevel(),
                )
