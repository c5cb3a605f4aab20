"""Plan a report: the chapters, the source's kind and the parameter that gets it.

What a report runs: the book's chapters, the source's kind, and which parameter
of each chapter receives it; the records of what ran.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal


#: File names of the book's chapters in their folder.
CHAPTER_GLOB = "[0-9][0-9]_*.ipynb"

#: Parameters that receive a recording, per chapter number (those a chapter lacks are
#: left out; a chapter not listed gets ``SOURCE`` if it has one).
RECORDING_PARAMETERS: dict[int, tuple[str, ...]] = {
    1: ("SOURCE",),
    2: ("SOURCE",),
    3: ("SOURCE",),
    4: ("RAT_SOURCE",),
    5: ("SOURCE",),
    6: ("SOURCE", "HEADING_SOURCE"),
    7: ("SOURCE", "HEAD_SOURCE"),
}
#: Parameters that receive a cohort manifest (a chapter not listed: ``COHORT_MANIFEST``).
MANIFEST_PARAMETERS: dict[int, tuple[str, ...]] = {8: ("COHORT_MANIFEST",)}
_RECORDING_DEFAULT = ("SOURCE",)
_MANIFEST_DEFAULT = ("COHORT_MANIFEST",)

#: Reference recordings a chapter can also be given by name.
_REFERENCE = re.compile(r"^(broad:\w+|fayat:example|fayat:tumble)$")
_RECORDING_SUFFIXES = (".nc", ".netcdf", ".nc4", ".cdf", ".hdf5", ".h5", ".mat")
_MANIFEST_SUFFIXES = (".csv", ".tsv")
#: A file in the output folder that marks it as a report (which a new one may replace).
_MARKER = "report.json"
_ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")

Status = Literal["ran", "failed", "not run"]


class ReportError(ValueError):
    """Signal a report that cannot start or whose pages cannot be rendered.

    A report that cannot start (a bad source, chapter list, parameter, book folder
    or output folder) or whose pages cannot be rendered; the message says what to do.
    """


@dataclass
class ChapterResult:
    """What happened to one chapter of a report.

    Attributes
    ----------
    number : int
        The chapter's number (from its file name, ``06_...`` → 6).
    name : str
        Its file name without ``.ipynb``.
    title : str
        Its title (the first heading).
    status : {"ran", "failed", "not run"}
        ``"not run"``: the chapter does not take this kind of source (``reason``).
    seconds : float or None
        Execution time (None when not run).
    parameters : dict
        The parameters injected (the source and the ``params`` that apply).
    skipped : list of str
        The lines the chapter printed that contain "skipped", in order.
    reason : str or None
        Why it did not run, or its error (``"ValueError: ..."``) when it failed.
    notebook : Path or None
        The executed notebook (for a failed chapter, up to the failing cell).
    page : Path or None
        Its HTML page, once rendered.
    """

    number: int
    name: str
    title: str
    status: Status
    seconds: float | None = None
    parameters: dict[str, Any] = field(default_factory=dict)
    skipped: list[str] = field(default_factory=list)
    reason: str | None = None
    notebook: Path | None = None
    page: Path | None = None


@dataclass
class ReportResult:
    """The outcome of :func:`run_report`.

    Attributes
    ----------
    source : str
        The source as given.
    kind : {"recording", "manifest"}
        What the source is.
    out : Path
        The output folder.
    chapters : list of ChapterResult
        One per chosen chapter, in order.
    index : Path or None
        ``out/index.html`` when rendered, else None (``out/index.md`` is always written).
    """

    source: str
    kind: str
    out: Path
    chapters: list[ChapterResult]
    index: Path | None = None

    @property
    def failed(self) -> list[ChapterResult]:
        """The chapters that failed."""
        return [c for c in self.chapters if c.status == "failed"]

    @property
    def ok(self) -> bool:
        """True when no chapter failed."""
        return not self.failed


@dataclass(frozen=True)
class _Chapter:
    number: int
    path: Path
    title: str
    parameters: dict[str, Any]  # papermill.inspect_notebook: name -> description

    @property
    def name(self) -> str:
        return self.path.stem


@dataclass(frozen=True)
class _Source:
    kind: Literal["recording", "manifest"]
    value: str  # absolute path, or a reference name
    given: str

    @property
    def label(self) -> str:
        """The file's name (a manifest's with its folder), or the reference name."""
        path = Path(self.value)
        if not path.is_absolute():
            return self.value
        if self.kind == "manifest" and path.parent.name:
            return f"{path.parent.name}/{path.name}"
        return path.name


# --------------------------------------------------------------------- chapters


def _default_book_dir() -> tuple[Path, str]:
    env = os.environ.get("TILTLAB_BOOK_DIR", "")
    if env:
        return Path(env), "TILTLAB_BOOK_DIR"
    return Path(__file__).resolve().parents[3] / "notebooks", "the tiltlab checkout"


def find_chapters(book_dir: str | os.PathLike | None = None) -> Path:
    """Find the folder of the book's chapters (``NN_*.ipynb``).

    Parameters
    ----------
    book_dir : path-like, optional
        The chapters' folder, or a folder with a ``notebooks/`` subfolder holding them
        (a checkout, or its ``book/``). Default: the environment variable
        ``TILTLAB_BOOK_DIR``, else the ``notebooks/`` folder of the checkout that this
        package was installed from (an editable install).

    Returns
    -------
    Path
        The resolved folder.

    Raises
    ------
    ReportError
        If no chapters are there, saying what to pass.
    """
    if book_dir is None:
        where, origin = _default_book_dir()
    else:
        where, origin = Path(book_dir), "--book"
    for folder in (where, where / "notebooks"):
        if folder.is_dir() and any(folder.glob(CHAPTER_GLOB)):
            return folder.resolve()
    raise ReportError(
        f"no chapters (NN_*.ipynb) in {where} ({origin}): pass --book PATH, the "
        "notebooks/ folder of a tiltlab checkout (git clone the repository), or set "
        "TILTLAB_BOOK_DIR to it"
    )


def _title(path: Path) -> str:
    nb = json.loads(path.read_text(encoding="utf-8"))
    for cell in nb.get("cells", []):
        if cell.get("cell_type") != "markdown":
            continue
        for line in "".join(cell.get("source", "")).splitlines():
            if line.startswith("# "):
                return line[2:].strip()
    return path.stem


def _chapters(folder: Path) -> dict[int, _Chapter]:
    import papermill as pm

    out = {}
    for path in sorted(folder.glob(CHAPTER_GLOB)):
        number = int(path.name[:2])
        if number in out:
            raise ReportError(
                f"{folder} has two chapters numbered {number}: "
                f"{out[number].path.name}, {path.name}"
            )
        out[number] = _Chapter(
            number, path, _title(path), dict(pm.inspect_notebook(str(path)))
        )
    return out


def parse_chapters(
    spec: str | Iterable[int] | None, available: Iterable[int]
) -> list[int]:
    """Chapter numbers from ``"4,6,8"``, ``"4-6"``, ``"all"`` or numbers.

    Parameters
    ----------
    spec : str, iterable of int or None
        The choice; None or ``"all"``: every available chapter.
    available : iterable of int
        The numbers of the chapters present.

    Returns
    -------
    list of int
        Sorted, without duplicates.

    Raises
    ------
    ReportError
        On a malformed list or a chapter that is not there.

    Examples
    --------
    >>> parse_chapters("4, 6-8", range(1, 9))
    [4, 6, 7, 8]
    """
    have = sorted(set(available))
    if spec is None or (isinstance(spec, str) and spec.strip().lower() == "all"):
        return have
    numbers: set[int] = set()
    if isinstance(spec, str):
        for part in (p.strip() for p in spec.split(",")):
            m = re.fullmatch(r"(\d+)(?:\s*-\s*(\d+))?", part)
            if not m:
                raise ReportError(
                    f"--chapters {spec!r}: give chapter numbers such as 4,6,8 or 6-8"
                )
            lo, hi = int(m[1]), int(m[2] or m[1])
            if hi < lo:
                raise ReportError(f"--chapters {spec!r}: range {part} is empty")
            numbers.update(range(lo, hi + 1))
    else:
        numbers = {int(n) for n in spec}
    missing = sorted(numbers - set(have))
    if missing:
        raise ReportError(
            f"no chapter {', '.join(map(str, missing))}: the book has chapters "
            f"{', '.join(map(str, have))}"
        )
    if not numbers:
        raise ReportError("no chapters chosen")
    return sorted(numbers)


# --------------------------------------------------------------------- sources


def _classify(source: str | os.PathLike, what: str = "source") -> _Source:
    given = os.fspath(source)
    if _REFERENCE.match(given):
        return _Source("recording", given, given)
    path = Path(given).expanduser()
    if path.is_dir():
        raise ReportError(
            f"{given} is a folder: give a recording (.nc) or a cohort manifest (.csv); "
            f"'tiltlab cohort init {given} --pattern ...' writes a manifest"
        )
    if not path.is_file():
        what = "is a directory, not a file" if path.is_dir() else "no such file"
        raise ReportError(f"{given}: {what}")
    suffix = path.suffix.lower()
    if suffix in _MANIFEST_SUFFIXES or suffix == ".txt":
        from ..cohort import read_manifest

        try:
            read_manifest(path)
        except ValueError as exc:
            raise ReportError(
                f"{given} is not a cohort manifest ({exc}); a logger's CSV must be "
                f"converted first: tiltlab convert {given} --mapping mapping.json "
                "--out session.nc"
            ) from None
        if what != "source":
            raise ReportError(f"{what} {given} is a cohort manifest, not a recording")
        return _Source("manifest", str(path.resolve()), given)
    if suffix not in _RECORDING_SUFFIXES:
        from .. import io

        try:
            looks = f" (it looks like: {io.detect(path)})"
        except OSError:
            looks = ""
        raise ReportError(
            f"{given}{looks}: the chapters read a Recording (.nc), a BROAD-layout "
            f".hdf5/.mat file or a cohort manifest (.csv); convert it first: "
            f"tiltlab convert {given} --out session.nc"
        )
    return _Source("recording", str(path.resolve()), given)


def _source_parameters(
    ch: _Chapter, table: Mapping[int, tuple[str, ...]], default: tuple[str, ...]
) -> list[str]:
    names = [n for n in table.get(ch.number, default) if n in ch.parameters]
    return names or [n for n in default if n in ch.parameters]


def _plan(
    ch: _Chapter, source: _Source, recording: _Source | None, given: Iterable[str]
) -> tuple[dict[str, Any], str | None]:
    """Find the source parameters of one chapter, or why it does not run.

    The source parameters of one chapter, or why it does not run (a chapter whose
    source parameter the user gave, ``given``, runs with it).
    """
    rec_names = _source_parameters(ch, RECORDING_PARAMETERS, _RECORDING_DEFAULT)
    man_names = _source_parameters(ch, MANIFEST_PARAMETERS, _MANIFEST_DEFAULT)
    if source.kind == "manifest":
        if man_names:
            return dict.fromkeys(man_names, source.value), None
        if rec_names and recording is not None:
            return dict.fromkeys(rec_names, recording.value), None
        wanted, why = (
            rec_names,
            (
                f"chapter {ch.number} analyses one recording and {source.label} is a "
                "cohort manifest: give one of its recordings as well (--recording FILE)"
            ),
        )
    elif rec_names:
        return dict.fromkeys(rec_names, source.value), None
    else:
        wanted, why = (
            man_names,
            (
                f"chapter {ch.number} analyses a cohort and {source.label} is one "
                "recording: give a cohort manifest (.csv; 'tiltlab cohort init' writes one)"
            ),
        )
    if wanted:  # the chapter runs when the user gave its source parameter
        return {}, None if set(wanted) & set(given) else why
    return {}, f"chapter {ch.number} has no parameter for a recording or a manifest"


def _absolute_if_file(value: Any) -> Any:
    """Make a relative path to an existing file or folder absolute.

    A relative path to an existing file or folder, made absolute (chapters run in
    their own folder); any other value as it is.
    """
    if isinstance(value, str) and value and not os.path.isabs(value):
        with_path = Path(value).expanduser()
        try:
            if with_path.exists() and (os.sep in value or "." in value):
                return str(with_path.resolve())
        except OSError:
            return value
    return value
