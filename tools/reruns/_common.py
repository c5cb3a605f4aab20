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
