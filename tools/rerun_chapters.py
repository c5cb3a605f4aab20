"""Run chapters a second time, with papermill, on another data source or parameter set.

The book build executes every chapter with its default parameters; this script proves
that the chapters also run unchanged on other data (``make rerun``; CI runs it). Each
chapter's rerun is described by ``tools/reruns/<notebook stem>.py``, which defines either

* ``PARAMS``: the papermill parameters, or
* ``prepare(tmp: Path) -> dict``: writes the data the rerun needs (a simulated tumble test,
  a cohort …) into a temporary folder and returns the parameters,

and optionally ``check(nb_path: Path, params: dict) -> str``, which compares a number the
executed chapter printed with the package computing it directly, so that a rerun cannot
silently analyse the wrong thing, and whose checks include the chapter's glued prose
(its summary's computed statements agree with the tables they summarise). Every rerun
also checks that every value the chapter's prose glues was produced on the other data.
Every chapter must have a rerun module. A module may
also define ``VARIANTS``: a dict of further reruns, name → ``prepare`` function (with an
optional ``check_<name>``), e.g. the chapter on a converted recording from another lab.

Usage: ``python tools/rerun_chapters.py [NOTEBOOK_STEM[:VARIANT] ...]`` (``main`` names
the module's main rerun).
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


def _jobs(stem: str, module) -> list[tuple[str, object, object]]:
    """(label, prepare-or-params, check) for the module's main rerun and its variants."""
    main = module.prepare if hasattr(module, "prepare") else dict(module.PARAMS)
    jobs = [(stem, main, getattr(module, "check", None))]
    for name, prep in getattr(module, "VARIANTS", {}).items():
        jobs.append((f"{stem} [{name}]", prep, getattr(module, f"check_{name}", None)))
    return jobs


def main(argv: list[str]) -> int:
    from reruns._common import check_glued_prose

    wanted = set(argv)
    failures = ran = 0
    with tempfile.TemporaryDirectory() as tmp:
        for stem, module in reruns():
            if (
                wanted
                and stem not in wanted
                and not any(w.startswith(f"{stem}:") for w in wanted)
            ):
                continue
            for label, how, check in _jobs(stem, module):
                name = label.partition(" [")[2].rstrip("]") or "main"
                if wanted and stem not in wanted and f"{stem}:{name}" not in wanted:
                    continue
                ran += 1
                work = Path(tmp) / label.replace(" [", "_").replace("]", "")
                work.mkdir(parents=True, exist_ok=True)
                out = work / f"{stem}.rerun.ipynb"
                t0 = time.perf_counter()
                try:
                    if callable(how):
                        print(f"== {label}: preparing its data", flush=True)
                        params = how(work)
                    else:
                        params = dict(how)
                    print(f"== {label} with {params}", flush=True)
                    pm.execute_notebook(
                        str(NOTEBOOKS / f"{stem}.ipynb"),
                        str(out),
                        parameters=params,
                        cwd=str(NOTEBOOKS),
                        kernel_name="python3",
                        progress_bar=False,
                    )
                    note = check(out, params) if check else "completed"
                    note = f"{note}; {check_glued_prose(out)}"
                    print(
                        f"   ok in {time.perf_counter() - t0:.0f} s: {note}", flush=True
                    )
                except Exception as exc:  # report every rerun, then fail
                    failures += 1
                    print(f"   FAILED: {type(exc).__name__}: {exc}", flush=True)
    print(f"{ran - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
