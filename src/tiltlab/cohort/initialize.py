r"""Writing a cohort manifest from the files of a folder.

:func:`init_manifest` finds the files of a folder whose relative paths match a
pattern such as ``"{group}/{subject}_{timepoint}.nc"`` (:data:`PATTERN_HELP` states
its grammar) or an explicit regular expression with named groups, reads the session,
subject, group, time point and covariates from each path (``nested_subjects`` names
subjects whose ids restart in each group ``<group>-<subject>``), chooses each file's
reader from its content unless one is given, and validates the table as
:func:`~tiltlab.cohort.read_manifest` does, naming the file rather than a line.

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
"""

from __future__ import annotations

import functools
import json
import re
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import pandas as pd

from .._stack import user_stacklevel
from .. import io as _io
from .manifest import _RESTART_INIT, Manifest, StudyLabels, _check_table, _portable
from .sessions import READERS, session_path

__all__ = ["PATTERN_HELP", "StudyLabels", "init_manifest"]


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
    """Compile a pattern (:data:`PATTERN_HELP`) to a regex; list its fields.

    Each field becomes a greedy ``[^/]+`` (a field named again, a back-reference).
    """
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
    """Compile a user's regular expression and list its named groups (the fields)."""
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
    """Tell whether an HDF5 file has the variables of a BROAD trial.

    True for an HDF5 file with the variables of a BROAD trial (which
    :func:`tiltlab.io.detect` may describe as a NetCDF-4 file, h5netcdf opening any
    HDF5 file).
    """
    import h5py

    from ..io.broad import _BROAD_VARS

    try:
        with h5py.File(path, "r") as f:
            names = set(map(str, f.keys()))
    except OSError:
        return False
    return all(k in names for k in _BROAD_VARS)


def _reader_from_content(path: Path, label: str) -> str:
    """Choose the reader of a file from its content (:func:`tiltlab.io.detect`).

    The reader of a file, chosen from its content (:func:`tiltlab.io.detect`);
    a file of another kind is refused, listing the readers to choose from.
    """
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


def _old_label_keywords(func):
    """Accept ``groups=`` and ``timepoints=`` (now ``declared=``), with a warning."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        old = {k: kwargs.pop(k) for k in ("groups", "timepoints") if k in kwargs}
        if old:
            if kwargs.get("declared") is not None:
                raise TypeError(
                    f"{func.__name__}: pass declared= only (groups= and timepoints= "
                    "are its old form)"
                )
            warnings.warn(
                f"{func.__name__}: {' and '.join(f'{k}=' for k in old)} moved into "
                "declared=StudyLabels(groups=..., timepoints=...); the old keywords go "
                "in the next release",
                FutureWarning,
                stacklevel=user_stacklevel(),
            )
            kwargs["declared"] = StudyLabels(**old)
        return func(*args, **kwargs)

    return wrapper


@_old_label_keywords
def init_manifest(
    folder,
    pattern: str | None = None,
    *,
    regex: str | re.Pattern | None = None,
    reader: str | None = None,
    group: str | Mapping[str, str] | None = None,
    nested_subjects: bool = False,
    declared: StudyLabels | None = None,
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
        Reader of every file (see :data:`~tiltlab.cohort.READERS`). Default: chosen for each file from
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
    declared : StudyLabels, optional
        The study's declared groups and time points; a file whose group or time point
        is not declared (a typo) is refused, as by
        :func:`~tiltlab.cohort.read_manifest`. The keywords ``groups=`` and
        ``timepoints=`` of earlier releases still work, with a ``FutureWarning``.
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
        Validated as :func:`~tiltlab.cohort.read_manifest` would; ``file`` and ``calibration`` relative
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
        What :func:`~tiltlab.cohort.read_manifest` rejects (a subject in two groups, a session id or a
        subject and time point twice, one recording twice, an undeclared group or time
        point …), naming the file, as the manifest is not written yet.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from tiltlab import cohort
    >>> folder = Path(tempfile.mkdtemp())
    >>> for name in ["A/rat1_d0.nc", "A/rat1_d7.nc", "B/rat2_d0.nc"]:
    ...     (folder / name).parent.mkdir(exist_ok=True)
    ...     _ = (folder / name).write_text(name)  # stands for a recording
    >>> m = cohort.init_manifest(
    ...     folder,
    ...     "{group}/{subject}_{timepoint}.nc",
    ...     reader="netcdf",
    ...     declared=cohort.StudyLabels(groups="A,B", timepoints="d0,d7"),
    ... )
    >>> m.sessions
    ['rat1_d0', 'rat1_d7', 'rat2_d0']
    >>> m.table[["subject", "group", "timepoint", "file"]].values.tolist()[0]
    ['rat1', 'A', 'd0', 'A/rat1_d0.nc']
    """
    folder = Path(folder).resolve()
    if not folder.is_dir():
        raise FileNotFoundError(f"{folder}: no such folder")
    if reader is not None and reader not in READERS:
        raise ValueError(f"unknown reader {reader!r}; known: {sorted(READERS)}")
    layout = _layout(pattern, regex, group)
    rows = _Rows(
        folder=folder,
        layout=layout,
        reader=reader,
        group=group,
        nested_subjects=nested_subjects,
        reader_options=json.dumps(dict(reader_options or {}), sort_keys=True),
        calibration=calibration,
    )
    found = [r for p in sorted(folder.rglob("*")) if (r := rows.row(p)) is not None]
    if not found:
        raise ValueError(f"no file under {folder} matches {layout.shown}")
    return _written(found, folder, declared or StudyLabels(), out)


class _Layout(NamedTuple):
    """A pattern or regex compiled, its fields and how messages show it."""

    compiled: re.Pattern
    fields: list[str]
    shown: str


def _layout(pattern, regex, group) -> _Layout:
    """Compile the pattern or the regex (exactly one given) and check its fields."""
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
    return _Layout(compiled, fields, shown)


@dataclass(frozen=True)
class _Rows:
    """The options of :func:`init_manifest` that make a file's row."""

    folder: Path
    layout: _Layout
    reader: str | None
    group: str | Mapping[str, str] | None
    nested_subjects: bool
    reader_options: str  # JSON
    calibration: str | Mapping[str, str] | None

    def row(self, p: Path) -> tuple[dict[str, str], str] | None:
        """Make the row of a file and its label (None if the file does not match)."""
        if not p.is_file():
            return None
        rel = p.relative_to(self.folder).as_posix()
        m = self.layout.compiled.fullmatch(rel)
        if m is None:
            return None
        label = f"file {rel!r}"
        f = {k: ("" if v is None else str(v)) for k, v in m.groupdict().items()}
        found = f.get("subject") or f.get("session", "")
        tp = f.get("timepoint", "")
        grp = self._group(f, found, label)
        subject = f"{grp}-{found}" if self.nested_subjects else found
        session = f.get("session", "")
        if session and self.nested_subjects:
            session = f"{grp}-{session}"
        session = session or (f"{subject}_{tp}" if tp else subject)
        cal = self._calibration(f, found, subject, grp)
        row = {
            "session": session,
            "subject": subject,
            "group": grp,
            "timepoint": tp,
            "file": str(p),
            "reader": self.reader or _reader_from_content(p, label),
            "reader_options": self.reader_options,
            "calibration": str(session_path(cal, self.folder)) if cal else "",
        }
        row.update({k: v for k, v in f.items() if k not in row})
        return row, label

    def _group(self, f: dict[str, str], found: str, label: str) -> str:
        """Find the group of a file: its field, else the mapping or the one name."""
        if "group" in f:
            return f["group"]
        if isinstance(self.group, Mapping):
            if found not in self.group:
                raise ValueError(
                    f"{label}: the group mapping has no entry for subject {found!r}"
                )
            return str(self.group[found])
        return str(self.group)

    def _calibration(self, f: dict[str, str], found: str, subject: str, grp: str):
        """Find the subject's tumble-test path as given (``""`` when none)."""
        cal = self.calibration
        if isinstance(cal, Mapping):
            return str(cal.get(subject, cal.get(found, "")))
        if cal is None:
            return ""
        try:
            return str(cal).format(**{**f, "subject": found, "group": grp})
        except (KeyError, IndexError) as exc:
            raise ValueError(
                f"calibration pattern {cal!r} names {exc}, which is not a "
                f"field of the pattern ({', '.join(self.layout.fields)})"
            ) from None


def _written(found, folder: Path, declared: StudyLabels, out) -> Manifest:
    """Validate the rows found as a manifest, and write it to ``out`` if given."""
    rows = [r for r, _ in found]
    labels = [label for _, label in found]
    df = pd.DataFrame(rows)
    base = Path(out).resolve().parent if out is not None else folder
    for c in ("file", "calibration"):
        df[c] = [_portable(v, base) if v else "" for v in df[c]]
    name = Path(out).name if out is not None else "manifest"
    table = _check_table(
        df.astype(str),
        base,
        name,
        declared.groups,
        timepoints=declared.timepoints,
        labels=labels,
        restart_hint=_RESTART_INIT,
    )
    manifest = Manifest(table=table, root=base, path=None)
    if out is not None:
        out = manifest.to_csv(Path(out).resolve())
        manifest = Manifest(table=table, root=base, path=out)
    return manifest
