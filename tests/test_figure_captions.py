"""Every figure of the book is numbered, captioned, described for screen readers and
rendered sharp: checked on the stored chapters (the browser test checks the built book)."""

import json
import re
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).parents[1] / "notebooks").glob("[0-9][0-9]_*.ipynb"))
RETINA = '%config InlineBackend.figure_formats = ["retina"]'


def _cells(nb_path: Path) -> list[dict]:
    return json.loads(nb_path.read_text())["cells"]


def _figure_cells(nb_path: Path) -> list[dict]:
    return [
        c
        for c in _cells(nb_path)
        if c["cell_type"] == "code" and "plt.show()" in "".join(c["source"])
    ]


@pytest.mark.parametrize("nb_path", NOTEBOOKS, ids=lambda p: p.stem)
def test_every_figure_cell_has_a_caption_a_name_and_alt_text(nb_path):
    chapter = nb_path.name[:2]
    problems = []
    for cell in _figure_cells(nb_path):
        meta = cell["metadata"].get("mystnb", {})
        fig, image = meta.get("figure", {}), meta.get("image", {})
        first = "".join(cell["source"]).splitlines()[0][:60]
        if len(fig.get("caption", "")) < 40:
            problems.append(f"no caption (≥ 40 characters): {first!r}")
        if not re.fullmatch(rf"fig-{chapter}-[a-z0-9-]+", fig.get("name", "")):
            problems.append(f"no name fig-{chapter}-<slug>: {first!r}")
        if len(image.get("alt", "").strip()) < 10:
            problems.append(f"no alt text: {first!r}")
    assert not problems, f"{nb_path.name}:\n  " + "\n  ".join(problems)


@pytest.mark.parametrize("nb_path", NOTEBOOKS, ids=lambda p: p.stem)
def test_figures_render_at_twice_the_pixel_density(nb_path):
    first_code = next(c for c in _cells(nb_path) if c["cell_type"] == "code")
    assert RETINA in "".join(first_code["source"]), (
        f"{nb_path.name}: the first code cell must set {RETINA}"
    )


def test_figure_names_are_unique_across_the_book():
    names = [
        c["metadata"].get("mystnb", {}).get("figure", {}).get("name")
        for nb in NOTEBOOKS
        for c in _figure_cells(nb)
    ]
    names = [n for n in names if n]
    dupes = sorted({n for n in names if names.count(n) > 1})
    assert not dupes, f"figure names used twice: {dupes}"
