r"""Cross-validate the learned estimators on BROAD and compare them with filters.

Grouped cross-validation on BROAD, the committed model files, and the comparison
table against filters and RIANN.

Folds are groups of whole trials: no window of a test trial is ever seen in training.
Trials are dealt to the folds in order within each BROAD group (undisturbed and
disturbed separately), so every fold holds disturbed trials in its test set.

Files written by :func:`cross_validate` (the ``learn`` command) in its output folder:

* ``<variant>_fold<k>.pt``: weights, configuration and ``fs`` (:func:`save`);
* ``run.json``: the command line, the configurations, the folds, package versions;
* ``history.json``: training curves (per variant, fold and epoch);
* ``metrics.json``: per test trial, QAE (Eq. 4, degrees) and BROAD's RMSEs;
* ``SHA256SUMS``: the sha256 of every file above, checked by :func:`check_files`,
  and by :func:`load_model` for each weights file it loads.
"""

from __future__ import annotations

import json
import platform
import time
from collections.abc import Callable, Iterable, Sequence as Seq
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .. import _deprecate
from .. import _validate as _v
from .._labels import label_columns
from .. import datasets
from .. import evaluate
from .. import filters
from .. import quaternion as quat
from .data import sequence
from ..io.checksums import check_sums, write_sums
from .files import load_model, save, sha256, write_json
from .training import TrainConfig, closed_loop_estimate, closed_loop_estimates, train

__all__ = [
    "ABLATIONS",
    "ablate",
    "folds",
    "cross_validate",
    "validation_split",
    "check_files",
    "trial_errors",
    "learned_estimate",
    "compare",
    "compare_summary",
    "BASELINES",
    "ERROR_COLUMNS",
]

#: Error columns of :func:`trial_errors` and :func:`compare`: name → long name (deg).
ERROR_COLUMNS: dict[str, str] = {
    "inclination": "inclination RMSE",
    "heading": "heading RMSE",
    "total": "total RMSE",
    "qae_mean": "mean QAE",
    "qae_median": "median QAE",
}

#: Baselines of the comparison: label -> (registry method, 9D)
BASELINES: dict[str, tuple[str, bool]] = {
    "Mahony 9D": ("mahony", True),
    "ESKF 9D": ("eskf", True),
    "VQF 9D": ("vqf", True),
    "RIANN 6D": ("riann", False),
}


def folds(trials: Iterable[int], n_folds: int) -> list[list[int]]:
    """Deal BROAD trials to ``n_folds`` test folds, each with both kinds of trial.

    Deal BROAD trials to ``n_folds`` test folds, undisturbed and disturbed separately
    (in trial order), so that each fold has both kinds.

    Parameters
    ----------
    trials : iterable of int
        BROAD trial numbers.
    n_folds : int
        Number of folds, in ``2 .. len(trials)``.

    Returns
    -------
    list of list of int
        The test trials of each fold, each sorted.

    Raises
    ------
    ValueError
        If ``n_folds`` is out of range.
    """
    groups = datasets.broad_trial_groups()
    trials = sorted(int(t) for t in trials)
    if n_folds < 2 or n_folds > len(trials):
        raise ValueError(f"n_folds must be in 2..{len(trials)}, got {n_folds}")
    out: list[list[int]] = [[] for _ in range(n_folds)]
    k = 0
    for kind in ("undisturbed", "disturbed"):
        for t in trials:
            if kind in groups.get(t, []):
                out[k % n_folds].append(t)
                k += 1
    return [sorted(f) for f in out]


@_deprecate.renamed(recording="rec")
def trial_errors(q, rec) -> dict[str, float]:
    """Score an estimate by QAE and BROAD's RMSEs over the movement samples.

    QAE is Eq. 4 (mean and median, degrees), over the movement samples with a valid
    reference.

    Parameters
    ----------
    q : array_like (N, 4)
        Estimated unit quaternions (w, x, y, z), one per sample of ``rec``.
    rec : xarray.Dataset
        BROAD trial Recording with ``q_ref`` and ``movement``.

    Returns
    -------
    dict
        ``qae_mean`` and ``qae_median`` (degrees), and BROAD's ``inclination``,
        ``heading`` and ``total`` RMSEs (degrees).
    """
    e = evaluate.broad_errors(q, rec)
    q = np.asarray(q, float)
    ref = rec["q_ref"].transpose("time", "quat").values
    mask = np.all(np.isfinite(ref), axis=1) & rec["movement"].values.astype(bool)
    d = np.abs(np.sum(q[mask] * ref[mask], axis=1))
    qae_deg = np.degrees(np.arccos(np.clip(2 * d * d - 1, -1, 1)))
    return {
        "qae_mean": float(qae_deg.mean()),
        "qae_median": float(np.median(qae_deg)),
        "inclination": e["inclination"],
        "heading": e["heading"],
        "total": e["total"],
    }


def validation_split(train_trials: Iterable[int], n: int) -> list[int]:
    """Pick ``n`` validation trials, evenly spread, from a fold's training trials.

    Parameters
    ----------
    train_trials : iterable of int
        The fold's training trials.
    n : int
        How many to keep out for validation (0: none).

    Returns
    -------
    list of int
        Sorted validation trials; the same for the same inputs.

    Examples
    --------
    >>> validation_split([1, 2, 3, 4, 5, 6, 7, 8], 2)
    [1, 5]
    """
    pool = sorted(int(t) for t in train_trials)
    n = int(_v.integer(n, "n", minimum=0))
    if n >= len(pool) and n:
        raise ValueError(
            f"cannot keep {n} of {len(pool)} training trials for validation: at "
            "least one must remain for training"
        )
    if n == 0:
        return []
    step = len(pool) / n
    return sorted(pool[int(i * step)] for i in range(n))


def cross_validate(
    out: str | Path,
    *,
    trials: Seq[int] | None = None,
    n_folds: int = 5,
    variants: Seq[str] = ("quaternion", "gain"),
    config: TrainConfig | None = None,
    n_validation: int = 0,
    command: str = "",
    progress: Callable[[str], None] = print,
) -> pd.DataFrame:
    """Train one model per variant and fold and evaluate it on its held-out trials.

    Train one model per variant and fold, evaluate it on its held-out trials and
    write the files listed in the module docstring to ``out``.

    Parameters
    ----------
    out : str or pathlib.Path
        Output folder (created if needed).
    trials : sequence of int, optional
        BROAD trial numbers; default all of them.
    n_folds : int, default 5
        Number of folds (:func:`folds`).
    variants : sequence of str, default ("quaternion", "gain")
        Model variants (``TrainConfig.variant``) to train.
    config : TrainConfig, optional
        Base configuration, default ``TrainConfig()``; ``variant`` is set per variant.
    n_validation : int, default 0
        Training trials of each fold kept out of its training for validation
        (:func:`validation_split`): the weights of the epoch with the lowest
        closed-loop validation error are kept, and training stops early after
        ``config.patience`` epochs without improvement. 0 trains on every training
        trial for ``config.epochs`` epochs.
    command : str, default ""
        Command line recorded in the output files.
    progress : callable, default print
        Called with a progress message (str).

    Returns
    -------
    pandas.DataFrame
        One row per (variant, trial) with the fold and :func:`trial_errors`.
    """
    import torch

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    base = config or TrainConfig()
    trials = sorted(datasets.broad_trials()) if trials is None else sorted(trials)
    fold_list = folds(trials, n_folds)
    recs = {t: datasets.load_broad_trial(t) for t in trials}
    seqs = {
        t: sequence(r, acc_scale=base.acc_scale, mag_scale=base.mag_scale)
        for t, r in recs.items()
    }
    history: dict[str, Any] = {}
    rows: list[dict[str, Any]] = []
    configs = {}
    n_validation = int(_v.integer(n_validation, "n_validation", minimum=0))
    held = {
        k: validation_split([t for t in trials if t not in test], n_validation)
        for k, test in enumerate(fold_list)
    }
    for variant in variants:
        cfg = TrainConfig.from_dict({**base.to_dict(), "variant": variant})
        configs[variant] = cfg.to_dict()
        for k, test in enumerate(fold_list):
            train_set = [seqs[t] for t in trials if t not in test and t not in held[k]]
            progress(f"{variant}, fold {k + 1}/{len(fold_list)}: test trials {test}")
            t0 = time.perf_counter()
            model, hist = train(
                train_set,
                cfg,
                validation=[seqs[t] for t in held[k]],
                progress=progress,
            )
            history[f"{variant}/fold{k}"] = hist
            save(model, cfg, train_set[0].fs, out / f"{variant}_fold{k}.pt")
            for t in test:
                q = closed_loop_estimate(model, seqs[t], cfg)
                rows.append(
                    {"variant": variant, "fold": k, "trial": t}
                    | trial_errors(q, recs[t])
                )
            progress(f"  done in {time.perf_counter() - t0:.0f} s")
    table = pd.DataFrame(rows)
    write_json(
        {
            "command": command,
            "configs": configs,
            "folds": fold_list,
            **(
                {"validation": [held[k] for k in range(len(fold_list))]}
                if n_validation
                else {}
            ),
            "trials": list(trials),
            "versions": {
                "python": platform.python_version(),
                "torch": torch.__version__,
                "numpy": np.__version__,
            },
        },
        out / "run.json",
    )
    write_json(history, out / "history.json")
    write_json(table.to_dict(orient="records"), out / "metrics.json")
    _write_sums(out)
    return table


#: Ablations in the spirit of Zaheer et al.'s Tables 2 (activations: first, hidden,
#: last) and 3 (total and sample loss), all other settings at their defaults.
ABLATIONS: dict[str, dict[str, Any]] = {
    **{
        f"table2/{'-'.join(a)}": {"activations": a}
        for a in [
            ("tanh", "tanh", "tanh"),
            ("prelu", "prelu", "prelu"),
            ("prelu", "prelu", "tanh"),
            ("gelu", "gelu", "gelu"),
            ("gelu", "gelu", "tanh"),
        ]
    },
    **{
        f"table3/{total}-{loss}": {"total": total, "loss": loss}
        for total, loss in [
            ("L1", "acos_taylor1"),
            ("L2", "acos_taylor1"),
            ("L2", "acos_taylor2"),
            ("L1", "l1_product"),
            ("L2", "l1_product"),
            ("L2", "l2_product"),
        ]
    },
}


def ablate(
    out: str | Path,
    *,
    fold: int = 0,
    n_folds: int = 5,
    epochs: int = 2,
    config: TrainConfig | None = None,
    command: str = "",
    progress: Callable[[str], None] = print,
) -> pd.DataFrame:
    """Train and evaluate the quaternion variant once per entry of :data:`ABLATIONS`.

    Train the quaternion variant once per entry of :data:`ABLATIONS` on one fold's
    training trials (``epochs`` epochs) and evaluate it, in closed loop, on that fold's
    test trials. Writes ``ablation.json`` to ``out``.

    Parameters
    ----------
    out : str or pathlib.Path
        Output folder (created if needed).
    fold : int, default 0
        Index of the test fold, in ``0 .. n_folds - 1``.
    n_folds : int, default 5
        Number of folds the BROAD trials are dealt to (:func:`folds`).
    epochs : int, default 2
        Training epochs of each ablation.
    config : TrainConfig, optional
        Base configuration (default ``TrainConfig()``); ``epochs`` and the
        ``"quaternion"`` variant override it, then each :data:`ABLATIONS` entry.
    command : str, default ""
        Command line recorded in ``ablation.json``.
    progress : callable, default print
        Called with a progress message (str).

    Returns
    -------
    pandas.DataFrame
        One row per ablation: ``train_qae_deg`` (last epoch, teacher-forced windows),
        ``test_qae_deg`` and ``test_qae_rad`` (closed loop, mean over the test trials'
        movement samples), ``test_inclination`` (mean RMSE, degrees).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    base = TrainConfig.from_dict(
        {
            **(config or TrainConfig()).to_dict(),
            "epochs": epochs,
            "variant": "quaternion",
        }
    )
    trials = sorted(datasets.broad_trials())
    test = folds(trials, n_folds)[fold]
    recs = {t: datasets.load_broad_trial(t) for t in trials}
    seqs = {t: sequence(r) for t, r in recs.items()}
    rows = []
    for name, change in ABLATIONS.items():
        cfg = TrainConfig.from_dict({**base.to_dict(), **change})
        progress(f"{name}")
        model, hist = train([seqs[t] for t in trials if t not in test], cfg)
        errs = [
            trial_errors(closed_loop_estimate(model, seqs[t], cfg), recs[t])
            for t in test
        ]
        qae_deg = float(np.mean([e["qae_mean"] for e in errs]))
        rows.append(
            {
                "ablation": name,
                "train_qae_deg": hist[-1]["qae_deg"],
                "test_qae_deg": qae_deg,
                "test_qae_rad": float(np.radians(qae_deg)),
                "test_inclination": float(np.mean([e["inclination"] for e in errs])),
            }
        )
    table = pd.DataFrame(rows)
    write_json(
        {
            "command": command,
            "base_config": base.to_dict(),
            "fold": fold,
            "test_trials": test,
            "rows": table.to_dict(orient="records"),
        },
        out / "ablation.json",
    )
    _write_sums(out)
    return table


def _write_sums(out: Path) -> None:
    names = [
        p.name for p in out.iterdir() if p.suffix in (".pt", ".json") and p.is_file()
    ]
    write_sums(out, {n: sha256(out / n) for n in names})


def check_files(folder: str | Path) -> dict[str, str]:
    """Verify every file listed in ``folder/SHA256SUMS``; return name -> sha256.

    ``SHA256SUMS`` is parsed strictly (:func:`~tiltlab.learn.files.read_sums`):
    blank lines are ignored and the ``*`` binary marker accepted; an empty file or a
    malformed line is an error naming the line.

    Parameters
    ----------
    folder : str or pathlib.Path
        Folder holding ``SHA256SUMS`` and the files it lists.

    Returns
    -------
    dict
        File name (str) -> SHA-256 hex digest (str) of every verified file.

    Raises
    ------
    tiltlab.io.IntegrityError
        (a ``ValueError``) naming the first file that is missing or whose checksum
        differs, the line of ``SHA256SUMS`` that is malformed, or a missing
        ``SHA256SUMS`` (:func:`tiltlab.io.check_sums`).
    """
    return check_sums(folder)


@_deprecate.renamed(recording="rec")
def learned_estimate(rec, weights: str | Path):
    """Estimate the orientation of a Recording in closed loop with a saved model.

    The model is the one in ``weights`` (a ``.pt`` file written by :func:`save`); the
    result is labelled like :func:`tiltlab.filters.estimate`.

    Parameters
    ----------
    rec : xarray.Dataset
        Recording to estimate, at the sampling rate the model was trained at.
    weights : str or pathlib.Path
        Model file (``.pt``) written by :func:`save`.

    Returns
    -------
    xarray.DataArray (time, quat)
        Unit quaternions (w, x, y, z), sensor to world (ENU).

    Raises
    ------
    ValueError
        If the recording's sampling rate differs from the model's.
    """
    from ..filters import recordings as _rec

    model, cfg, fs = load_model(weights)
    seq = sequence(rec, acc_scale=cfg.acc_scale, mag_scale=cfg.mag_scale)
    if abs(seq.fs - fs) > 1e-6 * fs:
        raise ValueError(
            f"the model was trained at fs = {fs:.6g} Hz; the recording has "
            f"fs = {seq.fs:.6g} Hz (resample it, or train at its rate)"
        )
    q = closed_loop_estimate(model, seq, cfg)
    like = _rec.prepare(rec).like
    return _v.labelled(
        quat.normalize(q),
        like,
        "q",
        dims=("time", "quat"),
        coords={"quat": list("wxyz")},
        attrs={
            "method": f"cnn_{cfg.variant}",
            "units": "1",
            "frame": "sensor->world",
            "world_frame": "ENU",
            "weights": Path(weights).name,
        },
    )


def _compare_trials(folder: str, trials: list[int], fold: int, variants: list[str]):
    """Rows of :func:`compare` for some trials of one fold (run in a worker process).

    The fold's CNNs estimate the trials together (:func:`closed_loop_estimates`,
    one batch across trials at every block); the baselines run trial by trial.
    """
    import torch

    torch.set_num_threads(1)
    recs = [datasets.load_broad_trial(t) for t in trials]
    rows = []
    for v in variants:
        model, cfg, _ = load_model(Path(folder) / f"{v}_fold{fold}.pt")
        seqs = [
            sequence(r, acc_scale=cfg.acc_scale, mag_scale=cfg.mag_scale) for r in recs
        ]
        qs = closed_loop_estimates(model, seqs, cfg)
        label = "CNN (quaternion)" if v == "quaternion" else "CNN (learned gain)"
        for t, q, rec in zip(trials, qs, recs):
            rows.append({"method": label, "trial": t} | trial_errors(q, rec))
    one_thread = {"riann": {"threads": 1}}  # the workers share the cores
    for t, rec in zip(trials, recs):
        for label, (method, use_mag) in BASELINES.items():
            q = filters.estimate(
                rec, method, use_mag=use_mag, **one_thread.get(method, {})
            )
            errs = trial_errors(q.values, rec)
            if not use_mag:  # the heading of a 6D method is relative: tilt only
                for key in ("heading", "total", "qae_mean", "qae_median"):
                    errs[key] = np.nan
            rows.append({"method": label, "trial": t} | errs)
    return rows


def compare(
    folder: str | Path,
    *,
    trials: Seq[int] | None = None,
    n_jobs: int = 1,
    progress: bool = False,
) -> pd.DataFrame:
    """Compare the committed CNN folds with the baselines on every test trial.

    Every test trial of the committed folds: the CNN (both variants, each trial
    estimated by the model of the fold that held it out) and the baselines of
    :data:`BASELINES` with their default parameters, all computed now.

    Parameters
    ----------
    folder : path
        Output folder of :func:`cross_validate` (checked against its SHA256SUMS).
    trials : sequence of int, optional
        BROAD trials (default: every trial of a test fold).
    n_jobs : int
        Worker processes. Each fold's trials are split into ``n_jobs`` groups (one
        group with ``n_jobs=1``); a worker estimates a group's trials with the
        fold's CNNs in one batch (the closed loop is sequential in time, not across
        trials), then runs the baselines.
    progress : bool
        Show a progress bar (trials done).

    Returns
    -------
    pandas.DataFrame
        Rows (method, trial) with :func:`trial_errors` columns; the heading, total
        and QAE of the 6D RIANN are NaN (its heading origin is arbitrary). Rows are
        ordered by trial, then method, whatever ``n_jobs``.
    """
    import concurrent.futures as cf
    import multiprocessing as mp

    from tqdm import tqdm

    folder = Path(folder)
    check_files(folder)
    meta = json.loads((folder / "run.json").read_text())
    fold_of = {t: k for k, f in enumerate(meta["folds"]) for t in f}
    variants = list(meta["configs"])
    trials = sorted(fold_of) if trials is None else [int(t) for t in trials]
    for t in trials:
        if t not in fold_of:
            raise ValueError(f"trial {t} is in no test fold of {folder}")
    n_jobs = int(_v.integer(n_jobs, "n_jobs", minimum=1))
    args = []
    for k in sorted({fold_of[t] for t in trials}):
        mine = [t for t in trials if fold_of[t] == k]
        for part in np.array_split(np.array(mine), min(n_jobs, len(mine))):
            args.append((str(folder), [int(t) for t in part], k, variants))
    bar = tqdm(total=len(trials), desc="trials", disable=not progress)
    rows = []
    if n_jobs == 1:
        for a in args:
            rows += _compare_trials(*a)
            bar.update(len(a[1]))
    else:
        ctx = mp.get_context("spawn")
        with cf.ProcessPoolExecutor(n_jobs, mp_context=ctx) as pool:
            for a, part in zip(args, pool.map(_compare_trials, *zip(*args))):
                rows += part
                bar.update(len(a[1]))
    bar.close()
    order = {m: i for i, m in enumerate(["CNN (quaternion)", "CNN (learned gain)"])}
    order |= {m: len(order) + i for i, m in enumerate(BASELINES)}
    table = pd.DataFrame(rows)
    table = table.sort_values(
        ["trial", "method"], key=lambda c: c.map(order) if c.name == "method" else c
    )
    return _label_errors(table.reset_index(drop=True))


def _label_errors(table: pd.DataFrame) -> pd.DataFrame:
    """Attach units and long names to the error columns (and method, trial)."""
    known = {"method": ("", "method"), "trial": ("", "BROAD trial")}
    known |= {c: ("deg", name) for c, name in ERROR_COLUMNS.items()}
    present = {c: v for c, v in known.items() if c in table.columns}
    return label_columns(
        table,
        units={c: u for c, (u, _) in present.items()},
        long_name={c: n for c, (_, n) in present.items()},
    )


def compare_summary(
    table: pd.DataFrame,
    *,
    columns: Seq[str] = ("inclination", "heading", "total", "qae_mean"),
    statistics: Seq[str] = ("mean", "median"),
) -> pd.DataFrame:
    """Summarise :func:`compare` per method, in the order the methods appear.

    Parameters
    ----------
    table : pandas.DataFrame
        Rows (method, trial) from :func:`compare`.
    columns : sequence of str
        Error columns to summarise (keys of :data:`ERROR_COLUMNS`).
    statistics : sequence of str
        Pandas aggregations, applied over trials (``"mean"``, ``"median"``…).

    Returns
    -------
    pandas.DataFrame
        One row per method, one column ``"<column> <statistic>"`` per pair, in
        degrees, labelled (``attrs["units"]``, ``attrs["long_name"]``); a method
        without a value (RIANN's heading) is NaN.

    Examples
    --------
    >>> import pandas as pd
    >>> from tiltlab import learn
    >>> t = pd.DataFrame({"method": ["a", "a", "b"], "trial": [1, 2, 1],
    ...                   "inclination": [1.0, 3.0, 2.0]})
    >>> s = learn.compare_summary(t, columns=["inclination"], statistics=["mean"])
    >>> s.to_dict()
    {'inclination mean': {'a': 2.0, 'b': 2.0}}
    >>> s.attrs["long_name"]["inclination mean"]
    'inclination RMSE, mean over trials'
    """
    missing = [c for c in ("method", *columns) if c not in table.columns]
    if missing:
        raise ValueError(f"table has no column(s) {missing} (from learn.compare)")
    unknown = [c for c in columns if c not in ERROR_COLUMNS]
    if unknown:
        raise ValueError(
            f"unknown error column(s) {unknown}; known: {list(ERROR_COLUMNS)}"
        )
    methods = list(dict.fromkeys(table["method"]))
    grouped = table.groupby("method", sort=False)
    parts = {
        f"{c} {stat}": grouped[c].agg(stat) for c in columns for stat in statistics
    }
    out = pd.DataFrame(parts).loc[methods]
    out.index.name = "method"
    names = {
        f"{c} {stat}": f"{ERROR_COLUMNS[c]}, {stat} over trials"
        for c in columns
        for stat in statistics
    }
    return label_columns(out, units="deg", long_name=names)
