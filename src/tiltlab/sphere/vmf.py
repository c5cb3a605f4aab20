r"""von Mises–Fisher distribution on :math:`S^2`: weighted maximum likelihood, bootstrap
confidence cone, mean tilt point of a map, angle to the sagittal plane, rotation to the pole.

The density of a von Mises–Fisher (vMF) distribution with mean direction :math:`\mu` and
concentration :math:`\kappa` on the unit sphere is (Benhamou 2023, Eq. 14a)

.. math::
    f(x) = \frac{\kappa}{4\pi\sinh\kappa}\,e^{\kappa\,\mu\cdot x}
         = \frac{\kappa}{2\pi(1-e^{-2\kappa})}\,e^{\kappa(\mu\cdot x - 1)} .

For weights :math:`w_i \ge 0` (frequency weights, e.g. samples per facet) the
log-likelihood :math:`\sum_i w_i[\log C(\kappa) + \kappa\,\mu\cdot x_i]` is maximised by

.. math::
    \hat\mu = \frac{S}{\lVert S\rVert},\quad S=\sum_i w_i x_i,\qquad
    A_3(\hat\kappa) = \coth\hat\kappa - \frac1{\hat\kappa} = \bar R = \frac{\lVert S\rVert}{\sum_i w_i},

:math:`A_3` being the mean resultant length :math:`E[\mu\cdot x]` (Fisher 1953). We solve
:math:`A_3(\kappa)=\bar R` exactly (safeguarded Newton), starting from Banerjee et al.'s
approximation :math:`\kappa \approx \bar R(3-\bar R^2)/(1-\bar R^2)`.

References
----------
.. [1] R. A. Fisher, "Dispersion on a sphere", Proc. R. Soc. Lond. A 217:295–305, 1953.
   doi:10.1098/rspa.1953.0064
.. [2] A. Banerjee, I. S. Dhillon, J. Ghosh, S. Sra, "Clustering on the unit hypersphere
   using von Mises-Fisher distributions", JMLR 6:1345–1382, 2005.
.. [3] A. T. A. Wood, "Simulation of the von Mises Fisher distribution", Commun. Stat.
   Simul. Comput. 23(1):157–164, 1994. doi:10.1080/03610919408813161
.. [4] R. Fayat et al., Sensors 21(18):6318, 2021, §2.8. doi:10.3390/s21186318
.. [5] P. Hall, J. L. Horowitz, B.-Y. Jing, "On blocking rules for the bootstrap with
   dependent data", Biometrika 82(3):561–574, 1995. doi:10.1093/biomet/82.3.561
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import xarray as xr

from .. import _validate
from .mesh import SphereMesh, _read, as_unit_vectors, sphere_mesh

__all__ = [
    "VMFFit",
    "ConfidenceCone",
    "a3",
    "a3_inverse",
    "vmf_fit",
    "vmf_logpdf",
    "vmf_pdf",
    "vmf_sample",
    "vmf_cap_area",
    "vmf_bootstrap",
    "mean_tilt_point",
    "sagittal_angle",
    "rotation_to_pole",
    "rotate_to_pole",
    "angle",
]


class VMFFit(NamedTuple):
    """Maximum-likelihood vMF fit: mean direction ``mu`` (3,), concentration ``kappa``,
    mean resultant length ``rbar`` and total weight ``n``."""

    mu: np.ndarray
    kappa: float
    rbar: float
    n: float


class ConfidenceCone(NamedTuple):
    """Bootstrap confidence cone around ``mu``: half-angle (rad) at ``level``, κ interval,
    and the bootstrap angles between each replicate's mean and ``mu``."""

    mu: np.ndarray
    kappa: float
    half_angle: float
    kappa_low: float
    kappa_high: float
    level: float
    angles: np.ndarray


def angle(u, v) -> np.ndarray:
    """Angle (rad) between directions, atan2(‖u×v‖, u·v) (accurate near 0 and π)."""
    u, v = np.asarray(u, float), np.asarray(v, float)
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1))


# ---------------------------------------------------------------------------
# A3 and its inverse
# ---------------------------------------------------------------------------

_SMALL = 1e-3


def a3(kappa) -> np.ndarray:
    r"""Mean resultant length :math:`A_3(\kappa)=\coth\kappa-1/\kappa` of a vMF on :math:`S^2` (series for κ < 1e-3)."""
    k = np.asarray(kappa, float)
    if np.any(k < 0):
        raise ValueError("kappa must be >= 0")
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        big = 1.0 / np.tanh(k) - 1.0 / k
    series = k / 3.0 - k**3 / 45.0 + 2.0 * k**5 / 945.0
    return np.where(k < _SMALL, series, big)


def _a3_prime(k):
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        big = 1.0 / k**2 - 1.0 / np.sinh(k) ** 2
    series = 1.0 / 3.0 - k**2 / 15.0 + 2.0 * k**4 / 189.0
    return np.where(k < _SMALL, series, big)


def a3_inverse(rbar, *, tol: float = 1e-13, max_iter: int = 100) -> np.ndarray:
    r"""Solve :math:`A_3(\kappa)=\bar R` for κ (vectorised safeguarded Newton; exact MLE of κ).

    :math:`\bar R = 0` gives 0 and :math:`\bar R = 1` gives ∞. Newton steps that leave the
    current bracket are replaced by bisection (in log κ above 1).
    """
    r = np.asarray(rbar, float)
    if np.any(~np.isfinite(r)) or np.any(r < 0) or np.any(r > 1):
        raise ValueError("rbar must lie in [0, 1]")
    scalar = r.ndim == 0
    r = np.atleast_1d(r).astype(float)
    out = np.zeros_like(r)
    out[r >= 1.0] = np.inf
    todo = (r > 0) & (r < 1)
    rr = r[todo]
    k = rr * (3.0 - rr**2) / (1.0 - rr**2)  # Banerjee et al. (2005)
    # A3(k) < 1 - 1/k + ... gives k < 1/(1-r) + 1 ; A3(k) > k/3 - k^3/45 > 0 gives k > 3r - ...
    lo = np.zeros_like(rr)
    hi = 1.0 / (1.0 - rr) + 1.0
    for _ in range(max_iter):
        f = a3(k) - rr
        lo = np.where(f < 0, k, lo)
        hi = np.where(f > 0, k, hi)
        step = f / _a3_prime(k)
        k_new = k - step
        bad = ~((k_new > lo) & (k_new < hi)) | ~np.isfinite(k_new)
        mid = np.where(
            hi > 2 * np.maximum(lo, 1e-300) + 1,
            np.sqrt(np.maximum(lo, 1e-12) * hi),
            0.5 * (lo + hi),
        )
        k_new = np.where(bad, mid, k_new)
        done = np.abs(k_new - k) <= tol * np.maximum(k, 1.0)
        k = k_new
        if np.all(done):
            break
    out[todo] = k
    return out[0] if scalar else out


# ---------------------------------------------------------------------------
# fit, density, sampling
# ---------------------------------------------------------------------------


def _weights(w, n: int) -> np.ndarray | None:
    if w is None:
        return None
    w = np.asarray(w, float)
    if w.shape != (n,):
        raise ValueError(f"weights must have shape ({n},), got {w.shape}")
    if np.any(~np.isfinite(w)) or np.any(w < 0):
        raise ValueError("weights must be finite and >= 0")
    if w.sum() <= 0:
        raise ValueError("weights sum to zero")
    return w


def vmf_fit(x, weights=None) -> VMFFit:
    r"""Weighted maximum-likelihood vMF fit (exact κ from :math:`A_3(\kappa)=\bar R`).

    Parameters
    ----------
    x : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Directions (normalised here): a labelled (time, axis) series (e.g.
        :func:`tiltlab.filters.gravity`), a Recording (its ``gravity``) or an array.
    weights : array_like, shape (N,), optional
        Frequency weights (counts, durations); default 1.

    Returns
    -------
    VMFFit

    Raises
    ------
    ValueError
        When the resultant vanishes (no preferred direction).
    """
    x = as_unit_vectors(x, "x")
    w = _weights(weights, x.shape[0])
    s = x.sum(axis=0) if w is None else w @ x
    n = float(x.shape[0] if w is None else w.sum())
    rn = float(np.linalg.norm(s))
    if rn <= 1e-12 * n:
        raise ValueError("the resultant vector is zero: no mean direction")
    rbar = min(rn / n, 1.0)
    return VMFFit(s / rn, float(a3_inverse(rbar)), rbar, n)


def vmf_logpdf(x, mu, kappa: float) -> np.ndarray:
    r"""log of Eq. 14a, evaluated stably as :math:`\log\kappa-\log(2\pi(1-e^{-2\kappa}))+\kappa(\mu\cdot x-1)`."""
    x = np.asarray(x, float)
    mu = np.asarray(mu, float) / np.linalg.norm(mu)
    kappa = _validate.nonnegative(kappa, "kappa")
    if kappa == 0:
        return np.full(x.shape[:-1], -np.log(4 * np.pi))
    return (
        np.log(kappa)
        - np.log(2 * np.pi)
        - np.log1p(-np.exp(-2 * kappa))
        + kappa * (x @ mu - 1.0)
    )


def vmf_pdf(x, mu, kappa: float) -> np.ndarray:
    """vMF density (sr⁻¹), Eq. 14a."""
    return np.exp(vmf_logpdf(x, mu, kappa))


def _frame(mu) -> np.ndarray:
    """Rotation matrix whose third column is ``mu`` (first two columns complete a right-handed frame)."""
    mu = np.asarray(mu, float) / np.linalg.norm(mu)
    e = np.eye(3)[np.argmin(np.abs(mu))]
    u = np.cross(mu, e)
    u /= np.linalg.norm(u)
    return np.column_stack([u, np.cross(mu, u), mu])


def vmf_sample(mu, kappa: float, n: int, rng=None) -> np.ndarray:
    r"""``n`` independent draws from vMF(μ, κ) on :math:`S^2` (exact inverse-CDF of Wood 1994).

    :math:`w = \mu\cdot x = 1 + \log\big(u + (1-u)e^{-2\kappa}\big)/\kappa`, longitude uniform.
    """
    kappa = _validate.nonnegative(kappa, "kappa")
    n = _validate.integer(n, "n", minimum=0)
    rng = np.random.default_rng(rng)
    u = rng.random(int(n))
    if kappa == 0:
        w = 2 * u - 1
    else:
        w = 1.0 + np.log(u + (1 - u) * np.exp(-2 * kappa)) / kappa
    w = np.clip(w, -1, 1)
    phi = rng.uniform(0, 2 * np.pi, int(n))
    s = np.sqrt(1 - w * w)
    local = np.column_stack([s * np.cos(phi), s * np.sin(phi), w])
    return local @ _frame(mu).T


def vmf_cap_area(kappa, level) -> np.ndarray:
    r"""Area (sr) of the μ-centred cap holding a fraction ``level`` of a vMF(κ): the theoretical cumulative isopleth.

    :math:`P(\mu\cdot x \ge t)=\frac{1-e^{-\kappa(1-t)}}{1-e^{-2\kappa}}`, and the cap
    area is :math:`2\pi(1-t) = -\frac{2\pi}{\kappa}\log\big(1-p(1-e^{-2\kappa})\big)`.
    """
    k, p = np.asarray(kappa, float), np.asarray(level, float)
    if np.any(k <= 0) or np.any((p <= 0) | (p >= 1)):
        raise ValueError("kappa must be > 0 and level in (0, 1)")
    return -2 * np.pi * np.log1p(-p * (-np.expm1(-2 * k))) / k


def vmf_bootstrap(
    x,
    weights=None,
    *,
    n_boot: int = 1000,
    level: float = 0.95,
    block: int = 1,
    block_s: float | None = None,
    fs: float | None = None,
    rng=None,
) -> ConfidenceCone:
    r"""Bootstrap confidence cone for the vMF mean direction (and a percentile interval for κ).

    Each replicate resamples the data with replacement and refits μ and κ; the cone's
    half-angle is the ``level`` quantile of the angles between the replicate means and
    :math:`\hat\mu`.

    * ``weights=None``, ``block=1``: the i.i.d. bootstrap of the rows.
    * ``block > 1``: circular moving-block bootstrap for a time series (rows in time
      order; blocks of ``block`` samples). Samples of a head-tilt trajectory are strongly
      autocorrelated, and the i.i.d. bootstrap then gives far too narrow a cone [5]_.
    * ``weights`` (frequency weights, e.g. counts per facet): replicates draw
      multinomial counts with probabilities :math:`w_i/\sum w` and total
      :math:`\mathrm{round}(\sum w)` (equivalent to resampling the underlying samples).

    ``x`` is a labelled (time, axis) series, a Recording (its ``gravity``) or an (N, 3)
    array. ``block_s`` gives the block length in seconds instead of samples
    (``block = round(block_s · fs)``), with ``fs`` read from the data (or given for a
    plain array; a missing or contradictory ``fs`` is an error).
    """
    sig = _read(x, name="x", fs=fs, need_fs=block_s is not None)
    x = as_unit_vectors(sig.values, "x")
    n = x.shape[0]
    w = _weights(weights, n)
    level = _validate.fraction(level, "level", open_low=True, open_high=True)
    n_boot = _validate.integer(n_boot, "n_boot", minimum=2)
    if block_s is not None:
        if block != 1:
            raise ValueError("give block (samples) or block_s (seconds), not both")
        block = max(1, int(round(_validate.positive(block_s, "block_s") * sig.fs)))
    block = _validate.integer(block, "block", minimum=1)
    rng = np.random.default_rng(rng)
    fit = vmf_fit(x, w)
    nb_ = int(n_boot)
    S, N = np.empty((nb_, 3)), np.empty(nb_)
    if w is not None:
        if block != 1:
            raise ValueError(
                "block bootstrap is defined for unweighted time series only"
            )
        tot, p = int(round(w.sum())), w / w.sum()
        for b in range(nb_):  # one vectorised draw per replicate (memory stays O(N))
            c = rng.multinomial(tot, p).astype(float)
            S[b], N[b] = c @ x, c.sum()
    elif block == 1:
        for b in range(nb_):
            S[b] = x[rng.integers(0, n, n)].sum(axis=0)
        N[:] = n
    else:
        if block > n:
            raise ValueError(f"block must be in [1, {n}], got {block}")
        xx = np.concatenate([x, x[: block - 1]])
        cs = np.concatenate([np.zeros((1, 3)), np.cumsum(xx, axis=0)])
        bsum = (
            cs[block : block + n] - cs[:n]
        )  # (n, 3): sum over the circular block starting at i
        nblocks = int(np.ceil(n / block))
        for b in range(nb_):
            S[b] = bsum[rng.integers(0, n, nblocks)].sum(axis=0)
        N[:] = nblocks * block
    rn = np.linalg.norm(S, axis=1)
    mus = S / rn[:, None]
    angles = angle(mus, fit.mu)
    kap = a3_inverse(np.clip(rn / N, 0, 1))
    lo, hi = np.quantile(kap, [(1 - level) / 2, (1 + level) / 2])
    return ConfidenceCone(
        fit.mu,
        fit.kappa,
        float(np.quantile(angles, level)),
        float(lo),
        float(hi),
        float(level),
        angles,
    )


# ---------------------------------------------------------------------------
# mean tilt point, sagittal angle, rotation to the pole
# ---------------------------------------------------------------------------


def mean_tilt_point(tmap, mesh: SphereMesh | None = None) -> VMFFit:
    r"""Average tilt point of a map (Fayat et al. §2.8): vMF fit of the facet centroids weighted by their counts.

    Parameters
    ----------
    tmap : xarray.Dataset (from :func:`~tiltlab.sphere.tilt_map`) or array (F,)
        Samples (or time) per facet.
    mesh : SphereMesh, optional
        Needed when ``tmap`` is an array (default the 5000-vertex mesh).
    """
    if isinstance(tmap, xr.Dataset):
        c, w = tmap["centroid"].values, tmap["count"].values
    else:
        mesh = sphere_mesh() if mesh is None else mesh
        c, w = mesh.centroids, np.asarray(tmap, float)
        if w.shape != (mesh.n_faces,):
            raise ValueError(f"map has shape {w.shape}, mesh has {mesh.n_faces} facets")
    return vmf_fit(c, w)


def sagittal_angle(mu, lesion_side: str = "left") -> np.ndarray:
    r"""Signed angle (rad) of the tilt direction :math:`\mu` to the sagittal (xz) plane; positive = head tilted toward the lesion side.

    Sensor frame: x nose, y left, z up; :math:`\mu` is the gravity-up direction in that
    frame. When the head rolls so that its **left** ear goes down, the up direction
    seen from the head moves toward **−y** (:math:`\mu_y<0`): a tilt toward the lesion
    side shows as a deviation of the gravity vector *away* from it (Fayat et al. §3.3).
    Hence

    .. math:: \alpha = \arcsin(-s\,\mu_y),\qquad s = +1 \text{ (left lesion)},\ -1 \text{ (right)},

    so α > 0 means the head is tilted toward the lesioned side. :math:`|\alpha|` is
    Fayat et al.'s "angular distance to the sagittal plane" (Fig. 4c).
    """
    mu = np.asarray(mu, float)
    if mu.shape[-1] != 3:
        raise ValueError("mu must have a last axis of length 3")
    s = {"left": 1.0, "right": -1.0}.get(lesion_side)
    if s is None:
        raise ValueError(f"lesion_side must be 'left' or 'right', got {lesion_side!r}")
    mu = mu / np.linalg.norm(mu, axis=-1, keepdims=True)
    return np.arcsin(np.clip(-s * mu[..., 1], -1, 1))


def rotation_to_pole(point) -> np.ndarray:
    r"""The minimal rotation matrix R (3×3) with :math:`R\,p = e_z` (about the axis :math:`p\times e_z`).

    Rodrigues' formula; for :math:`p=-e_z` a half-turn about x.
    """
    p = np.asarray(point, float).reshape(3)
    p = p / np.linalg.norm(p)
    ez = np.array([0.0, 0.0, 1.0])
    c = float(p @ ez)
    if c < -1 + 1e-15:
        return np.diag([1.0, -1.0, -1.0])
    v = np.cross(p, ez)
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1.0 + c)


def rotate_to_pole(vectors, baseline):
    """Rotate directions so that ``baseline`` sits at the north pole (Fayat et al. Fig. 3e).

    Angles between directions are preserved; a point's distance to the pole afterwards
    is its distance to the baseline point. ``vectors`` of shape (..., 3), or a labelled
    (time, axis) series / a Recording (its ``gravity``), which gives a DataArray back
    with the same coordinates and attributes.
    """
    if isinstance(vectors, (xr.DataArray, xr.Dataset)):
        sig = _read(vectors, allow_nan=True)
        out = sig.values @ rotation_to_pole(baseline).T
        attrs = {"units": "1", "long_name": "direction, baseline at the pole"}
        if "method" in sig.attrs:
            attrs["method"] = sig.attrs["method"]
        return _validate.labelled(
            out, sig, "rotated", dims=("time", "axis"), attrs=attrs
        )
    v = np.asarray(vectors, float)
    if v.shape[-1] != 3:
        raise ValueError("vectors must have a last axis of length 3")
    return v @ rotation_to_pole(baseline).T
