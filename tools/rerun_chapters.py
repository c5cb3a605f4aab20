"""Run chapters a second time, with papermill, on another data source or parameter set.

The book build executes every chapter with its default parameters; this script proves
that the chapters also run unchanged on other data (``make rerun``; CI runs it). Each
chapter's rerun is described by ``tools/reruns/<notebook stem>.py``, which defines either

* ``PARAMS``: the papermill parameters, or
* ``prepare(tmp: Path) -> dict``: writes the data the rerun needs (a simulated tumble test,
  a cohort …) into a temporary folder and returns the parameters,

and optionally ``check(nb_path: Path, params: dict) -> str``, which compares a number the
executed chapter printed with the package computing it directly, so that a rerun cannot
silently analyse the wrong thing. Every chapter must have a rerun module.

Usage: ``python tools/rerun_chapters.py [NOTEBOOK_STEM ...]``
"""

from __future__ import annotations

import importlib
import sys
import tempfile
import time
from pathlib import Path

import papermill as pm

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
sys.path.insert(0, str(Path(__file__).resolve().parent))


def reruns() -> list[tuple[str, object]]:
    """(notebook stem, rerun module) for every chapter; a chapter without one is an error."""
    out = []
    for nb in sorted(NOTEBOOKS.glob("[0-9][0-9]_*.ipynb")):
        try:
            module = importlib.import_module(f"reruns.{nb.stem}")
        except ModuleNotFoundError as exc:
            raise SystemExit(
                f"{nb.name} has no rerun: add tools/reruns/{nb.stem}.py"
            ) from exc
        if not hasattr(module, "PARAMS") and not hasattr(module, "prepare"):
            raise SystemExit(
                f"tools/reruns/{nb.stem}.py defines neither PARAMS nor prepare"
            )
        out.append((nb.stem, module))
    return out


def main(argv: list[str]) -> int:
    wanted = set(argv)
    failures = ran = 0
    with tempfile.TemporaryDirectory() as tmp:
        for stem, module in reruns():
            if wanted and stem not in wanted:
                continue
            ran += 1
            out = Path(tmp) / f"{stem}.rerun.ipynb"
            t0 = time.perf_counter()
            try:
                if hasattr(module, "prepare"):
                    print(f"== {stem}: preparing its data", flush=True)
                    params = module.prepare(Path(tmp))
                else:
                    params = dict(module.PARAMS)
                print(f"== {stem} with {params}", flush=True)
                pm.execute_notebook(
                    str(NOTEBOOKS / f"{stem}.ipynb"),
                    str(out),
                    parameters=params,
                    cwd=str(NOTEBOOKS),
                    kernel_name="python3",
                    progress_bar=False,
                )
                check = getattr(module, "check", None)
                note = check(out, params) if check else "completed"
                print(f"   ok in {time.perf_counter() - t0:.0f} s: {note}", flush=True)
            except Exception as exc:  # report every rerun, then fail
                failures += 1
                print(f"   FAILED: {type(exc).__name__}: {exc}", flush=True)
    print(f"{ran - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
