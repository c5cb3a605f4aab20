r"""Tune the filter baselines of the learned estimators on the networks' training folds.

A fair comparison gives the filters what the networks get: data to fit their
parameters on, and none of the trials they are scored on. :func:`tune_baselines`
runs chapter 4's grid search (:func:`tiltlab.evaluate.grid_search`) for each
baseline of :data:`TUNED_BASELINES` on the **training trials** of each
cross-validation fold (every trial but the fold's held-out ones, as for the networks
of :func:`~.cv.cross_validate`) and keeps the parameters minimising the mean
inclination RMSE (the ``inclination`` error of :func:`~.cv.trial_errors`, BROAD's
definition). :func:`tuned_compare` scores each held-out trial with its fold's
parameters, in rows like :func:`~.cv.compare`; :func:`tuned_summary` sets the tuned
rows against the defaults.

The chosen parameters are committed (``python -m tiltlab.learn tune-baselines``):
:func:`save_tuned` writes ``params.json`` and a ``SHA256SUMS`` that
:func:`load_tuned` verifies.
"""

from __future__ import annotations

import json
import platform
from collections.abc import Callable, Iterable, Mapping, Sequence as Seq
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .. import _validate as _v
from .. import datasets
from .. import evaluate
from .. import filters
from .._labels import label_columns
from ..stats import wilcoxon_signed_rank
from .cv import ERROR_COLUMNS, check_files, trial_errors
from .files import SUMS_FILE, sha256

__all__ = [
    "TUNED_BASELINES",
    "BASELINE_GRIDS",
    "PARAMS_FILE",
    "tune_baselines",
    "save_tuned",
    "load_tuned",
    "tuned_compare",
    "tuned_summary",
]

#: Baselines tuned on each fold's training trials: label -> (registry method, 9D).
#: All four run 9D, with the magnetometer, as the filter baselines of Zaheer et al.;
#: VQF (at its defaults) and RIANN stay as in :data:`~.cv.BASELINES`.
TUNED_BASELINES: dict[str, tuple[str, bool]] = {
    "Madgwick 9D": ("madgwick", True),
    "Mahony 9D": ("mahony", True),
    "complementary 9D": ("complementary", True),
    "ESKF 9D": ("eskf", True),
}

#: Parameter grids of :func:`tune_baselines`, per label of :data:`TUNED_BASELINES`.
#: Madgwick and Mahony: chapter 4's BROAD grids (§4.1), Mahony's ``kp`` widened to
#: 3; the complementary filter: chapter 4's ``tau_acc_s`` widened to 0.3 s, and its
#: magnetometer time constant. Chapter 4 has no ESKF: its grid spans each noise
#: around the default; a first, narrower grid (``gyr_noise`` 0.002–0.02,
#: ``acc_noise`` 0.1–0.5, ``norm_gain`` 0–10, ``mag_noise`` 0.05–1) had its
#: optimum on three edges in every fold, so it was extended past them once
#: (``norm_gain`` 0, no adaptation, is the end of its range; ``mag_noise`` 5 rad
#: leaves the heading update almost no weight). Parameters not listed keep their
#: registry defaults.
BASELINE_GRIDS: dict[str, dict[str, tuple[float, ...]]] = {
    "Madgwick 9D": {"beta": (0.01, 0.02, 0.05, 0.1, 0.2)},
    "Mahony 9D": {"kp": (0.1, 0.3, 1.0, 3.0), "ki": (0.0, 0.003, 0.03)},
    "complementary 9D": {
        "tau_acc_s": (0.3, 1.0, 3.0, 10.0, 30.0),
        "tau_mag_s": (0.3, 1.0, 5.0, 20.0),
    },
    "ESKF 9D": {
        "gyr_noise": (0.0005, 0.001, 0.002, 0.005),
        "acc_noise": (0.2, 0.5, 1.0, 2.0),
        "norm_gain": (0.0, 3.0, 10.0),
        "mag_noise": (0.2, 1.0, 5.0),
    },
}

#: Units of the tuned parameters: the registry's, with those of the ESKF's own
#: (``acc_noise`` is a unit-vector deviation there, not the RTS smoother's) and of
#: the magnetometer parameters, as the filters' docstrings state them.
_PARAMETER_UNITS: dict[str, str] = {
    **filters.PARAMETER_UNITS,
    "tau_mag_s": "s",
    "gyr_noise": "rad/√s",
    "acc_noise": "1",
    "norm_gain": "1",
    "mag_noise": "rad",
    "bias_noise": "rad/s/√s",
}

#: The file :func:`save_tuned` writes and :func:`load_tuned` reads.
PARAMS_FILE = "params.json"

Loader = Callable[[int], Any]

#: The columns of :func:`tune_baselines` that are not parameters.
_TABLE_COLUMNS = (
    "method",
    "fold",
    "test_trials",
    "n_train",
    "parameters",
    "train_inclination",
)


def _check_folds(folds, trials) -> tuple[list[list[int]], list[int]]:
    """Check the folds; return them (lists of int) and the trials (default: union)."""
    if isinstance(folds, (str, bytes)) or not isinstance(folds, Iterable):
        raise TypeError("folds must be a sequence of sequences of trial numbers")
    out = [sorted(int(t) for t in f) for f in folds]
    if not out:
        raise ValueError("folds is empty: give at least one fold of held-out trials")
    for k, f in enumerate(out):
        if not f:
            raise ValueError(f"fold {k} holds no trial")
        if len(set(f)) != len(f):
            raise ValueError(f"fold {k} lists a trial twice: {f}")
    seen: dict[int, int] = {}
    for k, f in enumerate(out):
        for t in f:
            if t in seen:
                raise ValueError(
                    f"trial {t} is held out by folds {seen[t]} and {k}: the folds "
                    "must not overlap"
                )
            seen[t] = k
    trials = sorted(seen) if trials is None else sorted({int(t) for t in trials})
    missing = sorted(set(seen) - set(trials))
    if missing:
        raise ValueError(f"held-out trial(s) {missing} are not in trials {trials}")
    for k, f in enumerate(out):
        if not set(trials) - set(f):
            raise ValueError(f"fold {k} holds out every trial: nothing to tune on")
    return out, trials


def _check_grids(grids) -> dict[str, dict[str, tuple]]:
    """Check the grids and return them as label -> parameter -> values, in order."""
    grids = BASELINE_GRIDS if grids is None else grids
    if not isinstance(grids, Mapping) or not grids:
        raise ValueError("grids must be a non-empty mapping label -> parameter grid")
    out = {}
    for label, grid in grids.items():
        if label not in TUNED_BASELINES:
            raise ValueError(
                f"unknown baseline {label!r}; known: {sorted(TUNED_BASELINES)} (VQF "
                "runs at its defaults and RIANN is pretrained: neither is tuned)"
            )
        if not isinstance(grid, Mapping) or not grid:
            raise ValueError(f"the grid of {label!r} is empty")
        values = {p: tuple(float(x) for x in np.atleast_1d(v)) for p, v in grid.items()}
        empty = [p for p, v in values.items() if not v]
        if empty:
            raise ValueError(f"the grid of {label!r} has no value for {empty}")
        filters.get_method(TUNED_BASELINES[label][0]).resolve(
            {p: v[0] for p, v in values.items()}
        )
        out[label] = values
    return out


def _describe(params: Mapping[str, Any]) -> str:
    """Write parameters as ``name=value, …`` (``defaults`` when there are none)."""
    return ", ".join(f"{k}={v:g}" for k, v in params.items()) or "defaults"


def _label_params(table: pd.DataFrame, names: list[str]) -> pd.DataFrame:
    """Attach units and long names to a :func:`tune_baselines` table."""
    known = {
        "method": ("", "baseline (9D: with magnetometer)"),
        "fold": ("1", "cross-validation fold"),
        "test_trials": ("", "held-out BROAD trials of the fold"),
        "n_train": ("1", "training trials the parameters were chosen on"),
        "parameters": ("", "chosen parameters"),
        "train_inclination": (
            "deg",
            "inclination RMSE at the chosen parameters, mean over the training trials",
        ),
    }
    known |= {p: (_PARAMETER_UNITS.get(p, ""), f"chosen {p}") for p in names}
    present = {c: v for c, v in known.items() if c in table.columns}
    return label_columns(
        table,
        units={c: u for c, (u, _) in present.items()},
        long_name={c: n for c, (_, n) in present.items()},
    )


def tune_baselines(
    folds: Seq[Seq[int]],
    *,
    trials: Seq[int] | None = None,
    load: Loader | None = None,
    grids: Mapping[str, Mapping[str, Seq[float]]] | None = None,
    n_jobs: int = 1,
    progress: bool = False,
) -> pd.DataFrame:
    """Choose each baseline's parameters on the training trials of each fold.

    For every baseline of ``grids`` (labels of :data:`TUNED_BASELINES`) and every
    fold, the parameters minimising the mean inclination RMSE over the fold's
    **training** trials (``trials`` less the fold's held-out ones) on the baseline's
    grid.

    Parameters
    ----------
    folds : sequence of sequence of int
        Held-out BROAD trials of each fold (e.g. ``run.json["folds"]`` of the
        committed networks); the folds must not overlap.
    trials : sequence of int, optional
        Every trial of the design (default: the union of ``folds``); a fold trains on
        those it does not hold out.
    load : callable, optional
        ``load(trial) -> Recording`` with ``acc``, ``gyr``, ``mag``, ``q_ref`` and
        ``movement`` (default :func:`tiltlab.datasets.load_broad_trial`). Called once
        per trial that some fold trains on, and never for a trial that no fold trains
        on.
    grids : mapping, optional
        Label of :data:`TUNED_BASELINES` -> parameter -> values (default
        :data:`BASELINE_GRIDS`). Parameters not in a grid keep the registry's
        defaults.
    n_jobs : int, default 1
        Threads of :func:`tiltlab.evaluate.grid_search`.
    progress : bool, default False
        Show a progress bar over the baselines.

    Returns
    -------
    pandas.DataFrame
        One row per (method, fold): ``method``, ``fold``, ``test_trials`` (tuple of
        the held-out trials), ``n_train``, ``parameters`` (text), one column per
        parameter of the grids (NaN where a method has no such parameter) and
        ``train_inclination`` (the minimal mean RMSE, degrees); labelled
        (``attrs["units"]``, ``attrs["long_name"]``), with the grids searched in
        ``attrs["grids"]``.

    Raises
    ------
    ValueError
        Empty or overlapping folds, a fold holding out every trial, a held-out trial
        not in ``trials``, an unknown baseline label or parameter, an empty grid.

    Notes
    -----
    All four baselines run **9D** (``use_mag=True``), as the filter baselines of
    Zaheer et al.: the score is the inclination, but Madgwick's and Mahony's
    magnetometer terms and the ESKF's heading update also move the tilt or the gyro
    bias, so the magnetometer belongs to the tuned method. The ESKF's magnetometer
    update is heading-only (:func:`tiltlab.filters.eskf`); its ``mag_noise`` is tuned
    with the other noises.

    Each trial's grid scores are computed once and reused by every fold that trains
    on it; a fold's choice reads only its training trials' scores, so a held-out
    trial never influences its own fold's parameters. Ties go to the first grid
    point in the grid's order (:func:`tiltlab.evaluate.optimum`).

    Examples
    --------
    >>> import json
    >>> from pathlib import Path
    >>> from tiltlab import learn  # doctest: +SKIP
    >>> run = json.loads(Path("data/learn/run.json").read_text())  # doctest: +SKIP
    >>> chosen = learn.tune_baselines(run["folds"])  # doctest: +SKIP
    >>> learn.tuned_compare(chosen)  # doctest: +SKIP
    """
    from tqdm import tqdm

    folds, trials = _check_folds(folds, trials)
    grids = _check_grids(grids)
    n_jobs = int(_v.integer(n_jobs, "n_jobs", minimum=1))
    load = datasets.load_broad_trial if load is None else load
    train = [[t for t in trials if t not in set(f)] for f in folds]
    needed = sorted({t for tr in train for t in tr})
    recs = {t: load(t) for t in needed}
    names = list(dict.fromkeys(p for g in grids.values() for p in g))
    rows = []
    for label in tqdm(grids, desc="baselines", disable=not progress):
        method, use_mag = TUNED_BASELINES[label]
        scores = evaluate.grid_search(
            recs, method, grids[label], use_mag=use_mag, n_jobs=n_jobs
        )
        for k, (test, tr) in enumerate(zip(folds, train)):
            best = evaluate.optimum(scores.sel(recording=tr))
            score = best.pop("score")
            params = {p: float(best[p]) for p in grids[label]}
            rows.append(
                {
                    "method": label,
                    "fold": k,
                    "test_trials": tuple(test),
                    "n_train": len(tr),
                    "parameters": _describe(params),
                    **{p: params.get(p, np.nan) for p in names},
                    "train_inclination": float(score),
                }
            )
    table = _label_params(pd.DataFrame(rows), names)
    table.attrs["grids"] = {label: dict(g) for label, g in grids.items()}
    return table


def save_tuned(
    table: pd.DataFrame,
    out: str | Path,
    *,
    grids: Mapping[str, Mapping[str, Seq[float]]] | None = None,
    command: str = "",
) -> Path:
    """Write the chosen parameters to ``out/params.json`` with a ``SHA256SUMS``.

    Parameters
    ----------
    table : pandas.DataFrame
        The output of :func:`tune_baselines`; not modified.
    out : str or pathlib.Path
        Output folder (created if needed).
    grids : mapping, optional
        The grids ``table`` was tuned on, recorded beside the chosen parameters (the
        parameter columns of ``table`` that are set); default ``table.attrs["grids"]``
        (set by :func:`tune_baselines`), else :data:`BASELINE_GRIDS`.
    command : str, default ""
        The command line, recorded.

    Returns
    -------
    pathlib.Path
        The ``params.json`` written.

    Raises
    ------
    ValueError
        If ``table`` lacks a column of :func:`tune_baselines`.
    """
    need = ["method", "fold", "test_trials", "n_train", "train_inclination"]
    missing = [c for c in need if c not in table.columns]
    if missing:
        raise ValueError(f"table has no column(s) {missing} (from tune_baselines)")
    grids = _check_grids(table.attrs.get("grids") if grids is None else grids)
    unknown = sorted(set(table["method"]) - set(grids))
    if unknown:
        raise ValueError(f"table has method(s) {unknown} without a grid in grids")
    chosen = []
    for _, row in table.iterrows():
        params = _row_params(table, row)
        chosen.append(
            {
                "method": str(row["method"]),
                "fold": int(row["fold"]),
                "test_trials": [int(t) for t in row["test_trials"]],
                "n_train": int(row["n_train"]),
                "params": params,
                "train_inclination": float(row["train_inclination"]),
            }
        )
    folds = {c["fold"]: c["test_trials"] for c in chosen}
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / PARAMS_FILE
    meta = {
        "command": command,
        "score": "mean inclination RMSE over the fold's training trials (deg)",
        "folds": [folds[k] for k in sorted(folds)],
        "methods": {label: list(TUNED_BASELINES[label]) for label in grids},
        "grids": {
            label: {p: list(v) for p, v in g.items()} for label, g in grids.items()
        },
        "chosen": chosen,
        "versions": {"python": platform.python_version(), "numpy": np.__version__},
    }
    # keys in order (not sorted): the order of the methods and their parameters is
    # that of the table's columns when read back
    path.write_text(json.dumps(meta, indent=1) + "\n")
    (out / SUMS_FILE).write_text(f"{sha256(path)}  {PARAMS_FILE}\n")
    return path


def load_tuned(folder: str | Path) -> pd.DataFrame:
    """Read the committed parameters of :func:`save_tuned`, checking their sha256.

    Parameters
    ----------
    folder : str or pathlib.Path
        Folder holding ``params.json`` and ``SHA256SUMS``.

    Returns
    -------
    pandas.DataFrame
        The table of :func:`tune_baselines`, labelled, with the grids searched in
        ``attrs["grids"]``.

    Raises
    ------
    tiltlab.io.IntegrityError
        (a ``ValueError``) if ``params.json`` is missing or its sha256 differs from
        ``SHA256SUMS``.
    ValueError
        If there is no ``SHA256SUMS``, or it does not list ``params.json``.

    Examples
    --------
    >>> chosen = load_tuned("data/learn_baselines")  # doctest: +SKIP
    >>> chosen.set_index(["method", "fold"])["parameters"]  # doctest: +SKIP
    """
    folder = Path(folder)
    if PARAMS_FILE not in check_files(folder):
        raise ValueError(f"{folder / SUMS_FILE} does not list {PARAMS_FILE}")
    meta = json.loads((folder / PARAMS_FILE).read_text())
    grids = {
        label: {p: tuple(v) for p, v in g.items()} for label, g in meta["grids"].items()
    }
    names = list(dict.fromkeys(p for g in grids.values() for p in g))
    rows = [
        {
            "method": c["method"],
            "fold": c["fold"],
            "test_trials": tuple(c["test_trials"]),
            "n_train": c["n_train"],
            "parameters": _describe(c["params"]),
            **{p: c["params"].get(p, np.nan) for p in names},
            "train_inclination": c["train_inclination"],
        }
        for c in meta["chosen"]
    ]
    table = _label_params(pd.DataFrame(rows), names)
    table.attrs["grids"] = grids
    return table


def _row_params(table: pd.DataFrame, row: pd.Series) -> dict[str, float]:
    """Return the parameters set in one row of a :func:`tune_baselines` table."""
    return {
        c: float(row[c])
        for c in table.columns
        if c not in _TABLE_COLUMNS and pd.notna(row[c])
    }


def _chosen_params(table: pd.DataFrame) -> dict[tuple[str, int], dict[str, float]]:
    """Map (method, trial) to the parameters its fold chose, from a tuning table."""
    need = ["method", "test_trials"]
    missing = [c for c in need if c not in table.columns]
    if missing:
        raise ValueError(f"table has no column(s) {missing} (from tune_baselines)")
    out: dict[tuple[str, int], dict[str, float]] = {}
    for _, row in table.iterrows():
        label = row["method"]
        if label not in TUNED_BASELINES:
            raise ValueError(
                f"unknown baseline {label!r}; known: {sorted(TUNED_BASELINES)}"
            )
        params = _row_params(table, row)
        filters.get_method(TUNED_BASELINES[label][0]).resolve(params)
        for t in row["test_trials"]:
            if (label, int(t)) in out:
                raise ValueError(f"trial {t} is held out twice for {label!r}")
            out[(label, int(t))] = params
    return out


def _score_trial(trial, rec, chosen, labels, defaults) -> list[dict[str, Any]]:
    """Rows of :func:`tuned_compare` for one trial."""
    rows = []
    for label in labels:
        method, use_mag = TUNED_BASELINES[label]
        runs = [(f"{label} (tuned)", chosen[(label, trial)])]
        if defaults:
            runs.append((f"{label} (defaults)", {}))
        for name, params in runs:
            q = filters.estimate(rec, method, use_mag=use_mag, **params)
            rows.append(
                {"method": name, "trial": trial, "parameters": _describe(params)}
                | trial_errors(q.values, rec)
            )
    return rows


def tuned_compare(
    chosen: pd.DataFrame,
    *,
    trials: Seq[int] | None = None,
    load: Loader | None = None,
    defaults: bool = True,
    n_jobs: int = 1,
    progress: bool = False,
) -> pd.DataFrame:
    """Score each held-out trial with the parameters its fold chose.

    Rows like :func:`~.cv.compare`'s, to set beside the networks' rows: each trial is
    estimated by every baseline of ``chosen`` with the parameters of the fold that
    held it out (``"<label> (tuned)"``) and, with ``defaults``, with the registry's
    defaults (``"<label> (defaults)"``).

    Parameters
    ----------
    chosen : pandas.DataFrame
        Output of :func:`tune_baselines` or :func:`load_tuned`; not modified.
    trials : sequence of int, optional
        Trials to score (default: every held-out trial of ``chosen``).
    load : callable, optional
        ``load(trial) -> Recording`` (default
        :func:`tiltlab.datasets.load_broad_trial`).
    defaults : bool, default True
        Also score each baseline with its default parameters.
    n_jobs : int, default 1
        Threads (one trial each at a time; the numba kernels release the GIL).
    progress : bool, default False
        Show a progress bar over the trials.

    Returns
    -------
    pandas.DataFrame
        Rows (method, trial): ``method``, ``trial``, ``parameters`` (text) and the
        columns of :func:`~.cv.trial_errors` (degrees), labelled.

    Raises
    ------
    ValueError
        If a trial is held out by no fold of ``chosen``, a label or parameter of
        ``chosen`` is unknown, or a trial is held out twice.

    Notes
    -----
    VQF at its defaults and RIANN are the rows of :func:`~.cv.compare`, not repeated
    here. RIANN is a pretrained network, not refitted on the folds: its rows count
    as in-sample, since its published training data may include BROAD trials
    (Weber et al. 2021, cited by :func:`tiltlab.filters.run_riann`).

    Examples
    --------
    >>> chosen = load_tuned("data/learn_baselines")  # doctest: +SKIP
    >>> table = tuned_compare(chosen)  # doctest: +SKIP
    >>> compare_summary(table, columns=["inclination"])  # doctest: +SKIP
    """
    from tqdm import tqdm

    params = _chosen_params(chosen)
    labels = list(dict.fromkeys(chosen["method"]))
    held = sorted({t for _, t in params})
    trials = held if trials is None else [int(t) for t in trials]
    for t in trials:
        for label in labels:
            if (label, t) not in params:
                raise ValueError(f"trial {t} is held out by no fold of {label!r}")
    n_jobs = int(_v.integer(n_jobs, "n_jobs", minimum=1))
    load = datasets.load_broad_trial if load is None else load

    def job(t):
        return _score_trial(t, load(t), params, labels, defaults)

    bar = tqdm(total=len(trials), desc="trials", disable=not progress)
    parts = []
    if n_jobs == 1:
        for t in trials:
            parts.append(job(t))
            bar.update()
    else:
        with ThreadPoolExecutor(max_workers=n_jobs) as ex:
            for part in ex.map(job, trials):
                parts.append(part)
                bar.update()
    bar.close()
    table = pd.DataFrame([r for part in parts for r in part])
    known = {"method": ("", "method"), "trial": ("", "BROAD trial")}
    known["parameters"] = ("", "parameters")
    known |= {c: ("deg", n) for c, n in ERROR_COLUMNS.items()}
    return label_columns(
        table,
        units={c: u for c, (u, _) in known.items()},
        long_name={c: n for c, (_, n) in known.items()},
    )


_SUMMARY = {
    "mean_defaults": "inclination RMSE at the defaults, mean over trials",
    "mean_tuned": "inclination RMSE tuned on the fold, mean over trials",
    "median_defaults": "inclination RMSE at the defaults, median over trials",
    "median_tuned": "inclination RMSE tuned on the fold, median over trials",
    "n_lower": "trials with a lower RMSE tuned than at the defaults",
    "n_trials": "trials",
    "p": "paired Wilcoxon signed-rank p-value (two-sided), tuned vs defaults",
}


def tuned_summary(table: pd.DataFrame, *, column: str = "inclination") -> pd.DataFrame:
    """Set each baseline's tuned rows against its defaults, trial by trial.

    Parameters
    ----------
    table : pandas.DataFrame
        Output of :func:`tuned_compare` (with ``defaults=True``).
    column : str, default "inclination"
        Error column compared (a key of :data:`~.cv.ERROR_COLUMNS`).

    Returns
    -------
    pandas.DataFrame
        One row per baseline: mean and median of ``column`` at the defaults and
        tuned, ``n_lower`` (trials improved by tuning), ``n_trials`` and ``p``
        (two-sided paired Wilcoxon signed-rank test,
        :func:`tiltlab.stats.wilcoxon_signed_rank`; NaN where fewer than two trials
        differ, as when every fold chose the defaults); labelled.

    Raises
    ------
    ValueError
        If ``column`` is unknown, a column is missing, or a baseline lacks its
        default or tuned rows for some trial.

    Examples
    --------
    >>> import pandas as pd
    >>> t = pd.DataFrame({"method": ["A (tuned)"] * 3 + ["A (defaults)"] * 3,
    ...                   "trial": [1, 2, 3] * 2,
    ...                   "inclination": [1.0, 2.0, 3.0, 2.0, 3.0, 5.0]})
    >>> s = tuned_summary(t)
    >>> row = s.loc["A"]
    >>> float(row["mean_tuned"]), round(float(row["mean_defaults"]), 3)
    (2.0, 3.333)
    >>> int(row["n_lower"])
    3
    """
    if column not in ERROR_COLUMNS:
        raise ValueError(
            f"unknown error column {column!r}; known: {list(ERROR_COLUMNS)}"
        )
    missing = [c for c in ("method", "trial", column) if c not in table.columns]
    if missing:
        raise ValueError(f"table has no column(s) {missing} (from tuned_compare)")
    wide = table.pivot(index="trial", columns="method", values=column)
    rows = {}
    for name in dict.fromkeys(table["method"]):
        if not name.endswith(" (tuned)"):
            continue
        label = name[: -len(" (tuned)")]
        base = f"{label} (defaults)"
        if base not in wide.columns:
            raise ValueError(f"no rows {base!r}: run tuned_compare with defaults=True")
        pair = wide[[name, base]]
        if pair.isna().any().any():
            raise ValueError(f"{label!r} lacks its tuned or default rows for a trial")
        tuned, default = pair[name].to_numpy(), pair[base].to_numpy()
        if np.count_nonzero(tuned != default) < 2:  # same parameters: nothing to test
            p_value = np.nan
        else:
            test = wilcoxon_signed_rank(tuned, default, alternative="two-sided")
            p_value = float(test.p)
        rows[label] = {
            "mean_defaults": float(default.mean()),
            "mean_tuned": float(tuned.mean()),
            "median_defaults": float(np.median(default)),
            "median_tuned": float(np.median(tuned)),
            "n_lower": int(np.sum(tuned < default)),
            "n_trials": len(tuned),
            "p": p_value,
        }
    out = pd.DataFrame.from_dict(rows, orient="index", columns=list(_SUMMARY))
    out.index.name = "method"
    units = dict.fromkeys(list(_SUMMARY)[:4], "deg") | {
        "n_lower": "1",
        "n_trials": "1",
        "p": "1",
    }
    return label_columns(out, units=units, long_name=_SUMMARY, role={"p": "p-value"})
