"""Every exercise has its solution under labelled toggles: the code under "Solution N:
show the code", the answer text inside a "Solution N: the answer" dropdown, nothing of
the solution visible before the reader opens it (checked on the stored chapters)."""

import json
import re
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).parents[1] / "notebooks").glob("[0-9][0-9]_*.ipynb"))
ANSWER = re.compile(r"^:::\{dropdown\} Solution (\d+): the answer\n.*\n:::\s*$", re.S)
PROMPT = re.compile(r"^Solution (\d+): show the code$")


def _exercise_section(nb_path: Path) -> list[dict]:
    cells = json.loads(nb_path.read_text())["cells"]
    start = next(
        i
        for i, c in enumerate(cells)
        if c["cell_type"] == "markdown"
        and re.search(r"^## Exercises", "".join(c["source"]), re.M)
    )
    end = next(
        (
            i
            for i in range(start + 1, len(cells))
            if cells[i]["cell_type"] == "markdown"
            and re.search(r"^## ", "".join(cells[i]["source"]), re.M)
        ),
        len(cells),
    )
    return cells[start:end]


@pytest.mark.parametrize("nb_path", NOTEBOOKS, ids=lambda p: p.stem)
def test_solutions_sit_under_labelled_toggles(nb_path):
    section = _exercise_section(nb_path)
    listed = re.findall(r"^(\d+)\. ", "".join(section[0]["source"]), re.M)
    assert listed, f"{nb_path.name}: the Exercises section lists no exercise"
    problems, answered, coded = [], set(), set()
    seen_solution = False
    for cell in section[1:]:
        src = "".join(cell["source"])
        if cell["cell_type"] == "code":
            seen_solution = True
            prompt = cell["metadata"].get("mystnb", {}).get("code_prompt_show", "")
            m = PROMPT.match(prompt)
            if "hide-cell" not in cell["metadata"].get("tags", []) or not m:
                problems.append(
                    f"solution code without a labelled toggle: {src[:50]!r}"
                )
            else:
                coded.add(m.group(1))
        elif seen_solution:
            m = ANSWER.match(src)
            if not m:
                problems.append(
                    f"answer text outside a Solution dropdown: {src[:50]!r}"
                )
            else:
                answered.add(m.group(1))
    missing = [n for n in listed if n not in answered]
    if missing:
        problems.append(f"exercises without an answer dropdown: {missing}")
    if not coded:
        problems.append("no solution code")
    assert not problems, f"{nb_path.name}:\n  " + "\n  ".join(problems)
