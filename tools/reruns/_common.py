"""What the per-chapter rerun modules share."""

from __future__ import annotations

import json
import re
from pathlib import Path


def printed(nb_path: Path, pattern: str, what: str) -> list:
    """All matches of ``pattern`` in the executed notebook's stream outputs (strings,
    or tuples for several groups); an ``AssertionError`` saying that the chapter
    printed no ``what`` when there is none."""
    nb = json.loads(nb_path.read_text())
    text = "".join(
        "".join(o.get("text", ""))
        for c in nb["cells"]
        if c["cell_type"] == "code"
        for o in c.get("outputs", [])
        if o.get("output_type") == "stream"
    )
    found = re.findall(pattern, text)
    if not found:
        raise AssertionError(f"the chapter printed no {what}")
    return found


_GLUE_ROLE = re.compile(r"\{glue(?::[a-z]+)?\}`([A-Za-z0-9_]+)(?::[^`]*)?`")
_RECORD = "application/papermill.record/"


def glued(nb_path: Path) -> dict[str, str]:
    """Every value the executed chapter glued (MyST-NB ``glue``), name → its text: the
    ``text/markdown`` form where there is one (computed words and sentences), else
    ``text/plain`` (numbers)."""
    nb = json.loads(nb_path.read_text())
    out = {}
    for cell in nb["cells"]:
        for o in cell.get("outputs", []) if cell["cell_type"] == "code" else []:
            name = o.get("metadata", {}).get("scrapbook", {}).get("name")
            if name is None:
                continue
            data = o.get("data", {})
            out[name] = data.get(f"{_RECORD}text/markdown") or data.get(
                f"{_RECORD}text/plain", ""
            )
    return out


def glue_roles(nb_path: Path) -> set[str]:
    """The glue names the chapter's markdown refers to."""
    nb = json.loads(nb_path.read_text())
    return {
        name
        for c in nb["cells"]
        if c["cell_type"] == "markdown"
        for name in _GLUE_ROLE.findall("".join(c["source"]))
    }


def check_glued_prose(nb_path: Path) -> str:
    """Every glued statement the chapter's prose refers to was produced by this run, and
    none is empty or NaN: otherwise an ``AssertionError`` naming them."""
    values = glued(nb_path)
    roles = glue_roles(nb_path)
    missing = sorted(roles - values.keys())
    empty = sorted(
        n for n in roles & values.keys() if values[n].strip() in ("", "nan", "''")
    )
    if missing or empty:
        raise AssertionError(
            f"the prose refers to glued values this run did not produce: {missing}; "
            f"empty or NaN: {empty}"
        )
    return f"{len(roles)} glued statements produced"


def glued_float(values: dict[str, str], name: str) -> float:
    """A glued number as a float (an ``AssertionError`` naming it when absent)."""
    if name not in values:
        raise AssertionError(f"the chapter glued no {name}")
    return float(values[name])
