"""Run chapters a second time, with papermill, on another data source or parameter set.

The book build executes every chapter with its default parameters; this script proves
that the chapters also run unchanged on other data (``make rerun``; CI runs it). Each
rerun must finish without an error; some also check a number the chapter prints against
the package computing it directly, so that a rerun cannot silently analyse the wrong
thing.

Usage: ``python tools/rerun_chapters.py [NOTEBOOK_STEM ...]``
"""

from __future__ import annotations

import json
import re
import sys
import tempfile
import time
from pathlib import Path

import papermill as pm

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"


def _printed(nb_path: Path, pattern: str) -> list[str]:
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


def check_immobility(nb_path: Path, params: dict) -> str:
    """The immobile fraction the chapter prints equals Fayat's rules applied directly."""
    from tiltlab import behavior, datasets

    rec = datasets.load(params["SOURCE"])
    expected = float(
        behavior.immobility(
            rec, threshold_deg_s=params["IMMOBILE_DEG_S"], gyr_offset="auto"
        ).mean()
    )
    found = _printed(nb_path, r"immobile ([0-9.]+)% of the time")
    if not found:
        raise AssertionError("the chapter printed no immobile fraction")
    got = float(found[0]) / 100
    if abs(got - expected) > 0.0005:
        raise AssertionError(
            f"chapter says {got:.1%} immobile, behavior.immobility gives {expected:.1%}"
        )
    return f"immobile fraction {got:.1%} (package: {expected:.1%})"


# (notebook, parameters, optional check)
RERUNS = [
    (
        "06_tilt_maps_sphere",
        {"SOURCE": "broad:2", "IMMOBILE_DEG_S": 12.0},
        check_immobility,
    ),
]


def main(argv: list[str]) -> int:
    wanted = set(argv)
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        for stem, params, check in RERUNS:
            if wanted and stem not in wanted:
                continue
            out = Path(tmp) / f"{stem}.rerun.ipynb"
            t0 = time.perf_counter()
            print(f"== {stem} with {params}", flush=True)
            try:
                pm.execute_notebook(
                    str(NOTEBOOKS / f"{stem}.ipynb"),
                    str(out),
                    parameters=params,
                    cwd=str(NOTEBOOKS),
                    kernel_name="python3",
                    progress_bar=False,
                )
                note = check(out, params) if check else "completed"
                print(f"   ok in {time.perf_counter() - t0:.0f} s: {note}", flush=True)
            except Exception as exc:  # report every rerun, then fail
                failures += 1
                print(f"   FAILED: {type(exc).__name__}: {exc}", flush=True)
    print(f"{len(RERUNS) - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
