"""Scale: every registered orientation method on one 6-hour 300 Hz recording.

Target (issue "bad input, faults and scale"): every public method handles a 6-hour
300 Hz recording (6.48 M samples) on a 2-core, 24 GB machine, the error-state RTS
smoother included (its backward pass is checkpointed: bounded memory).

What is measured: each method of :func:`tiltlab.filters.methods` runs through
:func:`tiltlab.filters.estimate` on a synthetic Recording (slow rotations with rest
periods, noise, gyro bias; acc, gyr and mag, float64), in 6D and, where the method
supports it, in 9D. Each run is a fresh subprocess, so that memory peaks do not mix:
the subprocess loads the arrays, builds the Recording, warms the method up on 3000
samples (numba compilation or cache load), then resets its peak-RSS mark (Linux
``/proc/self/clear_refs``) and times one ``estimate`` call. Reported per run:

* ``seconds``: the wall time of that call (on the full recording, or extrapolated);
* ``peak GB``: the process's peak resident memory during the call (``VmHWM``; it
  includes the Python interpreter, the loaded arrays and the Recording);
* ``+GB``: that peak minus the resident memory just before the call, i.e. what the
  method (and ``estimate``'s output) added;
* ``samples/s``: samples over the measured wall time.

Not measured: generating the recording, imports, compilation. The pure-Python
``ahrs_*`` adapters would take hours: they run on 10 minutes and their time is
extrapolated linearly (labelled ``extrapolated``; their memory is that of the
10-minute run). ``riann`` (an ONNX network) first runs on 30 minutes; if that
predicts more than 15 minutes for the whole recording, the 30-minute rate is
extrapolated (labelled), otherwise it runs on the whole recording, unless the memory
the probe added, scaled linearly, exceeds 90 % of the available memory: then that run
is not started (it would push the machine into swap or the OOM killer) and the method
is reported as failed with the probe's figures (``--force`` runs it anyway). For
extrapolated rows the note also gives ``+GB`` scaled linearly to the whole recording
(an upper estimate for a method whose memory does not grow with N). A method that
fails (an exception, a crash, a time-out, not started) is reported in the table, and
the exit status is then 1.

Scaling section (after the table): each method that ran, on the first N/100, N/10 and
N samples of the N it ran on (×1, ×10, ×100), all in one more fresh subprocess (memory
is not measured there): best of 3 calls where the table predicts at most 2 s per call,
else one call; at N, where the table's call took more than 10 s, that call is used
(marked ``*``) instead of a rerun. One line per method with its throughput at each
size and the fitted exponent of time ~ n^b (1: linear). It adds about a tenth of the
table's time, plus a few seconds per method.

The figures are wall times on a shared machine: other programs' CPU load slows them.

Run: ``python benchmarks/bench_scale.py [--quick] [--hours 6] [--json out.json]``
(``--quick``: 10 minutes instead of 6 hours; nothing is written unless ``--json``).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

FS = 300.0
WARMUP = 3000
#: methods timed on a short recording and extrapolated linearly (pure Python)
SLOW = ("ahrs_madgwick", "ahrs_mahony", "ahrs_ekf")
SLOW_S = 600.0  # 10 minutes
RIANN_PROBE_S = 1800.0  # 30 minutes
RIANN_MAX_S = 900.0  # extrapolate riann when it would take longer than 15 minutes
M_ENU = 48.0 * np.array([0.0, np.cos(np.radians(64.0)), -np.sin(np.radians(64.0))])


def synthetic(n: int, fs: float = FS, seed: int = 0):
    """acc (m/s²), gyr (rad/s), mag (µT) of slow rotations with rest periods, float64.

    Angular rates are sums of slow sines under an envelope that rests a third of each
    4-minute cycle; sensor noise and a constant gyro bias are added. Cheap: a few
    vectorised passes over the N samples.
    """
    from tiltlab import quaternion as Q

    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    env = np.clip(1.5 * np.sin(2 * np.pi * t / 240.0) + 0.5, 0.0, 1.0)
    omega = np.empty((n, 3))
    omega[:, 0] = 1.2 * np.sin(0.7 * t)
    omega[:, 1] = 0.9 * np.cos(0.43 * t + 1.0)
    omega[:, 2] = 0.8 * np.sin(0.29 * t + 2.0)
    omega *= env[:, None]
    del t, env
    # truth with the filters' indexing: q[k] = q[k-1] ⊗ exp(ω_k Δt/2)
    q = Q.integrate_gyro(np.vstack([omega[1:], omega[-1:]]), fs, Q.identity())
    acc = 9.81 * Q.gravity(q)
    acc += 0.05 * rng.standard_normal((n, 3))
    mag = Q.rotate_inverse(q, M_ENU)
    del q
    mag += 0.5 * rng.standard_normal((n, 3))
    gyr = omega
    gyr += 0.005 * rng.standard_normal((n, 3))
    gyr += [0.004, -0.003, 0.002]
    return acc, gyr, mag


# ------------------------------------------------------------------ the subprocess


def _status_kb(field: str) -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    return -1


def child(method: str, data: Path, n: int, use_mag: bool) -> dict:
    """One timed ``estimate`` call in this (fresh) process; returns the measurements."""
    from tiltlab import filters as F
    from tiltlab.schema import make_recording

    arrays = {
        k: np.load(data / f"{k}.npy", mmap_mode="r") for k in ("acc", "gyr", "mag")
    }
    acc, gyr, mag = (np.array(arrays[k][:n]) for k in ("acc", "gyr", "mag"))
    del arrays

    def recording(a, g, m):
        return make_recording(
            a,
            g,
            FS,
            acc_units="m/s^2",
            gyr_units="rad/s",
            mag=m if use_mag else None,
            mag_units="uT",
        )

    F.estimate(
        recording(acc[:WARMUP], gyr[:WARMUP], mag[:WARMUP]), method, use_mag=use_mag
    )
    rec = recording(acc, gyr, mag)
    del acc, gyr, mag
    base_kb = _status_kb("VmRSS")
    try:  # reset the peak-RSS mark (VmHWM) to the current RSS
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        reset = True
    except OSError:
        reset = False
    t0 = time.perf_counter()
    q = F.estimate(rec, method, use_mag=use_mag)
    seconds = time.perf_counter() - t0
    peak_kb = _status_kb("VmHWM")
    if peak_kb < 0:
        peak_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    ok = q.shape == (n, 4) and bool(np.all(np.isfinite(q.values)))
    return {
        "seconds": seconds,
        "peak_gb": peak_kb * 1024 / 1e9,
        "base_gb": base_kb * 1024 / 1e9,
        "peak_reset": reset,
        "finite": ok,
    }


# ------------------------------------------------------------------ the parent


def available_gb() -> float:
    """MemAvailable of /proc/meminfo, GB (inf where unknown)."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024 / 1e9
    except OSError:
        pass
    return float("inf")


def run_one(
    method: str, data: Path, n: int, use_mag: bool, timeout: float, out: Path
) -> dict:
    """Run :func:`child` in a fresh interpreter; its own peak RSS from ``wait4``."""
    res_path = out / f"{method}_{int(use_mag)}_{n}.json"
    cmd = [
        sys.executable,
        __file__,
        "--child",
        method,
        "--data",
        str(data),
        "--n",
        str(n),
        "--out",
        str(res_path),
    ] + (["--use-mag"] if use_mag else [])
    log = out / f"{method}_{int(use_mag)}_{n}.log"
    t0 = time.perf_counter()
    with open(log, "w") as fh:
        proc = subprocess.Popen(cmd, stdout=fh, stderr=subprocess.STDOUT)
        timed_out = False
        while True:
            pid, status, ru = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if time.perf_counter() - t0 > timeout:
                proc.kill()  # the child started here
                pid, status, ru = os.wait4(proc.pid, 0)
                timed_out = True
                break
            time.sleep(0.2)
    proc.returncode = os.waitstatus_to_exitcode(status)
    row = {"process_peak_gb": ru.ru_maxrss * 1024 / 1e9}
    if res_path.is_file():
        row.update(json.loads(res_path.read_text()))
    if timed_out:
        row["error"] = f"timed out after {timeout:.0f} s"
    elif proc.returncode != 0 and "error" not in row:
        tail = log.read_text(errors="replace").strip().splitlines()[-3:]
        row["error"] = f"exit status {proc.returncode}: " + " | ".join(tail)
    elif "seconds" not in row and "error" not in row:
        row["error"] = "no result"
    return row


def run_probed(
    method: str,
    data: Path,
    n: int,
    n_probe: int,
    use_mag: bool,
    timeout: float,
    force: bool,
) -> dict:
    """A probe on ``n_probe`` samples, then the whole recording if the probe predicts at
    most ``RIANN_MAX_S`` seconds and (unless ``force``) memory that fits; otherwise the
    probe, extrapolated (too slow) or reported as a failure (too large)."""
    p = run_one(method, data, n_probe, use_mag, timeout, data)
    if "error" in p:
        return {**p, "n_run": n_probe, "extrapolated": True}
    added = p["peak_gb"] - p["base_gb"]
    probe = {
        "n": n_probe,
        "seconds": p["seconds"],
        "peak_gb": p["peak_gb"],
        "added_gb": added,
        "predicted_s": p["seconds"] * n / n_probe,
        "predicted_added_gb": added * n / n_probe,
    }
    minutes = f"{n_probe / FS / 60:g}"
    if probe["predicted_s"] > RIANN_MAX_S:
        note = (
            f"extrapolated from {minutes} min (> {RIANN_MAX_S / 60:g} min predicted; "
            "peak of the short run)"
        )
        return {
            **p,
            "probe": probe,
            "n_run": n_probe,
            "extrapolated": True,
            "note": note,
        }
    info = (
        f"the {minutes}-min probe: {p['seconds']:.0f} s, +{added:.2f} GB "
        f"(peak {p['peak_gb']:.2f} GB)"
    )
    avail = available_gb()
    if probe["predicted_added_gb"] > 0.9 * avail and not force:
        # its memory grows with N: a run that would not fit is not started (it would
        # push the machine into swap or the OOM killer) but reported as a failure
        error = (
            f"not run: {info}; linearly +{probe['predicted_added_gb']:.1f} GB for the "
            f"whole recording > 90 % of the {avail:.1f} GB available (--force runs it)"
        )
        return {"probe": probe, "n_run": n, "extrapolated": False, "error": error}
    r = run_one(method, data, n, use_mag, timeout, data)
    r = {**r, "probe": probe, "n_run": n, "extrapolated": False, "note": "measured"}
    if "error" in r:
        r["error"] += f" ({info})"
    return r


def child_scaling(data: Path, spec: list[dict]) -> list[dict]:
    """For each ``{"method", "use_mag", "sizes", "repeats"}`` of ``spec``: warm up, then
    time ``estimate`` on the first ``sizes`` samples, best of ``repeats`` calls (after
    one untimed call when more than one; 0: not timed, None returned); a method's
    exception is reported in its entry."""
    from tiltlab import filters as F
    from tiltlab.schema import make_recording

    from _timing import best_of

    n = max(max(e["sizes"]) for e in spec)
    arrays = {
        k: np.load(data / f"{k}.npy", mmap_mode="r") for k in ("acc", "gyr", "mag")
    }
    acc, gyr, mag = (np.array(arrays[k][:n]) for k in ("acc", "gyr", "mag"))
    del arrays

    def estimate(e: dict, k: int):
        rec = make_recording(
            acc[:k],
            gyr[:k],
            FS,
            acc_units="m/s^2",
            gyr_units="rad/s",
            mag=mag[:k] if e["use_mag"] else None,
            mag_units="uT",
        )
        return lambda: F.estimate(rec, e["method"], use_mag=e["use_mag"])

    out = []
    for e in spec:
        try:
            estimate(e, min(WARMUP, n))()
            times = [
                best_of(estimate(e, k), r, warmup=r > 1) if r else None
                for k, r in zip(e["sizes"], e["repeats"], strict=True)
            ]
            out.append({"seconds": times})
        except Exception as exc:  # reported by the parent, not hidden
            out.append({"error": f"{type(exc).__name__}: {exc}"})
    return out


def _repeats(row: dict, sizes: list[int]) -> list[int]:
    """Calls per size for the scaling section, from the table's time at N: 3 where a
    call is predicted to take at most 2 s, else 1; at N itself, 0 (the table's call is
    used) where it took more than 10 s."""
    per_sample = row["seconds"] / row["n_run"]
    reps = [3 if k * per_sample <= 2.0 else 1 for k in sizes]
    if row["seconds"] > 10.0:
        reps[-1] = 0
    return reps


def print_scale_scaling(rows: list[dict], data: Path, timeout: float) -> list[str]:
    """Time each successful row's method at N/100, N/10 and N (its measured N) in one
    fresh subprocess, print one scaling line per row and store it in the row; returns
    the failures."""
    from _scaling_extra import RTS_STEP, fit_exponent, note_far, print_line

    ok = [r for r in rows if "error" not in r]
    spec = []
    for r in ok:
        sizes = [r["n_run"] // 100, r["n_run"] // 10, r["n_run"]]
        spec.append(
            {
                "method": r["method"],
                "use_mag": r["dims"] != "6D",
                "sizes": sizes,
                "repeats": _repeats(r, sizes),
            }
        )
    if not spec:
        return []
    (data / "scaling_spec.json").write_text(json.dumps(spec))
    t0 = time.perf_counter()
    res = run_one("scaling", data, 0, False, timeout, data)
    wall = time.perf_counter() - t0
    if "error" in res:
        print(f"\nscaling: FAILED: {res['error']}")
        return ["scaling section"]
    print(
        "\nscaling (each method on N/100, N/10 and N samples, N as in the table; best "
        "of 3 calls where a call takes at most 2 s, else 1; * = N point from the "
        "table, not rerun):"
    )
    failed, exps = [], {}
    for r, e, got in zip(ok, spec, res["scaling"], strict=True):
        label = f"{r['method']} {r['dims']}"
        if "error" in got:
            print(f"{label:18s} FAILED: {got['error']}")
            failed.append(f"{label} (scaling)")
            continue
        times = got["seconds"]
        if times[-1] is None:
            times[-1] = r["seconds"]
            label += " *"
        b = fit_exponent(e["sizes"], times)
        print_line(label, e["sizes"], times, b)
        r["scaling"] = {"sizes": e["sizes"], "seconds": times, "exponent": b}
        exps[label] = b
    note_far(
        exps,
        "per-call costs that do not grow with n (validating the Recording, the "
        "initial orientation, building the output DataArray) weigh at N/100",
        high_known={"rts_smoother": RTS_STEP},
    )
    if any(k.endswith("*") for k in exps):
        print(
            "note: * rows fit reruns and the table's call, made at different times: "
            "a change of the machine's load between them moves their exponent"
        )
    print(f"(scaling section: {wall:.0f} s)")
    return failed


def _child_main(args) -> None:
    try:
        if args.child == "scaling":
            spec = json.loads((Path(args.data) / "scaling_spec.json").read_text())
            res = {"scaling": child_scaling(Path(args.data), spec), "seconds": 0.0}
        else:
            res = child(args.child, Path(args.data), args.n, args.use_mag)
    except Exception as exc:  # reported by the parent, not hidden
        res = {"error": f"{type(exc).__name__}: {exc}"}
    Path(args.out).write_text(json.dumps(res))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--quick", action="store_true", help="10 minutes instead of --hours"
    )
    ap.add_argument("--hours", type=float, default=6.0, help="recording length (h)")
    ap.add_argument(
        "--methods", nargs="*", default=None, help="subset of methods (default: all)"
    )
    ap.add_argument(
        "--timeout", type=float, default=3600.0, help="per run, seconds (killed after)"
    )
    ap.add_argument("--json", default=None, help="also write the table to this file")
    ap.add_argument(
        "--force",
        action="store_true",
        help="run riann on the whole recording even when its probe predicts that it "
        "will not fit in the available memory",
    )
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--data", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--n", type=int, default=0, help=argparse.SUPPRESS)
    ap.add_argument("--use-mag", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--out", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        _child_main(args)
        return

    from tiltlab import filters as F

    seconds = 600.0 if args.quick else args.hours * 3600.0
    n = int(round(seconds * FS))
    names = list(args.methods or F.methods())
    unknown = sorted(set(names) - set(F.methods()))
    if unknown:
        ap.error(f"unknown method(s) {unknown}")
    n_slow = min(n, int(SLOW_S * FS))
    n_probe = min(n, int(RIANN_PROBE_S * FS))
    label = f"{seconds / 3600:g} h" if seconds >= 3600 else f"{seconds / 60:g} min"
    print(
        f"tiltlab.filters at scale: {label} at {FS:g} Hz = {n:,} samples, "
        f"{os.cpu_count()} CPU cores, "
        f"{os.sysconf('SC_PAGE_SIZE') * os.sysconf('SC_PHYS_PAGES') / 2**30:.0f} GiB"
    )
    with tempfile.TemporaryDirectory(prefix="bench_scale_") as tmp:
        tmp = Path(tmp)
        t0 = time.perf_counter()
        acc, gyr, mag = synthetic(n)
        for k, v in (("acc", acc), ("gyr", gyr), ("mag", mag)):
            np.save(tmp / f"{k}.npy", v)
        del acc, gyr, mag
        print(f"synthetic recording: {time.perf_counter() - t0:.1f} s (not timed)\n")
        head = (
            f"{'method':15s} {'dims':>4s} {'seconds':>9s} {'peak GB':>8s} "
            f"{'+GB':>6s} {'samples/s':>10s}  note"
        )
        print(head)
        print("-" * len(head))
        rows, failed = [], []
        for name in names:
            m = F.METHODS[name]
            if m.requires_mag:  # e.g. davenport: acc + mag only
                modes: tuple[bool, ...] = (True,)
            else:
                modes = (False, True) if m.supports_mag else (False,)
            for use_mag in modes:
                dims = "9D" if use_mag else "6D"
                row = {
                    "method": name,
                    "dims": "A+M" if m.requires_mag else dims,
                    "n": n,
                }
                if name in SLOW and n_slow < n:
                    r = run_one(name, tmp, n_slow, use_mag, args.timeout, tmp)
                    row.update(r, n_run=n_slow, extrapolated=True)
                    row["note"] = (
                        f"extrapolated from {n_slow / FS / 60:g} min "
                        "(time linear; peak of the short run)"
                    )
                elif name == "riann" and n_probe < n:
                    row.update(
                        run_probed(
                            name, tmp, n, n_probe, use_mag, args.timeout, args.force
                        )
                    )
                else:
                    r = run_one(name, tmp, n, use_mag, args.timeout, tmp)
                    row.update(r, n_run=n, extrapolated=False, note="measured")
                if "error" in row:
                    row["note"] = f"FAILED on {row['n_run']:,} samples: {row['error']}"
                    failed.append(f"{name} {row['dims']}")
                    print(
                        f"{name:15s} {row['dims']:>4s} {'-':>9s} {'-':>8s} "
                        f"{'-':>6s} {'-':>10s}  {row['note']}",
                        flush=True,
                    )
                else:
                    if not row["finite"]:
                        row["note"] += "; WARNING: non-finite or misshapen output"
                        failed.append(f"{name} {row['dims']} (output)")
                    row["samples_per_s"] = row["n_run"] / row["seconds"]
                    row["seconds_total"] = row["seconds"] * n / row["n_run"]
                    row["added_gb"] = row["peak_gb"] - row["base_gb"]
                    if row["extrapolated"]:
                        row["added_gb_linear"] = row["added_gb"] * n / row["n_run"]
                        row["note"] += (
                            f"; +{row['added_gb_linear']:.2f} GB if memory grew "
                            "linearly"
                        )
                    if not row["peak_reset"]:
                        row["note"] += "; peak of the whole process"
                    print(
                        f"{name:15s} {row['dims']:>4s} {row['seconds_total']:9.1f} "
                        f"{row['peak_gb']:8.2f} {row['added_gb']:6.2f} "
                        f"{row['samples_per_s']:10.3g}  {row['note']}",
                        flush=True,
                    )
                rows.append(row)
        rts = [r for r in rows if r["method"] == "rts_smoother" and "error" not in r]
        if rts:
            r = rts[0]
            print(
                f"\nrts_smoother on {label}: peak {r['peak_gb']:.2f} GB "
                f"(+{r['added_gb']:.2f} GB over the loaded Recording), "
                f"{r['seconds_total']:.0f} s"
            )
        failed += print_scale_scaling(rows, tmp, args.timeout)
    if args.json:
        Path(args.json).write_text(
            json.dumps(
                {"fs": FS, "n": n, "hours": seconds / 3600, "rows": rows}, indent=1
            )
        )
        print(f"written: {args.json}")
    if failed:
        print(f"FAILED: {', '.join(failed)}")
        sys.exit(1)


if __name__ == "__main__":
    main()
