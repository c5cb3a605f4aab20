r"""Error definitions and statistics of tilt estimates.

Per-sample tilt errors, BROAD's RMSEs, Fayat's
Table-1 statistics, error versus angular speed, empirical CDFs and agreement between
estimates.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from .. import quaternion as quat
from .._labels import label_columns

__all__ = [
    "MOTION_STATES",
    "STATISTICS",
    "FAYAT_TABLE1",
    "shift_quaternions",
    "shifted_score",
    "tilt_errors",
    "error_stats",
    "error_summary",
    "table1",
    "state_scores",
    "binned_by_speed",
    "ecdf",
    "pairwise_tilt_rms",
    "broad_errors",
    "tilt_rmse",
]

#: Behavioural states of Table 1 (plus ``all`` in :func:`state_scores`).
MOTION_STATES = ("immobile", "moving")
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

#: Long names of the statistics of Table 1 and of :func:`error_stats`.
STATISTIC_NAMES = {
    "mean": "mean",
    "std": "standard deviation",
    "median": "median",
    "q25": "25th percentile",
    "q75": "75th percentile",
    "q95": "95th percentile",
    "rmse": "RMS",
    "n": "samples",
}


def _label_table1(df: pd.DataFrame) -> pd.DataFrame:
    """Table 1 with its columns labelled: tilt errors in degrees, by state and method."""
    return label_columns(
        df,
        units="deg",
        long_name={c: f"tilt error, {c[0]}, {c[1]}" for c in df.columns},
    )


FAYAT_TABLE1 = _label_table1(FAYAT_TABLE1)


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

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import evaluate
    >>> level = [1.0, 0.0, 0.0, 0.0]
    >>> half = np.radians(5.0) / 2  # 5° about x
    >>> tipped = [np.cos(half), np.sin(half), 0.0, 0.0]
    >>> np.round(evaluate.tilt_errors([level, tipped], [level, level]), 3)
    array([0., 5.])
    >>> np.round(evaluate.tilt_errors([tipped], [[0.0, 0.0, 1.0]]), 3)  # gravity-up ref
    array([5.])
    """
    q = _quat_array(q_est, "q_est")
    r = ref.values if isinstance(ref, xr.DataArray) else np.asarray(ref, dtype=float)
    if r.ndim != 2 or r.shape[0] != q.shape[0] or r.shape[1] not in (3, 4):
        raise ValueError(
            f"ref must have shape ({q.shape[0]}, 4) or ({q.shape[0]}, 3), got {r.shape}"
        )
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


def _valid_mask(q_est: np.ndarray, rec: xr.Dataset, movement_only: bool) -> np.ndarray:
    q_ref = rec["q_ref"].transpose("time", "quat").values
    mask = np.all(np.isfinite(q_ref), axis=1) & np.all(np.isfinite(q_est), axis=1)
    if movement_only:
        if "movement" not in rec:
            raise ValueError(
                "recording has no 'movement' variable; pass movement_only=False"
            )
        mask &= rec["movement"].values.astype(bool)
    return mask


def broad_errors(
    q_est,
    rec: xr.Dataset,
    *,
    movement_only: bool = True,
    remove_heading_offset: bool = False,
) -> dict[str, float]:
    r"""RMSE (degrees) of inclination (= tilt), heading and total error, BROAD's definition.

    Error quaternion in the earth frame :math:`e = q_{est} \otimes q_{ref}^{-1}`; total
    :math:`2\arccos|e_w|`, heading :math:`2\arctan|e_z/e_w|`, inclination
    :math:`2\arccos\sqrt{e_w^2+e_z^2}` (:func:`tiltlab.quaternion.tilt_error` etc.).
    RMS over the samples where ``movement`` is true (BROAD's rule) and the reference
    is valid (NaN where optical tracking was lost).

    Parameters
    ----------
    q_est : xarray.DataArray or array_like, shape (N, 4)
        Estimated unit quaternions (w, x, y, z), one per sample of ``rec``.
    rec : xarray.Dataset
        Recording with ``q_ref`` (and ``movement``).
    movement_only : bool
        Score only the samples where the Recording's boolean ``movement`` variable is
        true (BROAD's rule; a ``ValueError`` if it has none); False scores every
        sample with a finite estimate and reference.
    remove_heading_offset : bool
        Remove the constant heading offset between the estimate's and the reference's
        world frames first (circular mean over the valid samples). BROAD does not do
        this; use it for 6D methods, whose heading origin is arbitrary. The inclination
        error is unaffected.

    Returns
    -------
    dict
        ``inclination``, ``heading``, ``total`` (degrees) and ``n`` (samples used).
    """
    if "q_ref" not in rec:
        raise ValueError("recording has no 'q_ref' (reference orientation)")
    q = (
        q_est.transpose("time", "quat").values
        if isinstance(q_est, xr.DataArray)
        else np.asarray(q_est, float)
    )
    if q.shape != (rec.sizes["time"], 4):
        raise ValueError(
            f"q_est must have shape ({rec.sizes['time']}, 4), got {q.shape}"
        )
    mask = _valid_mask(q, rec, movement_only)
    if not mask.any():
        raise ValueError("no valid samples (movement with a finite reference)")
    qe, qr = q[mask], rec["q_ref"].transpose("time", "quat").values[mask]
    if remove_heading_offset:
        e = quat.error_quaternion(qe, qr)
        e = np.where(e[:, :1] < 0, -e, e)
        psi = 2.0 * np.arctan2(e[:, 3], e[:, 0])
        off = np.arctan2(np.mean(np.sin(psi)), np.mean(np.cos(psi)))
        qe = quat.mul(np.array([np.cos(off / 2), 0.0, 0.0, -np.sin(off / 2)]), qe)
    err = quat.error_angles(qe, qr)

    def rms(v):
        return float(np.degrees(np.sqrt(np.mean(v * v))))

    return {
        "inclination": rms(err[:, 2]),
        "heading": rms(err[:, 1]),
        "total": rms(err[:, 0]),
        "n": int(mask.sum()),
    }


def tilt_rmse(q_est, rec: xr.Dataset) -> float:
    """Inclination RMSE (degrees) over BROAD's movement samples: a ``score_fn`` for :func:`grid_search`.

    Parameters
    ----------
    q_est, rec
        As for :func:`broad_errors` (estimate and Recording with ``q_ref``).

    Returns
    -------
    float
        Inclination RMSE (degrees), see :func:`broad_errors`.
    """
    return broad_errors(q_est, rec)["inclination"]


def shifted_score(
    shifts: Sequence[float], score_fn: Callable[[Any, xr.Dataset], float] | None = None
) -> Callable[[Any, xr.Dataset], xr.DataArray]:
    """Make a ``score_fn`` for :func:`grid_search` that scores at several time shifts.

    It scores the estimate at several time shifts (:func:`shift_quaternions`, in samples): returns a DataArray over
    ``shift``, so that the shift is one more dimension of the grid (and of LOTO selection).
    The same shifts must be applied to every method compared.

    Parameters
    ----------
    shifts : sequence of float
        Time shifts (samples, fractional allowed); non-empty and finite.
    score_fn : callable, optional
        ``score_fn(q_est, rec) -> float`` applied to each shifted estimate; default
        :func:`tilt_rmse` (degrees).

    Returns
    -------
    callable
        ``score(q_est, rec) -> xarray.DataArray`` over the ``shift`` dimension (same
        units as ``score_fn``).

    Raises
    ------
    ValueError
        If ``shifts`` is empty or holds a non-finite value.
    """
    sh = np.asarray(shifts, dtype=float).ravel()
    if sh.size == 0 or not np.all(np.isfinite(sh)):
        raise ValueError("shifts must be a non-empty sequence of finite numbers")
    fn = score_fn or tilt_rmse
    attrs = {"units": "deg", "long_name": "tilt RMSE"} if fn is tilt_rmse else {}

    def score(q, rec):
        return xr.DataArray(
            [float(fn(shift_quaternions(q, d), rec)) for d in sh],
            dims=("shift",),
            coords={
                "shift": (
                    "shift",
                    sh,
                    {"units": "1", "long_name": "time shift (samples)"},
                )
            },
            attrs=attrs,
        )

    return score


def error_stats(errors, mask=None) -> dict[str, float]:
    """Compute the Table-1 statistics of finite errors.

    Mean, std, median, Q25, Q75, Q95, plus ``n`` and ``rmse``; ``mask`` selects samples. NaN statistics when nothing is selected.

    Parameters
    ----------
    errors : array_like
        Errors (any shape, flattened; e.g. degrees); non-finite values are ignored.
    mask : array_like of bool, optional
        Samples to keep, same number of samples as ``errors``; default all.

    Returns
    -------
    dict
        ``mean``, ``std`` (ddof=1; 0 for a single value), ``median``, ``q25``, ``q75``,
        ``q95`` and ``rmse`` (units of ``errors``), and ``n`` (samples used).

    Raises
    ------
    ValueError
        If ``mask`` and ``errors`` have different numbers of samples.
    """
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
    return {
        "mean": float(e.mean()),
        "std": float(e.std(ddof=1)) if e.size > 1 else 0.0,
        "median": float(med),
        "q25": float(q25),
        "q75": float(q75),
        "q95": float(q95),
        "rmse": float(np.sqrt(np.mean(e * e))),
        "n": int(e.size),
    }


def error_summary(
    estimates: Mapping[str, Any],
    rec: xr.Dataset,
    *,
    ref: str = "q_ref",
    mask: str | None = "movement",
) -> pd.DataFrame:
    r"""Tilt errors of several estimates of one recording, one row per estimate.

    The table to show after running each filter once on a trial: per-sample tilt errors
    (:func:`tilt_errors`) against the recording's reference, summarised over the samples
    selected by ``mask`` (BROAD scores its ``movement`` samples) where the reference is
    finite.

    Parameters
    ----------
    estimates : mapping str → array_like or xarray.DataArray, shape (N, 4)
        Estimated orientations (sensor → world) of ``rec``'s samples, by method.
    rec : xarray.Dataset
        Recording holding the reference ``ref``.
    ref : str
        Reference variable: quaternions (time, quat), e.g. ``q_ref``, or gravity-up
        directions (time, axis), e.g. ``tilt_ref``.
    mask : str or None
        Boolean variable of ``rec`` selecting the scored samples; ignored when ``rec``
        has no such variable (all samples are scored). ``None``: all samples.

    Returns
    -------
    pandas.DataFrame
        Index ``method``; columns ``rmse``, ``mean``, ``median``, ``q95`` (degrees) and
        ``n`` (samples scored). With ``ref="q_ref"`` and ``mask="movement"``, ``rmse`` is
        BROAD's inclination RMSE (:func:`tilt_rmse`). ``attrs["mask"]`` names the mask
        used (``None`` when all samples were scored); ``attrs["units"]`` and
        ``attrs["long_name"]`` label the columns.

    Raises
    ------
    ValueError
        If ``estimates`` is empty or ``rec`` has no variable ``ref``.
    """
    if not estimates:
        raise ValueError("estimates is empty")
    if ref not in rec:
        raise ValueError(
            f"recording has no reference {ref!r}: tilt errors need ground truth"
        )
    used = mask if mask is not None and mask in rec else None
    sel = rec[used].values.astype(bool) if used is not None else None
    rows = {}
    for name, q in estimates.items():
        st = error_stats(tilt_errors(q, rec[ref].values), sel)
        rows[name] = {k: st[k] for k in ("rmse", "mean", "median", "q95", "n")}
    df = pd.DataFrame.from_dict(rows, orient="index")
    df.index.name = "method"
    df["n"] = df["n"].astype(int)
    df = label_columns(
        df,
        units={c: "1" if c == "n" else "deg" for c in df.columns},
        long_name={
            c: "samples scored" if c == "n" else f"tilt error, {STATISTIC_NAMES[c]}"
            for c in df.columns
        },
    )
    df.attrs["mask"] = used
    return df


def table1(
    errors: Mapping[str, Any], immobile, *, statistics: Sequence[str] = STATISTICS
) -> pd.DataFrame:
    """Fayat-style Table 1: statistics of per-sample errors during immobility and movement.

    Parameters
    ----------
    errors : mapping
        Method name → per-sample errors (degrees), all of the same length (NaN = no
        reference). Several sessions may be concatenated.
    immobile : array_like of bool
        Immobility mask of the same length.
    statistics : sequence of str
        Rows of the table, in order: names of :data:`STATISTICS` (the default, all of
        them), ``"rmse"`` or ``"n"`` (samples used).

    Returns
    -------
    pandas.DataFrame
        Index ``statistic``; columns MultiIndex (``state`` ∈ immobile, moving;
        ``method``), like :data:`FAYAT_TABLE1`; values in degrees, columns labelled
        (``attrs["units"]``, ``attrs["long_name"]``).
    """
    if not errors:
        raise ValueError("errors is empty")
    unknown = [s for s in statistics if s not in STATISTICS and s not in ("rmse", "n")]
    if unknown:
        raise ValueError(
            f"statistics: unknown {unknown}; known: {[*STATISTICS, 'rmse', 'n']}"
        )
    im = np.asarray(immobile, dtype=bool).ravel()
    cols = {}
    for state, m in (("immobile", im), ("moving", ~im)):
        for name, e in errors.items():
            n_e = np.asarray(e).size
            if im.size != n_e:
                raise ValueError(
                    f"immobile has {im.size} samples, errors[{name!r}] has {n_e}"
                )
            st = error_stats(e, m)
            cols[(state, name)] = [st[s] for s in statistics]
    df = pd.DataFrame(cols, index=pd.Index(list(statistics), name="statistic"))
    df.columns.names = ["state", "method"]
    return _label_table1(df)


def state_scores(
    q,
    rec: xr.Dataset,
    *,
    ref: str = "tilt_ref",
    state: str = "immobile",
    stat: str = "mean",
) -> xr.DataArray:
    """Compute a tilt-error statistic per behavioural state.

    A DataArray-valued ``score_fn`` for :func:`grid_search` (dims ``state`` = immobile, moving, all).

    Parameters
    ----------
    q : array_like (N, 4)
        Estimate.
    rec : xarray.Dataset
        Recording with the reference ``ref`` (quaternions (time, quat) or gravity-up
        directions (time, axis)) and a boolean ``state`` variable (True = immobile).
    ref : str
        Name of the Recording's reference variable the tilt errors are computed
        against (default ``"tilt_ref"``).
    state : str
        Name of the Recording's boolean variable that is True on immobile samples
        (default ``"immobile"``); the other samples count as moving.
    stat : str
        One of :data:`STATISTICS` or ``"rmse"``.

    Returns
    -------
    xarray.DataArray (state,)
        The statistic of the tilt errors (degrees) for ``state`` =
        immobile, moving, all.

    Raises
    ------
    ValueError
        If ``rec`` lacks ``ref`` or ``state``, or ``stat`` is unknown.
    """
    if ref not in rec or state not in rec:
        raise ValueError(f"recording needs variables {ref!r} and {state!r}")
    if stat not in STATISTICS + ("rmse",):
        raise ValueError(f"stat must be one of {STATISTICS + ('rmse',)}, got {stat!r}")
    e = tilt_errors(q, rec[ref].values)
    im = rec[state].values.astype(bool)
    vals = [error_stats(e, im)[stat], error_stats(e, ~im)[stat], error_stats(e)[stat]]
    return xr.DataArray(
        vals,
        dims=("state",),
        coords={"state": ["immobile", "moving", "all"]},
        attrs={"units": "deg", "long_name": f"tilt error, {STATISTIC_NAMES[stat]}"},
    )


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
    if (
        edges.ndim != 1
        or edges.size < 2
        or np.any(np.isnan(edges))
        or np.any(np.diff(edges) <= 0)
    ):
        raise ValueError(
            "edges must be a 1-D increasing array with at least two values, got "
            f"{edges.tolist() if edges.size <= 10 else edges.shape}"
        )
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
                out["q25"][i, b], out["median"][i, b], out["q75"][i, b] = np.percentile(
                    v, [25, 50, 75]
                )
    dims = (
        "estimator",
        "speed",
    )  # not "method": it would clash with the ``method`` argument of ``.sel``
    coords = {
        "estimator": names,
        "speed": (
            "speed",
            0.5 * (edges[:-1] + edges[1:]),
            {"units": "deg/s", "long_name": "angular speed, bin centre"},
        ),
        "speed_lo": ("speed", edges[:-1], {"units": "deg/s"}),
        "speed_hi": ("speed", edges[1:], {"units": "deg/s"}),
    }
    names = {k: f"tilt error, {STATISTIC_NAMES[k]}" for k in out}
    return xr.Dataset(
        {
            **{
                k: (dims, v, {"units": "deg", "long_name": names[k]})
                for k, v in out.items()
            },
            "n": (dims, cnt, {"units": "1", "long_name": "samples"}),
        },
        coords=coords,
    )


def ecdf(values) -> tuple[np.ndarray, np.ndarray]:
    """Empirical CDF of the finite values: sorted ``x`` and ``F(x) = i / n`` (i = 1…n).

    Parameters
    ----------
    values : array_like
        Values (any shape, flattened); non-finite values are ignored.

    Returns
    -------
    x : numpy.ndarray (n,)
        Sorted finite values (units of ``values``).
    F : numpy.ndarray (n,)
        Cumulative fractions ``i / n``, i = 1…n.

    Raises
    ------
    ValueError
        If there is no finite value.
    """
    v = np.asarray(values, dtype=float).ravel()
    v = np.sort(v[np.isfinite(v)])
    if v.size == 0:
        raise ValueError("no finite values")
    return v, np.arange(1, v.size + 1) / v.size


def pairwise_tilt_rms(estimates: Mapping[str, Any], mask=None) -> xr.DataArray:
    """Compute the RMS tilt difference (degrees) between every pair of estimates.

    The estimates are of the same recording (agreement between filters when there is no ground truth).

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
    if m.shape != (n,):
        raise ValueError(
            f"mask must have one value per sample ({n}), got shape {m.shape}"
        )
    out = np.zeros((len(names), len(names)))
    for i, a in enumerate(names):
        for j in range(i + 1, len(names)):
            d = np.degrees(quat.angle_between(g[a][m], g[names[j]][m]))
            out[i, j] = out[j, i] = float(np.sqrt(np.mean(d * d)))
    return xr.DataArray(
        out,
        dims=("estimator", "other"),
        coords={"estimator": names, "other": names},
        name="tilt_rms_difference",
        attrs={"units": "deg", "long_name": "RMS tilt difference"},
    )
