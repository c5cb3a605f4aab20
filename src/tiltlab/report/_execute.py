"""One chapter executed with papermill, and the lines it printed about what it skipped."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

from ._plan import (
    Status,
    _ANSI,
    _Chapter,
)


# --------------------------------------------------------------------- execution


def _skipped_lines(notebook: Path) -> list[str]:
    """Collect printed lines containing "skipped", in order, without repeats."""
    try:
        nb = json.loads(notebook.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    lines: list[str] = []
    for cell in nb.get("cells", []):
        for output in (
            cell.get("outputs", []) if cell.get("cell_type") == "code" else []
        ):
            if output.get("output_type") != "stream":
                continue
            for line in "".join(output.get("text", "")).splitlines():
                line = _ANSI.sub("", line).strip()
                if "skipped" in line.lower() and line not in lines:
                    lines.append(line)
    return lines


def _execute(
    ch: _Chapter, params: dict[str, Any], notebook: Path, progress: bool
) -> tuple[Status, float, str | None]:
    import papermill as pm
    from papermill.exceptions import PapermillExecutionError

    bar: bool | dict[str, Any] = (
        {"desc": f"chapter {ch.number}", "unit": "cell", "leave": True}
        if progress
        else False
    )
    t0 = time.perf_counter()
    try:
        pm.execute_notebook(
            str(ch.path),
            str(notebook),
            parameters=params,
            cwd=str(ch.path.parent),
            progress_bar=bar,
            log_output=False,
        )
    except PapermillExecutionError as exc:
        lines = _ANSI.sub("", str(exc.evalue)).strip()
        where = f" (cell [{exc.exec_count}])" if exc.exec_count else ""
        error = f"{exc.ename}: {lines}" if lines else exc.ename
        return "failed", time.perf_counter() - t0, f"{error}{where}"
    except Exception as exc:  # no kernel, unreadable notebook ...: still a report
        text = " ".join(str(exc).split())
        return "failed", time.perf_counter() - t0, f"{type(exc).__name__}: {text}"
    return "ran", time.perf_counter() - t0, None


# --------------------------------------------------------------------- the index
