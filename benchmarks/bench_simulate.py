"""Throughput of tiltlab.simulate.

Targets (issue 3): one hour of 300 Hz 6-axis data in < 2 s on one core, and the
paper-size cohort (58 animals × 7 sessions × 20 min at 100 Hz ≈ 49 M samples) in
< 3 min on 2 cores.

Then a scaling section: head kinematics, the sensor model (``recording_from_motion`` on
that motion) and ``simulate_session`` end to end, at 36 s, 6 min and 1 h of 300 Hz
(×1, ×10, ×100: 10,800 to 1,080,000 samples), best of 3 each; one line per operation
with its throughput at each size and the fitted exponent of time ~ n^b (1: linear).
The cohort is not scaled (its smallest useful run is already minutes): its
per-session cost is what the subset measures.

Usage::

    python benchmarks/bench_simulate.py            # 1 h single session + a 35-session cohort subset, extrapolated
    python benchmarks/bench_simulate.py --full     # also the paper-size cohort (writes ~5 GB to a temp dir)
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from tiltlab.simulate import (
    CohortDesign,
    SensorModel,
    head_kinematics,
    recording_from_motion,
    simulate_cohort,
    simulate_session,
)

from _scaling_extra import note_far, scaling_section

PAPER_SAMPLES = 58 * 7 * 1200 * 100


def bench_session(repeats: int = 3) -> None:
    fs, dur = 300.0, 3600.0
    n = int(dur * fs)
    simulate_session(5.0, fs, seed=0)  # compile / load the numba cache
    t_kin, t_all = [], []
    for r in range(repeats):
        t0 = time.perf_counter()
        m = head_kinematics(dur, fs, seed=r)
        t1 = time.perf_counter()
        recording_from_motion(
            m, rng=np.random.default_rng(r), sensor=SensorModel(), keep_true=False
        )
        t2 = time.perf_counter()
        t_kin.append(t1 - t0)
        t_all.append(t2 - t0)
    best = min(t_all)
    print(f"1 h of 300 Hz 6-axis data ({n:,} samples), one core, best of {repeats}:")
    print(
        f"  head kinematics     {min(t_kin):6.3f} s   ({n / min(t_kin) / 1e6:5.2f} M samples/s)"
    )
    print(
        f"  + sensor model, validated Recording: total {best:6.3f} s   ({n / best / 1e6:5.2f} M samples/s)"
    )
    print(
        f"  target < 2 s: {'PASS' if best < 2.0 else 'FAIL'} (ratio to target {best / 2.0:.2f})"
    )


def bench_session_scaling(fs: float = 300.0) -> None:
    """Scaling of one session's simulation at 36 s, 6 min and 1 h of ``fs`` Hz."""
    sizes = [int(d * fs) for d in (36.0, 360.0, 3600.0)]
    motions = {k: head_kinematics(k / fs, fs, seed=0) for k in sizes}
    cases = [
        ("head kinematics", lambda k: head_kinematics(k / fs, fs, seed=0)),
        (
            "sensor model",
            lambda k: recording_from_motion(
                motions[k], rng=np.random.default_rng(0), keep_true=False
            ),
        ),
        (
            "simulate_session",
            lambda k: simulate_session(k / fs, fs, seed=0, keep_true=False),
        ),
    ]
    exps = scaling_section(f"one session at {fs:g} Hz", sizes, cases)
    note_far(
        exps,
        "fixed per-session costs (drawing the behaviour and the sensor, building and "
        "validating the Recording) still weigh at 36 s",
    )


def bench_cohort(
    design: CohortDesign, duration_s: float, workers: int, keep: bool, label: str
) -> float:
    n_sessions = sum(design.groups.values()) * len(design.time_points)
    n = n_sessions * int(duration_s * 100)
    tmp = Path(tempfile.mkdtemp(prefix="tiltlab_bench_cohort_"))
    try:
        t0 = time.perf_counter()
        simulate_cohort(
            tmp / "cohort",
            design=design,
            duration_s=duration_s,
            fs=100.0,
            seed=0,
            workers=workers,
            progress=True,
        )
        wall = time.perf_counter() - t0
        size = sum(f.stat().st_size for f in (tmp / "cohort").rglob("*") if f.is_file())
    finally:
        if keep:
            print(f"  kept in {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    rate = n / wall
    print(
        f"{label}: {n_sessions} sessions × {duration_s:g} s at 100 Hz = {n:,} samples, {workers} workers"
    )
    print(
        f"  wall {wall:7.2f} s   {rate / 1e6:5.2f} M samples/s   {size / 1e9:5.2f} GB written"
    )
    return rate


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument(
        "--full",
        action="store_true",
        help="also run the paper-size cohort (20 min sessions)",
    )
    ap.add_argument(
        "--duration",
        type=float,
        default=1200.0,
        help="session length of the default cohort subset (s)",
    )
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--keep", action="store_true", help="keep the cohort directories")
    args = ap.parse_args()

    bench_session()
    bench_session_scaling()
    print()
    # default: one animal per group (35 sessions) at the paper's session length; the
    # per-session cost is then representative and extrapolates to the 406 sessions
    rate = bench_cohort(
        CohortDesign.small(1),
        args.duration,
        args.workers,
        args.keep,
        "cohort subset (1 animal per group)",
    )
    est = PAPER_SAMPLES / rate
    print(
        f"  extrapolated paper-size cohort ({PAPER_SAMPLES:,} samples): {est:6.1f} s "
        f"(target < 180 s: {'PASS' if est < 180 else 'FAIL'}, ratio {est / 180:.2f})"
    )
    if args.full:
        print()
        rate = bench_cohort(
            CohortDesign(), 1200.0, args.workers, args.keep, "paper-size cohort"
        )
        wall = PAPER_SAMPLES / rate
        print(
            f"  measured paper-size time {wall:6.1f} s (target < 180 s: {'PASS' if wall < 180 else 'FAIL'}, ratio {wall / 180:.2f})"
        )


if __name__ == "__main__":
    main()
