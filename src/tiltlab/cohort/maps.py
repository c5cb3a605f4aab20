"""Group-averaged tilt maps and Fig. A5's angular velocity of a cohort (Fayat et al. 2021).

The feature pipeline keeps scalars per session. Two of the paper's figures need the
per-sample tilt of sessions again:

* :func:`group_tilt_maps` — Figs 3c–d: per session the time fraction per facet of the
  tilt map (:func:`tiltlab.sphere.tilt_map`), averaged over the animals of each group at
  each time point;
* :func:`circling_example` picks Fig. A5's animal (the one of a group whose circling
  index rose most between the baseline and the time point at which its group circles
  most); :func:`gravity_frame_velocity` computes the angular velocity of one session in
  the head frame and in the gravity-aligned frame (§2.10), and
  :func:`velocity_quantiles` keeps their distributions over the moving samples as
  quantiles, small enough to save with a cohort's feature tables;
  :func:`circling_examples` does all three for several groups.

Every session is read and its tilt computed as :func:`run_cohort` does
(:func:`~tiltlab.cohort.load_session_tilt`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
import xarray as xr

from .. import axes as _axes
from .. import behavior, filters, quaternion, sphere
from .config import FeatureConfig
from .lookup import load_session_tilt, session_row
from .manifest import Manifest
from .sessions import load_session
from .schedulers import backend as _backend

__all__ = [
    "group_tilt_maps",
    "circling_example",
    "gravity_frame_velocity",
    "velocity_quantiles",
    "circling_examples",
]


def _usable(features: xr.Dataset) -> pd.DataFrame:
    """One row per usable session (status ``ok``): subject, group, time point."""
    need = [c for c in ("subject", "group", "timepoint") if c not in features.variables]
    if "session" not in features.dims or need:
        raise ValueError(f"not a cohort feature table (missing {need or ['session']})")
    df = pd.DataFrame(
        {c: features[c].values.astype(str) for c in ("subject", "group", "timepoint")},
        index=pd.Index(features["session"].values.astype(str), name="session"),
    )
    if "status" in features.variables:
        df = df[features["status"].values.astype(str) == "ok"]
    return df


def _session_fraction(
    row: dict, root, config: FeatureConfig, mesh_n: int
) -> np.ndarray:
    """Time fraction per facet of one session's tilt map (a worker task)."""
    _, g = load_session_tilt(row, root, config)
    tmap = sphere.tilt_map(g, mesh=sphere.sphere_mesh(mesh_n))
    return tmap["fraction"].to_numpy()


def group_tilt_maps(
    manifest: Manifest,
    features: xr.Dataset,
    config: FeatureConfig | None = None,
    *,
    groups: Sequence[str] | None = None,
    timepoints: Sequence[str] | None = None,
    max_animals: int | None = None,
    scheduler=None,
    workers: int | None = None,
    progress: bool = False,
) -> xr.Dataset:
    r"""Average the sessions' tilt maps over the animals of each group and time point.

    For every usable session (``status == "ok"`` in ``features``) of the chosen groups
    and time points, the tilt :math:`g_s` is computed as the pipeline computes it and
    mapped on the configuration's sphere mesh; the time fractions per facet
    :math:`p_f` are averaged over the animals of the cell (Fayat et al. 2021, Figs
    3c–d).

    Parameters
    ----------
    manifest : Manifest
        The cohort manifest (:func:`~tiltlab.cohort.read_manifest`).
    features : xarray.Dataset
        Its feature table (:func:`~tiltlab.cohort.run_cohort`): which sessions are usable.
    config : FeatureConfig, optional
        The pipeline's configuration (orientation method, mesh size); default
        ``FeatureConfig()``.
    groups, timepoints : sequence of str, optional
        The cells mapped; default every group and time point of ``features``.
    max_animals : int, optional
        At most this many animals per cell, the first in sorted order (default all).
    scheduler, workers
        As for :func:`~tiltlab.cohort.run_cohort` (``None`` and one worker: serial).
    progress : bool
        Show a progress bar of sessions.

    Returns
    -------
    xarray.Dataset
        ``fraction`` (group, timepoint, facet): the group-averaged time fraction (NaN
        for a cell without a session), and ``n_animals`` (group, timepoint); attrs
        ``mesh_n``, ``method`` and ``axis_labels`` (from the first session's tilt).

    Raises
    ------
    ValueError
        A group or time point not in ``features``, or ``max_animals < 1``.

    Examples
    --------
    >>> maps = cohort.group_tilt_maps(manifest, features, max_animals=4)  # doctest: +SKIP
    >>> maps["fraction"].sel(group="Kainate", timepoint="1d")            # doctest: +SKIP
    """
    config = config or FeatureConfig()
    if max_animals is not None and int(max_animals) < 1:
        raise ValueError(f"max_animals must be at least 1, got {max_animals}")
    usable = _usable(features)
    groups = _chosen(groups, usable["group"], "group")
    timepoints = _chosen(timepoints, usable["timepoint"], "time point")
    cells, rows = {}, []
    for group in groups:
        for tp in timepoints:
            cell = usable[(usable["group"] == group) & (usable["timepoint"] == tp)]
            subjects = sorted(cell["subject"])[:max_animals]
            cells[group, tp] = range(len(rows), len(rows) + len(subjects))
            rows += [session_row(manifest, s, tp, usable) for s in subjects]
    mesh = sphere.sphere_mesh(config.mesh_n)
    fractions = _map_sessions(rows, manifest.root, config, scheduler, workers, progress)
    out = np.full((len(groups), len(timepoints), mesh.n_faces), np.nan)
    count = np.zeros((len(groups), len(timepoints)), dtype=int)
    for (group, tp), idx in cells.items():
        i, j = groups.index(group), timepoints.index(tp)
        count[i, j] = len(idx)
        if len(idx):
            out[i, j] = np.mean([fractions[k] for k in idx], axis=0)
    attrs = {"mesh_n": int(config.mesh_n), "method": config.method}
    if rows:
        attrs["axis_labels"] = list(
            _axes.axis_labels(load_session(rows[0], manifest.root))
        )
    return xr.Dataset(
        {
            "fraction": (
                ("group", "timepoint", "facet"),
                out,
                {"units": "1", "long_name": "group-averaged time fraction per facet"},
            ),
            "n_animals": (
                ("group", "timepoint"),
                count,
                {"units": "1", "long_name": "animals averaged"},
            ),
        },
        coords={"group": list(groups), "timepoint": list(timepoints)},
        attrs=attrs,
    )


def _chosen(chosen, present: pd.Series, what: str) -> list[str]:
    """Return the requested names in order, checked against those of the table."""
    known = list(dict.fromkeys(present))
    if chosen is None:
        return known
    chosen = [str(c) for c in chosen]
    unknown = [c for c in chosen if c not in known]
    if unknown:
        raise ValueError(f"{what}(s) {unknown} not in the feature table: {known}")
    return chosen


def _map_sessions(rows, root, config, scheduler, workers, progress) -> list[np.ndarray]:
    """Each row's facet fractions, on the chosen back end, in row order."""
    from tqdm import tqdm

    pool = _backend(scheduler, workers)
    try:
        futures = [
            pool.submit(_session_fraction, row, root, config, int(config.mesh_n))
            for row in rows
        ]
        bar = tqdm(
            total=len(rows), desc="tilt maps", unit="session", disable=not progress
        )
        for _ in pool.as_completed(futures):
            bar.update()
        bar.close()
        return [f.result() for f in futures]
    finally:
        pool.close()


def circling_example(
    features: xr.Dataset, group: str, baseline: str, compared: Sequence[str]
) -> tuple[str | None, str | None]:
    """Choose Fig. A5's animal: the one whose circling index rose most.

    The time point is the one of ``compared`` at which the group's median circling
    index is largest; the animal is the one of the group whose index increased most
    from ``baseline`` to it. Like Fayat et al.'s Fig. A5, an illustrative example, not
    a typical one.

    Parameters
    ----------
    features : xarray.Dataset
        A cohort feature table with ``circling_index``.
    group : str
        The group.
    baseline : str
        The baseline time point.
    compared : sequence of str
        The time points after it.

    Returns
    -------
    animal, timepoint : str or None
        ``(None, None)`` when the group has no circling index at the baseline or after
        it (e.g. recordings without a gyroscope).
    """
    if "circling_index" not in features:
        return None, None
    usable = _usable(features)
    value = features["circling_index"].to_series()
    usable = usable.assign(value=value.reindex(usable.index).to_numpy())
    usable = usable[(usable["group"] == str(group))].dropna(subset=["value"])
    wide = usable.pivot_table(index="subject", columns="timepoint", values="value")
    compared = [str(t) for t in compared if str(t) in wide.columns]
    if str(baseline) not in wide.columns or not compared:
        return None, None
    late = str(wide[compared].median().idxmax())
    increase = (wide[late] - wide[str(baseline)]).dropna()
    return (str(increase.idxmax()), late) if len(increase) else (None, None)


def gravity_frame_velocity(
    manifest: Manifest,
    subject: str,
    timepoint: str,
    features: xr.Dataset,
    config: FeatureConfig | None = None,
) -> xr.Dataset:
    r"""One session's angular velocity in the head and the gravity-aligned frames.

    The gravity-aligned frame is reached by the minimal rotation :math:`R_g` taking the
    tilt :math:`\hat g_s` to :math:`e_z` (:func:`tiltlab.filters.tilt_quaternion`), so
    that :math:`\omega^{(g)}_z = \hat g_s\cdot\omega` is the azimuthal angular velocity
    whose mean over the moving samples is the circling index (Fayat et al. 2021,
    §2.10, Fig. A5).

    Parameters
    ----------
    manifest : Manifest
        The cohort manifest.
    subject, timepoint : str
        The session (one of the usable sessions of ``features``).
    features : xarray.Dataset
        The cohort's feature table.
    config : FeatureConfig, optional
        The pipeline's configuration (default ``FeatureConfig()``).

    Returns
    -------
    xarray.Dataset
        ``omega`` (frame, time, axis; frames ``"head"`` and ``"gravity"``, deg/s) and
        ``moving`` (time); attrs ``subject``, ``timepoint``, ``session``,
        ``axis_labels``, ``max_check_deg_s`` (the largest
        :math:`|\omega^{(g)}_z-\hat g_s\cdot\omega|`), ``circling_index`` (recomputed,
        circles/min) and ``circling_index_table`` (the feature table's).
    """
    config = config or FeatureConfig()
    usable = _usable(features)
    row = session_row(manifest, subject, timepoint, usable)
    rec, g = load_session_tilt(row, manifest.root, config)
    moving = ~np.asarray(
        behavior.immobility(
            rec,
            threshold_deg_s=config.threshold_deg_s,
            merge_gap_s=config.merge_gap_s,
            min_duration_s=config.min_duration_s,
        )
    )
    head = np.asarray(rec["gyr"])
    gravity = np.asarray(quaternion.rotate(filters.tilt_quaternion(g), rec["gyr"]))
    azimuthal = np.asarray(behavior.azimuthal_speed(rec, g))
    session = str(row["session"])
    return xr.Dataset(
        {
            "omega": (
                ("frame", "time", "axis"),
                np.stack([head, gravity]),
                {"units": "deg/s", "long_name": "angular velocity"},
            ),
            "moving": (("time",), moving, {"long_name": "moving sample"}),
        },
        coords={
            "frame": ["head", "gravity"],
            "time": rec["time"].to_numpy(),
            "axis": ["x", "y", "z"],
        },
        attrs={
            "subject": str(subject),
            "timepoint": str(timepoint),
            "session": session,
            "axis_labels": list(_axes.axis_labels(rec)),
            "max_check_deg_s": float(np.nanmax(np.abs(gravity[:, 2] - azimuthal))),
            "circling_index": (
                float(np.nanmean(gravity[moving, 2]) * 60 / 360)
                if moving.any()
                else float("nan")  # as the feature table: no moving sample
            ),
            "circling_index_table": float(
                features["circling_index"].sel(session=session)
            ),
        },
    )


def velocity_quantiles(velocity: xr.Dataset, n: int = 1001) -> xr.Dataset:
    """Keep the distributions of :func:`gravity_frame_velocity` over the moving samples.

    Parameters
    ----------
    velocity : xarray.Dataset
        :func:`gravity_frame_velocity`'s result.
    n : int
        Number of equally spaced probability levels, 0 to 1 (at least 2).

    Returns
    -------
    xarray.Dataset
        ``omega`` (frame, quantile, axis): the quantiles of each component over the
        moving samples, with ``n_moving`` and the input's attrs. Their empirical CDF
        is that of the moving samples to within 1/(n−1). NaN when no sample moves.

    Examples
    --------
    >>> q = cohort.velocity_quantiles(cohort.gravity_frame_velocity(m, "K01", "1d", f))  # doctest: +SKIP
    """
    if int(n) < 2:
        raise ValueError(f"n must be at least 2, got {n}")
    levels = np.linspace(0.0, 1.0, int(n))
    moving = velocity["moving"].to_numpy().astype(bool)
    omega = velocity["omega"].to_numpy()[:, moving, :]
    if omega.shape[1]:
        q = np.nanquantile(omega, levels, axis=1).transpose(1, 0, 2)
    else:  # no moving sample: no distribution
        q = np.full((omega.shape[0], levels.size, omega.shape[2]), np.nan)
    return xr.Dataset(
        {"omega": (("frame", "quantile", "axis"), q, velocity["omega"].attrs)},
        coords={
            "frame": velocity["frame"].to_numpy(),
            "quantile": levels,
            "axis": velocity["axis"].to_numpy(),
        },
        attrs={**velocity.attrs, "n_moving": int(moving.sum())},
    )


def circling_examples(
    manifest: Manifest,
    features: xr.Dataset,
    config: FeatureConfig | None = None,
    *,
    groups: Sequence[str],
    baseline: str,
    compared: Sequence[str],
    n: int = 1001,
) -> xr.Dataset:
    """Fig. A5 for several groups: each group's example animal before and after.

    For every group, :func:`circling_example` picks the animal and the time point;
    :func:`gravity_frame_velocity` and :func:`velocity_quantiles` give the
    distributions of its angular velocity over the moving samples at ``baseline`` and
    at that time point.

    Parameters
    ----------
    manifest : Manifest
        The cohort manifest.
    features : xarray.Dataset
        Its feature table.
    config : FeatureConfig, optional
        The pipeline's configuration (default ``FeatureConfig()``).
    groups : sequence of str
        The groups.
    baseline : str
        The baseline time point.
    compared : sequence of str
        The time points after it.
    n : int
        Quantile levels kept (:func:`velocity_quantiles`).

    Returns
    -------
    xarray.Dataset
        ``omega`` (group, visit, frame, quantile, axis; deg/s; visits ``"baseline"``
        and ``"late"``), ``subject`` (group), ``timepoint``, ``circling_index``,
        ``circling_index_table``, ``max_check_deg_s`` and ``n_moving`` (group, visit);
        attrs ``axis_labels``. A group without an example (no circling index) is
        left out.

    Examples
    --------
    >>> ex = cohort.circling_examples(m, f, groups=["Kainate"], baseline="baseline",
    ...                               compared=["1h", "1d"])        # doctest: +SKIP
    """
    config = config or FeatureConfig()
    picked, per_group = [], []
    for group in groups:
        animal, late = circling_example(features, group, baseline, compared)
        if animal is None:
            continue
        visits = [
            velocity_quantiles(
                gravity_frame_velocity(manifest, animal, tp, features, config), n
            )
            for tp in (baseline, late)
        ]
        picked.append(str(group))
        per_group.append(visits)
    visits = ["baseline", "late"]
    levels = np.linspace(0.0, 1.0, int(n))
    data = {
        "omega": (
            ("group", "visit", "frame", "quantile", "axis"),
            np.array([[v["omega"].to_numpy() for v in g] for g in per_group]).reshape(
                len(picked), 2, 2, int(n), 3
            ),
            {"units": "deg/s", "long_name": "angular velocity, moving samples"},
        ),
        "subject": (
            ("group",),
            np.array([g[0].attrs["subject"] for g in per_group], dtype=str),
        ),
        "timepoint": (
            ("group", "visit"),
            np.array(
                [[v.attrs["timepoint"] for v in g] for g in per_group], dtype=str
            ).reshape(len(picked), 2),
        ),
    }
    described = {
        "circling_index": ("1/min", "circling index, recomputed"),
        "circling_index_table": ("1/min", "circling index of the feature table"),
        "max_check_deg_s": ("deg/s", "largest |ω_z(gravity) − ω·g|"),
        "n_moving": ("1", "moving samples"),
    }
    for name, (units, long_name) in described.items():
        values = [[v.attrs[name] for v in g] for g in per_group]
        data[name] = (
            ("group", "visit"),
            np.array(values, dtype=float).reshape(len(picked), 2),
            {"units": units, "long_name": long_name},
        )
    labels = per_group[0][0].attrs["axis_labels"] if per_group else ["x", "y", "z"]
    return xr.Dataset(
        data,
        coords={
            "group": picked,
            "visit": visits,
            "frame": ["head", "gravity"],
            "quantile": levels,
            "axis": ["x", "y", "z"],
        },
        attrs={"axis_labels": list(labels)},
    )
