"""Inference speed of the learned orientation estimators (tiltlab.learn) on the CPU,
against filters and the published RIANN network, all measured in the same run on the
same BROAD trial (trial 2: 53,240 samples at 285.7 Hz).

What is timed (median wall time of ``--repeat`` calls, after an untimed warm-up on the
trial's first samples; samples/s; ratio = how many times slower than Mahony 9D):

* Mahony 9D, ESKF 9D, VQF 9D: ``tiltlab.filters.run_method(method, inputs)`` on inputs read
  once by ``tiltlab.filters.prepare(rec, use_mag=True)`` (as bench_filters.py: reading
  the Recording is not timed);
* RIANN 6D: ``tiltlab.filters.run_method("riann", inputs_6d)`` (onnxruntime with its default
  threads; each call also creates the ONNX session, as ``filters.estimate`` does);
* CNN input: ``tiltlab.learn.sequence(rec)`` (reads the Recording, integrates the gyro,
  Davenport orientation of every sample), timed on its own;
* CNN (quaternion) and CNN (learned gain): the closed-loop network loop
  ``tiltlab.learn.closed_loop_estimate(model, seq, cfg)``, with ``torch.set_num_threads(1)`` and ``(2)``;
  and "batched xB": ``tiltlab.learn.closed_loop_estimates(model, [seq] * B, cfg)`` (B = 6
  recordings in one batch, as chapter 5 runs a fold's trials; the first of ``--threads``),
  its samples/s counting all B recordings.
  The end to end cost of a CNN is its input row plus its loop row (printed below the
  table).

Scaling section: Mahony 9D, RIANN 6D, the CNN input and both CNN loops (with the first
of ``--threads``) on the trial's first N/100, N/10 and N samples (×1, ×10, ×100; best
of ``--repeat`` calls each), one line per method with its throughput at each size and
the fitted exponent of time ~ n^b (1: linear). Per-call costs that do not grow with n
(Mahony's input checks, the CNN input's reading of the Recording, RIANN's ONNX session
created at each call) pull the exponent below 1 where they weigh at the smallest size.

The weights do not change the speed: ``data/learn/<variant>_fold0.pt`` is used when it
exists, else ``/tmp/quick/<variant>_fold0.pt``, else a model trained for 5 steps (the
script prints which). The figures are wall times: run it on an otherwise idle machine.

Run: ``.venv/bin/python benchmarks/bench_learn.py [--quick] [--repeat 3] [--trial 2]
[--threads 1 2]`` (with ``TILTLAB_DATA_DIR`` pointing at the data, ``TILTLAB_OFFLINE=1``
offline). With more torch threads than idle cores, the loop's threads wait on each
other (a 2-thread run on a 2-core machine with another busy process can be 10-100x
slower than 1 thread): pass ``--threads 1`` on a busy machine.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
from pathlib import Path

import torch

import tiltlab
import tiltlab.learn as L
from tiltlab import filters as F
from _scaling_extra import ladder, note_far, scaling_section
from _timing import best_of

ROOT = Path(__file__).resolve().parents[1]
MODEL_DIRS = (ROOT / "data" / "learn", Path("/tmp/quick"))
VARIANTS = {"quaternion": "CNN (quaternion)", "gain": "CNN (learned gain)"}
BATCH = 6  # recordings per batch in the batched CNN rows (a fold's test trials)
FILTERS = [
    ("Mahony 9D", "mahony", True),
    ("ESKF 9D", "eskf", True),
    ("VQF 9D", "vqf", True),
    ("RIANN 6D", "riann", False),
    ("learned gain 6D", "learned_gain", False),
]
WARMUP = 2000  # samples of the untimed warm-up call


def median_of(fn, repeat: int) -> float:
    """Median wall time (s) of ``repeat`` calls of ``fn()`` (each timed by best_of)."""
    return statistics.median(best_of(fn, repeat=1) for _ in range(repeat))


def head(obj, n: int):
    """The first ``n`` samples of a learn.Sequence or filters Inputs (for warm-ups)."""
    cut = {
        f.name: getattr(obj, f.name)[:n]
        for f in dataclasses.fields(obj)
        if f.name in ("Q", "acc", "gyr", "mag", "q_vec", "q_ref")
        and getattr(obj, f.name) is not None
    }
    return dataclasses.replace(obj, **cut)


def model_for(variant: str, rec):
    """(model, config, where it came from) for ``variant``."""
    for folder in MODEL_DIRS:
        path = folder / f"{variant}_fold0.pt"
        if path.is_file():
            model, cfg, _ = L.load_model(path)
            return model, cfg, str(path)
    cfg = L.TrainConfig(variant=variant, epochs=1)
    seq = L.sequence(rec, acc_scale=cfg.acc_scale, mag_scale=cfg.mag_scale)
    model, _ = L.train([seq], cfg, max_steps=5)
    torch.use_deterministic_algorithms(False)  # set by train; load() leaves it off
    return model, cfg, "untrained (5 steps on this trial; no model file found)"


def print_learn_scaling(rec, inputs, models, threads: int, repeat: int) -> None:
    """Scaling of Mahony, RIANN, the CNN input and the CNN loops on the trial's first
    N/100, N/10 and N samples."""
    n = rec.sizes["time"]
    sizes = ladder(n)
    torch.set_num_threads(threads)
    x9 = {k: head(inputs[True], k) for k in sizes}
    x6 = {k: head(inputs[False], k) for k in sizes}
    recs = {k: rec.isel(time=slice(0, k)) for k in sizes}
    cases = [
        ("Mahony 9D", lambda k: F.run_method("mahony", x9[k])),
        ("RIANN 6D", lambda k: F.run_method("riann", x6[k])),
        ("learned gain 6D", lambda k: F.run_method("learned_gain", x6[k])),
    ]
    seqs = {}
    for variant, (model, cfg) in models.items():
        key = (cfg.acc_scale, cfg.mag_scale)
        if key not in seqs:
            cases.append(
                (
                    "CNN input" + (f" {len(seqs) + 1}" if seqs else ""),
                    lambda k, a=key[0], m=key[1]: L.sequence(
                        recs[k], acc_scale=a, mag_scale=m
                    ),
                )
            )
            seq = L.sequence(rec, acc_scale=key[0], mag_scale=key[1])
            seqs[key] = {k: head(seq, k) for k in sizes}
        cases.append(
            (
                VARIANTS[variant].replace("learned ", ""),
                lambda k, mo=model, c=cfg, s=seqs[key]: L.closed_loop_estimate(
                    mo, s[k], c
                ),
            )
        )
    exps = scaling_section(
        f"BROAD trial, torch threads {threads}, best of {repeat}",
        sizes,
        cases,
        repeat,
    )
    note_far(
        exps,
        f"per-call costs that do not grow with n weigh at {sizes[0]:,} samples "
        "(Mahony: input checks and the call, a fraction of a millisecond; CNN input: "
        "reading the Recording through xarray; RIANN: an ONNX session created at "
        "each call)",
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--quick", action="store_true", help="smoke run: one timed call per method"
    )
    ap.add_argument(
        "--repeat", type=int, default=3, help="timed calls per method (median)"
    )
    ap.add_argument("--trial", type=int, default=2, help="BROAD trial")
    ap.add_argument(
        "--threads",
        type=int,
        nargs="+",
        default=[1, 2],
        help="torch thread counts of the CNN loop (default: 1 2)",
    )
    args = ap.parse_args()
    repeat = 1 if args.quick else args.repeat

    rec = tiltlab.datasets.load(f"broad:{args.trial}")
    n = rec.sizes["time"]
    fs = float(rec.attrs["fs"])
    load1 = os.getloadavg()[0]
    print(
        f"tiltlab.learn inference benchmark: BROAD trial {args.trial}, N = {n:,} samples "
        f"at {fs:.1f} Hz, {os.cpu_count()} CPU cores, median of {repeat} call(s), "
        f"torch {torch.__version__} (load average {load1:.2f})"
    )

    models = {}
    for variant in VARIANTS:
        model, cfg, origin = model_for(variant, rec)
        models[variant] = (model, cfg)
        print(f"  {variant} model: {origin}")

    rows = []  # (method, threads, seconds)

    # ---- filters and RIANN, on inputs read once
    inputs = {True: F.prepare(rec, use_mag=True), False: F.prepare(rec)}
    for label, method, use_mag in FILTERS:
        x = inputs[use_mag]
        F.run_method(method, head(x, WARMUP))  # warm-up (numba compile / cache load)
        rows.append((label, "-", median_of(lambda: F.run_method(method, x), repeat)))

    # ---- CNN: input preparation, then the closed-loop network loop
    seqs = {}
    for variant, (model, cfg) in models.items():
        key = (cfg.acc_scale, cfg.mag_scale)
        if key not in seqs:
            L.sequence(rec, acc_scale=key[0], mag_scale=key[1])  # warm-up
            t_seq = median_of(
                lambda: L.sequence(rec, acc_scale=key[0], mag_scale=key[1]), repeat
            )
            rows.append(("CNN input (sequence)", "-", t_seq))
            seqs[key] = L.sequence(rec, acc_scale=key[0], mag_scale=key[1])
        seq = seqs[key]
        for threads in args.threads:
            torch.set_num_threads(threads)
            L.closed_loop_estimate(model, head(seq, WARMUP), cfg)  # warm-up
            t = median_of(lambda: L.closed_loop_estimate(model, seq, cfg), repeat)
            rows.append((VARIANTS[variant], str(threads), t))
        torch.set_num_threads(args.threads[0])
        many = [seq] * BATCH
        t = median_of(lambda: L.closed_loop_estimates(model, many, cfg), repeat)
        rows.append(
            (f"{VARIANTS[variant]} batched x{BATCH}", str(args.threads[0]), t / BATCH)
        )

    t_mahony = rows[0][2]
    print(
        f"\n{'method':30s} {'torch threads':>13s} {'median (s)':>11s} "
        f"{'samples/s':>12s} {'vs Mahony':>10s}"
    )
    for label, threads, t in rows:
        print(
            f"{label:30s} {threads:>13s} {t:11.4f} {n / t:12,.0f} {t / t_mahony:9.1f}x"
        )

    t_in = dict((r[0], r[2]) for r in rows)["CNN input (sequence)"]
    print("\nend to end (CNN input + network loop):")
    for label, threads, t in rows:
        if label in VARIANTS.values():
            tt = t_in + t
            print(
                f"  {label:20s} {threads} thread(s): {tt:.3f} s, {n / tt:,.0f} samples/s, "
                f"{tt / t_mahony:.1f}x Mahony"
            )
    print_learn_scaling(rec, inputs, models, args.threads[0], repeat)
    load2 = os.getloadavg()[0]
    if max(load1, load2) > 0.5:
        print(
            f"\nnote: load average {load1:.2f} -> {load2:.2f} during the run: other "
            "programs shared the CPU, the wall times are pessimistic"
        )


if __name__ == "__main__":
    main()
