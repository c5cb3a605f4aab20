"""``tiltlab report``: chapters executed on the user's data, listed on an index page and
rendered with the book's look. Fast tests run tiny fake chapters; one test renders."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

nbformat = pytest.importorskip("nbformat")
pytest.importorskip("papermill")

from tiltlab import cli, io, report, schema  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def _notebook(path: Path, title: str, parameters: str, *cells: str) -> None:
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {
        "name": "python3",
        "display_name": "Python 3",
        "language": "python",
    }
    params = nbformat.v4.new_code_cell(parameters)
    params.metadata["tags"] = ["parameters"]
    nb.cells = [
        nbformat.v4.new_markdown_cell(f"# {title}\n\nA fake chapter."),
        params,
        *(nbformat.v4.new_code_cell(c) for c in cells),
    ]
    nbformat.write(nb, path)


@pytest.fixture
def book(tmp_path) -> Path:
    """A checkout-like folder with three fake chapters in ``notebooks/``: one that
    prints a "skipped" line, one that fails, one that takes a cohort manifest."""
    folder = tmp_path / "repo" / "notebooks"
    folder.mkdir(parents=True)
    _notebook(
        folder / "01_fake_recording.ipynb",
        "A recording chapter",
        'SOURCE = "broad:2"\nN = 1\nHEADING = "x"',
        "import os\nprint('cwd', os.getcwd())\nprint('source', SOURCE)\nprint('n', N)",
        "print(f'{os.path.basename(SOURCE)} has no gyroscope: the rotations are "
        "skipped')\nprint('all done')",
    )
    _notebook(
        folder / "02_fake_failure.ipynb",
        "A failing chapter",
        'SOURCE = "broad:2"',
        "raise ValueError('the filter diverged')",
        "print('never')",
    )
    _notebook(
        folder / "08_fake_cohort.ipynb",
        "A cohort chapter",
        "COHORT_MANIFEST = None\nN = 1",
        "print('manifest', COHORT_MANIFEST)\nprint('n', N)",
    )
    return folder


@pytest.fixture
def recording(tmp_path) -> Path:
    rng = np.random.default_rng(0)
    rec = schema.make_recording(
        np.tile([0, 0, 1.0], (50, 1)) + rng.normal(0, 0.01, (50, 3)),
        None,
        25.0,
        acc_units="g",
    )
    return io.save_netcdf(rec, tmp_path / "tag.nc")


@pytest.fixture
def manifest(tmp_path, recording) -> Path:
    path = tmp_path / "manifest.csv"
    path.write_text(
        "session,subject,group,timepoint,file,reader,reader_options\n"
        "s1,r1,Healthy,baseline,tag.nc,netcdf,\n"
    )
    return path


def _printed(notebook: Path) -> str:
    nb = json.loads(notebook.read_text())
    return "".join(
        "".join(o.get("text", ""))
        for c in nb["cells"]
        if c["cell_type"] == "code"
        for o in c.get("outputs", [])
    )


def test_recording_report_runs_injects_collects_and_survives_failure(
    book, recording, tmp_path
):
    out = tmp_path / "out"
    result = report.run_report(
        recording,
        "1,2,8",
        out,
        params={"N": 3},
        book_dir=book,
        render=False,
        progress=False,
    )
    first, failing, cohort_ch = result.chapters
    # the recording reached SOURCE, -p reached N; the chapter ran in its own folder
    assert first.status == "ran" and first.seconds > 0
    assert first.parameters == {"SOURCE": str(recording.resolve()), "N": 3}
    text = _printed(first.notebook)
    assert f"cwd {book.resolve()}" in text
    assert f"source {recording.resolve()}" in text and "n 3" in text
    assert first.skipped == ["tag.nc has no gyroscope: the rotations are skipped"]
    # a failure is recorded with its error, the next chapter still considered
    assert failing.status == "failed"
    assert failing.reason.startswith("ValueError: the filter diverged")
    assert failing.notebook is not None and "never" not in _printed(failing.notebook)
    # a cohort chapter given a recording is not run, with the reason
    assert cohort_ch.status == "not run" and "cohort manifest" in cohort_ch.reason
    assert cohort_ch.notebook is None
    assert not result.ok and result.failed == [failing] and result.index is None
    # the index lists every chapter: status, time, skipped lines, the error
    index = (out / "index.md").read_text()
    assert "| 1\\. A recording chapter | ran |" in index
    assert "| 2\\. A failing chapter | **failed** |" in index
    assert "| 8\\. A cohort chapter | not run | – | – |" in index
    assert "rotations are skipped" in index and "the filter diverged" in index
    summary = json.loads((out / "report.json").read_text())
    assert [c["status"] for c in summary["chapters"]] == ["ran", "failed", "not run"]
    # a previous report's folder is replaced; any other non-empty folder is refused
    again = report.run_report(
        recording, [1], out, book_dir=book, render=False, progress=False
    )
    assert [c.number for c in again.chapters] == [1]
    assert not (out / "notebooks" / "02_fake_failure.ipynb").exists()
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    with pytest.raises(report.ReportError, match="not empty"):
        report.run_report(recording, [1], tmp_path / "mine", book_dir=book)


def test_manifest_goes_to_the_cohort_chapter_and_recording_on_request(
    book, manifest, recording, tmp_path
):
    result = report.run_report(
        manifest, "1,8", tmp_path / "a", book_dir=book, render=False, progress=False
    )
    rec_ch, cohort_ch = result.chapters
    assert rec_ch.status == "not run" and "--recording" in rec_ch.reason
    assert cohort_ch.status == "ran"
    assert cohort_ch.parameters == {"COHORT_MANIFEST": str(manifest.resolve())}
    assert f"manifest {manifest.resolve()}" in _printed(cohort_ch.notebook)
    both = report.run_report(
        manifest,
        "1,8",
        tmp_path / "b",
        book_dir=book,
        recording_path=recording,
        params={"N": 2},
        render=False,
        progress=False,
    )
    assert [c.status for c in both.chapters] == ["ran", "ran"]
    assert both.chapters[0].parameters == {"SOURCE": str(recording.resolve()), "N": 2}
    assert both.ok
    # a chapter whose source parameter is given with -p runs whatever SOURCE is
    given = report.run_report(
        manifest,
        "1",
        tmp_path / "c",
        book_dir=book,
        params={"SOURCE": "broad:3"},
        render=False,
        progress=False,
    )
    assert given.chapters[0].status == "ran"
    assert given.chapters[0].parameters == {"SOURCE": "broad:3"}


def test_errors_before_running(book, recording, tmp_path, monkeypatch):
    def run(source=recording, chapters="1", **kw):
        kw.setdefault("book_dir", book)
        return report.run_report(
            source, chapters, tmp_path / "o", render=False, progress=False, **kw
        )

    with pytest.raises(report.ReportError, match="no chapter 5: the book has"):
        run(chapters="1,5")
    with pytest.raises(report.ReportError, match="give chapter numbers"):
        run(chapters="one")
    with pytest.raises(report.ReportError, match="has a parameter N_BOOT"):
        run(params={"N_BOOT": 1})
    with pytest.raises(report.ReportError, match="no such file"):
        run(source=tmp_path / "missing.nc")
    with pytest.raises(report.ReportError, match="not a cohort manifest"):
        (tmp_path / "logger.csv").write_text("t,ax,ay,az\n0,0,0,1\n")
        run(source=tmp_path / "logger.csv")
    with pytest.raises(report.ReportError, match="goes with a cohort manifest"):
        run(recording_path=recording)
    with pytest.raises(report.ReportError, match="pass --book"):
        run(book_dir=tmp_path)
    monkeypatch.setenv("TILTLAB_BOOK_DIR", str(tmp_path / "nowhere"))
    with pytest.raises(report.ReportError, match="TILTLAB_BOOK_DIR"):
        run(book_dir=None)
    monkeypatch.setenv("TILTLAB_BOOK_DIR", str(book.parent))  # a checkout works too
    assert report.find_chapters() == book.resolve()
    assert not (tmp_path / "o").exists()  # nothing written before the checks pass
    assert report.parse_chapters("2, 6-8", range(1, 9)) == [2, 6, 7, 8]
    assert report.parse_chapters(None, [8, 1]) == [1, 8]


def test_cli_report(book, recording, tmp_path, capsys):
    args = ["report", str(recording), "--book", str(book), "--no-render"]
    status = cli.main(
        [*args, "--chapters", "1", "--out", str(tmp_path / "ok"), "-p", "N=[1, 2]"]
    )
    out = capsys.readouterr().out
    assert status == 0, out
    assert "01_fake_recording  ran in" in out and "1 skipped line(s)" in out
    assert "n [1, 2]" in _printed(tmp_path / "ok" / "notebooks/01_fake_recording.ipynb")
    status = cli.main(
        [*args, "--chapters", "1,2,8", "--out", str(tmp_path / "bad"), "--no-progress"]
    )
    out = capsys.readouterr().out
    assert status == 1
    assert "failed in" in out and "ValueError: the filter diverged" in out
    assert "not run: chapter 8 analyses a cohort" in out
    # user errors: one line, no traceback
    nowhere = ["--book", str(tmp_path / "nowhere"), "--out", str(tmp_path / "x")]
    status = cli.main(["report", str(recording), *nowhere])
    err = capsys.readouterr().err
    assert status == 1 and err.count("\n") == 1 and "pass --book PATH" in err
    status = cli.main([*args, "--out", str(tmp_path / "y"), "-p", "N"])
    assert status == 2 and "give NAME=VALUE" in capsys.readouterr().err
    status = cli.main([*args, "--out", str(tmp_path / "z"), "-p", "NOPE=1"])
    err = capsys.readouterr().err
    assert status == 1 and err.count("\n") == 1 and "parameter NOPE" in err


def test_rendered_report_looks_like_the_book(book, recording, tmp_path):
    """One small book: the index and the chapters' pages, with the book's theme,
    favicon and bibliography; a failed chapter's page shows its error."""
    pytest.importorskip("jupyter_book")
    config = book.parent / "book"
    config.mkdir()
    for name in ("_config.yml", "references.bib", "bibliography.md"):
        shutil.copy2(ROOT / "book" / name, config / name)
    for name in ("_static", "_ext"):
        shutil.copytree(ROOT / "book" / name, config / name)
    out = tmp_path / "html"
    result = report.run_report(recording, "1,2,8", out, book_dir=book, progress=False)
    assert result.index == out / "index.html" and result.index.is_file()
    index = result.index.read_text()
    assert "tiltlab report: tag.nc" in index  # the book's title bar, the report's title
    assert "rotations are skipped" in index and "the filter diverged" in index
    assert 'href="notebooks/01_fake_recording.html"' in index
    assert "sphinx-book-theme" in index or "book-theme" in index
    assert "favicon.svg" in index
    page = (out / "notebooks" / "01_fake_recording.html").read_text()
    assert "1. A recording chapter" in page and "all done" in page
    failed = (out / "notebooks" / "02_fake_failure.html").read_text()
    assert "the filter diverged" in failed
    assert result.chapters[0].page == out / "notebooks" / "01_fake_recording.html"
    assert result.chapters[2].page is None
    assert (out / "bibliography.html").is_file()
