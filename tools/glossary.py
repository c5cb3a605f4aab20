"""Write the book's parameter glossary from the package's docstrings.

Every parameter of every public function and class (those in a public module's
``__all__``) gets a row: its name, what it means (the first sentence of its numpydoc
description, from the function that uses it most plainly) and where it is used. The
page is generated, so it cannot drift from the code; ``tests/test_glossary.py`` fails
when the committed page is stale or a parameter is undocumented.

Usage: ``python tools/glossary.py [--check]`` (writes ``book/glossary.md``).
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import pkgutil
import re
import sys
from collections import defaultdict
from pathlib import Path

import tiltlab

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "book" / "glossary.md"

HEADER = """\
# Parameter glossary

Every parameter name of the package's public functions, with what it means and where it
is used. The same name means the same thing everywhere (see
[the conventions](conventions.md)): data come first, then `fs`, then keyword options. A
Recording argument is `rec`; an input that may be an array, a DataArray or a Recording
is `data`; a gyroscope offset is `gyr_offset`. This page is generated from the
docstrings, so it lists what the code takes today.

| name | meaning | used in |
|---|---|---|
"""

_ROLE = re.compile(r":(?:func|class|meth|mod|attr|data|obj|exc|ref):`~?([^`]+)`")
_MATH = re.compile(r":math:`([^`]+)`")
_HEADER_LINE = re.compile(r"^([A-Za-z_][\w, *]*?)(\s*:\s*(.*))?$")


def public_callables():
    """Yield ``(qualified name, object)`` for every public function and class.

    Returns
    -------
    iterator of (str, object)
        Only objects defined in the package, from modules without an underscore in
        their dotted name, deduplicated by identity.
    """
    seen: set[int] = set()
    for info in pkgutil.walk_packages(tiltlab.__path__, "tiltlab."):
        parts = info.name.split(".")[1:]
        if any(p.startswith("_") for p in parts):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name, None)
            if getattr(obj, "__deprecated_alias_of__", None) is not None:
                continue
            if not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if not getattr(obj, "__module__", "").startswith("tiltlab"):
                continue
            if id(obj) in seen:
                continue
            seen.add(id(obj))
            yield f"{info.name}.{name}", obj


def parameters(obj) -> list[str]:
    """List the named parameters of a function or class constructor.

    Parameters
    ----------
    obj : callable
        A function or class.

    Returns
    -------
    list of str
        Names, without ``self`` and without ``*args`` / ``**kwargs``.
    """
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    skip = (inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD)
    return [p.name for p in sig.parameters.values() if p.kind not in skip]


def described(obj) -> dict[str, str]:
    """Read the numpydoc ``Parameters`` (and a record's ``Attributes``) sections.

    Parameters
    ----------
    obj : callable
        A function or class.

    Returns
    -------
    dict
        Parameter name → its description (joined lines); ``a, b : float`` gives both.
    """
    doc = inspect.getdoc(obj) or ""
    lines = doc.splitlines()
    out: dict[str, str] = {}
    for section in ("Parameters", "Attributes"):
        starts = [
            i
            for i, line in enumerate(lines[:-1])
            if line.strip() == section and set(lines[i + 1].strip()) == {"-"}
        ]
        for start in starts:
            _read_section(lines, start, out)
    return out


def _read_section(lines: list[str], start: int, out: dict[str, str]) -> None:
    names: list[str] = []
    text: list[str] = []

    def flush():
        for n in names:
            out.setdefault(n, " ".join(text).strip())

    for i in range(start + 2, len(lines)):
        line = lines[i]
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        if line and not line.startswith(" ") and set(nxt.strip()) == {"-"}:
            break  # next section
        if line and not line.startswith(" "):
            flush()
            head = _HEADER_LINE.match(line.strip())
            raw = head.group(1) if head else line.split(":")[0]
            names = [n.strip().lstrip("*") for n in raw.split(",") if n.strip()]
            text = []
        elif line.strip():
            text.append(line.strip())
    flush()


def plain(text: str) -> str:
    """Turn reStructuredText markup into the book's Markdown, first sentence only.

    Parameters
    ----------
    text : str
        A numpydoc parameter description.

    Returns
    -------
    str
        Its first sentence, with roles as code and ``:math:`` as inline math, table
        pipes escaped.
    """
    text = _MATH.sub(lambda m: f"${m.group(1)}$", text)
    text = _ROLE.sub(lambda m: f"`{m.group(1).rsplit('.', 1)[-1]}`", text)
    text = text.replace("``", "`")
    match = re.search(r"(?<![.\w][a-z])\.(\s|$)", text)
    if match and match.start() > 20:
        text = text[: match.start() + 1]
    if len(text) > 220:
        text = text[:217].rsplit(" ", 1)[0] + " …"
    return text.replace("|", "\\|")


def glossary() -> tuple[str, list[str]]:
    """Build the glossary page.

    Returns
    -------
    page : str
        The Markdown page.
    undocumented : list of str
        ``"name (module.function)"`` for every parameter with no description.
    """
    meaning: dict[str, list[str]] = defaultdict(list)
    users: dict[str, list[str]] = defaultdict(list)
    undocumented: list[str] = []
    for qualname, obj in public_callables():
        docs = described(obj)
        short = qualname.replace("tiltlab.", "", 1)
        for name in parameters(obj):
            if docs.get(name):
                meaning[name].append(plain(docs[name]))
            elif inspect.isclass(obj):
                continue  # a record's undocumented field is not a parameter
            else:
                undocumented.append(f"{name} ({short})")
            users[name].append(short)
    rows = []
    for name in sorted(users, key=str.lower):
        texts = meaning.get(name) or ["(undocumented)"]
        # the most used description; ties: the shorter, then alphabetical
        text = min(set(texts), key=lambda t: (-texts.count(t), len(t), t))
        used = sorted(set(users[name]))
        where = ", ".join(f"`{u}`" for u in used[:3])
        if len(used) > 3:
            where += f" and {len(used) - 3} more"
        rows.append(f"| `{name}` | {text} | {where} |")
    return HEADER + "\n".join(rows) + "\n", undocumented


def main(argv: list[str] | None = None) -> int:
    """Write (or check) ``book/glossary.md``.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (``--check`` only compares).

    Returns
    -------
    int
        0 when written or current, 1 when ``--check`` finds it stale.
    """
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true")
    args = parser.parse_args(argv)
    page, _ = glossary()
    if args.check:
        current = PAGE.read_text(encoding="utf-8") if PAGE.exists() else ""
        if current != page:
            print("book/glossary.md is stale: run python tools/glossary.py")
            return 1
        return 0
    PAGE.write_text(page, encoding="utf-8")
    print(f"wrote {PAGE.relative_to(ROOT)} ({page.count(chr(10)) - 11} names)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
