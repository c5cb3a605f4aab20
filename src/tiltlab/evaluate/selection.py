r"""Scoring methods over parameter grids and recordings; LOTO parameter selection.

LOTO: leave-one-trial-out.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from .. import _validate as _v
from .. import filters as F
from ..filters.recordings import attr_value
from .._labels import label_columns
from .errors import tilt_rmse

__all__ = ["grid_search", "optimum", "loto", "error_table", "loto_summary"]


def _score_attrs(score_fn, first) -> dict:
    """Units and long name of scores: those of a DataArray score, else tilt_rmse's."""
    if isinstance(first, xr.DataArray) and "units" in first.attrs:
        return {k: first.attrs[k] for k in ("units", "long_name") if k in first.attrs}
    if score_fn is tilt_rmse:
        return {"units": "deg", "long_name": "tilt RMSE"}
    return {"units": "", "long_name": "score"}


def _n_jobs(n_jobs) -> int:
    if n_jobs is None:
        return os.cpu_count() or 1
    return _v.integer(n_jobs, "n_jobs", minimum=1)


def grid_search(
    recordings: Sequence[xr.Dataset] | Mapping[Any, xr.Dataset],
    method: str,
    param_grid: Mapping[str, Sequence],
    score_fn: Callable[[np.ndarray, xr.Dataset], float] = tilt_rmse,
    *,
    use_mag: bool = False,
    n_jobs: int | None = None,
    fixed: Mapping[str, Any] | None = None,
) -> xr.DataArray:
    """Score a method over a parameter grid and several recordings, in parallel.

    Each (parameter combination, recording) pair runs the numba kernel (which releases
    the GIL) in a thread pool of ``n_jobs`` workers; ``score_fn(q, recording)`` reduces
    each estimate (an (N, 4) array) to a number, so the estimates are never all held in
    memory.

    Parameters
    ----------
    recordings : sequence or mapping of Recordings
        A mapping's keys label the ``recording`` coordinate (else 0, 1, …).
    method : str
        A method of :data:`tiltlab.filters.METHODS`.
    param_grid : mapping
        Parameter name → sequence of values; the grid is their Cartesian product.
    score_fn : callable
        ``score_fn(q, rec) -> float``, or an ``xarray.DataArray`` with the same dims
        and coords for every call (e.g. one score per behavioural ``state``), whose dims
        are appended after ``recording``; default :func:`tilt_rmse`.
    use_mag : bool
        Run the method with the magnetometer (9D; the Recordings need ``mag``); a
        ``ValueError`` for a method that does not support one.
    n_jobs : int, optional
        Worker threads, default ``os.cpu_count()``.
    fixed : mapping, optional
        Further parameters held constant (unspecified ones take the registry's
        defaults).

    Returns
    -------
    xarray.DataArray
        Dims (one per grid parameter…, ``recording``, then the score's own dims),
        attrs ``units`` and ``long_name`` (a DataArray score's, else ``"deg"`` for
        :func:`tilt_rmse`), ``method``, ``use_mag`` and the fixed parameters.
    """
    m = F.get_method(method)
    if use_mag and not m.supports_mag:
        raise ValueError(
            f"method {method!r} does not use a magnetometer; "
            "use_mag=True is not supported"
        )
    if isinstance(recordings, Mapping):
        labels, recs = list(recordings.keys()), list(recordings.values())
    else:
        recs = list(recordings)
        labels = list(range(len(recs)))
    if not recs:
        raise ValueError("no recordings")
    if not param_grid:
        raise ValueError("param_grid is empty")
    names = list(param_grid)
    values = [list(np.atleast_1d(param_grid[n])) for n in names]
    if any(len(v) == 0 for v in values):
        raise ValueError("every parameter in param_grid needs at least one value")
    fixed = dict(fixed or {})
    m.resolve({**fixed, **{n: v[0] for n, v in zip(names, values)}})  # names known?
    data = [F.prepare(r, use_mag=use_mag) for r in recs]
    combos = list(itertools.product(*[range(len(v)) for v in values]))
    shape = tuple(len(v) for v in values) + (len(recs),)
    out = np.full(shape, np.nan)

    def job(ci, ri):
        params = {
            **fixed,
            **{n: values[j][i] for j, (n, i) in enumerate(zip(names, ci))},
        }
        q = F.run_method(method, data[ri], **params)
        s = score_fn(q, recs[ri])
        return ci, ri, (s if isinstance(s, xr.DataArray) else float(s))

    n_jobs = _n_jobs(n_jobs)
    tasks = [(ci, ri) for ci in combos for ri in range(len(recs))]
    if n_jobs == 1:
        results = [job(*t) for t in tasks]
    else:
        with ThreadPoolExecutor(max_workers=n_jobs) as ex:
            results = list(ex.map(lambda t: job(*t), tasks))
    extra_dims: tuple = ()
    extra_coords: dict = {}
    first = results[0][2]
    if isinstance(first, xr.DataArray):
        extra_dims = first.dims
        extra_coords = {
            d: first.coords[d].values for d in first.dims if d in first.coords
        }
        out = np.full(shape + first.shape, np.nan)
    for ci, ri, s in results:
        if extra_dims:
            if (
                not isinstance(s, xr.DataArray)
                or s.dims != extra_dims
                or s.shape != first.shape
            ):
                raise ValueError(
                    "score_fn must return DataArrays of identical dims and shape for every call"
                )
            s = s.values
        out[ci + (ri,)] = s
    coords = {
        n: np.asarray(v) if np.asarray(v).dtype != object else list(map(str, v))
        for n, v in zip(names, values)
    }
    coords["recording"] = labels
    coords.update(extra_coords)
    return xr.DataArray(
        out,
        dims=tuple(names) + ("recording",) + tuple(extra_dims),
        coords=coords,
        name="score",
        attrs={
            **_score_attrs(score_fn, first),
            "method": method,
            "use_mag": int(bool(use_mag)),
            **{f"param_{k}": attr_value(v) for k, v in fixed.items()},
        },
    )


def _param_dims(
    scores: xr.DataArray, dim: str, params: Sequence[str] | None
) -> list[str]:
    if dim not in scores.dims:
        raise ValueError(f"scores has no {dim!r} dimension (dims {scores.dims})")
    p = [d for d in scores.dims if d != dim] if params is None else list(params)
    for d in p:
        if d not in scores.dims or d == dim:
            raise ValueError(f"{d!r} is not a parameter dimension of scores")
    return p


def optimum(
    scores: xr.DataArray, *, dim: str = "recording", params: Sequence[str] | None = None
) -> dict[str, Any]:
    """Parameters minimising the mean score over ``dim`` (the optimistic all-trials optimum).

    Parameters
    ----------
    scores : xarray.DataArray
        Scores over parameter dims and ``dim`` (NaN-aware mean).
    dim : str
        The recording (trial) dimension the scores are averaged over (default
        ``"recording"``).
    params : sequence of str, optional
        Dims to optimise over (default: all but ``dim``); other dims must be absent.

    Returns
    -------
    dict
        Parameter name → value, plus ``score`` (the minimal mean).
    """
    p = _param_dims(scores, dim, params)
    if set(scores.dims) - set(p) - {dim}:
        raise ValueError(
            f"select or reduce the dims {sorted(set(scores.dims) - set(p) - {dim})} first"
        )
    m = scores.mean(dim).transpose(*p)
    if not np.isfinite(m.values).any():
        raise ValueError("no finite mean score")
    flat = int(np.nanargmin(m.values))
    ix = np.unravel_index(flat, m.shape)
    best = {d: m.coords[d].values[i].item() for d, i in zip(p, ix)}
    best["score"] = float(m.values[ix])
    return best


def _param_attrs(scores: xr.DataArray, d: str) -> dict:
    """Units and long name of the parameter ``d`` chosen without each trial."""
    units = scores.coords[d].attrs.get("units", "") if d in scores.coords else ""
    return {"units": str(units), "long_name": f"{d} chosen without the trial"}


def loto(
    scores: xr.DataArray, *, dim: str = "recording", params: Sequence[str] | None = None
) -> xr.Dataset:
    """Select parameters leaving one trial out (LOTO).

    Each trial is scored with the parameters that minimise the mean score over the *other* trials.

    Parameters
    ----------
    scores : xarray.DataArray
        Scores over parameter dims and ``dim`` (e.g. the output of
        :func:`grid_search`, with other dims selected away).
    dim : str
        The trial dimension (at least two trials).
    params : sequence of str, optional
        Parameter dims (default: all but ``dim``).

    Returns
    -------
    xarray.Dataset
        Over ``dim``: ``score`` (held-out score, in the units of ``scores``), and one
        variable per parameter with the value chosen without that trial (each with
        ``units`` and ``long_name``); attrs ``mean`` (mean held-out score),
        ``optimistic_mean`` (all-trials optimum) and ``optimistic_<param>``.
    """
    p = _param_dims(scores, dim, params)
    if set(scores.dims) - set(p) - {dim}:
        raise ValueError(
            f"select or reduce the dims {sorted(set(scores.dims) - set(p) - {dim})} first"
        )
    n = scores.sizes[dim]
    if n < 2:
        raise ValueError("leave-one-trial-out needs at least two trials")
    s = scores.transpose(*p, dim).values
    total = np.nansum(s, axis=-1)
    count = np.sum(np.isfinite(s), axis=-1)
    held = np.empty(n)
    chosen = {d: [] for d in p}
    for r in range(n):
        fin = np.isfinite(s[..., r])
        with np.errstate(invalid="ignore", divide="ignore"):
            m = (total - np.where(fin, s[..., r], 0.0)) / (count - fin)
        if not np.isfinite(m).any():
            raise ValueError("no finite score on the remaining trials")
        ix = np.unravel_index(int(np.nanargmin(m)), m.shape)
        held[r] = s[ix + (r,)]
        for d, i in zip(p, ix):
            chosen[d].append(scores.coords[d].values[i])
    best = optimum(scores, dim=dim, params=p)
    coords = {dim: scores.coords[dim].values} if dim in scores.coords else {}
    held_attrs = {
        "units": str(scores.attrs.get("units", "")),
        "long_name": f"held-out {scores.attrs.get('long_name', 'score')}",
    }
    ds = xr.Dataset(
        {
            "score": ((dim,), held, held_attrs),
            **{
                d: ((dim,), np.asarray(v), _param_attrs(scores, d))
                for d, v in chosen.items()
            },
        },
        coords=coords,
    )
    ds.attrs = {
        "mean": float(np.nanmean(held)),
        "optimistic_mean": best["score"],
        **{f"optimistic_{d}": best[d] for d in p},
    }
    return ds


def error_table(
    recordings: Mapping[Any, xr.Dataset],
    estimators: Mapping[str, Callable[[xr.Dataset], Any]],
    score_fn: Callable[[Any, xr.Dataset], float] | None = None,
    *,
    n_jobs: int | None = None,
) -> xr.DataArray:
    """Score several estimators on several recordings, in parallel threads.

    Parameters
    ----------
    recordings : mapping
        Label → Recording.
    estimators : mapping
        Name → ``f(rec) -> q`` (an (N, 4) array or DataArray), e.g.
        ``lambda r: filters.estimate(r, "madgwick", beta=0.03)``.
    score_fn : callable, optional
        ``score_fn(q, rec) -> float``; default :func:`tiltlab.evaluate.tilt_rmse`.
    n_jobs : int, optional
        Threads (default ``os.cpu_count()``); numba kernels release the GIL.

    Returns
    -------
    xarray.DataArray
        Dims (estimator, recording).
    """
    if not recordings or not estimators:
        raise ValueError("recordings and estimators must not be empty")
    score_fn = score_fn or tilt_rmse
    labels, names = list(recordings), list(estimators)
    tasks = [(i, j) for i in range(len(names)) for j in range(len(labels))]

    def job(t):
        i, j = t
        rec = recordings[labels[j]]
        return i, j, float(score_fn(estimators[names[i]](rec), rec))

    n_jobs = _n_jobs(n_jobs)
    if n_jobs == 1:
        res = [job(t) for t in tasks]
    else:
        with ThreadPoolExecutor(max_workers=n_jobs) as ex:
            res = list(ex.map(job, tasks))
    out = np.full((len(names), len(labels)), np.nan)
    for i, j, v in res:
        out[i, j] = v
    return xr.DataArray(
        out,
        dims=("estimator", "recording"),
        coords={"estimator": names, "recording": labels},
        name="score",
        attrs=_score_attrs(score_fn, None),
    )


#: Long names of the columns of :func:`loto_summary`.
_SUMMARY = {
    "loto_mean": "mean held-out score (LOTO)",
    "optimistic_mean": "mean score at the all-trials optimum",
    "parameters": "parameters of the all-trials optimum",
    "same_choice_all_folds": "same choice in every fold",
    "n_trials": "trials",
}


def loto_summary(
    grids: Mapping[str, xr.DataArray], *, dim: str = "recording"
) -> pd.DataFrame:
    """Summarise leave-one-trial-out selection, one row per method.

    Parameters
    ----------
    grids : mapping
        Method name → score DataArray over parameter dims and ``dim`` (other dims
        selected away).
    dim : str
        The trial dimension.

    Returns
    -------
    pandas.DataFrame
        Index the methods; columns ``loto_mean`` (mean held-out score),
        ``optimistic_mean`` (the all-trials optimum, optimistic), ``parameters``
        (the optimum's; the folds' choices are in :func:`loto`),
        ``same_choice_all_folds`` and ``n_trials``; labelled (scores in the units of
        the first grid).

    Examples
    --------
    >>> import xarray as xr
    >>> g = xr.DataArray([[3.0, 2.0, 2.5], [1.0, 1.5, 1.2]], dims=("beta", "recording"),
    ...                  coords={"beta": [0.01, 0.1]}, attrs={"units": "deg"})
    >>> t = loto_summary({"madgwick": g})
    >>> t.loc["madgwick", "parameters"], t.attrs["units"]["loto_mean"]
    ('beta=0.1', 'deg')
    """
    rows = {}
    for name, g in grids.items():
        ds = loto(g, dim=dim)
        params = {
            k[len("optimistic_") :]: v
            for k, v in ds.attrs.items()
            if k.startswith("optimistic_") and k != "optimistic_mean"
        }
        folds = {d: ds[d].values for d in params}
        stable = all(np.all(v == v[0]) for v in folds.values())
        rows[name] = {
            "loto_mean": ds.attrs["mean"],
            "optimistic_mean": ds.attrs["optimistic_mean"],
            "parameters": ", ".join(
                f"{k}={v:g}" if isinstance(v, (int, float)) else f"{k}={v}"
                for k, v in params.items()
            ),
            "same_choice_all_folds": bool(stable),
            "n_trials": int(g.sizes[dim]),
        }
    units = next(iter(grids.values())).attrs.get("units", "") if grids else ""
    return label_columns(
        pd.DataFrame.from_dict(rows, orient="index", columns=list(_SUMMARY)),
        units={"loto_mean": units, "optimistic_mean": units, "n_trials": "1"}
        | dict.fromkeys(["parameters", "same_choice_all_folds"], ""),
        long_name=_SUMMARY,
    )
