"""One vocabulary: every public parameter is documented and in the book's glossary.

The glossary page (``book/glossary.md``) is generated from the docstrings by
``tools/glossary.py``; these tests fail when it is stale, when a public function leaves
a parameter undescribed, or when the old names of the Recording argument and of the
gyroscope offset come back.
"""

from __future__ import annotations

import importlib.util
import inspect
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def glossary():
    spec = importlib.util.spec_from_file_location(
        "glossary", ROOT / "tools/glossary.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def built(glossary):
    return glossary.glossary()


def test_every_public_parameter_is_described(built):
    _, undocumented = built
    assert not undocumented, (
        f"{len(undocumented)} parameters without a description: {undocumented}"
    )


def test_the_glossary_page_is_current(built):
    page, _ = built
    current = (ROOT / "book" / "glossary.md").read_text(encoding="utf-8")
    assert current == page, "book/glossary.md is stale: run python tools/glossary.py"


def test_one_name_for_the_recording_and_the_gyroscope_offset(glossary):
    """``rec`` for a Recording, ``gyr_offset`` for a gyroscope offset (old names only as
    deprecated keywords)."""
    old = {"ds", "recording", "b0", "bias"}
    found = []
    for qualname, obj in glossary.public_callables():
        if inspect.isclass(obj):
            continue
        found += [f"{qualname}({n})" for n in glossary.parameters(obj) if n in old]
    assert not found, f"old parameter names still public: {found}"


def test_the_parser_reads_numpydoc_sections(glossary):
    def f(a, b, *, rec=None):
        """Do something.

        Parameters
        ----------
        a, b : float
            Two numbers. More text.
        rec : xarray.Dataset, optional
            A Recording.

        Returns
        -------
        float
            Their sum.
        """

    docs = glossary.described(f)
    assert docs == {
        "a": "Two numbers. More text.",
        "b": "Two numbers. More text.",
        "rec": "A Recording.",
    }
    assert glossary.plain(":func:`~tiltlab.io.read` and ``x`` | :math:`\\alpha`") == (
        "`read` and `x` \\| $\\alpha$"
    )
