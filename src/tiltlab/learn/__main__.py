"""Train the learned estimators from the command line: ``python -m tiltlab.learn``.

``python -m tiltlab.learn``: train the learned estimators with grouped
cross-validation on BROAD, check committed model files.

Examples
--------
::

    python -m tiltlab.learn train --out data/learn --epochs 40 --stride 32 \
        --validation 4 --patience 5 --threads 1               # the committed models
    python -m tiltlab.learn train --out /tmp/quick --epochs 1 --trials 1 2 24 25
    python -m tiltlab.learn ablate --out data/learn           # Tables 2-3 in small
    python -m tiltlab.learn check data/learn                  # verify SHA256SUMS
    python -m tiltlab.learn tune-baselines --out data/learn_baselines  # the filters
"""

from __future__ import annotations

import argparse
import shlex
import sys
from collections.abc import Sequence

from .baselines import save_tuned, tune_baselines
from .cv import ablate, check_files, cross_validate
from .training import TrainConfig


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``learn`` command line.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        The exit status.
    """
    p = argparse.ArgumentParser(prog="python -m tiltlab.learn", description=__doc__)
    sub = p.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("train", help="grouped cross-validation on BROAD")
    t.add_argument("--out", required=True, help="output folder")
    t.add_argument("--folds", type=int, default=5)
    t.add_argument("--trials", type=int, nargs="*", help="BROAD trials (default: all)")
    t.add_argument(
        "--variants", nargs="*", default=["quaternion", "gain"], help="model variants"
    )
    defaults = TrainConfig()
    for name in (
        "epochs",
        "batch",
        "stride",
        "channels",
        "seed",
        "threads",
        "patience",
    ):
        t.add_argument(f"--{name}", type=int, default=getattr(defaults, name))
    t.add_argument(
        "--validation",
        type=int,
        default=0,
        help="training trials per fold kept for validation and early stopping",
    )
    t.add_argument("--lr", type=float, default=defaults.lr)
    t.add_argument("--loss", default=defaults.loss)
    t.add_argument("--total", default=defaults.total)
    t.add_argument(
        "--activations", nargs=3, default=list(defaults.activations), metavar="ACT"
    )
    a = sub.add_parser("ablate", help="activation and loss ablations on one fold")
    a.add_argument("--out", required=True, help="output folder")
    a.add_argument("--fold", type=int, default=0)
    a.add_argument("--folds", type=int, default=5)
    a.add_argument("--epochs", type=int, default=2)
    a.add_argument("--threads", type=int, default=defaults.threads)
    c = sub.add_parser("check", help="verify the files listed in SHA256SUMS")
    c.add_argument("folder")
    b = sub.add_parser(
        "tune-baselines", help="tune the filter baselines on the networks' folds"
    )
    b.add_argument("--out", required=True, help="output folder")
    b.add_argument(
        "--learn", default="data/learn", help="folder of the networks (its run.json)"
    )
    b.add_argument("--jobs", type=int, default=1, help="threads of the grid search")
    args = p.parse_args(argv)
    try:
        if args.cmd == "check":
            for name, digest in check_files(args.folder).items():
                print(f"ok  {digest[:16]}  {name}")
            return 0
        argv_list = list(sys.argv[1:] if argv is None else argv)
        command = "python -m tiltlab.learn " + shlex.join(argv_list)
        progress = lambda s: print(s, file=sys.stderr, flush=True)  # noqa: E731
        if args.cmd == "tune-baselines":
            return _tune_baselines(args.out, args.learn, args.jobs, command)
        if args.cmd == "ablate":
            table = ablate(
                args.out,
                fold=args.fold,
                n_folds=args.folds,
                epochs=args.epochs,
                config=TrainConfig(threads=args.threads),
                command=command,
                progress=progress,
            )
            print(table.round(3).to_string(index=False))
            return 0
        cfg = TrainConfig(
            epochs=args.epochs,
            batch=args.batch,
            stride=args.stride,
            channels=args.channels,
            seed=args.seed,
            threads=args.threads,
            patience=args.patience,
            lr=args.lr,
            loss=args.loss,
            total=args.total,
            activations=tuple(args.activations),
        )
        table = cross_validate(
            args.out,
            trials=args.trials,
            n_folds=args.folds,
            variants=args.variants,
            config=cfg,
            n_validation=args.validation,
            command=command,
            progress=progress,
        )
    except (ValueError, OSError) as err:
        print(f"tiltlab.learn: {err}", file=sys.stderr)
        return 1
    summary = table.groupby("variant")[["qae_mean", "inclination", "total"]].mean()
    print(summary.round(2).to_string())
    return 0


def _tune_baselines(out: str, learn: str, jobs: int, command: str) -> int:
    """Tune the baselines on the folds of ``learn/run.json`` and write ``out``."""
    import json
    import time
    from pathlib import Path

    check_files(learn)
    folds = json.loads((Path(learn) / "run.json").read_text())["folds"]
    t0 = time.perf_counter()
    table = tune_baselines(folds, n_jobs=jobs, progress=True)
    path = save_tuned(table, out, command=command)
    print(table[["method", "fold", "parameters", "train_inclination"]].to_string())
    print(f"{path} written in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
