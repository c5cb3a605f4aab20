"""What the per-chapter rerun modules share."""

from __future__ import annotations

import json
import re
from pathlib import Path


def printed(nb_path: Path, pattern: str) -> list[str]:
    """All matches of ``pattern`` (one group) in the executed notebook's stream outputs."""
    nb = json.loads(nb_path.read_text())
    text = "".join(
        "".join(o.get("text", ""))
        for c in nb["cells"]
        if c["cell_type"] == "code"
        for o in c.get("outputs", [])
        if o.get("output_type") == "stream"
    )
    return re.findall(pattern, text)
