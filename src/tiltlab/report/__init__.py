"""Run your book on your data in one command.

Your book on your data in one command: chosen chapters, executed on your recording or
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
  a recording given as well (``recording_path=``, ``--recording``); otherwise they are
  listed as not run, with the reason, as chapter 8 is for a recording.

Chapters run with their own folder as the working directory, as in the book build.
"""

from __future__ import annotations

import os
import shutil
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from .._deprecate import renamed
from ._plan import (
    ChapterResult,
    ReportError,
    ReportResult,
    _MARKER,
    _absolute_if_file,
    _chapters,
    _classify,
    _plan,
    find_chapters,
    parse_chapters,
)
from ._execute import (
    _execute,
    _skipped_lines,
)
from ._render import (
    _duration,
    _index_markdown,
    _render,
    _summary_json,
)

__all__ = [
    "ChapterResult",
    "ReportError",
    "ReportResult",
    "find_chapters",
    "parse_chapters",
    "run_report",
]


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


@renamed(recording="recording_path")
def run_report(
    source: str | os.PathLike,
    chapters: str | Iterable[int] | None,
    out: str | os.PathLike,
    *,
    params: Mapping[str, Any] | None = None,
    book_dir: str | os.PathLike | None = None,
    recording_path: str | os.PathLike | None = None,
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
    recording_path : str or path-like, optional
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
    if recording_path is not None:
        if src.kind != "manifest":
            raise ReportError(
                "--recording goes with a cohort manifest; the source is a recording"
            )
        rec = _classify(recording_path, what="--recording")
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
