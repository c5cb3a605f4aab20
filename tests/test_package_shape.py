"""The package keeps its shape: no module grows past the size at which it stops being
read as one piece."""

from __future__ import annotations

from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "tiltlab"
MAX_LINES = 800


def test_no_module_over_800_lines():
    sizes = {
        str(p.relative_to(SRC)): len(p.read_text(encoding="utf-8").splitlines())
        for p in SRC.rglob("*.py")
    }
    too_long = {name: n for name, n in sorted(sizes.items()) if n > MAX_LINES}
    assert not too_long, (
        f"modules over {MAX_LINES} lines (split them by responsibility): {too_long}"
    )
