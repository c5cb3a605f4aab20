r"""Evaluation of tilt estimates: per-sample errors, Table-1 statistics, error versus
angular speed, empirical CDFs, per-trial error tables and leave-one-trial-out (LOTO)
parameter selection.

Error definitions
-----------------
The tilt error of an estimate is the angle between the estimated and the reference
gravity-up directions in the sensor frame,

.. math::
    \epsilon_k = \arccos\big(\hat g_k \cdot g^{\mathrm{ref}}_k\big),
    \qquad g = R(q)^\top e_z ,

which equals BROAD's inclination error :math:`2\arccos\sqrt{e_w^2 + e_z^2}` of the
error quaternion :math:`e = q \otimes q_{\mathrm{ref}}^{-1}` [2]_ (the heading part of
:math:`e` does not move :math:`e_z`). Fayat et al. [1]_ report the distribution of
:math:`\epsilon_k` (mean, standard deviation, median, Q25, Q75, Q95) during immobility
and movement separately (their Table 1); BROAD reports the RMS over the samples marked
``movement``.

Leave-one-trial-out selection
-----------------------------
For a score array :math:`S(\theta, r)` over a parameter grid :math:`\theta` and trials
:math:`r`, the held-out score of trial :math:`r` is :math:`S(\hat\theta_{-r}, r)` with
:math:`\hat\theta_{-r} = \arg\min_\theta \frac{1}{R-1}\sum_{r' \ne r} S(\theta, r')`:
parameters are never chosen on the trial they are scored on. The "all-trials
optimum" :math:`\min_\theta \bar S(\theta)` is optimistic (selection on the test data).

References
----------
.. [1] R. Fayat, V. Delgado Betancourt, T. Goyallon, M. Petremann, P. Liaudet,
   V. Descossy, L. Reveret, G. P. Dugué, "Inertial measurement of head tilt in
   rodents: principles and applications to vestibular research", Sensors 21(18):6318,
   2021. doi:10.3390/s21186318
.. [2] D. Laidig, M. Caruso, A. Cereatti, T. Seel, "BROAD — A Benchmark for Robust
   Inertial Orientation Estimation", Data 6(7):72, 2021. doi:10.3390/data6070072
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from . import quaternion as quat

__all__ = [
    "STATES",
    "STATISTICS",
    "FAYAT_TABLE1",
    "shift_quaternions",
    "shifted_score",
    "tilt_errors",
    "error_stats",
    "table1",
    "state_scores",
    "binned_by_speed",
    "ecdf",
    "optimum",
    "loto",
    "error_table",
    "loto_summary",
    "pairwise_tilt_rms",
    "mocap_reference",
]

#: Behavioural states of Table 1 (plus ``all`` in :func:`state_scores`).
STATES = ("immobile", "moving")
#: Statistics of Table 1, in order.
STATISTICS = ("mean", "std", "median", "q25", "q75", "q95")

#: Fayat et al. (2021) Table 1 [1]_: angular errors (degrees) of IMU head-tilt
#: estimation against optical motion capture in freely moving rats (36 min, 300 Hz),
#: with the optimal parameters of their grid search (low-pass 2 Hz; Madgwick β = 0.1;
#: Mahony kp = 0.3, kI = 1.8; EKF v_g = 1.0 deg² s⁻², v_a = 0.002 g²). Published
#: numbers, transcribed from the paper.
FAYAT_TABLE1 = pd.DataFrame(
    {
        ("immobile", "lowpass"): [0.43, 0.41, 0.32, 0.18, 0.55, 1.16],
        ("immobile", "madgwick"): [0.36, 0.25, 0.31, 0.19, 0.47, 0.81],
        ("immobile", "mahony"): [0.39, 0.25, 0.35, 0.20, 0.52, 0.83],
        ("immobile", "ekf"): [0.44, 0.27, 0.39, 0.24, 0.58, 0.91],
        ("moving", "lowpass"): [3.08, 2.58, 2.44, 1.35, 4.12, 7.67],
        ("moving", "madgwick"): [1.56, 1.23, 1.27, 0.73, 2.08, 3.83],
        ("moving", "mahony"): [1.52, 1.26, 1.19, 0.67, 2.00, 3.87],
        ("moving", "ekf"): [1.17, 0.99, 0.93, 0.53, 1.55, 2.99],
    },
    index=pd.Index(STATISTICS, name="statistic"),
)
FAYAT_TABLE1.columns.names = ["state", "method"]


def _quat_array(q, name: str) -> np.ndarray:
    if isinstance(q, xr.DataArray):
        if "quat" not in q.dims:
            raise ValueError(f"{name} must have a 'quat' dimension, got {q.dims}")
        q = q.transpose(..., "quat").values
    q = np.asarray(q, dtype=float)
    if q.ndim != 2 or q.shape[1] != 4:
        raise ValueError(f"{name} must have shape (N, 4), got {q.shape}")
    return q


def shift_quaternions(q, samples: float) -> np.ndarray:
    r"""Resample an orientation series at times shifted by ``samples`` sampling intervals.

    ``out[k] = q(k + samples)`` by normalised linear interpolation (nlerp, sign-aligned)
    between neighbouring samples; times outside the series take the end values. A
    positive shift advances the series (compensates an estimate that *lags* its
    reference by ``samples / fs`` seconds).

    Parameters
    ----------
    q : array_like or xarray.DataArray, shape (N, 4)
        Unit quaternions (w, x, y, z).
    samples : float
        Shift in samples (fractional allowed).

    Returns
    -------
    numpy.ndarray, shape (N, 4)
    """
    q = _quat_array(q, "q")
    s = float(samples)
    if not np.isfinite(s):
        raise ValueError(f"samples must be finite, got {samples!r}")
    n = q.shape[0]
    if n < 2 or s == 0.0:
        return q.copy()
    x = np.clip(np.arange(n) + s, 0.0, n - 1.0)
    i = np.minimum(np.floor(x).astype(np.int64), n - 2)
    f = (x - i)[:, None]
    a, b = q[i], q[i + 1]
    b = np.where(np.sum(a * b, axis=1, keepdims=True) < 0, -b, b)
    return quat.normalize((1.0 - f) * a + f * b)


def shifted_score(shifts: Sequence[float], score_fn: Callable[[Any, xr.Dataset], float] | None = None
                  ) -> Callable[[Any, xr.Dataset], xr.DataArray]:
    """A ``score_fn`` for :func:`tiltlab.filters.grid_search` that scores the estimate at
    several time shifts (:func:`shift_quaternions`, in samples): returns a DataArray over
    ``shift``, so that the shift is one more dimension of the grid (and of LOTO selection).
    The same shifts must be applied to every method compared."""
    from .filters import tilt_rmse

    sh = np.asarray(shifts, dtype=float).ravel()
    if sh.size == 0 or not np.all(np.isfinite(sh)):
        raise ValueError("shifts must be a non-empty sequence of finite numbers")
    fn = score_fn or tilt_rmse

    def score(q, rec):
        return xr.DataArray([float(fn(shift_quaternions(q, d), rec)) for d in sh], dims=("shift",),
                            coords={"shift": sh})

    return score


def tilt_errors(q_est, ref) -> np.ndarray:
    r"""Per-sample tilt error (degrees) between an estimate and a reference.

    Parameters
    ----------
    q_est : array_like or xarray.DataArray, shape (N, 4)
        Estimated orientations (sensor → world).
    ref : array_like, shape (N, 4) or (N, 3)
        Reference quaternions, or reference gravity-up directions in the sensor frame
        (any norm). Rows with NaN give NaN.

    Returns
    -------
    numpy.ndarray, shape (N,)
        :math:`\arccos(\hat g \cdot g_{ref})` in degrees.
    """
    q = _quat_array(q_est, "q_est")
    r = ref.values if isinstance(ref, xr.DataArray) else np.asarray(ref, dtype=float)
    if r.ndim != 2 or r.shape[0] != q.shape[0] or r.shape[1] not in (3, 4):
        raise ValueError(f"ref must have shape ({q.shape[0]}, 4) or ({q.shape[0]}, 3), got {r.shape}")
    bad = ~np.all(np.isfinite(r), axis=1) | ~np.all(np.isfinite(q), axis=1)
    if r.shape[1] == 4:
        r = quat.gravity(np.where(bad[:, None], [1.0, 0.0, 0.0, 0.0], r))
    else:
        nr = np.linalg.norm(np.where(bad[:, None], 1.0, r), axis=1, keepdims=True)
        r = np.where(bad[:, None], [0.0, 0.0, 1.0], r / np.where(nr == 0, 1.0, nr))
    g = quat.gravity(np.where(bad[:, None], [1.0, 0.0, 0.0, 0.0], q))
    e = np.degrees(quat.angle_between(g, r))
    e[bad] = np.nan
    return e


def error_stats(errors, mask=None) -> dict[str, float]:
    """Table-1 statistics (mean, std, median, Q25, Q75, Q95) of finite errors, plus ``n``
    and ``rmse``; ``mask`` selects samples. NaN statistics when nothing is selected."""
    e = np.asarray(errors, dtype=float).ravel()
    if mask is not None:
        m = np.asarray(mask, dtype=bool).ravel()
        if m.shape != e.shape:
            raise ValueError(f"mask has {m.size} samples, errors {e.size}")
        e = e[m]
    e = e[np.isfinite(e)]
    if e.size == 0:
        return {**{k: float("nan") for k in STATISTICS}, "rmse": float("nan"), "n": 0}
    q25, med, q75, q95 = np.percentile(e, [25, 50, 75, 95])
    return {"mean": float(e.mean()), "std": float(e.std(ddof=1)) if e.size > 1 else 0.0, "median": float(med),
            "q25": float(q25), "q75": float(q75), "q95": float(q95), "rmse": float(np.sqrt(np.mean(e * e))),
            "n": int(e.size)}


def table1(errors: Mapping[str, Any], immobile, *, statistics: Sequence[str] = STATISTICS) -> pd.DataFrame:
    """Fayat-style Table 1: statistics of per-sample errors during immobility and movement.

    Parameters
    ----------
    errors : mapping
        Method name → per-sample errors (degrees), all of the same length (NaN = no
        reference). Several sessions may be concatenated.
    immobile : array_like of bool
        Immobility mask of the same length.

    Returns
    -------
    pandas.DataFrame
        Index ``statistic``; columns MultiIndex (``state`` ∈ immobile, moving;
        ``method``), like :data:`FAYAT_TABLE1`.
    """
    if not errors:
        raise ValueError("errors is empty")
    im = np.asarray(immobile, dtype=bool).ravel()
    cols = {}
    for state, m in (("immobile", im), ("moving", ~im)):
        for name, e in errors.items():
            st = error_stats(e, m)
            cols[(state, name)] = [st[s] for s in statistics]
    df = pd.DataFrame(cols, index=pd.Index(list(statistics), name="statistic"))
    df.columns.names = ["state", "method"]
    return df


def state_scores(q, rec: xr.Dataset, *, ref: str = "tilt_ref", state: str = "immobile",
                 stat: str = "mean") -> xr.DataArray:
    """Tilt-error statistic per behavioural state: a DataArray-valued ``score_fn`` for
    :func:`tiltlab.filters.grid_search` (dims ``state`` = immobile, moving, all).

    Parameters
    ----------
    q : array_like (N, 4)
        Estimate.
    rec : xarray.Dataset
        Recording with the reference ``ref`` (quaternions (time, quat) or gravity-up
        directions (time, axis)) and a boolean ``state`` variable (True = immobile).
    stat : str
        One of :data:`STATISTICS` or ``"rmse"``.
    """
    if ref not in rec or state not in rec:
        raise ValueError(f"recording needs variables {ref!r} and {state!r}")
    if stat not in STATISTICS + ("rmse",):
        raise ValueError(f"stat must be one of {STATISTICS + ('rmse',)}, got {stat!r}")
    e = tilt_errors(q, rec[ref].values)
    im = rec[state].values.astype(bool)
    vals = [error_stats(e, im)[stat], error_stats(e, ~im)[stat], error_stats(e)[stat]]
    return xr.DataArray(vals, dims=("state",), coords={"state": ["immobile", "moving", "all"]})


def binned_by_speed(errors: Mapping[str, Any], speed, edges) -> xr.Dataset:
    """Median and interquartile range of errors by angular-speed bin (Fayat Fig. 2f).

    Parameters
    ----------
    errors : mapping
        Method → per-sample errors (degrees).
    speed : array_like
        Angular speed (°/s), same length.
    edges : array_like
        Bin edges (°/s), increasing.

    Returns
    -------
    xarray.Dataset
        Variables ``median``, ``q25``, ``q75``, ``n`` with dims (estimator, speed); the
        ``speed`` coordinate is the bin centre, ``speed_lo``/``speed_hi`` the edges.
    """
    edges = np.asarray(edges, dtype=float)
    if edges.ndim != 1 or edges.size < 2 or np.any(np.diff(edges) <= 0):
        raise ValueError("edges must be a 1-D increasing array with at least two values")
    sp = np.asarray(speed, dtype=float).ravel()
    idx = np.digitize(sp, edges) - 1
    nb = edges.size - 1
    names = list(errors)
    out = {k: np.full((len(names), nb), np.nan) for k in ("median", "q25", "q75")}
    cnt = np.zeros((len(names), nb), dtype=np.int64)
    for i, name in enumerate(names):
        e = np.asarray(errors[name], dtype=float).ravel()
        if e.shape != sp.shape:
            raise ValueError(f"errors[{name!r}] has {e.size} samples, speed {sp.size}")
        for b in range(nb):
            v = e[(idx == b) & np.isfinite(e)]
            cnt[i, b] = v.size
            if v.size:
                out["q25"][i, b], out["median"][i, b], out["q75"][i, b] = np.percentile(v, [25, 50, 75])
    dims = ("estimator", "speed")  # not "method": it would clash with the ``method`` argument of ``.sel``
    coords = {"estimator": names, "speed": 0.5 * (edges[:-1] + edges[1:]),
              "speed_lo": ("speed", edges[:-1]), "speed_hi": ("speed", edges[1:])}
    return xr.Dataset({**{k: (dims, v, {"units": "deg"}) for k, v in out.items()}, "n": (dims, cnt)}, coords=coords)


def ecdf(values) -> tuple[np.ndarray, np.ndarray]:
    """Empirical CDF of the finite values: sorted ``x`` and ``F(x) = i / n`` (i = 1…n)."""
    v = np.asarray(values, dtype=float).ravel()
    v = np.sort(v[np.isfinite(v)])
    if v.size == 0:
        raise ValueError("no finite values")
    return v, np.arange(1, v.size + 1) / v.size


def _param_dims(scores: xr.DataArray, dim: str, params: Sequence[str] | None) -> list[str]:
    if dim not in scores.dims:
        raise ValueError(f"scores has no {dim!r} dimension (dims {scores.dims})")
    p = [d for d in scores.dims if d != dim] if params is None else list(params)
    for d in p:
        if d not in scores.dims or d == dim:
            raise ValueError(f"{d!r} is not a parameter dimension of scores")
    return p


def optimum(scores: xr.DataArray, *, dim: str = "recording", params: Sequence[str] | None = None) -> dict[str, Any]:
    """Parameters minimising the mean score over ``dim`` (the optimistic all-trials optimum).

    Parameters
    ----------
    scores : xarray.DataArray
        Scores over parameter dims and ``dim`` (NaN-aware mean).
    params : sequence of str, optional
        Dims to optimise over (default: all but ``dim``); other dims must be absent.

    Returns
    -------
    dict
        Parameter name → value, plus ``score`` (the minimal mean).
    """
    p = _param_dims(scores, dim, params)
    if set(scores.dims) - set(p) - {dim}:
        raise ValueError(f"select or reduce the dims {sorted(set(scores.dims) - set(p) - {dim})} first")
    m = scores.mean(dim).transpose(*p)
    if not np.isfinite(m.values).any():
        raise ValueError("no finite mean score")
    flat = int(np.nanargmin(m.values))
    ix = np.unravel_index(flat, m.shape)
    best = {d: m.coords[d].values[i].item() for d, i in zip(p, ix)}
    best["score"] = float(m.values[ix])
    return best


def loto(scores: xr.DataArray, *, dim: str = "recording", params: Sequence[str] | None = None) -> xr.Dataset:
    """Leave-one-trial-out selection: each trial scored with the parameters that minimise
    the mean score over the *other* trials.

    Parameters
    ----------
    scores : xarray.DataArray
        Scores over parameter dims and ``dim`` (e.g. the output of
        :func:`tiltlab.filters.grid_search`, with other dims selected away).
    dim : str
        The trial dimension (at least two trials).
    params : sequence of str, optional
        Parameter dims (default: all but ``dim``).

    Returns
    -------
    xarray.Dataset
        Over ``dim``: ``score`` (held-out score), and one variable per parameter with
        the value chosen without that trial; attrs ``mean`` (mean held-out score),
        ``optimistic_mean`` (all-trials optimum) and ``optimistic_<param>``.
    """
    p = _param_dims(scores, dim, params)
    if set(scores.dims) - set(p) - {dim}:
        raise ValueError(f"select or reduce the dims {sorted(set(scores.dims) - set(p) - {dim})} first")
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
    ds = xr.Dataset({"score": ((dim,), held), **{d: ((dim,), np.asarray(v)) for d, v in chosen.items()}}, coords=coords)
    ds.attrs = {"mean": float(np.nanmean(held)), "optimistic_mean": best["score"],
                **{f"optimistic_{d}": best[d] for d in p}}
    return ds


def error_table(recordings: Mapping[Any, xr.Dataset], estimators: Mapping[str, Callable[[xr.Dataset], Any]],
                score_fn: Callable[[Any, xr.Dataset], float] | None = None, *, n_jobs: int | None = None) -> xr.DataArray:
    """Score several estimators on several recordings, in parallel threads.

    Parameters
    ----------
    recordings : mapping
        Label → Recording.
    estimators : mapping
        Name → ``f(rec) -> q`` (an (N, 4) array or DataArray), e.g.
        ``lambda r: filters.estimate(r, "madgwick", beta=0.03)``.
    score_fn : callable, optional
        ``score_fn(q, rec) -> float``; default :func:`tiltlab.filters.tilt_rmse`.
    n_jobs : int, optional
        Threads (default ``os.cpu_count()``); numba kernels release the GIL.

    Returns
    -------
    xarray.DataArray
        Dims (estimator, recording).
    """
    from .filters import tilt_rmse

    if not recordings or not estimators:
        raise ValueError("recordings and estimators must not be empty")
    score_fn = score_fn or tilt_rmse
    labels, names = list(recordings), list(estimators)
    tasks = [(i, j) for i in range(len(names)) for j in range(len(labels))]

    def job(t):
        i, j = t
        rec = recordings[labels[j]]
        return i, j, float(score_fn(estimators[names[i]](rec), rec))

    n_jobs = n_jobs or os.cpu_count() or 1
    if n_jobs == 1:
        res = [job(t) for t in tasks]
    else:
        with ThreadPoolExecutor(max_workers=n_jobs) as ex:
            res = list(ex.map(job, tasks))
    out = np.full((len(names), len(labels)), np.nan)
    for i, j, v in res:
        out[i, j] = v
    return xr.DataArray(out, dims=("estimator", "recording"), coords={"estimator": names, "recording": labels}, name="score")


def loto_summary(grids: Mapping[str, xr.DataArray], *, dim: str = "recording") -> pd.DataFrame:
    """One row per method: LOTO mean score, optimistic all-trials optimum and the
    parameters chosen (the optimum's; the folds' choices are in :func:`loto`).

    Parameters
    ----------
    grids : mapping
        Method name → score DataArray over parameter dims and ``dim`` (other dims
        selected away).
    """
    rows = {}
    for name, g in grids.items():
        ds = loto(g, dim=dim)
        params = {k[len("optimistic_"):]: v for k, v in ds.attrs.items() if k.startswith("optimistic_") and k != "optimistic_mean"}
        folds = {d: ds[d].values for d in params}
        stable = all(np.all(v == v[0]) for v in folds.values())
        rows[name] = {"loto_mean": ds.attrs["mean"], "optimistic_mean": ds.attrs["optimistic_mean"],
                      "parameters": ", ".join(f"{k}={v:g}" if isinstance(v, (int, float)) else f"{k}={v}"
                                              for k, v in params.items()),
                      "same_choice_all_folds": bool(stable), "n_trials": int(g.sizes[dim])}
    return pd.DataFrame.from_dict(rows, orient="index")


def pairwise_tilt_rms(estimates: Mapping[str, Any], mask=None) -> xr.DataArray:
    """RMS tilt difference (degrees) between every pair of estimates of the same recording
    (agreement between filters when there is no ground truth).

    Parameters
    ----------
    estimates : mapping
        Method → quaternions (N, 4), all the same length.
    mask : array_like of bool, optional
        Samples to use (e.g. movement only).

    Returns
    -------
    xarray.DataArray
        Dims (estimator, other), symmetric with a zero diagonal.
    """
    names = list(estimates)
    if len(names) < 2:
        raise ValueError("need at least two estimates")
    g = {k: quat.gravity(_quat_array(v, k)) for k, v in estimates.items()}
    n = g[names[0]].shape[0]
    if any(v.shape[0] != n for v in g.values()):
        raise ValueError("all estimates must have the same length")
    m = np.ones(n, bool) if mask is None else np.asarray(mask, bool)
    out = np.zeros((len(names), len(names)))
    for i, a in enumerate(names):
        for j in range(i + 1, len(names)):
            d = np.degrees(quat.angle_between(g[a][m], g[names[j]][m]))
            out[i, j] = out[j, i] = float(np.sqrt(np.mean(d * d)))
    return xr.DataArray(out, dims=("estimator", "other"), coords={"estimator": names, "other": names}, name="tilt_rms_difference",
                        attrs={"units": "deg"})


def mocap_reference(rec: xr.Dataset, mocap: xr.Dataset, *, threshold: float | str = 12.0, gyr_offset=None,
                    drop_fraction: float = 0.02, cutoff_hz: float = 2.0) -> xr.Dataset:
    r"""Reference head tilt from motion-capture markers, in the IMU frame (Fayat §2.6).

    The pipeline: (1) TTL synchronisation: the IMU samples flagged ``sync`` carry the
    video TTLs emitted every ``ttl_every`` frames; clock slips are repaired
    (:func:`tiltlab.calibration.repair_ttl_slips`) to get one mocap frame per IMU
    sample; (2) marker quality control: the frames with the ``drop_fraction`` largest
    deviations of the marker-1–2 distance from its median are dropped
    (:func:`tiltlab.calibration.marker_distance_qc`); (3) head frame from markers 1–3
    and tilt :math:`z^h = R_h^	op e_z` (:func:`tiltlab.calibration.tilt_from_markers`);
    (4) immobility from the angular speed (:func:`tiltlab.behavior.immobility`, Fayat
    §2.9); (5) the IMU→head rotation :math:`R` by Kabsch alignment of the normalised
    low-passed (``cutoff_hz``) acceleration with :math:`z^h` during immobility
    (:func:`tiltlab.calibration.imu_to_head_alignment`); (6) the reference in the IMU
    frame :math:`g^{ref} = R^	op z^h`.

    Parameters
    ----------
    rec : xarray.Dataset
        IMU Recording with a boolean ``sync`` variable (TTL-bearing samples); already
        offset-corrected if offsets are to be corrected.
    mocap : xarray.Dataset
        Markers (``markers`` (frame, marker, axis), boolean ``ttl``; attr ``ttl_every``),
        as from :func:`tiltlab.simulate.simulate_mocap_session`.
    threshold : float or "auto"
        Immobility threshold (°/s).
    gyr_offset : array_like (3,), optional
        Gyroscope offset (units of ``rec.gyr``) for the immobility detection.

    Returns
    -------
    xarray.Dataset
        ``rec`` restricted to the synchronised span, with ``tilt_ref`` (time, axis; NaN
        where QC dropped the frame), ``immobile`` (time) and attrs ``qc_dropped``,
        ``optical_tilt_uncertainty_deg``, ``kabsch_rms_deg``, ``n_clock_slips``.
    """
    from . import behavior
    from . import calibration as cal

    for v in ("sync", "acc", "gyr"):
        if v not in rec:
            raise ValueError(f"rec needs a {v!r} variable")
    if "markers" not in mocap or "ttl" not in mocap:
        raise ValueError("mocap needs 'markers' and 'ttl' variables")
    cycle = int(mocap.attrs.get("ttl_every", 0))
    if cycle < 1:
        raise ValueError("mocap has no valid 'ttl_every' attribute")
    ttl_imu = np.flatnonzero(rec["sync"].values.astype(bool))
    ttl_frames = np.flatnonzero(mocap["ttl"].values.astype(bool))
    if ttl_frames.size == 0:
        raise ValueError("mocap has no TTL frame")
    n = min(ttl_imu.size, ttl_frames.size)
    rep = cal.repair_ttl_slips(mocap["markers"].transpose("frame", "marker", "axis").values, ttl_imu[:n],
                               cycle=cycle, first_frame=int(ttl_frames[0]))
    out = rec.isel(time=rep.imu_index)
    p1, p2, p3 = rep.mocap[:, 0], rep.mocap[:, 1], rep.mocap[:, 2]
    qc = cal.marker_distance_qc(p1, p2, drop_fraction=drop_fraction)
    tilt_head = cal.tilt_from_markers(p1, p2, p3)
    tilt_head[~qc.keep] = np.nan
    im = behavior.immobility(out, threshold=threshold, gyr_offset=gyr_offset)
    acc = out["acc"].transpose("time", "axis").values
    al = cal.imu_to_head_alignment(acc, tilt_head, float(rec.attrs["fs"]), still=im.values, cutoff_hz=cutoff_hz)
    g_imu = tilt_head @ al.matrix  # R^T z for each row z
    out = out.assign(tilt_ref=(("time", "axis"), g_imu, {"units": "1", "frame": "sensor",
                                                          "long_name": "reference gravity-up direction from motion capture"}),
                     immobile=im)
    out.attrs.update({"qc_dropped": int((~qc.keep).sum()), "optical_tilt_uncertainty_deg": qc.tilt_uncertainty_deg,
                      "kabsch_rms_deg": al.rms_deg, "n_clock_slips": int(rep.n_duplicated + rep.n_deleted),
                      "immobility_threshold_deg_s": float(im.attrs["threshold_deg_s"])})
    return out
