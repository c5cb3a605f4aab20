"""Tumble-test design: which and how many orientations a calibration needs.

Subsets of poses that best match a Fibonacci lattice, the orthogonality of pose
triplets, exhaustive subset studies of the offset fit (Fayat et al. 2021, Sensors
21(18):6318, doi:10.3390/s21186318, Fig. 1c) and the systematic offset uncertainty left
by the scale and misalignment errors that the offset-only fit ignores. The fits
themselves are in :mod:`tiltlab.calibration.accel`.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from .. import _validate as _v
from ..frames import fibonacci_lattice
from ._util import vec3
from .accel import _points, fit_offsets_batch

__all__ = [
    "offset_systematic_uncertainty",
    "lattice_subset",
    "triplet_orthogonality",
    "all_subsets",
    "orientation_count_study",
]


def lattice_subset(directions, k: int) -> np.ndarray:
    """Pick the ``k`` given directions that best match a k-point Fibonacci lattice.

    Indices of ``k`` of the given directions best matching a k-point Fibonacci lattice
    (greedy nearest neighbour, each direction used once; Fayat Fig. 1c for N ≥ 5).

    Parameters
    ----------
    directions : array_like, shape (N, 3)
        Candidate unit directions (e.g. the poses of a tumble test).
    k : int
        Number of directions to choose, ``1 <= k <= N``.

    Returns
    -------
    numpy.ndarray of int64, shape (k,)
        Indices into ``directions``, in lattice order.
    """
    d = vec3(directions, "directions", ndim=2)
    k = _v.integer(k, "k", minimum=1)
    if k > d.shape[0]:
        raise ValueError(f"k must be between 1 and {d.shape[0]}, got {k}")
    target = fibonacci_lattice(k)
    free = np.ones(d.shape[0], bool)
    out = []
    for t in target:
        score = np.where(free, d @ t, -np.inf)
        j = int(np.argmax(score))
        out.append(j)
        free[j] = False
    return np.array(out, dtype=np.int64)


def triplet_orthogonality(directions) -> np.ndarray:
    r"""|det[u_1 u_2 u_3]| of unit directions (…, 3, 3): 1 for mutually orthogonal, 0 for coplanar.

    Parameters
    ----------
    directions : array_like, shape (..., 3, 3)
        Triplets of directions (rows; normalised here, any non-zero length).

    Returns
    -------
    numpy.ndarray, shape (...)
        The absolute determinant, in [0, 1].

    Raises
    ------
    ValueError
        If a direction is a zero vector.
    """
    d = vec3(directions, "directions")
    nd = np.linalg.norm(d, axis=-1, keepdims=True)
    if np.any(nd == 0):
        raise ValueError("directions has zero vectors: their direction is undefined")
    u = d / nd
    return np.abs(np.linalg.det(u))


def all_subsets(
    n: int, k: int, *, max_subsets: int | None = None, rng=None
) -> np.ndarray:
    """All k-subsets of range(n) as an int array (S, k), or ``max_subsets`` of them drawn at random.

    Parameters
    ----------
    n : int
        Size of the set, ``range(n)``.
    k : int
        Size of each subset.
    max_subsets : int, optional
        If there are more than this many subsets, draw this many at random (with
        replacement between draws, so duplicates are possible); default all.
    rng : int or numpy.random.Generator, optional
        Seed or generator for the random draw.

    Returns
    -------
    numpy.ndarray of int64, shape (S, k)
        One subset per row, indices sorted within each row.
    """
    from math import comb

    n = _v.integer(n, "n", minimum=0)
    k = _v.integer(k, "k", minimum=0)
    if max_subsets is not None:
        max_subsets = _v.integer(max_subsets, "max_subsets", minimum=1)
    total = comb(n, k)
    if max_subsets is None or total <= max_subsets:
        return np.array(list(combinations(range(n), k)), dtype=np.int64).reshape(-1, k)
    rng = np.random.default_rng(rng)
    return np.sort(
        np.array([rng.choice(n, k, replace=False) for _ in range(max_subsets)]), axis=1
    )


def offset_systematic_uncertainty(
    points,
    *,
    scale_sd: float = 0.01,
    misalign_sd: float = 0.005,
    n_draws: int = 2000,
    radius: float = 1.0,
    rng=None,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Spread of offset-only solutions over plausible, unmodelled scale/misalignment errors.

    With few poses (e.g. a three-point test) the offsets absorb the scale errors: if the
    sensor matrix is :math:`T`, the offsets consistent with the same static means are
    :math:`o = T o'` where :math:`o'` solves the offset fit on :math:`T^{-1}a_p`.
    Drawing :math:`T = (I + \mathrm{diag}(s))(I + E)` with :math:`s \sim N(0, \sigma_s)`,
    off-diagonal :math:`E \sim N(0, \sigma_m)` gives the systematic uncertainty that the
    data cannot remove.

    Parameters
    ----------
    points : array_like, shape (P, 3)
        Static accelerometer means (units of ``radius``, e.g. g), P ≥ 3.
    scale_sd : float
        Standard deviation :math:`\sigma_s` of the scale errors (fraction, e.g. 0.01 for
        1 %).
    misalign_sd : float
        Standard deviation :math:`\sigma_m` of the off-diagonal misalignment terms
        (radians, small-angle).
    n_draws : int
        Number of drawn matrices T (≥ 2).
    radius : float
        Norm of the readings at rest (1 for g).
    rng : int or numpy.random.Generator, optional
        Seed or generator for the draws.

    Returns
    -------
    offsets : ndarray (n_draws, 3)
        Offset solutions under each drawn T.
    sd : ndarray (3,)
        Their standard deviation per axis.
    """
    p = _points(points, radius, min_n=3)
    scale_sd = _v.nonnegative(scale_sd, "scale_sd")
    misalign_sd = _v.nonnegative(misalign_sd, "misalign_sd")
    n_draws = _v.integer(n_draws, "n_draws", minimum=2)
    rng = np.random.default_rng(rng)
    s = rng.normal(0.0, scale_sd, (n_draws, 3))
    E = rng.normal(0.0, misalign_sd, (n_draws, 3, 3)) * (1 - np.eye(3))
    T = (np.eye(3) + s[:, :, None] * np.eye(3)) @ (np.eye(3) + E)
    Ti = np.linalg.inv(T)
    z = np.einsum("bij,pj->bpi", Ti, p)
    o_prime = fit_offsets_batch(z, radius=radius)
    o = np.einsum("bij,bj->bi", T, o_prime)
    return o, o.std(axis=0, ddof=1)


def orientation_count_study(
    means, directions, ns, *, radius: float = 1.0, max_subsets: int = 5000, rng=None
) -> list[dict]:
    r"""Residual norm error versus the number N of orientations used for the offsets (Fayat Fig. 1c).

    For each N, offsets are fitted (:func:`fit_offsets_batch`) on a subset of the P poses
    and evaluated on *all* poses as :math:`\frac1P\sum_p |r - \|a_p - o\||`. For N ≥ 4
    the subset best matching an N-point Fibonacci lattice is used (:func:`lattice_subset`);
    for N ≤ 3 all subsets (or ``max_subsets`` random ones) are evaluated and the
    distribution summarised by its median and by the value at the most orthogonal subset.

    Parameters
    ----------
    means : array_like (P, 3)
        Static means of one tumble test.
    directions : array_like (P, 3)
        Target gravity directions of the poses (for subset selection).
    ns : iterable of int
        Numbers N of orientations to study.
    radius : float
        Expected norm (1 g).
    max_subsets : int
        Largest number of subsets evaluated for N ≤ 3 (random ones beyond it).
    rng : int or numpy.random.Generator, optional
        Random source of those subsets.

    Returns
    -------
    list of dict
        One record per N: ``n``, ``residual`` (lattice subset, or orthogonal subset for
        N ≤ 3), ``residual_median`` (over subsets for N ≤ 3), ``orthogonality``.
    """
    p = _points(means, radius, name="means", min_n=3)
    d = vec3(directions, "directions", ndim=2)
    rng = np.random.default_rng(rng)

    def resid(o):
        return np.mean(
            np.abs(np.linalg.norm(p[None] - o[:, None, :], axis=2) - radius), axis=1
        )

    out = []
    for n in ns:
        n = int(n)
        if n <= 3:
            sub = all_subsets(p.shape[0], n, max_subsets=max_subsets, rng=rng)
            r = resid(fit_offsets_batch(p[sub], radius=radius))
            if n == 3:
                orth = triplet_orthogonality(d[sub])
                k = int(np.argmax(orth))
                out.append(
                    {
                        "n": n,
                        "residual": float(r[k]),
                        "residual_median": float(np.median(r)),
                        "orthogonality": float(orth[k]),
                    }
                )
            else:
                out.append(
                    {
                        "n": n,
                        "residual": float(np.median(r)),
                        "residual_median": float(np.median(r)),
                        "orthogonality": float("nan"),
                    }
                )
        else:
            idx = lattice_subset(d, n)
            r = resid(fit_offsets_batch(p[idx][None], radius=radius))[0]
            out.append(
                {
                    "n": n,
                    "residual": float(r),
                    "residual_median": float(r),
                    "orthogonality": float("nan"),
                }
            )
    return out
