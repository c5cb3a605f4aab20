"""No chapter types a data-dependent number in its prose.

Every number a chapter's markdown states about its data comes from the computation: a
MyST-NB ``{glue:text}`` role or a sentence the chapter prints. This test scans the markdown
cells of the stored chapters (and the introduction) for digits that are left once the
places where a typed number is legitimate are removed:

* equations (``$…$``, ``$$…$$``, ``{math}`` roles and blocks) and code (inline and fenced);
* glue roles, citations, cross-references and link targets;
* sentences and table rows that carry a citation (published numbers, typed with it);
* names of paper items and book items (``Fig. 3e``, ``Table A5``, ``Eq. 2``, ``§4.2``,
  ``chapter 4``, ``Exercise 2``), heading and list numbering;
* digits inside identifiers (``HDF5``, ``float64``, ``9D``, ``A5``);
* the short, explicit allow-list below: facts that no data can change.

What remains is a number a rerun on other data could contradict; the test names it with
its context.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
CHAPTERS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
PAGES = [ROOT / "book" / "intro.md"]

# Facts no data can change, written as the exact phrase the prose uses.
ALLOW = {
    "g = 9.81",  # standard gravity, a definition
    "24 h",  # a day
    "360°",  # a full turn
    "180°",  # half a turn
    "90°",  # a right angle
    "1 Hz",  # the error budget's defined cut-off (a parameter named in the text)
}

_MATH_BLOCK = re.compile(r"\$\$.*?\$\$|```\{math\}.*?```|:::\{math\}.*?:::", re.S)
_FENCE = re.compile(r"```.*?```|~~~.*?~~~", re.S)
_INLINE_MATH = re.compile(r"(?<!\\)\$[^$\n]+?(?<!\\)\$")
_ROLE = re.compile(r"\{[a-z:\-]+\}`[^`]*`")
_CODE = re.compile(r"`[^`\n]*`")
_LINK_TARGET = re.compile(r"\]\([^)]*\)|^\[[^\]]+\]:.*$", re.M)
_COMMENT = re.compile(r"<!--.*?-->|^%.*$", re.S | re.M)
_DIRECTIVE_OPTION = re.compile(r"^:[a-z\-]+:.*$", re.M)
_ITEM = re.compile(
    r"(?:\b(?:Figs?|Figures?|Tables?|Tab|Eqs?|Equations?|Sections?|Chapters?|chapters?"
    r"|Exercises?|exercises?|Solutions?|solution|Steps?|steps?|Appendix|Algorithm"
    r"|Part|part|item|Items?|Panels?|panels?|rows?|Rows?|columns?|Columns?|Trials?"
    r"|trials?|Ch|sections?|figures?|tables?|equations?|[Dd]evices?|[Mm]ethods?"
    r"|[Mm]arkers?|[Ss]essions?|[Aa]nimals?|[Rr]ats?|[Tt]rial|[Ss]eeds?|[Ff]olds?"
    r"|[Ee]xample|[Cc]ase|[Pp]oses?|[Gg]roups?|[Ll]ayers?|[Ss]ubjects?|[Cc]ells?"
    r"|[Mm]odels?|[Vv]ersion|[Ee]pisodes?|[Ww]eeks?(?= after)|A(?=\.\d))\.?|§)"
    r"\s*[A-Z]?\d+(?:\.\d+)*[a-z]?"
    r"(?:\s*(?:[–\-,]|and|or|to)\s*[A-Z]?\d+(?:\.\d+)*[a-z]?)*"
)
_HEADING_NUMBER = re.compile(r"^(#+\s+)[\d.]+\s", re.M)
_LIST_NUMBER = re.compile(r"^(\s*)\d+\.\s", re.M)
_YEAR = re.compile(
    r"(?:et al\.?,?|[A-Z][a-z]+(?:,| and| &)?)\s+\(?(?:19|20)\d\d[a-z]?\)?"
)
_NUMBER = re.compile(r"\d+(?:[.,]\d+)*")
_UNITS_AFTER = re.compile(
    r"^(?:s|ms|Hz|kHz|min|h|deg|g|m|cm|mm|k|M|kB|MB|GB|x|th|st|nd|rd)\b"
)


def _strip(text: str) -> str:
    text = _HEADING_NUMBER.sub(r"\1", text)
    text = _LIST_NUMBER.sub(r"\1", text)
    text = _COMMENT.sub(" ", text)
    text = _MATH_BLOCK.sub(" ", text)
    text = _FENCE.sub(" ", text)
    text = _DIRECTIVE_OPTION.sub(" ", text)
    text = _INLINE_MATH.sub(" ", text)
    text = _LINK_TARGET.sub("] ", text)
    return text


def _cited_units(text: str) -> list[str]:
    """Sentences and table rows; those carrying a citation are dropped (published)."""
    units = []
    for line in text.split("\n"):
        if line.lstrip().startswith("|"):
            units.append(line)
            continue
        units.extend(re.split(r"(?<=[.;:!?])\s+(?=[A-Z(*_])", line))
    return [u for u in units if "{cite" not in u and "[@" not in u]


def stray_numbers(markdown: str) -> list[tuple[str, str]]:
    """The typed numbers left in ``markdown`` once the legitimate places are removed,
    each as (number, context)."""
    found = []
    for unit in _cited_units(_strip(markdown)):
        unit = _ROLE.sub(" ", unit)
        unit = _CODE.sub(" ", unit)
        for phrase in ALLOW:
            unit = unit.replace(phrase, " ")
        unit = _ITEM.sub(" ", unit)
        unit = _YEAR.sub(" ", unit)
        for m in _NUMBER.finditer(unit):
            start, end = m.span()
            before = unit[:start]
            if before and (before[-1].isalpha() or before[-1] == "_"):
                continue  # part of an identifier: HDF5, float64, A5
            if re.search(r"[A-Za-z]-$", before) or unit[end:].startswith("-parameter"):
                continue  # a model name (MPU-9250) or a model's size (9-parameter)
            if unit[end : end + 1].isalpha() and not _UNITS_AFTER.match(unit[end:]):
                continue  # 9D, 2nd-order names … (not a unit)
            context = unit[max(0, start - 40) : end + 40].replace("\n", " ").strip()
            found.append((m.group(0).rstrip(".,"), context))
    return found


def _markdown_cells(path: Path) -> list[tuple[int, str]]:
    if path.suffix == ".md":
        return [(0, path.read_text())]
    cells = json.loads(path.read_text())["cells"]
    return [
        (i, "".join(c["source"]))
        for i, c in enumerate(cells)
        if c["cell_type"] == "markdown"
    ]


@pytest.mark.parametrize("path", CHAPTERS + PAGES, ids=lambda p: p.stem)
def test_no_typed_data_numbers(path):
    problems = [
        f"cell {i}: …{context}…"
        for i, text in _markdown_cells(path)
        for _, context in stray_numbers(text)
    ]
    assert not problems, (
        f"{path.name} types numbers in its prose that its computation should produce "
        "(glue them, print them, or cite them):\n  " + "\n  ".join(problems)
    )


@pytest.mark.parametrize(
    ("text", "stray"),
    [
        ("The error is 0.42° on average.", ["0.42"]),
        ("The error is {glue:text}`err:.2f`° on average.", []),
        ("Fayat et al. report 0.9° {cite}`fayat2021`.", []),
        ("See Fig. 3e and Table A5–A6, and §4.2.", []),
        ("Stored as HDF5 with float64 values, 9D fusion.", []),
        ("The rule $\\theta < 5$ holds.", []),
        ("It took 12 s on 300Hz data.", ["12", "300"]),
        ("| method | error |\n|---|---|\n| Madgwick | 1.2 |", ["1.2"]),
        ("| method | error |\n|---|---|\n| Madgwick {cite}`x` | 1.2 |", []),
        ("Call `lowpass(x, 2.5)` here.", []),
        ("## 3. Drift\n\n1. First item, as in section 5 and device 1.", []),
        ("An MPU-9250 needs a 9-parameter fit over 30-s holds.", ["30"]),
    ],
)
def test_the_scan_itself(text, stray):
    assert [number for number, _ in stray_numbers(text)] == stray


_GLUE_ROLE = re.compile(r"\{glue(?::[a-z]+)?\}`([A-Za-z0-9_]+)(?::[^`]*)?`")
_GLUE_CALL = re.compile(r"""glue\(\s*(?:f?["'])([A-Za-z0-9_{}]+)["']""")


@pytest.mark.parametrize("path", CHAPTERS, ids=lambda p: p.stem)
def test_glued_names_are_glued(path):
    """Every name a chapter's prose glues is glued by one of its code cells (a rerun
    then checks that it was produced on other data)."""
    cells = json.loads(path.read_text())["cells"]
    roles = {
        name
        for c in cells
        if c["cell_type"] == "markdown"
        for name in _GLUE_ROLE.findall("".join(c["source"]))
    }
    calls = [
        name
        for c in cells
        if c["cell_type"] == "code"
        for name in _GLUE_CALL.findall("".join(c["source"]))
    ]
    patterns = [
        re.compile(re.sub(r"\\\{[^}]*\\\}", r"\\w+", re.escape(n))) for n in calls
    ]
    unglued = sorted(r for r in roles if not any(p.fullmatch(r) for p in patterns))
    assert not unglued, f"{path.name}: the prose refers to names never glued: {unglued}"
