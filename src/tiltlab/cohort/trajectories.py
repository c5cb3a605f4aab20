r"""Trajectories of each animal's mean head-tilt point over time (Fayat et al. Fig. 3e).

Each session's mean tilt during immobility is a unit vector :math:`\mu_{a,t}` (the
features ``tilt_immobile_x/y/z``). To compare animals whose heads are carried
differently, each animal's trajectory is rotated so that its baseline point goes to
the north pole :math:`e_z`, by the smallest rotation doing so,

.. math::
    R_a = \exp\big(\theta_a [k_a]_\times\big),\qquad
    k_a = \frac{\mu_{a,0}\times e_z}{\lVert\mu_{a,0}\times e_z\rVert},\qquad
    \cos\theta_a = \mu_{a,0}\cdot e_z,

(Rodrigues' formula), and :math:`p_{a,t} = R_a\,\mu_{a,t}`. A rotation keeps angles,
so the angle of :math:`p_{a,t}` from the pole is the angle between the animal's mean
tilt at :math:`t` and at baseline. The group's trajectory is the mean direction
(von Mises–Fisher maximum-likelihood estimate) of its animals' rotated points at each
time point, :math:`\bar p_{g,t} = \sum_a p_{a,t} / \lVert\sum_a p_{a,t}\rVert`.
Near the pole the sensor's x (nose) and y (left) directions keep their meaning: the
rotation moves them by at most :math:`\theta_a`.

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021, Fig. 3e.
   doi:10.3390/s21186318
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr

__all__ = ["pole_rotation", "tilt_trajectories"]

_AXES = ("x", "y", "z")


def pole_rotation(u) -> np.ndarray:
    r"""Return the smallest rotation matrix taking the direction ``u`` to the pole +z.

    Parameters
    ----------
    u : array_like, shape (3,)
        A non-zero direction (normalised here).

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        :math:`R` with :math:`R\,u/\lVert u\rVert = e_z`, a rotation about
        :math:`u \times e_z` (the identity for :math:`u \parallel e_z`, a half turn
        about x for :math:`u \parallel -e_z`).

    Raises
    ------
    ValueError
        If ``u`` is not a finite non-zero 3-vector.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab.cohort import pole_rotation
    >>> u = np.array([np.sin(0.3), 0.0, np.cos(0.3)])
    >>> np.round(pole_rotation(u) @ u, 12).tolist() == [0.0, 0.0, 1.0]
    True
    """
    u = np.asarray(u, dtype=float)
    if u.shape != (3,) or not np.all(np.isfinite(u)) or not np.linalg.norm(u) > 0:
        raise ValueError(f"u must be a finite non-zero 3-vector, got {u!r}")
    u = u / np.linalg.norm(u)
    k = np.cross(u, [0.0, 0.0, 1.0])
    s, c = np.linalg.norm(k), u[2]
    if s < 1e-15:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    k = k / s
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def _points(features: xr.Dataset, prefix: str) -> np.ndarray:
    names = [f"{prefix}_{a}" for a in _AXES]
    missing = [n for n in names if n not in features]
    if missing:
        raise ValueError(
            f"the feature table has no {missing} (the mean tilt during immobility of "
            "each session; compute the cohort's features with run_cohort)"
        )
    pts = np.stack([np.asarray(features[n].values, float) for n in names], axis=-1)
    if "status" in features:
        pts[np.asarray(features["status"].values) != "ok"] = np.nan
    return pts


def tilt_trajectories(
    features: xr.Dataset,
    *,
    baseline: str = "baseline",
    timepoints: Sequence[str] | None = None,
    groups: Sequence[str] | None = None,
    prefix: str = "tilt_immobile",
) -> xr.Dataset:
    """Rotate each animal's mean-tilt trajectory so its baseline point is the pole.

    Parameters
    ----------
    features : xarray.Dataset
        Cohort feature table along ``session`` (:func:`tiltlab.cohort.run_cohort`),
        with coordinates ``subject``, ``group``, ``timepoint`` and the variables
        ``<prefix>_x``, ``<prefix>_y``, ``<prefix>_z``.
    baseline : str
        Time point of the pole.
    timepoints : sequence of str, optional
        Time points in order (default: the table's, baseline first).
    groups : sequence of str, optional
        Groups kept, in order (default: the table's order of appearance).
    prefix : str
        Name stem of the mean-tilt variables.

    Returns
    -------
    xarray.Dataset
        ``point`` (subject, timepoint, axis): rotated unit vectors (NaN where a
        session is missing or failed, or the animal has no baseline); ``angle``
        (subject, timepoint): its angle from the pole (deg), the angle between the
        animal's mean tilt and its baseline; ``mean`` (group, timepoint, axis): the
        group's mean direction; ``mean_angle`` (group, timepoint, deg) and
        ``n_animals`` (group, timepoint). Coordinate ``animal_group`` (subject) gives
        each animal's group.

    Raises
    ------
    ValueError
        A table without the mean-tilt variables or the grouping coordinates, or a
        baseline that is not one of its time points.

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> from tiltlab.cohort import tilt_trajectories
    >>> mu = np.array([[0.0, 0.0, 1.0], [0.0, np.sin(0.2), np.cos(0.2)]])
    >>> ds = xr.Dataset(
    ...     {f"tilt_immobile_{a}": ("session", mu[:, i]) for i, a in enumerate("xyz")},
    ...     coords={"subject": ("session", ["r1", "r1"]),
    ...             "group": ("session", ["A", "A"]),
    ...             "timepoint": ("session", ["baseline", "1d"])})
    >>> float(tilt_trajectories(ds)["angle"].sel(subject="r1", timepoint="1d").round(3))
    11.459
    """
    for c in ("subject", "group", "timepoint"):
        if c not in features.coords:
            raise ValueError(f"the feature table has no {c!r} coordinate")
    pts = _points(features, prefix)
    subj = np.asarray(features["subject"].values).astype(str)
    grp = np.asarray(features["group"].values).astype(str)
    tp = np.asarray(features["timepoint"].values).astype(str)
    order = (
        list(dict.fromkeys(tp)) if timepoints is None else [str(t) for t in timepoints]
    )
    if baseline not in order:
        raise ValueError(f"baseline {baseline!r} is not a time point: {order}")
    order = [baseline] + [t for t in order if t != baseline]
    groups = list(dict.fromkeys(grp)) if groups is None else [str(g) for g in groups]
    animals = [s for s in dict.fromkeys(subj) if grp[subj == s][0] in groups]
    point = np.full((len(animals), len(order), 3), np.nan)
    for i, a in enumerate(animals):
        for j, t in enumerate(order):
            rows = np.flatnonzero((subj == a) & (tp == t))
            if rows.size:
                point[i, j] = pts[rows[0]] / np.linalg.norm(pts[rows[0]])
        if np.all(np.isfinite(point[i, 0])):
            point[i] = point[i] @ pole_rotation(point[i, 0]).T
        else:
            point[i] = np.nan
    angle = np.degrees(np.arccos(np.clip(point[..., 2], -1.0, 1.0)))
    animal_group = np.array([grp[subj == a][0] for a in animals])
    mean = np.full((len(groups), len(order), 3), np.nan)
    n = np.zeros((len(groups), len(order)), dtype=int)
    for g, name in enumerate(groups):
        sel = point[animal_group == name]
        ok = np.all(np.isfinite(sel), axis=-1)
        n[g] = ok.sum(axis=0)
        total = np.where(ok[..., None], sel, 0.0).sum(axis=0)
        norm = np.linalg.norm(total, axis=-1, keepdims=True)
        mean[g] = np.where(norm > 0, total / np.where(norm > 0, norm, 1.0), np.nan)
    mean_angle = np.degrees(np.arccos(np.clip(mean[..., 2], -1.0, 1.0)))
    return xr.Dataset(
        {
            "point": (
                ("subject", "timepoint", "axis"),
                point,
                {"units": "1", "long_name": "mean tilt, baseline rotated to the pole"},
            ),
            "angle": (
                ("subject", "timepoint"),
                angle,
                {"units": "deg", "long_name": "angle of the mean tilt from baseline"},
            ),
            "mean": (
                ("group", "timepoint", "axis"),
                mean,
                {
                    "units": "1",
                    "long_name": "group mean direction of the rotated points",
                },
            ),
            "mean_angle": (
                ("group", "timepoint"),
                mean_angle,
                {"units": "deg", "long_name": "angle of the group mean from the pole"},
            ),
            "n_animals": (
                ("group", "timepoint"),
                n,
                {"units": "1", "long_name": "animals with a point"},
            ),
        },
        coords={
            "subject": animals,
            "timepoint": order,
            "axis": list(_AXES),
            "group": groups,
            "animal_group": ("subject", animal_group),
        },
        attrs={
            "baseline": baseline,
            "references": "R. Fayat et al., Sensors 21(18):6318, 2021, Fig. 3e",
        },
    )
