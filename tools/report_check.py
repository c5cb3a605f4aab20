"""Check ``tiltlab report`` for real: the book's chapters on a user's data, as HTML.

Two reports, each by the command line as a user types it (CI runs this script):

(a) chapter 6 on a recording from another lab (an accelerometer + magnetometer tag
    from the data mirror's ``foreign`` folder, converted by ``tiltlab convert``), with
    small parameters: it must run and list the sections it skipped (no gyroscope);
(b) chapter 8 on a small simulated cohort (a manifest), with a small power analysis.

Each must exit 0 and leave ``index.html``, the chapter's page and a ``report.json``
saying the chapter ran. Needs the data mirror (``TILTLAB_DATA_DIR``) and the ``book``
extra. Usage: ``python tools/report_check.py [--keep DIR]`` (``--keep`` keeps the
reports in DIR instead of a temporary folder). Exit status 0 if both reports pass.
"""

from __future__ import annotations

import argparse
import json
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

#: chapter 6 on the foreign tag: coarse lattice, few bootstrap replicates, short
#: simulated sessions
TAG_PARAMS = {"N_LATTICE": 2000, "N_BOOT": 100, "SIM_DURATION_S": 60}
#: chapter 8 on the small cohort: a small power analysis and tilt maps
COHORT_PARAMS = {"POWER_N": [3, 4, 6], "N_SIM_POWER": 100, "MAP_ANIMALS": 2}


def _tag(tmp: Path) -> Path:
    from reruns._foreign import convert

    return convert("tag", tmp)


def _cohort(tmp: Path) -> Path:
    """A cohort unlike chapter 8's default (as tools/reruns/08_...py writes one, smaller):
    three groups of three animals, two time points, 1-min sessions."""
    from tiltlab import simulate

    design = simulate.CohortDesign.small().select(
        groups={"Arsanilate": 3, "ShamArsanilate": 3, "Healthy": 3},
        time_points=["baseline", "1d"],
    )
    folder = simulate.simulate_cohort(
        tmp / "cohort",
        design=design,
        duration_s=60.0,
        fs=100.0,
        seed=3,
        workers=2,
        progress=False,
    )
    return folder / "manifest.csv"


def _report(source: Path, chapter: int, params: dict, out: Path) -> int:
    command = [
        sys.executable,
        "-m",
        "tiltlab.cli",
        "report",
        str(source),
        "--chapters",
        str(chapter),
        "--out",
        str(out),
        "--book",
        str(ROOT / "notebooks"),
        "--no-progress",
    ]
    for name, value in params.items():
        command += ["-p", f"{name}={json.dumps(value)}"]
    print("$ tiltlab " + shlex.join(command[3:]), flush=True)
    return subprocess.run(command).returncode


def _check(out: Path, chapter_name: str, status: int, want_skipped: bool) -> list[str]:
    """What is wrong with one report (nothing: an empty list)."""
    problems = []
    if status != 0:
        problems.append(f"tiltlab report exited with status {status}")
    for page in ("index.html", f"notebooks/{chapter_name}.html", "report.json"):
        if not (out / page).is_file():
            problems.append(f"{page} is missing")
    if (out / "report.json").is_file():
        summary = json.loads((out / "report.json").read_text())
        chapters = {c["name"]: c for c in summary["chapters"]}
        got = chapters.get(chapter_name, {})
        if got.get("status") != "ran":
            problems.append(
                f"{chapter_name}: {got.get('status')} ({got.get('reason')})"
            )
        if want_skipped and not got.get("skipped"):
            problems.append(f"{chapter_name} listed no skipped section")
    if (out / "index.html").is_file():
        index = (out / "index.html").read_text()
        if f"notebooks/{chapter_name}.html" not in index:
            problems.append("index.html does not link the chapter's page")
        if want_skipped and "skipped" not in index:
            problems.append("index.html lists no skipped section")
    return problems


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--keep", metavar="DIR", help="keep the reports in DIR")
    args = parser.parse_args(argv)
    t_start = time.perf_counter()
    failures = 0
    with tempfile.TemporaryDirectory(prefix="report-check-") as tmp_name:
        tmp = Path(tmp_name)
        where = Path(args.keep) if args.keep else tmp / "reports"
        where.mkdir(parents=True, exist_ok=True)
        cases = (
            ("tag", _tag, 6, "06_tilt_maps_sphere", TAG_PARAMS, True),
            ("cohort", _cohort, 8, "08_cohorts_group_statistics", COHORT_PARAMS, False),
        )
        for label, prepare, chapter, name, params, want_skipped in cases:
            t0 = time.perf_counter()
            print(f"== report ({label}): chapter {chapter}", flush=True)
            try:
                source = prepare(tmp)
            except Exception as exc:  # the data are missing: a failure, said clearly
                failures += 1
                print(f"   FAILED to prepare: {type(exc).__name__}: {exc}", flush=True)
                continue
            out = where / label
            status = _report(source, chapter, params, out)
            problems = _check(out, name, status, want_skipped)
            took = time.perf_counter() - t0
            if problems:
                failures += 1
                print(f"   FAILED in {took:.0f} s: " + "; ".join(problems), flush=True)
            else:
                print(f"   ok in {took:.0f} s: {out / 'index.html'}", flush=True)
    total = time.perf_counter() - t_start
    print(f"{2 - failures} passed, {failures} failed in {total:.0f} s")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
