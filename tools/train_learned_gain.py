"""Train and cross-validate the learned-gain Mahony filter on BROAD (issue #26).

Usage: ``python tools/train_learned_gain.py [--out src/tiltlab/_weights/learned_gain] [--results FILE]``
or ``python tools/train_learned_gain.py --loto data/learn_gain_loto`` (leave one trial out).

Uses the 5 folds of the committed CNNs (``data/learn/run.json``). Per fold: grid
search on the 24 training trials (mean inclination RMSE) of the parent's fixed gains
(kp, ki > 0, kb > 0: a zero gain would stay zero under the multiplicative schedule;
the specific force low-passed in the world frame with VQF's default 3 s) and, apart,
of the package's Mahony (kb = 0, no low-pass); then the schedule trained on 20 of the
trials, early-stopped on the other 4; then all scored on the 6 held-out trials.
Across the 30 held-out trials: one-sided paired Wilcoxon signed-rank tests (learned
< parent, learned < VQF 6D), with VQF 6D/9D on the same trials.
Finally a model trained on all 30 trials is written to ``--out`` (``weights.json``,
with the fold models ``fold<i>.json`` and ``SHA256SUMS``). Single-threaded.

With ``--loto DIR`` it instead runs the paper's protocol (leave one trial out): for
each of the 30 trials, the parent is tuned and the schedule trained (validation
trials by :func:`tiltlab.learn.cv.validation_split`) on the other 29, and the
weights are written to ``DIR/fold<k>.json`` for the k-th trial in increasing order
(with ``SHA256SUMS`` and ``run.json``, whose ``folds`` lists each model's held-out
trial and ``models`` its tuned parent), so that
:func:`tiltlab.learn.gain_compare` scores them like any folds. Scoring is left to the
reader of the weights (chapter 5 runs them on the held-out trials).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from tiltlab import filters
from tiltlab.datasets import load_broad_trial
from tiltlab.evaluate import broad_errors
from tiltlab.filters._common import start_orientation
from tiltlab.filters.learned_gain import GainWeights, learned_gain, save_gain_weights
from tiltlab.learn.cv import validation_split
from tiltlab.learn.gain_schedule import gain_trial, train_schedule
from tiltlab.stats import wilcoxon_signed_rank

#: the package's Mahony (kb = 0, no low-pass), reported apart
MAHONY_KP = (0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 1.0, 2.0, 5.0)
MAHONY_KI = (0.0, 0.001, 0.003, 0.01, 0.03)
#: the parent (gains > 0: a zero gain stays zero under the multiplicative schedule)
KP_GRID = (0.2, 0.5, 1.0, 2.0, 5.0)
KI_GRID = (0.003, 0.01, 0.03, 0.1)
KB_GRID = (0.0003, 0.001, 0.003)
#: world-frame low-pass of the specific force: VQF's default tau_acc (not tuned)
TAU_ACC_S = 3.0


def _arrays(rec):
    acc = rec["acc"].transpose("time", ...).values
    gyr = rec["gyr"].transpose("time", ...).values
    return acc, gyr, float(rec.attrs["fs"])


def _incl(q, rec) -> float:
    return float(broad_errors(q, rec)["inclination"])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="src/tiltlab/_weights/learned_gain")
    ap.add_argument("--results", default="/tmp/learned_gain_results.json")
    ap.add_argument("--max-iter", type=int, default=100)
    ap.add_argument("--l2", type=float, default=1e-4)
    ap.add_argument("--loto", default=None, help="leave-one-trial-out output folder")
    args = ap.parse_args()
    folds = json.loads(Path("data/learn/run.json").read_text())["folds"]
    trials = sorted(t for f in folds for t in f)
    recs = {t: load_broad_trial(t) for t in trials}
    prepared = {}
    for t, rec in recs.items():
        acc, gyr, fs = _arrays(rec)
        q0 = start_orientation(None, acc, None, fs, 0.1)
        prepared[t] = gain_trial(
            acc,
            gyr,
            fs,
            rec["q_ref"].transpose("time", "quat").values,
            rec["movement"].values.astype(bool),
            q0,
        )
    t0 = time.perf_counter()
    grid = {}
    points = [(kp, ki, 0.0, 0.0) for kp in MAHONY_KP for ki in MAHONY_KI] + [
        (kp, ki, kb, TAU_ACC_S) for kp in KP_GRID for ki in KI_GRID for kb in KB_GRID
    ]
    for g in points:
        w = GainWeights.parent(*g)
        grid[g] = {
            t: _incl(learned_gain(*_arrays(r)[:2], _arrays(r)[2], weights=w), r)
            for t, r in recs.items()
        }
    grid_s = time.perf_counter() - t0

    def tune(train, mahony=False):
        keys = [g for g in grid if (g[3] == 0) == mahony]
        return min(keys, key=lambda g: np.mean([grid[g][t] for t in train]))

    def fit_schedule(train):
        """Tune the parent on ``train``, then train its schedule on all but one in
        six of those trials (the validation trials for early stopping)."""
        parent = tune(train)
        val = validation_split(train, -(-len(train) // 6))
        fit = [t for t in train if t not in val]
        w, hist = train_schedule(
            [prepared[t] for t in fit],
            [prepared[t] for t in val],
            *parent,
            l2=args.l2,
            max_iter=args.max_iter,
        )
        return parent, fit, val, w, hist

    if args.loto:
        _loto(Path(args.loto), trials, fit_schedule, grid_s)
        return
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows, fold_info, train_s = [], [], 0.0
    for i, held in enumerate(folds):
        train = [t for t in trials if t not in held]
        (kp, ki, kb, tau), fit, val, w, hist = fit_schedule(train)
        mkp, mki, _, _ = tune(train, mahony=True)
        train_s += hist["seconds"]
        w = w._replace(
            meta={"fold": i, "train": fit, "validation": val, "held_out": held}
        )
        save_gain_weights(w, out / f"fold{i}.json")
        fold_info.append(
            {
                "fold": i,
                "kp": kp,
                "ki": ki,
                "kb": kb,
                "tau_acc_s": tau,
                "mahony_kp": mkp,
                "mahony_ki": mki,
                "w_p": w.w_p.tolist(),
                "w_i": w.w_i.tolist(),
                "w_b": w.w_b.tolist(),
                "seconds": hist["seconds"],
                "val_parent": hist["validation_parent"],
                "val_best": min(hist["validation"], default=None),
                "iterations": len(hist["train"]),
            }
        )
        for t in held:
            rec = recs[t]
            acc, gyr, fs = _arrays(rec)
            row = {
                "trial": t,
                "fold": i,
                "mahony": _incl(filters.mahony(acc, gyr, fs, kp=mkp, ki=mki), rec),
                "parent": grid[kp, ki, kb, tau][t],
                "learned": _incl(learned_gain(acc, gyr, fs, weights=w), rec),
                "vqf_6d": _incl(filters.estimate(rec, "vqf").values, rec),
                "vqf_9d": _incl(filters.estimate(rec, "vqf", use_mag=True).values, rec),
            }
            rows.append(row)
            print(row, flush=True)
    summary = {}
    for k in ("mahony", "parent", "learned", "vqf_6d", "vqf_9d"):
        v = np.array([r[k] for r in rows])
        summary[k] = {"mean": float(v.mean()), "median": float(np.median(v))}
    lp = np.array([r["learned"] for r in rows])
    pp = np.array([r["parent"] for r in rows])
    test = wilcoxon_signed_rank(lp, pp, alternative="less")
    summary["wilcoxon_learned_lt_parent_p"] = float(test.p)
    vq = np.array([r["vqf_6d"] for r in rows])
    summary["wilcoxon_learned_lt_vqf6d_p"] = float(
        wilcoxon_signed_rank(lp, vq, alternative="less").p
    )
    summary["n_better"] = int(np.sum(lp < pp))
    # final model on all 30 trials
    (kp, ki, kb, tau), fit, val, w, hist = fit_schedule(trials)
    w = w._replace(
        meta={
            "trained_on": "BROAD",
            "train": fit,
            "validation": val,
            "script": "tools/train_learned_gain.py",
        }
    )
    save_gain_weights(w, out / "weights.json")
    res = {
        "rows": rows,
        "summary": summary,
        "folds": fold_info,
        "grid_seconds": grid_s,
        "train_seconds_folds": train_s,
        "final": {
            "kp": kp,
            "ki": ki,
            "kb": kb,
            "tau_acc_s": tau,
            "seconds": hist["seconds"],
        },
    }
    Path(args.results).write_text(json.dumps(res, indent=1))
    print(json.dumps(summary, indent=1))


def _loto(out: Path, trials, fit_schedule, grid_s: float) -> None:
    """Leave one trial out: a parent and a schedule per held-out trial."""
    out.mkdir(parents=True, exist_ok=True)
    models, total = {}, 0.0
    for k, t in enumerate(trials):
        train = [s for s in trials if s != t]
        (kp, ki, kb, tau), fit, val, w, hist = fit_schedule(train)
        total += hist["seconds"]
        meta = {"fold": k, "held_out": [t], "train": fit, "validation": val}
        save_gain_weights(w._replace(meta=meta), out / f"fold{k}.json")
        models[f"fold{k}.json"] = {
            "held_out": t,
            "kp": kp,
            "ki": ki,
            "kb": kb,
            "tau_acc_s": tau,
            "iterations": len(hist["train"]),
            "seconds": round(hist["seconds"], 1),
        }
        print(t, models[f"fold{k}.json"], flush=True)
    run = {
        "command": "python tools/train_learned_gain.py --loto " + str(out),
        "protocol": "leave one trial out; parent tuned and schedule trained on the "
        "other 29 trials, one in six of them kept for early stopping",
        "threads": 1,
        "folds": [[t] for t in trials],
        "grid_seconds": round(grid_s, 1),
        "train_seconds": round(total, 1),
        "models": models,
    }
    (out / "run.json").write_text(json.dumps(run, indent=1) + "\n")


if __name__ == "__main__":
    main()
