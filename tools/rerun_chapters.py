"""Run chapters a second time, with papermill, on another data source or parameter set.

The book build executes every chapter with its default parameters; this script proves
that the chapters also run unchanged on other data (``make rerun``; CI runs it). Each
rerun must finish without an error; some also check a number the chapter prints against
the package computing it directly, so that a rerun cannot silently analyse the wrong
thing. An entry's parameters are a dict, or a *prepare* function that writes the data the
rerun needs (e.g. a simulated cohort) into a temporary folder and returns the parameters.

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


def prepare_small_cohort(tmp: Path) -> dict:
    """A cohort unlike chapter 8's default: three groups, three time points, 1-min sessions."""
    from tiltlab import simulate

    design = simulate.CohortDesign.small().select(
        groups={"Arsanilate": 4, "ShamArsanilate": 4, "Healthy": 4},
        time_points=["baseline", "1d", "7d"],
    )
    folder = simulate.simulate_cohort(
        tmp / "cohort08",
        design=design,
        duration_s=60.0,
        fs=100.0,
        seed=3,
        workers=2,
        progress=False,
    )
    return {
        "COHORT_MANIFEST": str(folder / "manifest.csv"),
        "SEED": 3,
        "MAP_ANIMALS": 2,
        "POWER_N": [3, 4, 6, 8],
        "N_SIM_POWER": 100,
    }


def check_cohort_tables(nb_path: Path, params: dict) -> str:
    """The chapter analysed the prepared cohort (its groups and time points) and printed
    its tables: one Fayat block (lesion vs control, lesion vs sham, sham vs control)
    between groups and every group against baseline, per feature and time point."""
    import pandas as pd

    manifest = pd.read_csv(params["COHORT_MANIFEST"])
    n_groups = manifest["group"].nunique()
    n_post = manifest["timepoint"].nunique() - 1
    found = _printed(
        nb_path,
        r"Computed (\d+) tables \((\d+) tests\) for (\d+) features, (\d+) groups, "
        r"(\d+) time points after",
    )
    if not found:
        raise AssertionError("the chapter printed no table summary line")
    tables, tests, n_features, groups, post = map(int, found[0])
    if (groups, post) != (n_groups, n_post):
        raise AssertionError(
            f"chapter analysed {groups} groups × {post} time points, the prepared cohort "
            f"has {n_groups} × {n_post}"
        )
    expected = n_features * n_post * (3 + n_groups)
    if tables != 2 * n_features or tests != expected:
        raise AssertionError(
            f"chapter computed {tables} tables / {tests} tests, expected "
            f"{2 * n_features} / {expected}"
        )
    return f"{tables} tables, {tests} tests on {groups} groups × {post} time points"


def check_learned_trials(nb_path: Path, params: dict) -> str:
    """The learned-estimator chapter compared every method on exactly the trials asked."""
    found = _printed(
        nb_path, r"compared (\d+) methods on (\d+) held-out trials: \[([0-9, ]*)\]"
    )
    if not found:
        raise AssertionError("the chapter printed no comparison line")
    n_methods, _, listed = found[0]
    trials = sorted(int(t) for t in listed.split(",") if t.strip())
    if trials != sorted(params["TRIALS"]):
        raise AssertionError(
            f"chapter compared trials {trials}, asked {params['TRIALS']}"
        )
    return f"{n_methods} methods on trials {trials}"


# (notebook, parameters or prepare(tmp) -> parameters, optional check)
RERUNS = [
    (
        "05_learned_orientation",
        {"TRIALS": [6, 28], "EXAMPLE_TRIAL": 6, "SOURCE": "broad:10", "N_JOBS": 1},
        check_learned_trials,
    ),
    (
        "06_tilt_maps_sphere",
        {"SOURCE": "broad:2", "IMMOBILE_DEG_S": 12.0},
        check_immobility,
    ),
    ("08_cohorts_group_statistics", prepare_small_cohort, check_cohort_tables),
]


def main(argv: list[str]) -> int:
    wanted = set(argv)
    failures = ran = 0
    with tempfile.TemporaryDirectory() as tmp:
        for stem, spec, check in RERUNS:
            if wanted and stem not in wanted:
                continue
            ran += 1
            out = Path(tmp) / f"{stem}.rerun.ipynb"
            t0 = time.perf_counter()
            try:
                if callable(spec):
                    print(f"== {stem}: preparing its data", flush=True)
                params = spec(Path(tmp)) if callable(spec) else spec
                print(f"== {stem} with {params}", flush=True)
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
    print(f"{ran - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
