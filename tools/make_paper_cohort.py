"""Simulate Fayat et al.'s cohort at the paper's scale and commit its feature tables.

Usage: ``python tools/make_paper_cohort.py [--out data/cohort_fayat2021] [--workers 2]``

The design is the paper's (Fayat et al. 2021, §2.3): five groups of 20, 11, 11, 5 and
11 animals (Kainate, ShamKainate, Arsanilate, ShamArsanilate, Healthy), a baseline
session and sessions 1 h, 1 d, 2 d, 7 d, 14 d and 28 d after the injection, 20 min
each, at 300 Hz (the rate of their IMU). ``tiltlab.simulate.simulate_cohort`` writes
the 406 sessions and the 58 tumble tests to a temporary folder like a lab's own data;
``tiltlab.cohort.run_cohort`` then computes the features twice, with the project's
default configuration and with ``FeatureConfig.fayat2021()`` (the paper's
definitions). Written to ``--out``: ``features_default.nc``,
``features_fayat2021.nc`` (:func:`tiltlab.cohort.save_features`), ``truth.csv``
(the planted effects of every session), the two figures of the paper that need the
recordings, computed with the default configuration before the recordings are
deleted — ``maps_default.nc`` (Figs 3c–d: the tilt maps of every group and time point
averaged over all animals, :func:`tiltlab.cohort.group_tilt_maps`, time fractions
stored as float32) and ``velocity_default.nc`` (Fig. A5: every group's example
animal, :func:`tiltlab.cohort.circling_examples`, 1001 quantiles, float32) —,
``run.json`` (command, design, seed,
configurations, timings, versions) and ``SHA256SUMS``. The recordings themselves
(about 20 GB) are deleted. Chapter 8 reads these tables instead of simulating the
cohort at this size. The output does not depend on ``--workers``.
"""

from __future__ import annotations

import argparse
import json
import platform
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

import tiltlab
from tiltlab import cohort, io, simulate

FILES = (
    "features_default.nc",
    "features_fayat2021.nc",
    "truth.csv",
    "maps_default.nc",
    "velocity_default.nc",
)


def figures(manifest, features, config, design, out: Path, workers: int) -> None:
    """Save the figures' data that need the recordings (Figs 3c–d and A5)."""
    maps = cohort.group_tilt_maps(
        manifest,
        features,
        config,
        scheduler="processes" if workers > 1 else None,
        workers=workers,
        progress=True,
    )
    maps["fraction"] = maps["fraction"].astype(np.float32)
    io.save_netcdf(maps, out / "maps_default.nc")
    examples = cohort.circling_examples(
        manifest,
        features,
        config,
        groups=list(design.groups),
        baseline=design.time_points[0],
        compared=list(design.time_points[1:]),
    )
    examples["omega"] = examples["omega"].astype(np.float32)
    io.save_netcdf(examples, out / "velocity_default.nc")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="data/cohort_fayat2021")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--duration", type=float, default=1200.0, help="session (s)")
    ap.add_argument("--fs", type=float, default=300.0, help="sampling rate (Hz)")
    ap.add_argument("--scratch", default=None, help="folder for the recordings")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scratch = Path(tempfile.mkdtemp(prefix="tiltlab_paper_", dir=args.scratch))
    design = simulate.CohortDesign()
    timings = {}
    try:
        t0 = time.perf_counter()
        folder = simulate.simulate_cohort(
            scratch / "cohort",
            design=design,
            duration_s=args.duration,
            fs=args.fs,
            seed=args.seed,
            workers=args.workers,
            progress=True,
        )
        timings["simulate_s"] = round(time.perf_counter() - t0, 1)
        manifest = cohort.read_manifest(folder / "manifest.csv")
        configs = {
            "default": cohort.FeatureConfig(),
            "fayat2021": cohort.FeatureConfig.fayat2021(),
        }
        for name, config in configs.items():
            t0 = time.perf_counter()
            features = cohort.run_cohort(
                manifest,
                config,
                scheduler="processes" if args.workers > 1 else None,
                workers=args.workers,
                cache_dir=scratch / f"cache_{name}",
                progress=True,
            )
            failed = int((features["status"] != "ok").sum())
            if failed:
                raise RuntimeError(f"{failed} sessions failed with the {name} config")
            cohort.save_features(features, out / f"features_{name}.nc")
            timings[f"features_{name}_s"] = round(time.perf_counter() - t0, 1)
            if name == "default":
                t0 = time.perf_counter()
                figures(manifest, features, config, design, out, args.workers)
                timings["figures_default_s"] = round(time.perf_counter() - t0, 1)
        shutil.copyfile(folder / "truth.csv", out / "truth.csv")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    run = {
        "command": f"python tools/make_paper_cohort.py --out {args.out}",
        "design": "Fayat et al. 2021: "
        + ", ".join(f"{g} {n}" for g, n in design.groups.items()),
        "time_points": list(design.time_points),
        "duration_s": args.duration,
        "fs": args.fs,
        "seed": args.seed,
        "workers": args.workers,
        "configs": {k: json.loads(c.to_json()) for k, c in configs.items()},
        "timings": timings,
        "versions": {
            "tiltlab": tiltlab.__version__,
            "numpy": np.__version__,
            "python": platform.python_version(),
        },
    }
    (out / "run.json").write_text(json.dumps(run, indent=1) + "\n")
    io.write_sums(out, {n: io.file_sha256(out / n) for n in FILES})
    print(json.dumps(timings))


if __name__ == "__main__":
    main()
