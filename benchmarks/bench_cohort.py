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
import threading
import time
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np

from tiltlab import behavior, cohort, filters, io, simulate, sphere, units
from tiltlab.cohort import features as _features
from tiltlab.cohort import run as _run
from tiltlab.cohort.schedulers import backend
from tiltlab.quality import QualityWarning

from _timing import print_scaling

PAPER_SESSIONS = 58 * 7
PAPER_SAMPLES = PAPER_SESSIONS * 1200 * 300
TARGET_S = 180.0
STAGES = (
    "read session",
    "read tumble test",
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
    by other programs, which inflates every wall time measured meanwhile. ``main`` is
    this process's own CPU time and ``workers`` the CPU seconds of each descendant that
    used more than 0.5 s (pool or dask workers), sampled every 0.2 s by a thread while
    they live.
    """

    def __init__(self):
        self.tick = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100
        self.own = self.other = self.main = float("nan")
        self.workers: dict[int, float] = {}
        self._stop = threading.Event()

    def _scan(self) -> tuple[set[int], dict[int, list[str]]]:
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
        return tree, fields

    def _tree(self) -> float:
        tree, fields = self._scan()
        return sum(sum(int(x) for x in fields[p][11:15]) for p in tree if p in fields)

    def _sample(self) -> None:
        me = os.getpid()
        while not self._stop.wait(0.2):
            try:
                tree, fields = self._scan()
            except OSError:
                continue
            for p in tree - {me}:
                if p in fields:
                    cpu = (int(fields[p][11]) + int(fields[p][12])) / self.tick
                    if p not in self._start:
                        self._start[p] = 0.0 if p not in self._before else cpu
                    self._last[p] = cpu

    @staticmethod
    def _busy() -> float:
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
        return sum(v) - v[3] - v[4]  # all but idle and iowait

    def __enter__(self) -> "CpuMeter":
        try:
            self._t0, self._b0 = self._tree(), self._busy()
            self._before = self._scan()[0]
        except OSError:
            self._t0 = None
            return self
        self._m0 = sum(os.times()[:2])
        self._start: dict[int, float] = {}
        self._last: dict[int, float] = {}
        self._thread = threading.Thread(target=self._sample, daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        if self._t0 is None:
            return
        self._stop.set()
        self._thread.join()
        own = self._tree() - self._t0
        self.own = own / self.tick
        self.other = max(self._busy() - self._b0 - own, 0) / self.tick
        self.main = sum(os.times()[:2]) - self._m0
        used = {p: self._last[p] - self._start[p] for p in self._last}
        self.workers = {p: c for p, c in used.items() if c > 0.5}


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
    # (no validation stage: load_session validated the Recording, and run_cohort's
    # session_features(validate=False) does not validate it again)
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
    marks = (t0, t1a, t1, t3, t4, t5, t6, t7, t8, t9, t10)
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
    # how much of "read session" is the reader's own validation, the only one
    path = cohort.session_path(rows[0]["file"], root)
    t_raw = min(_timed(lambda: io.load_netcdf(path)) for _ in range(3))
    t_read = min(_timed(lambda: cohort.load_session(rows[0], root)) for _ in range(3))
    per = total / len(rows)
    once = t_read - t_raw
    print(
        f"   read session = file {t_raw:.3f} s + the reader's validation "
        f"{once:.3f} s, the session's only validation ({once / per:.0%} of the pipeline)"
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


def startup(scheduler: str, workers: int) -> tuple[float, list]:
    """Wall time to start ``workers`` workers of a back end, give each a task, close it.

    Returns the time and, from the workers, their ``MALLOC_TRIM_THRESHOLD_`` and numba
    thread count (what ``run_cohort``'s tasks see there).
    """
    import numba

    t0 = time.perf_counter()
    b = backend(scheduler, workers)
    try:
        futs = [b.submit(time.sleep, 0.3) for _ in range(workers)]
        for f in futs:
            f.result()
        info = [
            b.submit(os.getenv, "MALLOC_TRIM_THRESHOLD_").result(),
            b.submit(numba.get_num_threads).result(),
        ]
    finally:
        b.close()
    return time.perf_counter() - t0 - 0.3, info


def same_features(a, b) -> bool:
    names = [v for v in a.data_vars if a[v].dtype.kind == "f"]
    return all(np.array_equal(a[v].values, b[v].values, equal_nan=True) for v in names)


def _row(name, wall, cpu, t_serial, cores, samples, n) -> str:
    per = sorted(cpu.workers.values(), reverse=True)
    in_workers = sum(per) if per else cpu.main
    shown = " + ".join(f"{c:.1f}" for c in per) if per else f"{cpu.main:.1f} (main)"
    return (
        f"   {name:<24}{wall:8.2f}{samples / wall / 1e6:9.2f}{t_serial / wall:9.2f}"
        f"{cpu.own:8.1f}{cpu.own / (wall * cores):7.0%}{in_workers / n:10.3f}"
        f"{cpu.other:8.1f}   {shown}"
    )


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
        t_start, info_dask = startup("dask", workers)
        t_pstart, info_proc = startup("processes", workers)
    t_dask, cpu_dask, ds_dask = run(
        manifest, config, tmp / "cache_dask", scheduler="dask", workers=workers
    )
    t_proc, cpu_proc, ds_proc = run(
        manifest, config, tmp / "cache_proc", scheduler="processes", workers=workers
    )
    print(
        f"   {'scheduler':<24}{'wall s':>8}{'M/s':>9}{'speed-up':>9}{'CPU s':>8}"
        f"{'util':>7}{'CPU s/ses':>10}{'other':>8}   CPU s per worker process"
    )
    print(_row("serial", t_serial, cpu_serial, t_serial, 1, samples, n))
    print(
        _row(
            f"dask, {workers} workers", t_dask, cpu_dask, t_serial, workers, samples, n
        )
    )
    print(
        _row(
            f"processes, {workers} workers",
            t_proc,
            cpu_proc,
            t_serial,
            workers,
            samples,
            n,
        )
    )
    print(
        "   (util: CPU s of the run's processes / (wall × cores it may use); CPU s/ses: "
        "CPU s in the workers (serial: this process) per session; other: CPU s taken by "
        "other programs meanwhile)"
    )
    print(
        f"   start-up (start the workers, one task each, close): dask {t_start:.2f} s, "
        f"processes {t_pstart:.2f} s; the workers see MALLOC_TRIM_THRESHOLD_="
        f"{info_dask[0]} (dask) / {info_proc[0]} (processes), numba threads "
        f"{info_dask[1]} / {info_proc[1]}"
    )
    for name, wall, t0 in (("dask", t_dask, t_start), ("processes", t_proc, t_pstart)):
        print(
            f"   {name}: speed-up {t_serial / wall:.2f} end to end, "
            f"{t_serial / max(wall - t0, 1e-9):.2f} without its start-up "
            f"(perfect: {workers})"
        )
    print(
        f"   identical features: dask {same_features(ds_serial, ds_dask)}, "
        f"processes {same_features(ds_serial, ds_proc)}"
    )
    other = cpu_serial.other + cpu_start.other + cpu_dask.other + cpu_proc.other
    busy = t_serial + t_start + t_pstart + t_dask + t_proc
    if other > max(2.0, 0.05 * workers * busy):
        print(
            f"   WARNING: other programs used {other:.0f} CPU s of the {workers * busy:.0f} "
            "available during these runs: the wall times above are inflated; judge by "
            "the CPU s per session, or rerun on an idle machine"
        )
    return {
        "serial": t_serial,
        "dask": t_dask,
        "processes": t_proc,
        "startup": t_start,
        "pstartup": t_pstart,
        "cpu_dask": cpu_dask.own,
        "cpu_serial": cpu_serial.own,
        "ses_dask": sum(cpu_dask.workers.values()) / n,
        "ses_processes": sum(cpu_proc.workers.values()) / n,
        "other": other,
    }


# --------------------------------------------------------------------------- scaling


def cropped(manifest: cohort.Manifest, tmp: Path, seconds: float, n: int):
    """``n`` sessions cycling the manifest's files, cut to their first ``seconds``."""
    import pandas as pd

    table = manifest.table
    folder = tmp / f"crop_{seconds:g}s"
    folder.mkdir(parents=True, exist_ok=True)
    files, cals = [], []
    for _, row in table.iterrows():
        dst = folder / Path(row["file"]).name
        if not dst.exists():
            rec = io.load_netcdf(cohort.session_path(row["file"], manifest.root))
            io.save_netcdf(rec.isel(time=slice(0, int(round(seconds * 300)))), dst)
        files.append(str(dst))
        cals.append(str(cohort.session_path(row["calibration"], manifest.root)))
    base = table.assign(file=files, calibration=cals)
    reps = [
        base.assign(session=base["session"] + f"_{k}")
        for k in range(-(-n // len(base)))
    ]
    rows = pd.concat(reps).head(n).reset_index(drop=True)
    return cohort.Manifest(table=rows, root=folder)


def _fit(sizes, times) -> float:
    return float(np.polyfit(np.log(sizes), np.log(times), 1)[0])


def bench_scaling(manifest, config, tmp: Path, workers: int, quick: bool) -> None:
    """Time at three sizes (×1, ×10, ×100) and the fitted exponent."""
    print("4. Scaling (time at ×1, ×10, ×100; time ~ n^b fitted on the three):")
    if not quick:
        secs = [12.0, 120.0, 1200.0]
        sub = subset(manifest, 3)
        ms = [cropped(sub, tmp, s_, 3) for s_ in secs]
        sizes = [3 * int(round(s_ * 300)) for s_ in secs]
        times = [run(m, config, tmp / "cache_scale", scheduler=None)[0] for m in ms]
        print(
            "   session duration 12 s / 120 s / 20 min, 3 sessions, serial (n = samples):"
        )
        print_scaling("   serial", sizes, times, _fit(sizes, times))
    k, secs_ = (1, 3.0) if quick else (1, 12.0)
    counts = [k, 10 * k, 100 * k]
    ms = [cropped(manifest, tmp, secs_, c) for c in counts]
    sizes = [c * int(round(secs_ * 300)) for c in counts]
    print(
        f"   session count {counts[0]} / {counts[1]} / {counts[2]} sessions of "
        f"{secs_:g} s (n = samples; start-up included):"
    )
    for name, kw in (
        ("serial", {"scheduler": None}),
        ("processes", {"scheduler": "processes", "workers": workers}),
        ("dask", {"scheduler": "dask", "workers": workers}),
    ):
        times = [run(m, config, tmp / "cache_scale", **kw)[0] for m in ms]
        print_scaling(f"   {name}", sizes, times, _fit(sizes, times))
        print(
            f"   {'':18s} {', '.join(f'{c}: {t:.2f} s' for c, t in zip(counts, times))}"
        )


def paper_size(
    cmp: dict, samples: int, workers: int, duration_s: float, n: int
) -> float:
    """Print the paper-size estimates (fixed start-up + measured cost per sample)."""
    scale = PAPER_SAMPLES / samples
    print(
        f"3. Paper-size design ({PAPER_SESSIONS} sessions, {PAPER_SAMPLES:,} samples), "
        f"{workers} workers, extrapolated from {n} measured sessions of {duration_s:g} s "
        "(start-up + cost per sample):"
    )
    serial = cmp["serial"] * scale
    print(f"   serial     {serial:7.1f} s")
    est = {}
    for name, start in (("dask", "startup"), ("processes", "pstartup")):
        t0 = min(cmp[start], cmp[name])
        est[name] = t0 + (cmp[name] - t0) * scale
        print(
            f"   {name:<10} {est[name]:7.1f} s ({PAPER_SAMPLES / est[name] / 1e6:.2f} M "
            f"samples/s; speed-up over serial {serial / est[name]:.2f})"
        )
    best = cmp["startup"] + cmp["cpu_serial"] / workers * scale
    print(
        f"   best case (serial CPU time per sample / {workers} idle cores + "
        f"cluster start): {best:7.1f} s"
    )
    for name, start in (("dask", "startup"), ("processes", "pstartup")):
        # scale * n: sessions of the measured length that hold the paper's samples
        cpu = cmp[start] + cmp[f"ses_{name}"] * scale * n / workers
        print(
            f"   {name:<10} from CPU accounting (start-up + the workers' CPU s per "
            f"session × {PAPER_SESSIONS} / {workers} idle cores): {cpu:7.1f} s "
            f"(speed-up over serial {cmp['cpu_serial'] * scale / cpu:.2f})"
        )
    return est["dask"]


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
    # cropped sessions may be clipped: that warning, once per session, is not timed
    warnings.filterwarnings("ignore", category=QualityWarning)
    # in the workers too (QualityWarning is a UserWarning; the workers start after this)
    os.environ["PYTHONWARNINGS"] = "ignore::UserWarning"

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
        est = paper_size(cmp, n_cmp * per_session, args.workers, duration_s, n_cmp)
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
            print(
                "   (smoke run: 30-s sessions carry more per-session overhead than 20-min "
                "ones; run without --quick for the estimate)"
            )
            print(f"   target < {TARGET_S:.0f} s: not assessed by a smoke run")
        else:
            verdict = "MET" if est < TARGET_S else "NOT MET"
            print(
                f"   target < {TARGET_S:.0f} s on {args.workers} cores: {verdict} "
                f"(ratio to target {est / TARGET_S:.2f})"
            )
        print()
        bench_scaling(manifest, config, tmp, args.workers, args.quick)
    finally:
        if args.keep:
            print(f"kept in {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
