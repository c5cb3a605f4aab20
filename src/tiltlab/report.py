"""Your book on your data in one command: chosen chapters, executed on your recording or
cohort, rendered as HTML with the book's look.

:func:`run_report` executes chapters of the book (the ``NN_*.ipynb`` notebooks of a
tiltlab checkout) with papermill, handing the data source to the parameter of each
chapter that takes one, then assembles a small Jupyter Book (an index page and the
executed chapters, execution off, the book's configuration, style sheets, extension and
bibliography) and builds it with ``jupyter-book`` into the output folder. The index
page lists, per chapter, whether it ran, how long it took and what it skipped and why
(the lines the chapter printed that contain "skipped"); a chapter that fails shows its
error there and the others still run. ``tiltlab report`` is the command line.

Which parameter receives the source:

* a recording (a NetCDF Recording written by ``tiltlab convert`` or
  :func:`tiltlab.io.save_netcdf`, any other file :func:`tiltlab.datasets.load` reads,
  or a reference name such as ``broad:2``) goes to ``SOURCE`` (chapters 1, 2, 3, 5;
  chapter 6 also ``HEADING_SOURCE``, chapter 7 also ``HEAD_SOURCE``) and to
  ``RAT_SOURCE`` in chapter 4 (its ``SOURCE`` needs a ground truth);
* a cohort manifest (a CSV read by :func:`tiltlab.cohort.read_manifest`) goes to
  ``COHORT_MANIFEST`` (chapter 8). With a manifest, the recording chapters run only on
  a recording given as well (``recording=``, ``--recording``); otherwise they are
  listed as not run, with the reason, as chapter 8 is for a recording.

Chapters run with their own folder as the working directory, as in the book build.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Any, Literal

__all__ = [
    "ChapterResult",
    "ReportError",
    "ReportResult",
    "find_chapters",
    "parse_chapters",
    "run_report",
]

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
    """A report that cannot start (a bad source, chapter list, parameter, book folder
    or output folder) or whose pages cannot be rendered; the message says what to do."""


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
    return Path(__file__).resolve().parents[2] / "notebooks", "the tiltlab checkout"


def find_chapters(book_dir: str | os.PathLike | None = None) -> Path:
    """The folder of the book's chapters (``NN_*.ipynb``).

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
        raise ReportError(f"{given}: no such file")
    suffix = path.suffix.lower()
    if suffix in _MANIFEST_SUFFIXES or suffix == ".txt":
        from .cohort import read_manifest

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
        from . import io

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
    """The source parameters of one chapter, or why it does not run (a chapter whose
    source parameter the user gave, ``given``, runs with it)."""
    rec_names = _source_parameters(ch, RECORDING_PARAMETERS, _RECORDING_DEFAULT)
    man_names = _source_parameters(ch, MANIFEST_PARAMETERS, _MANIFEST_DEFAULT)
    if source.kind == "manifest":
        if man_names:
            return dict.fromkeys(man_names, source.value), None
        if rec_names and recording is not None:
            return dict.fromkeys(rec_names, recording.value), None
        if set(rec_names) & set(given):
            return {}, None
        if rec_names:
            return {}, (
                f"chapter {ch.number} analyses one recording and {source.label} is a "
                "cohort manifest: give one of its recordings as well (--recording FILE)"
            )
    elif rec_names:
        return dict.fromkeys(rec_names, source.value), None
    elif set(man_names) & set(given):
        return {}, None
    elif man_names:
        return {}, (
            f"chapter {ch.number} analyses a cohort and {source.label} is one "
            "recording: give a cohort manifest (.csv; 'tiltlab cohort init' writes one)"
        )
    return {}, f"chapter {ch.number} has no parameter for a recording or a manifest"


def _absolute_if_file(value: Any) -> Any:
    """A relative path to an existing file or folder, made absolute (chapters run in
    their own folder); any other value as it is."""
    if isinstance(value, str) and value and not os.path.isabs(value):
        with_path = Path(value).expanduser()
        try:
            if with_path.exists() and (os.sep in value or "." in value):
                return str(with_path.resolve())
        except OSError:
            return value
    return value


# --------------------------------------------------------------------- execution


def _skipped_lines(notebook: Path) -> list[str]:
    """Printed lines (stream outputs) containing "skipped", in order, without repeats."""
    try:
        nb = json.loads(notebook.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    lines: list[str] = []
    for cell in nb.get("cells", []):
        for output in (
            cell.get("outputs", []) if cell.get("cell_type") == "code" else []
        ):
            if output.get("output_type") != "stream":
                continue
            for line in "".join(output.get("text", "")).splitlines():
                line = _ANSI.sub("", line).strip()
                if "skipped" in line.lower() and line not in lines:
                    lines.append(line)
    return lines


def _execute(
    ch: _Chapter, params: dict[str, Any], notebook: Path, progress: bool
) -> tuple[Status, float, str | None]:
    import papermill as pm
    from papermill.exceptions import PapermillExecutionError

    bar: bool | dict[str, Any] = (
        {"desc": f"chapter {ch.number}", "unit": "cell", "leave": True}
        if progress
        else False
    )
    t0 = time.perf_counter()
    try:
        pm.execute_notebook(
            str(ch.path),
            str(notebook),
            parameters=params,
            cwd=str(ch.path.parent),
            progress_bar=bar,
            log_output=False,
        )
    except PapermillExecutionError as exc:
        lines = _ANSI.sub("", str(exc.evalue)).strip()
        where = f" (cell [{exc.exec_count}])" if exc.exec_count else ""
        error = f"{exc.ename}: {lines}" if lines else exc.ename
        return "failed", time.perf_counter() - t0, f"{error}{where}"
    except Exception as exc:  # no kernel, unreadable notebook ...: still a report
        text = " ".join(str(exc).split())
        return "failed", time.perf_counter() - t0, f"{type(exc).__name__}: {text}"
    return "ran", time.perf_counter() - t0, None


# --------------------------------------------------------------------- the index


def _escape(text: str) -> str:
    """Text shown literally in MyST Markdown (every ASCII punctuation escaped)."""
    return re.sub(r"([!-/:-@\[-`{-~])", r"\\\1", text)


def _duration(seconds: float | None) -> str:
    if seconds is None:
        return "–"
    if seconds < 90:
        return f"{seconds:.0f} s" if seconds >= 1 else f"{seconds:.1f} s"
    return f"{seconds / 60:.1f} min"


def _value(value: Any) -> str:
    text = (
        json.dumps(value, ensure_ascii=False) if not isinstance(value, str) else value
    )
    return text if len(text) <= 80 else text[:77] + "..."


def _index_markdown(
    result: ReportResult, source: _Source, recording: _Source | None, pages: bool
) -> str:
    from . import __version__

    def link(c: ChapterResult) -> str:
        label = f"{c.number}. {c.title}"
        if pages and c.notebook is not None and c.notebook.is_file():
            # a role's text is literal (no escapes): only its delimiters are dropped
            plain = re.sub(r"[`<>|]", "", label)
            return f"{{doc}}`{plain} <notebooks/{c.name}>`"
        return _escape(label)

    ran = sum(c.status == "ran" for c in result.chapters)
    failed = len(result.failed)
    not_run = sum(c.status == "not run" for c in result.chapters)
    kind = "cohort manifest" if source.kind == "manifest" else "recording"
    lines = [
        f"# Report on {_escape(source.label)}",
        "",
        f"Chapters of the tiltlab book executed on the {kind} "
        f"`{source.value}`"
        + (f" (and the recording `{recording.value}`)" if recording else "")
        + f", {datetime.now():%Y-%m-%d %H:%M}, tiltlab {__version__}: "
        f"{ran} ran, {failed} failed, {not_run} not run.",
        "",
        "| Chapter | Status | Time | Skipped |",
        "|---|---|---|---|",
    ]
    for c in result.chapters:
        status = {"ran": "ran", "failed": "**failed**", "not run": "not run"}[c.status]
        skipped = str(len(c.skipped)) if c.skipped else "–"
        lines.append(f"| {link(c)} | {status} | {_duration(c.seconds)} | {skipped} |")
    lines.append("")
    for c in result.chapters:
        lines += [f"## {_escape(f'{c.number}. {c.title}')}", ""]
        if c.status == "not run":
            lines += [f"Not run: {_escape(c.reason or '')}", ""]
            continue
        verb = "Ran in" if c.status == "ran" else "Failed after"
        lines.append(f"{verb} {_duration(c.seconds)}")
        if c.parameters:
            shown = ", ".join(
                f"`{k} = {_value(v)}`".replace("``", "` `")
                for k, v in c.parameters.items()
            )
            lines[-1] += f" with {shown}"
        lines[-1] += "."
        lines.append("")
        if c.status == "failed":
            fence = "`" * max(
                4,
                max((len(m) for m in re.findall("`+", c.reason or "")), default=0) + 1,
            )
            lines += ["Error:", "", f"{fence}text", c.reason or "", fence, ""]
            if pages and c.notebook is not None and c.notebook.is_file():
                lines += [
                    f"The {{doc}}`chapter's page <notebooks/{c.name}>` shows its "
                    "cells up to the failing one.",
                    "",
                ]
        if c.skipped:
            lines += ["Skipped:", ""] + [f"- {_escape(s)}" for s in c.skipped] + [""]
        elif c.status == "ran":
            lines += ["Nothing skipped.", ""]
    return "\n".join(lines)


def _summary_json(result: ReportResult) -> str:
    def chapter(c: ChapterResult) -> dict[str, Any]:
        return {
            "number": c.number,
            "name": c.name,
            "title": c.title,
            "status": c.status,
            "seconds": c.seconds,
            "parameters": c.parameters,
            "skipped": c.skipped,
            "reason": c.reason,
            "notebook": str(c.notebook) if c.notebook else None,
            "page": str(c.page) if c.page else None,
        }

    summary = {
        "source": result.source,
        "kind": result.kind,
        "index": str(result.index) if result.index else None,
        "chapters": [chapter(c) for c in result.chapters],
    }
    return json.dumps(summary, indent=2, default=str, ensure_ascii=False)


# --------------------------------------------------------------------- rendering


def _book_config_dir(chapters_dir: Path) -> Path | None:
    """The ``book/`` folder beside the chapters (its ``_config.yml``), if any."""
    for candidate in (chapters_dir.parent / "book", chapters_dir.parent):
        if (candidate / "_config.yml").is_file():
            return candidate
    return None


def _config(book: Path | None, title: str) -> dict[str, Any]:
    import yaml

    config: dict[str, Any] = {}
    if book is not None:
        config = yaml.safe_load((book / "_config.yml").read_text(encoding="utf-8"))
        config = config or {}
    config["title"] = title
    config["only_build_toc_files"] = True
    execute = dict(config.get("execute") or {})
    execute["execute_notebooks"] = "off"
    config["execute"] = execute
    sphinx = dict(config.get("sphinx") or {})
    options = dict(sphinx.get("config") or {})
    vendored = book is not None and any(
        (book / p).is_dir() for p in options.get("html_extra_path", [])
    )
    if not vendored:  # MathJax not vendored (make book): the theme's default
        options.pop("html_extra_path", None)
        options.pop("mathjax_path", None)
    options["suppress_warnings"] = sorted(
        {*options.get("suppress_warnings", []), "mystnb.unknown_mime_type"}
    )
    sphinx["config"] = options
    config["sphinx"] = sphinx
    return config


def _copy_book_files(
    book: Path | None, dest: Path, config: dict[str, Any]
) -> list[str]:
    """Copy what the configuration names (style, extension, bibliography, vendored
    MathJax) and the reference pages; return the pages copied."""
    if book is None:
        return []
    for name in ("_static", "_ext", "_templates"):
        if (book / name).is_dir():
            shutil.copytree(book / name, dest / name)
    for extra in config.get("sphinx", {}).get("config", {}).get("html_extra_path", []):
        if (book / extra).is_dir():
            shutil.copytree(book / extra, dest / extra)
    bibs = [b for b in config.get("bibtex_bibfiles", []) if (book / b).is_file()]
    for bib in bibs:
        (dest / bib).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(book / bib, dest / bib)
    config["bibtex_bibfiles"] = bibs
    if not bibs:
        config.pop("bibtex_bibfiles", None)
    pages = []
    for page in ("conventions", "bibliography"):
        if (book / f"{page}.md").is_file() and (page != "bibliography" or bibs):
            shutil.copy2(book / f"{page}.md", dest / f"{page}.md")
            pages.append(page)
    return pages


_DOC_ROLE = re.compile(r"\{doc\}`([^`<]*?)\s*(?:<([^`>]+)>)?`")


def _unlink(text: str, keep: set[str], titles: Mapping[str, str]) -> str:
    """``{doc}`` references to pages the report does not have (the chapters not run, a
    reference page not copied) as plain text: the label, or the chapter's title."""

    def replace(m: re.Match) -> str:
        label, target = m[1].strip(), (m[2] or m[1]).strip()
        name = target.rstrip("/").rsplit("/", 1)[-1].removesuffix(".ipynb")
        if name in keep:
            return m[0]
        if m[2] is None and name in titles:
            return titles[name]
        return label if m[2] is not None else name.replace("_", " ")

    return _DOC_ROLE.sub(replace, text)


def _page_copy(
    notebook: Path,
    number: int,
    dest: Path,
    keep: set[str],
    titles: Mapping[str, str],
) -> None:
    """The executed notebook as a page of the report: its number before its title (the
    report's pages are not numbered by position, as the book's are), and references to
    pages the report lacks as plain text."""
    nb = json.loads(notebook.read_text(encoding="utf-8"))
    numbered = False
    for cell in nb.get("cells", []):
        if cell.get("cell_type") != "markdown":
            continue
        text = _unlink("".join(cell.get("source", "")), keep, titles)
        m = None if numbered else re.search(r"^# (.+)$", text, flags=re.M)
        if m:
            text = text[: m.start(1)] + f"{number}. " + text[m.start(1) :]
            numbered = True
        cell["source"] = text
    dest.write_text(json.dumps(nb, ensure_ascii=False, indent=1), encoding="utf-8")


def _render(
    result: ReportResult,
    index_md: str,
    chapters_dir: Path,
    title: str,
    titles: Mapping[str, str],
    progress: bool,
) -> Path:
    import yaml

    out = result.out
    book = _book_config_dir(chapters_dir)
    pages = [
        c for c in result.chapters if c.notebook is not None and c.notebook.is_file()
    ]
    with tempfile.TemporaryDirectory(prefix="tiltlab-report-") as tmp:
        src = Path(tmp) / "book"
        (src / "notebooks").mkdir(parents=True)
        config = _config(book, title)
        reference = _copy_book_files(book, src, config)
        (src / "index.md").write_text(index_md, encoding="utf-8")
        for c in pages:
            _page_copy(
                c.notebook,
                c.number,
                src / "notebooks" / f"{c.name}.ipynb",
                keep={p.name for p in pages} | set(reference),
                titles=titles,
            )
        parts = []
        if pages:
            parts.append(
                {
                    "caption": "Chapters",
                    "chapters": [{"file": f"notebooks/{c.name}"} for c in pages],
                }
            )
        if reference:
            parts.append(
                {"caption": "Reference", "chapters": [{"file": p} for p in reference]}
            )
        toc: dict[str, Any] = {"format": "jb-book", "root": "index"}
        if parts:
            toc["parts"] = parts
        (src / "_config.yml").write_text(yaml.safe_dump(config, sort_keys=False))
        (src / "_toc.yml").write_text(yaml.safe_dump(toc, sort_keys=False))
        build = Path(tmp) / "build"
        command = [
            sys.executable,
            "-c",
            "import sys; from jupyter_book.cli.main import main; sys.exit(main())",
            "build",
            str(src),
            "--builder",
            "html",
            "--path-output",
            str(build),
        ]
        if progress:
            print(
                f"rendering {len(pages)} chapter page(s) with jupyter-book ...",
                file=sys.stderr,
                flush=True,
            )
        t0 = time.perf_counter()
        done = subprocess.run(
            command,
            capture_output=True,
            text=True,
            env={**os.environ, "PYTHONWARNINGS": "ignore"},
        )
        log = out / "render.log"
        log.write_text(done.stdout + "\n" + done.stderr, encoding="utf-8")
        html = build / "_build" / "html"
        if done.returncode != 0 or not (html / "index.html").is_file():
            tail = [
                ln for ln in (done.stderr or done.stdout).splitlines() if ln.strip()
            ]
            last = tail[-1] if tail else f"exit status {done.returncode}"
            raise ReportError(
                f"jupyter-book could not render the report ({last.strip()}); see {log} "
                f"(the executed notebooks are in {out / 'notebooks'})"
            )
        shutil.copytree(html, out, dirs_exist_ok=True)
        if progress:
            print(
                f"rendered in {time.perf_counter() - t0:.0f} s",
                file=sys.stderr,
                flush=True,
            )
    for c in pages:
        page = out / "notebooks" / f"{c.name}.html"
        c.page = page if page.is_file() else None
    return out / "index.html"


# --------------------------------------------------------------------- entry point


def _prepare_out(out: Path) -> None:
    if out.exists() and not out.is_dir():
        raise ReportError(f"--out {out} is a file; give a folder")
    if out.is_dir() and any(out.iterdir()):
        if not (out / _MARKER).is_file():
            raise ReportError(
                f"--out {out} is a folder that is not empty; give a new folder (a "
                "previous report's folder is replaced)"
            )
        shutil.rmtree(out)
    (out / "notebooks").mkdir(parents=True, exist_ok=True)


def run_report(
    source: str | os.PathLike,
    chapters: str | Iterable[int] | None,
    out: str | os.PathLike,
    *,
    params: Mapping[str, Any] | None = None,
    book_dir: str | os.PathLike | None = None,
    recording: str | os.PathLike | None = None,
    render: bool = True,
    progress: bool = True,
) -> ReportResult:
    """Execute chapters of the book on a recording or a cohort and render them as HTML.

    Each chosen chapter runs with papermill in its own folder, its data-source
    parameter set to ``source`` (see the module docstring for which parameter takes
    what), and the ``params`` it has. A chapter that does not take this kind of source
    is listed as not run, with the reason; a chapter that fails is listed with its error
    and the others still run. The executed notebooks are written to
    ``out/notebooks/``, the index page's source to ``out/index.md``, a summary to
    ``out/report.json`` and, with ``render``, the HTML pages to ``out/`` (open
    ``out/index.html``): a small Jupyter Book with the book's configuration, style
    sheets and bibliography, built without executing anything again.

    Parameters
    ----------
    source : str or path-like
        A recording (a NetCDF Recording such as ``tiltlab convert`` writes, a
        BROAD-layout ``.hdf5``/``.mat`` file, or a reference name such as
        ``"broad:2"``) or a cohort manifest (``.csv``, see
        :func:`tiltlab.cohort.read_manifest`).
    chapters : str, iterable of int or None
        Chapter numbers: ``"4,6,8"``, ``"6-8"``, ``[4, 6]``; None or ``"all"``: every
        chapter.
    out : str or path-like
        The output folder: new, empty, or a previous report's (which is replaced).
    params : mapping, optional
        Parameter values (``{"N_BOOT": 100}``) given to every chosen chapter whose
        ``parameters`` cell has that name; they override the source (a chapter given
        its source parameter this way runs whatever ``source`` is). A relative path to
        an existing file is made absolute. A name no chosen chapter has is an error.
    book_dir : str or path-like, optional
        The chapters' folder (see :func:`find_chapters`; default
        ``TILTLAB_BOOK_DIR``, else the checkout's ``notebooks/``).
    recording : str or path-like, optional
        With a manifest as ``source``: a recording for the chapters that analyse one.
    render : bool, default True
        Build the HTML pages (False: only execute, e.g. in tests).
    progress : bool, default True
        A progress bar per chapter (cells executed) and a line per chapter on stderr.

    Returns
    -------
    ReportResult
        Per chapter: status (``"ran"``, ``"failed"``, ``"not run"``), time, the
        "skipped" lines it printed, the reason or error; ``index`` is
        ``out/index.html`` when rendered.

    Raises
    ------
    ReportError
        Before anything runs: an unreadable source, an unknown chapter or parameter
        name, no chapters found, an output folder that is not empty; after: pages that
        cannot be rendered.

    Examples
    --------
    >>> from tiltlab.report import run_report
    >>> result = run_report(
    ...     "tag.nc", "6,8", "report/", params={"N_LATTICE": 2000, "N_BOOT": 100}
    ... )  # doctest: +SKIP
    >>> [(c.number, c.status, c.seconds) for c in result.chapters]  # doctest: +SKIP
    [(6, 'ran', 21.3), (8, 'not run', None)]
    >>> result.chapters[0].skipped  # doctest: +SKIP
    ['tag.nc has no reference orientation (q_ref): the heading and posture maps are
    skipped']
    >>> result.chapters[1].reason  # doctest: +SKIP
    'chapter 8 analyses a cohort and tag.nc is one recording: give a cohort manifest ...'
    >>> result.index  # doctest: +SKIP
    PosixPath('/home/me/report/index.html')
    """
    try:
        import papermill  # noqa: F401
    except ImportError:
        raise ReportError(
            "a report needs papermill and jupyter-book: pip install 'tiltlab[book]'"
        ) from None
    folder = find_chapters(book_dir)
    available = _chapters(folder)
    chosen = [available[n] for n in parse_chapters(chapters, available)]
    src = _classify(source)
    rec = None
    if recording is not None:
        if src.kind != "manifest":
            raise ReportError(
                "--recording goes with a cohort manifest; the source is a recording"
            )
        rec = _classify(recording, what="--recording")
    user = {k: _absolute_if_file(v) for k, v in (params or {}).items()}
    unknown = [k for k in user if not any(k in ch.parameters for ch in chosen)]
    if unknown:
        which = ", ".join(str(ch.number) for ch in chosen)
        raise ReportError(
            f"no chosen chapter ({which}) has a parameter {unknown[0]}; see the "
            "parameters cell at the top of each chapter"
        )
    out_dir = Path(out).expanduser().resolve()
    _prepare_out(out_dir)

    result = ReportResult(
        source=os.fspath(source), kind=src.kind, out=out_dir, chapters=[]
    )
    # the marker first: an interrupted report's folder is replaced by the next one
    (out_dir / _MARKER).write_text(_summary_json(result), encoding="utf-8")
    for ch in chosen:
        injected, why = _plan(ch, src, rec, user)
        if why is not None:
            if progress:
                print(f"chapter {ch.number} not run: {why}", file=sys.stderr)
            result.chapters.append(
                ChapterResult(ch.number, ch.name, ch.title, "not run", reason=why)
            )
            continue
        injected.update({k: v for k, v in user.items() if k in ch.parameters})
        notebook = out_dir / "notebooks" / f"{ch.name}.ipynb"
        if progress:
            print(
                f"chapter {ch.number} ({ch.name}) on {src.label}",
                file=sys.stderr,
                flush=True,
            )
        status, seconds, error = _execute(ch, injected, notebook, progress)
        chapter = ChapterResult(
            ch.number,
            ch.name,
            ch.title,
            status,
            seconds=seconds,
            parameters=injected,
            skipped=_skipped_lines(notebook),
            reason=error,
            notebook=notebook if notebook.is_file() else None,
        )
        result.chapters.append(chapter)
        if progress:
            note = (
                f"; {len(chapter.skipped)} skipped line(s)" if chapter.skipped else ""
            )
            what = "ran" if status == "ran" else f"FAILED ({error})"
            print(
                f"chapter {ch.number} {what} in {_duration(seconds)}{note}",
                file=sys.stderr,
                flush=True,
            )
    index_md = _index_markdown(result, src, rec, pages=render)
    (out_dir / "index.md").write_text(index_md, encoding="utf-8")
    (out_dir / _MARKER).write_text(_summary_json(result), encoding="utf-8")
    if render:
        titles = {ch.name: f"{ch.title} (chapter {n})" for n, ch in available.items()}
        result.index = _render(
            result, index_md, folder, f"tiltlab report: {src.label}", titles, progress
        )
        (out_dir / _MARKER).write_text(_summary_json(result), encoding="utf-8")
    return result
