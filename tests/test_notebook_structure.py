"""Every chapter follows one skeleton a reader can rely on (static checks, no execution).

Title, overview (a numbered list with one item per numbered section), prerequisites
table, a ``parameters`` cell whose every name is used later and which names a data
source, numbered sections 1…N, summary, 2–3 exercises with hidden worked solutions,
"what's next" and references cited only through ``{cite}`` keys that exist in the
book's bibliography. Notebooks are stored without outputs.
"""

import ast
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
BIB_KEYS = set(
    re.findall(r"^@\w+\{([^,]+),", (ROOT / "book" / "references.bib").read_text(), re.M)
)
# names a parameters cell may use for its data source
SOURCE_NAMES = re.compile(r"^(SOURCE|[A-Z_]*_SOURCE|COHORT_MANIFEST)$")
SOLUTION_TAGS = {"hide-cell", "hide-input", "hide-output", "dropdown-cell"}


def _cells(path: Path) -> list[dict]:
    return json.loads(path.read_text())["cells"]


def _src(cell: dict) -> str:
    return "".join(cell["source"])


def _headings(cells: list[dict], level: int) -> list[tuple[int, str]]:
    out = []
    for i, c in enumerate(cells):
        if c["cell_type"] != "markdown":
            continue
        in_fence = False
        for line in _src(c).splitlines():
            if line.lstrip().startswith(("```", ":::")):
                in_fence = not in_fence
            if not in_fence and re.match(rf"^{'#' * level} (?!#)", line):
                out.append((i, line[level + 1 :].strip()))
    return out


def test_chapters_are_contiguous():
    numbers = [int(p.name[:2]) for p in NOTEBOOKS]
    assert numbers == list(range(1, len(numbers) + 1)), numbers


@pytest.fixture(params=NOTEBOOKS, ids=lambda p: p.stem)
def chapter(request):
    return request.param, _cells(request.param)


def test_stored_without_outputs(chapter):
    path, cells = chapter
    for i, c in enumerate(cells):
        if c["cell_type"] == "code":
            assert not c.get("outputs") and c.get("execution_count") is None, (
                f"{path.name}: cell {i} is stored with outputs"
            )


def test_skeleton(chapter):
    path, cells = chapter
    h1 = _headings(cells, 1)
    assert len(h1) == 1 and h1[0][0] == 0, f"{path.name}: one title, in the first cell"
    h2 = [t for _, t in _headings(cells, 2)]
    for required in ("Overview", "Prerequisites", "Summary", "Exercises"):
        assert required in h2, f"{path.name}: no '## {required}' section"
    assert "What's next" in h2, f'{path.name}: no "## What\'s next" section'
    assert h2[-1] == "References", f"{path.name}: the last section is not References"
    # the prerequisites section holds a table
    i_pre = next(i for i, t in _headings(cells, 2) if t == "Prerequisites")
    pre_text = _src(cells[i_pre]).split("## Prerequisites", 1)[1]
    assert re.search(r"^\|.*\|\s*$\n^\|\s*:?-{3,}", pre_text, re.M), (
        f"{path.name}: the prerequisites section has no table"
    )
    # numbered sections 1…N between the front matter and the summary, matching the overview
    numbered = [int(m.group(1)) for t in h2 if (m := re.match(r"^(\d+)\. ", t))]
    assert numbered == list(range(1, len(numbered) + 1)) and numbered, (
        f"{path.name}: numbered sections {numbered}"
    )
    i_ov = next(i for i, t in _headings(cells, 2) if t == "Overview")
    ov_text = _src(cells[i_ov]).split("## Overview", 1)[1].split("\n## ", 1)[0]
    items = re.findall(r"^\d+\. ", ov_text, re.M)
    assert len(items) == len(numbered), (
        f"{path.name}: the overview lists {len(items)} steps for {len(numbered)} sections"
    )
    order = [t for t in h2 if not re.match(r"^\d+\. ", t)]
    tail = order[order.index("Summary") :]
    assert tail == ["Summary", "Exercises", "What's next", "References"], (
        f"{path.name}: closing sections in order {tail}"
    )


def _parameters_cell(cells):
    tagged = [
        i
        for i, c in enumerate(cells)
        if c["cell_type"] == "code" and "parameters" in c["metadata"].get("tags", [])
    ]
    assert len(tagged) == 1, f"{len(tagged)} cells tagged 'parameters'"
    return tagged[0]


def test_parameters_are_used_and_name_a_source(chapter):
    path, cells = chapter
    i = _parameters_cell(cells)
    names = _parameter_names(cells)
    assert names, f"{path.name}: the parameters cell declares nothing"
    assert any(SOURCE_NAMES.match(n) for n in names), (
        f"{path.name}: no data-source parameter (SOURCE, *_SOURCE or COHORT_MANIFEST) in {names}"
    )
    used = set()
    for c in cells[i + 1 :]:
        if c["cell_type"] != "code":
            continue
        src = "\n".join(
            line
            for line in _src(c).splitlines()
            if not line.lstrip().startswith(("%", "!"))
        )
        used |= {
            n.id
            for n in ast.walk(ast.parse(src))
            if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)
        }
    unused = [n for n in names if n not in used]
    assert not unused, f"{path.name}: parameters never read: {unused}"


def test_exercises_have_hidden_solutions(chapter):
    path, cells = chapter
    i_ex = next(i for i, t in _headings(cells, 2) if t == "Exercises")
    i_next = next(i for i, t in _headings(cells, 2) if t == "What's next")
    text = _src(cells[i_ex]).split("## Exercises", 1)[1]
    exercises = re.findall(r"^\d+\. ", text, re.M)
    assert 2 <= len(exercises) <= 4, f"{path.name}: {len(exercises)} exercises"
    solutions = [
        c
        for c in cells[i_ex : i_next + 1]
        if c["cell_type"] == "code"
        and SOLUTION_TAGS & set(c["metadata"].get("tags", []))
        and _src(c).strip()
    ]
    assert len(solutions) >= len(exercises), (
        f"{path.name}: {len(exercises)} exercises but {len(solutions)} hidden solution cells"
    )


def test_references_are_cite_keys_in_the_bibliography(chapter):
    path, cells = chapter
    md = "\n".join(_src(c) for c in cells if c["cell_type"] == "markdown")
    keys = {
        k.strip()
        for group in re.findall(r"\{cite(?::\w+)?\}`([^`]+)`", md)
        for k in group.split(",")
    }
    assert keys, f"{path.name}: cites nothing"
    missing = sorted(keys - BIB_KEYS)
    assert not missing, f"{path.name}: cited but not in references.bib: {missing}"
    # no hand-made reference lists or numeric citations
    hand = re.findall(r"(?<![\w\]])\[\d{1,2}(?:[,–-]\s*\d{1,2})*\](?![(:])", md)
    assert not hand, f"{path.name}: numeric citations {hand[:5]}; use {{cite}}"
    # the references section only points at cited keys
    refs = _src(
        cells[next(i for i, t in _headings(cells, 2) if t == "References")]
    ).split("## References", 1)[1]
    assert "{cite" in refs or "{bibliography" in refs, (
        f"{path.name}: the references section does not use the bibliography"
    )


def _parameter_names(cells: list[dict]) -> list[str]:
    tree = ast.parse(_src(cells[_parameters_cell(cells)]))
    return [
        t.id
        for node in tree.body
        if isinstance(node, (ast.Assign, ast.AnnAssign))
        for t in (node.targets if isinstance(node, ast.Assign) else [node.target])
        if isinstance(t, ast.Name)
    ]


def test_intro_lists_every_chapters_parameters():
    """The introduction's table names exactly the parameters each chapter declares."""
    intro = (ROOT / "book" / "intro.md").read_text()
    rows = {
        int(m.group(1)): m.group(2)
        for m in re.finditer(r"^\|\s*(\d+)\s*\|(.*)\|\s*$", intro, re.M)
    }
    assert sorted(rows) == list(range(1, len(NOTEBOOKS) + 1)), (
        f"the introduction's parameter table has rows {sorted(rows)}"
    )
    for path in NOTEBOOKS:
        listed = set(re.findall(r"`([A-Z][A-Z0-9_]*)`", rows[int(path.name[:2])]))
        declared = set(_parameter_names(_cells(path)))
        assert listed == declared, (
            f"{path.name}: the introduction lists {sorted(listed)}, "
            f"the chapter declares {sorted(declared)}"
        )


def test_chapters_narrate_and_the_package_computes(chapter):
    """No function is defined in a chapter outside the worked solutions: analysis
    helpers live in the package, with tests."""
    path, cells = chapter
    defined = [
        node.name
        for c in cells
        if c["cell_type"] == "code" and not _src(c).lstrip().startswith("# Solution")
        for node in ast.walk(
            ast.parse(
                "\n".join(
                    line
                    for line in _src(c).splitlines()
                    if not line.lstrip().startswith(("%", "!"))
                )
            )
        )
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
    ]
    assert not defined, f"{path.name}: functions defined in the chapter: {defined}"


def test_chapters_read_in_short_cells(chapter):
    """Each code cell does one thing: at most 25 lines, about 12 on average."""
    path, cells = chapter
    sizes = [
        len(_src(c).strip().splitlines()) for c in cells if c["cell_type"] == "code"
    ]
    long = [(i, n) for i, n in enumerate(sizes) if n > 25]
    assert not long, f"{path.name}: code cells over 25 lines (index, lines): {long}"
    mean = sum(sizes) / len(sizes)
    assert mean <= 12, f"{path.name}: {mean:.1f} lines per code cell on average"
