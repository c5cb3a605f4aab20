"""Build the report's pages with jupyter-book.

The report's pages: an index, the executed chapters and the book's look, built with
jupyter-book.
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
from collections.abc import Mapping
from datetime import datetime
from pathlib import Path
from typing import Any

from ._plan import (
    ChapterResult,
    ReportError,
    ReportResult,
    _Source,
)


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
    from .. import __version__

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
    """Find the ``book/`` folder beside the chapters (its ``_config.yml``), if any."""
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
    """Copy what the configuration names and the reference pages.

    Copy what the configuration names (style, extension, bibliography, vendored
    MathJax) and the reference pages; return the pages copied.
    """
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
    """Render references to pages the report does not have as plain text.

    ``{doc}`` references to pages the report does not have (the chapters not run, a
    reference page not copied) as plain text: the label, or the chapter's title.
    """

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
    """Turn an executed notebook into a page of the report.

    The executed notebook as a page of the report: its number before its title (the
    report's pages are not numbered by position, as the book's are), and references to
    pages the report lacks as plain text.
    """
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
