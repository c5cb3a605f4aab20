"""Throughput of the cohort pipeline (tiltlab.cohort) on a simulated lesion study.

Target: the paper-size design — 58 animals × 7 time points × 20 min at 300 Hz
(406 sessions, ≈ 146 M samples) — through the per-session pipeline in < 3 min on 2 cores.

What is timed: everything ``tiltlab.cohort.run_cohort`` does per session — read the
session (NetCDF, validated) and the subject's tumble test, calibration (tumble-test
accelerometer offsets, then the session's gyroscope offset), the default orientation
filter (``FeatureConfig().method``), tilt, every feature family, the cache write — and
assembling the feature table. Not timed: simulating the sessions. ``tiltlab.simulate``
writes them (and one tumble test per animal) to a temporary folder first, as a lab's
files would lie on disk (the simulator's ground truth — ``q_ref``, ``state``,
``a_lin`` — is dropped, so that each file holds what a real one does: acc, gyr, temp).

The machine must be otherwise idle: the figures are wall times. Each end-to-end run
also reports the CPU seconds of this process tree and of everything else (Linux
``/proc``), and warns when other programs took a noticeable share of the CPU.

Sections:

1. per stage, in this process (one core), on a few sessions: samples/s of read,
   validation, calibration, filter, tilt and each feature family (the stages mirror
   ``session_features``; their features are checked against it);
2. end to end on the measured sessions: serial (``scheduler=None``) against
   ``scheduler="dask"`` (a local ``distributed`` cluster, ``--workers`` processes) and
   ``scheduler="processes"``, same sessions, fresh caches: the dask overhead;
3. the paper-size estimate, extrapolated from the dask run of the measured sessions
   (fixed cluster start-up + per-sample cost), or measured with ``--full``; and the
   best case (the serial run's CPU time per sample spread perfectly over the workers).

Usage::

    python benchmarks/bench_cohort.py           # 35 sessions (1 animal per group × 7 time points), 20 min at 300 Hz
    python benchmarks/bench_cohort.py --quick   # smoke run: 14 sessions of 30 s
    python benchmarks/bench_cohort.py --full    # all 406 sessions (≈ 9 GB in a temporary folder)
"""

from __future__ import annotations

import argparse
import logging
import os
import shutil
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from tiltlab import behavior, cohort, filters, io, schema, simulate, sphere, units
from tiltlab.cohort import features as _features
from tiltlab.cohort import run as _run

PAPER_SESSIONS = 58 * 7
PAPER_SAMPLES = PAPER_SESSIONS * 1200 * 300
TARGET_S = 180.0
STAGES = (
    "read session",
    "read tumble test",
    "validate",
    "calibration",
    "filter (orientation)",
    "tilt (gravity)",
    "immobility (speed, rules, valley)",
    "sphere (maps, visited, vMF)",
    "circling + speed quantiles",
    "activity (DBA, ODBA)",
    "time tilted",
)


# --------------------------------------------------------------------------- CPU meter


def _stat(pid: int) -> list[str] | None:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()
    except OSError:
        return None


class CpuMeter:
    """CPU seconds used by this process tree and by everything else during a block.

    Linux only (``/proc``); elsewhere both are NaN. The tree's CPU counts live
    descendants and, through ``cutime``/``cstime``, those already reaped (dask workers
    and pool processes). ``other`` is the machine's busy time minus the tree's: CPU taken
    by other programs, which inflates every wall time measured meanwhile.
    """

    def __init__(self):
        self.tick = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100
        self.own = self.other = float("nan")

    def _tree(self) -> float:
        me, parent, fields = os.getpid(), {}, {}
        for name in os.listdir("/proc"):
            if name.isdigit():
                st = _stat(int(name))
                if st is not None:
                    parent[int(name)], fields[int(name)] = int(st[1]), st
        tree, grew = {me}, True
        while grew:
            new = {p for p, pp in parent.items() if pp in tree and p not in tree}
            tree |= new
            grew = bool(new)
        return sum(sum(int(x) for x in fields[p][11:15]) for p in tree if p in fields)

    @staticmethod
    def _busy() -> float:
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
        return sum(v) - v[3] - v[4]  # all but idle and iowait

    def __enter__(self) -> "CpuMeter":
        try:
            self._t0, self._b0 = self._tree(), self._busy()
        except OSError:
            self._t0 = None
        return self

    def __exit__(self, *exc) -> None:
        if self._t0 is None:
            return
        own = self._tree() - self._t0
        self.own = own / self.tick
        self.other = max(self._busy() - self._b0 - own, 0) / self.tick


# --------------------------------------------------------------------------- data


def make_study(
    root: Path, design: simulate.CohortDesign, duration_s: float, workers: int
) -> cohort.Manifest:
    """Simulate the sessions, one tumble test per animal and the manifest (untimed)."""
    simulate.simulate_cohort(
        root,
        design=design,
        duration_s=duration_s,
        fs=300.0,
        seed=0,
        workers=workers,
        progress=False,
        calibration=True,
    )
    # keep what a lab's files hold (acc, gyr, temp): drop the simulator's ground truth
    for path in sorted((root / "sessions").glob("*.nc")):
        rec = io.load_netcdf(path)
        truth = [v for v in ("q_ref", "state", "a_lin") if v in rec]
        if truth:
            io.save_netcdf(rec.drop_vars(truth + ["quat"], errors="ignore"), path)
    manifest = cohort.read_manifest(root / "manifest.csv")
    if not (manifest.table["calibration"] != "").all():
        raise RuntimeError(
            "the simulated manifest names no tumble test for some sessions"
        )
    return manifest


def subset(manifest: cohort.Manifest, n: int) -> cohort.Manifest:
    """The first ``n`` sessions of a manifest (in memory)."""
    return cohort.Manifest(
        table=manifest.table.head(n).reset_index(drop=True), root=manifest.root
    )


# --------------------------------------------------------------------------- stages


def staged_features(
    row: dict, root: Path, config: cohort.FeatureConfig, clock: dict
) -> tuple[dict, int]:
    """``load_session`` + ``session_features``, stage by stage, adding times to ``clock``.

    Mirrors :func:`tiltlab.cohort.session_features` call for call; returns a few of its
    features (to check the mirror) and the number of samples.
    """
    t = time.perf_counter
    t0 = t()
    rec = cohort.load_session(row, root)
    t1a = t()
    cal = _run._calibration_of(row, str(root))  # read once per subject and process
    t1 = t()
    schema.validate(rec, allow_nan=True)
    for v in ("acc", "gyr"):
        assert np.isfinite(rec[v].values).all()
    t2 = t()
    rec, _ = _features._corrected(rec, config, cal)
    t3 = t()
    q = filters.estimate(
        rec, config.method, use_mag=config.use_mag, **config.method_params
    )
    t4 = t()
    g = filters.gravity(q)
    gv = g.values
    t5 = t()
    speed = behavior.angular_speed(rec)
    sp = np.asarray(speed, float)
    imm = _features._immobile(speed, config, config.threshold_deg_s)
    moving = ~imm
    if config.auto_threshold:
        try:
            thr = behavior.valley_threshold(speed)
            _features._immobile(speed, config, thr)
        except ValueError:
            pass
    t6 = t()
    mesh = sphere.sphere_mesh(config.mesh_n)
    out = {"immobile_fraction": float(imm.mean())}
    for key, mask in (("visited_fraction", None), ("visited_fraction_moving", moving)):
        tmap = sphere.tilt_map(g, mesh=mesh, mask=mask)
        out[key] = sphere.visited_fraction(
            tmap, mesh, min_count=config.visited_min_count, by="area"
        )
    if imm.sum() >= 2:
        fit = sphere.vmf_fit(gv[imm])
        out["tilt_immobile_sagittal_deg"] = float(
            np.degrees(sphere.sagittal_angle(fit.mu, config.lesion_side))
        )
    t7 = t()
    if moving.any():
        out["circling_index"] = behavior.circling_index(rec, g, moving=moving)
        for qq in config.speed_quantiles:
            np.quantile(sp[moving], qq)
    t8 = t()
    to_g = units.conversion_factor(rec["acc"].attrs["units"], "g")
    out["dba_mean"] = float(
        np.mean(behavior.dba(rec, window_s=config.dba_window_s)) * to_g
    )
    np.mean(behavior.odba(rec, window_s=config.dba_window_s))
    t9 = t()
    gz = np.clip(gv[:, 2] / np.linalg.norm(gv, axis=1), -1.0, 1.0)
    tilt_deg = np.degrees(np.arccos(gz))
    for th in config.tilt_thresholds_deg:
        float(np.mean(tilt_deg > th))
    t10 = t()
    marks = (t0, t1a, t1, t2, t3, t4, t5, t6, t7, t8, t9, t10)
    for name, a, b in zip(STAGES, marks[:-1], marks[1:]):
        clock[name] += b - a
    return out, rec.sizes["time"]


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def bench_stages(manifest: cohort.Manifest, n: int, config) -> dict:
    rows = list(manifest.rows())[:n]
    root = manifest.root
    # compile / load the numba caches outside the timings
    cohort.session_features(
        simulate.simulate_session(30.0, 300.0, seed=99, keep_true=False), config
    )
    clock: dict[str, float] = defaultdict(float)
    samples, mismatch = 0, []
    t_ref = 0.0
    for row in rows:
        got, n_s = staged_features(row, root, config, clock)
        samples += n_s
        t0 = time.perf_counter()
        rec = cohort.load_session(row, root)
        ref = cohort.session_features(
            rec, config, calibration=_run._calibration_of(row, str(root))
        )
        t_ref += time.perf_counter() - t0
        for k, v in got.items():
            if not np.isclose(v, float(ref[k].values), rtol=1e-9, equal_nan=True):
                mismatch.append(f"{row['session']}:{k}")
    total = sum(clock.values())
    print(
        f"1. Per stage, one core, {len(rows)} session(s), {samples:,} samples "
        f"({samples / len(rows) / 300 / 60:.1f} min at 300 Hz each):"
    )
    print(f"   {'stage':<36}{'s/session':>10}{'M samples/s':>13}{'share':>8}")
    feat = STAGES[6:]
    for name in STAGES:
        dt = clock[name]
        print(
            f"   {name:<36}{dt / len(rows):10.3f}{samples / dt / 1e6:13.2f}{dt / total:8.1%}"
        )
    f_dt = sum(clock[s] for s in feat)
    print(
        f"   {'all feature families':<36}{f_dt / len(rows):10.3f}"
        f"{samples / f_dt / 1e6:13.2f}{f_dt / total:8.1%}"
    )
    print(
        f"   {'pipeline total':<36}{total / len(rows):10.3f}{samples / total / 1e6:13.2f}"
        f"{1:8.0%}"
    )
    print(
        f"   (load_session + session_features as run_cohort calls them: "
        f"{t_ref / len(rows):.3f} s/session, {samples / t_ref / 1e6:.2f} M samples/s)"
    )
    # how much of "read session" is the reader's own validation (session_features
    # validates the same Recording again: the "validate" stage)
    path = cohort.session_path(rows[0]["file"], root)
    t_raw = min(_timed(lambda: io.load_netcdf(path)) for _ in range(3))
    t_read = min(_timed(lambda: cohort.load_session(rows[0], root)) for _ in range(3))
    per = total / len(rows)
    twice = (t_read - t_raw) + clock["validate"] / len(rows)
    print(
        f"   read session = file {t_raw:.3f} s + the reader's validation "
        f"{t_read - t_raw:.3f} s; validation in all (twice per session): "
        f"{twice:.3f} s/session ({twice / per:.0%} of the pipeline)"
    )
    if mismatch:
        print(
            f"   WARNING: the staged mirror disagrees with session_features on {mismatch}: "
            "update staged_features"
        )
    top = max(STAGES, key=clock.__getitem__)
    print(f"   dominant stage: {top} ({clock[top] / total:.0%} of the pipeline)")
    return {"clock": dict(clock), "samples": samples, "sessions": len(rows)}


# --------------------------------------------------------------------------- end to end


def run(manifest, config, cache: Path, **kwargs) -> tuple[float, CpuMeter, object]:
    """Wall time, CPU meter and features of one ``run_cohort`` with a fresh cache."""
    shutil.rmtree(cache, ignore_errors=True)
    with CpuMeter() as cpu:
        t0 = time.perf_counter()
        ds = cohort.run_cohort(
            manifest, config, cache_dir=cache, progress=False, **kwargs
        )
        wall = time.perf_counter() - t0
    if int(ds.attrs["n_failed"]):
        raise RuntimeError(f"failed sessions: {cohort.summary(ds)}")
    return wall, cpu, ds


def cluster_startup(workers: int) -> float:
    """Wall time to start and close a local dask cluster of ``workers`` processes."""
    from distributed import Client, LocalCluster

    t0 = time.perf_counter()
    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
    )
    client = Client(cluster)
    client.close()
    cluster.close()
    return time.perf_counter() - t0


def same_features(a, b) -> bool:
    names = [v for v in a.data_vars if a[v].dtype.kind == "f"]
    return all(np.array_equal(a[v].values, b[v].values, equal_nan=True) for v in names)


def bench_end_to_end(manifest, config, tmp: Path, workers: int, samples: int) -> dict:
    n = len(manifest)
    print(
        f"2. End to end (run_cohort, fresh cache), the same {n} sessions, "
        f"{samples:,} samples:"
    )
    t_serial, cpu_serial, ds_serial = run(
        manifest, config, tmp / "cache_serial", scheduler=None
    )
    with CpuMeter() as cpu_start:
        t_start = cluster_startup(workers)
    t_dask, cpu_dask, ds_dask = run(
        manifest, config, tmp / "cache_dask", scheduler="dask", workers=workers
    )
    t_proc, cpu_proc, ds_proc = run(
        manifest, config, tmp / "cache_proc", scheduler="processes", workers=workers
    )
    ideal = t_serial / workers
    print(
        f"   {'scheduler':<30}{'wall s':>8}{'M samples/s':>13}{'speed-up':>10}"
        f"{'CPU s':>8}{'other CPU s':>13}"
    )
    for name, wall, cpu in (
        ("serial (scheduler=None)", t_serial, cpu_serial),
        (f"dask, {workers} workers", t_dask, cpu_dask),
        (f"processes, {workers} workers", t_proc, cpu_proc),
    ):
        print(
            f"   {name:<30}{wall:8.2f}{samples / wall / 1e6:13.2f}{t_serial / wall:10.2f}"
            f"{cpu.own:8.1f}{cpu.other:13.1f}"
        )
    print(
        f"   dask overhead against serial / {workers} (perfect scaling, {ideal:.2f} s): "
        f"{t_dask - ideal:+.2f} s ({(t_dask - ideal) / ideal:+.0%}); starting and "
        f"closing the cluster alone takes {t_start:.2f} s; dask used "
        f"{cpu_dask.own - cpu_serial.own:+.1f} CPU s more than serial"
    )
    print(
        f"   dask against a local process pool of the same size: {t_dask - t_proc:+.2f} s "
        f"(the scheduler's own cost; the rest of the gap to perfect scaling is the "
        f"machine's and the worker start-up's)"
    )
    print(
        f"   identical features: dask {same_features(ds_serial, ds_dask)}, "
        f"processes {same_features(ds_serial, ds_proc)}"
    )
    other = cpu_serial.other + cpu_start.other + cpu_dask.other + cpu_proc.other
    busy = t_serial + t_start + t_dask + t_proc
    if other > max(2.0, 0.05 * workers * busy):
        print(
            f"   WARNING: other programs used {other:.0f} CPU s of the {workers * busy:.0f} "
            "available during these runs: the wall times above are inflated; rerun on "
            "an idle machine"
        )
    return {
        "serial": t_serial,
        "dask": t_dask,
        "processes": t_proc,
        "startup": t_start,
        "cpu_dask": cpu_dask.own,
        "cpu_serial": cpu_serial.own,
        "other": other,
    }


# --------------------------------------------------------------------------- main


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--quick", action="store_true", help="smoke run (14 × 30 s)")
    mode.add_argument(
        "--full",
        action="store_true",
        help="the paper-size design itself (406 × 20 min)",
    )
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument(
        "--stage-sessions", type=int, default=3, help="sessions timed stage by stage"
    )
    ap.add_argument(
        "--compare-sessions",
        type=int,
        default=35,
        help="sessions of the serial/dask comparison (default 35, all of the default subset)",
    )
    ap.add_argument("--keep", action="store_true", help="keep the temporary folder")
    args = ap.parse_args()
    logging.getLogger("distributed").setLevel(logging.ERROR)

    if args.quick:
        design = simulate.CohortDesign(groups={"Kainate": 1, "Healthy": 1})
        duration_s, label = 30.0, "smoke run: 2 animals × 7 time points × 30 s"
    elif args.full:
        design, duration_s = simulate.CohortDesign(), 1200.0
        label = "paper-size design: 58 animals × 7 time points × 20 min"
    else:
        design, duration_s = simulate.CohortDesign.small(1), 1200.0
        label = "subset: 1 animal per group (5) × 7 time points × 20 min"
    config = cohort.FeatureConfig()
    print(
        f"tiltlab cohort pipeline, {label}, 300 Hz; method {config.method!r} "
        f"{config.method_params}; {args.workers} workers"
    )
    tmp = Path(tempfile.mkdtemp(prefix="tiltlab_bench_cohort_"))
    try:
        t0 = time.perf_counter()
        manifest = make_study(tmp / "study", design, duration_s, args.workers)
        n_all = len(manifest)
        per_session = int(round(duration_s * 300))
        t_sim = time.perf_counter() - t0
        print(
            f"0. simulated {n_all} sessions + {manifest.table['subject'].nunique()} tumble "
            f"tests in {t_sim:.1f} s ({n_all * per_session / t_sim / 1e6:.2f} M samples/s "
            f"with {args.workers} workers, files written): not part of the timed pipeline"
        )
        print()
        stage_n = min(args.stage_sessions, n_all)
        bench_stages(manifest, stage_n, config)
        print()
        n_cmp = min(args.compare_sessions, n_all)
        cmp = bench_end_to_end(
            subset(manifest, n_cmp), config, tmp, args.workers, n_cmp * per_session
        )
        print()
        # paper-size: fixed cluster start-up + the measured per-sample cost of the dask run
        per_sample = (cmp["dask"] - cmp["startup"]) / (n_cmp * per_session)
        est = cmp["startup"] + per_sample * PAPER_SAMPLES
        print(
            f"3. Paper-size design ({PAPER_SESSIONS} sessions, {PAPER_SAMPLES:,} samples), "
            f"dask, {args.workers} workers:"
        )
        print(
            f"   extrapolated from {n_cmp} measured sessions of {duration_s:g} s: "
            f"{est:7.1f} s ({PAPER_SAMPLES / est / 1e6:.2f} M samples/s)"
        )
        if args.quick:
            print(
                "   (smoke run: 30-s sessions carry more per-session overhead than 20-min "
                "ones; run without --quick for the estimate)"
            )
        # best case: the serial run's CPU cost per sample, spread perfectly over the
        # workers of an idle machine, plus starting the cluster
        cpu_est = cmp["startup"] + cmp["cpu_serial"] / args.workers * (
            PAPER_SAMPLES / (n_cmp * per_session)
        )
        print(
            f"   best case (serial CPU time per sample / {args.workers} idle cores + "
            f"cluster start): {cpu_est:7.1f} s"
        )
        if args.full:
            t_full, _, _ = run(
                manifest,
                config,
                tmp / "cache_full",
                scheduler="dask",
                workers=args.workers,
            )
            est = t_full
            print(
                f"   measured: {t_full:7.1f} s ({PAPER_SAMPLES / t_full / 1e6:.2f} M samples/s)"
            )
        if args.quick:
            print(f"   target < {TARGET_S:.0f} s: not assessed by a smoke run")
        else:
            verdict = "MET" if est < TARGET_S else "NOT MET"
            print(
                f"   target < {TARGET_S:.0f} s on {args.workers} cores: {verdict} "
                f"(ratio to target {est / TARGET_S:.2f})"
            )
    finally:
        if args.keep:
            print(f"kept in {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
