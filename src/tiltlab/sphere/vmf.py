r"""Fit, evaluate and sample the von Mises–Fisher distribution on :math:`S^2`.

Weighted maximum likelihood, density, sampling, cap areas and bootstrap confidence
cones. The summaries of a tilt map built on them (mean tilt point, sagittal angle,
rotation to the pole) are in :mod:`tiltlab.sphere.tiltpoint`.

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

import warnings
from typing import NamedTuple

import numpy as np

from .._stack import user_stacklevel
from .. import _validate
from .mesh import _read, as_unit_vectors

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
    "angle",
]


class VMFFit(NamedTuple):
    """Maximum-likelihood vMF fit.

    Mean direction ``mu`` (3,), concentration ``kappa``, mean resultant length ``rbar``
    and total weight ``n``.
    """

    mu: np.ndarray
    kappa: float
    rbar: float
    n: float


class ConfidenceCone(NamedTuple):
    """Bootstrap confidence cone around ``mu``.

    Half-angle (rad) at ``level``, κ interval, and the bootstrap angles between each
    replicate's mean and ``mu``.
    """

    mu: np.ndarray
    kappa: float
    half_angle: float
    kappa_low: float
    kappa_high: float
    level: float
    angles: np.ndarray


def angle(u, v) -> np.ndarray:
    """Angle (rad) between directions, atan2(‖u×v‖, u·v) (accurate near 0 and π).

    ``u`` and ``v`` (..., 3) broadcast; NaN rows give NaN, a zero vector (no direction)
    is an error naming ``u`` or ``v``.

    Parameters
    ----------
    u, v : array_like, shape (..., 3)
        Directions (any non-zero length); they broadcast.

    Returns
    -------
    ndarray, shape (...)
        Angle (rad), in [0, π].

    Raises
    ------
    ValueError
        If ``u`` or ``v`` contains a zero vector.
    """
    u = _validate.vectors(u, "u", width=3, ndim=None, allow_nan=True)
    v = _validate.vectors(v, "v", width=3, ndim=None, allow_nan=True)
    for a, name in ((u, "u"), (v, "v")):
        if np.any(np.all(a == 0, axis=-1)):
            raise ValueError(f"{name} contains zero vectors (no direction)")
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, axis=-1))


def _direction(v, name: str) -> np.ndarray:
    """One direction (3,) as a unit vector; zero, non-finite or mis-shaped is an error naming it."""
    try:
        a = np.asarray(v, float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a 3-vector, got {v!r}") from None
    if a.shape != (3,):
        raise ValueError(f"{name} must be a 3-vector, got shape {a.shape}")
    n = np.linalg.norm(a)
    if not np.isfinite(n) or n == 0:
        raise ValueError(
            f"{name} must be a finite non-zero vector (a direction), got {a.tolist()}"
        )
    return a / n


def _kappa_array(kappa, name: str = "kappa") -> np.ndarray:
    k = np.asarray(kappa, float)
    bad = np.isnan(k) | (k < 0)
    if np.any(bad):
        raise ValueError(
            f"{name} must be >= 0 (and not NaN), got {k[bad].ravel()[0]!r}"
        )
    return k


# ---------------------------------------------------------------------------
# A3 and its inverse
# ---------------------------------------------------------------------------

_SMALL = 1e-3


def a3(kappa) -> np.ndarray:
    r"""Mean resultant length :math:`A_3(\kappa)=\coth\kappa-1/\kappa` of a vMF on :math:`S^2` (series for κ < 1e-3).

    Parameters
    ----------
    kappa : float or array_like
        Concentration κ ≥ 0.

    Returns
    -------
    ndarray
        Mean resultant length A_3(κ), in [0, 1).
    """
    k = _kappa_array(kappa)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        big = 1.0 / np.tanh(k) - 1.0 / k
    ks = np.minimum(k, _SMALL)  # the series only where it is used (no overflow)
    series = ks / 3.0 - ks**3 / 45.0 + 2.0 * ks**5 / 945.0
    return np.where(k < _SMALL, series, big)


def _a3_prime(k):
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        big = 1.0 / k**2 - 1.0 / np.sinh(k) ** 2
    ks = np.minimum(k, _SMALL)
    series = 1.0 / 3.0 - ks**2 / 15.0 + 2.0 * ks**4 / 189.0
    return np.where(k < _SMALL, series, big)


def a3_inverse(rbar, *, tol: float = 1e-13, max_iter: int = 100) -> np.ndarray:
    r"""Solve :math:`A_3(\kappa)=\bar R` for κ (vectorised safeguarded Newton; exact MLE of κ).

    :math:`\bar R = 0` gives 0 and :math:`\bar R = 1` gives ∞. Newton steps that leave the
    current bracket are replaced by bisection (in log κ above 1).

    Parameters
    ----------
    rbar : float or array_like
        Mean resultant length R̄, in [0, 1].
    tol : float
        Relative convergence tolerance on κ (> 0).
    max_iter : int
        Maximum number of Newton/bisection iterations (≥ 1).

    Returns
    -------
    float or ndarray
        Concentration κ ≥ 0 (a scalar for scalar ``rbar``); ∞ where R̄ = 1.

    Raises
    ------
    ValueError
        If ``rbar`` is outside [0, 1] or not finite.
    """
    r = np.asarray(rbar, float)
    bad = ~np.isfinite(r) | (r < 0) | (r > 1)
    if np.any(bad):
        raise ValueError(f"rbar must lie in [0, 1], got {r[bad].ravel()[0]!r}")
    tol = _validate.positive(tol, "tol")
    max_iter = _validate.integer(max_iter, "max_iter", minimum=1)
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


def _check_weights(w, n: int, name: str = "weights", ok=None) -> np.ndarray:
    """Return weights (n,) as floats, finite and >= 0 on the rows kept (``ok``).

    Anything else is a ``ValueError`` naming ``name``; rows outside ``ok`` are not
    checked (they are dropped by the caller).
    """
    try:
        w = np.asarray(w, float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numeric, got {w!r}") from None
    if w.shape != (n,):
        raise ValueError(f"{name} must have shape ({n},), got {w.shape}")
    ww = w if ok is None else w[ok]
    bad = ~np.isfinite(ww) | (ww < 0)
    if np.any(bad):
        raise ValueError(
            f"{name} must be finite and >= 0, got {int(bad.sum())} bad values "
            f"(first: {ww[np.argmax(bad)]!r})"
        )
    return w


def _weights(w, n: int, name: str = "weights") -> np.ndarray | None:
    if w is None:
        return None
    w = _check_weights(w, n, name)
    if w.sum() <= 0:
        raise ValueError(f"{name} sum to zero")
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
        The fit: μ̂, κ̂, :math:`\bar R` and the total weight.

    Raises
    ------
    ValueError
        When the resultant vanishes (no preferred direction, e.g. antipodal pairs:
        :math:`\bar R = 0`, so μ is undefined), and for zero vectors or bad weights.

    Warns
    -----
    RuntimeWarning
        When all samples (with non-zero weight) are identical — a single sample
        included: :math:`\bar R = 1` and the MLE :math:`\hat\kappa` is ∞ (returned as
        ``inf``; μ is then the common direction).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import sphere
    >>> x = sphere.vmf_sample([0.0, 0.0, 1.0], 10.0, 2000, rng=0)
    >>> fit = sphere.vmf_fit(x)
    >>> round(fit.kappa, 1), round(fit.rbar, 3)
    (9.8, 0.898)
    >>> float(round(np.degrees(sphere.angle(fit.mu, [0.0, 0.0, 1.0])), 1))
    0.4
    """
    x = as_unit_vectors(x, "x")
    w = _weights(weights, x.shape[0])
    s = x.sum(axis=0) if w is None else w @ x
    n = float(x.shape[0] if w is None else w.sum())
    rn = float(np.linalg.norm(s))
    if rn <= 1e-12 * n:
        raise ValueError(
            f"x: the resultant vector of the {x.shape[0]} directions is zero "
            f"(|S| = {rn:.3g}): no mean direction (e.g. antipodal pairs)"
        )
    rbar = min(rn / n, 1.0)
    kappa = float(a3_inverse(rbar))
    if np.isinf(kappa):
        what = (
            "x holds a single direction"
            if x.shape[0] == 1
            else f"all {x.shape[0]} directions in x are identical"
        )
        warnings.warn(
            f"vmf_fit: {what} (mean resultant length 1): the concentration "
            "estimate kappa is infinite",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    return VMFFit(s / rn, kappa, rbar, n)


def vmf_logpdf(x, mu, kappa: float) -> np.ndarray:
    r"""Log of Eq. 14a, evaluated stably as :math:`\log\kappa-\log(2\pi(1-e^{-2\kappa}))+\kappa(\mu\cdot x-1)`.

    ``x`` (..., 3) are directions (normalised here; NaN rows give NaN, zero rows are an
    error), ``mu`` a non-zero 3-vector and ``kappa`` ≥ 0 finite. κ → 0 tends to the
    uniform density :math:`1/(4\pi)` smoothly (series below κ = 10⁻⁸); large κ (10⁶)
    neither overflows nor loses the normalisation.

    Parameters
    ----------
    x : array_like, shape (..., 3)
        Directions at which to evaluate the density (normalised here).
    mu : array_like, shape (3,)
        Mean direction μ (normalised here).
    kappa : float
        Concentration κ ≥ 0, finite.

    Returns
    -------
    ndarray, shape (...)
        Log density (log sr⁻¹).
    """
    x = _validate.vectors(x, "x", width=3, ndim=None, allow_nan=True)
    nx = np.linalg.norm(x, axis=-1, keepdims=True)
    if np.any(nx == 0):
        raise ValueError(
            f"x contains {int((nx == 0).sum())} zero vectors (no direction)"
        )
    x = x / nx
    mu = _direction(mu, "mu")
    kappa = _validate.nonnegative(kappa, "kappa")
    if kappa == 0:
        return np.where(np.isnan(x[..., 0]), np.nan, -np.log(4 * np.pi))
    if (
        kappa < 1e-8
    ):  # log(kappa / (1 - e^{-2 kappa})) = -log 2 + kappa - kappa^2/6 + ...
        log_c = -np.log(4 * np.pi) + kappa - kappa * kappa / 6.0
    else:
        log_c = np.log(kappa) - np.log(2 * np.pi) - np.log(-np.expm1(-2 * kappa))
    return log_c + kappa * (x @ mu - 1.0)


def vmf_pdf(x, mu, kappa: float) -> np.ndarray:
    """Evaluate the vMF density (sr⁻¹), Eq. 14a.

    Parameters
    ----------
    x, mu, kappa : array_like (..., 3), array_like (3,), float
        As in :func:`vmf_logpdf`: the directions, the mean direction μ and the finite
        concentration κ ≥ 0.

    Returns
    -------
    ndarray, shape (...)
        Density (sr⁻¹).
    """
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

    :math:`w = \mu\cdot x = 1 + \log\big(u + (1-u)e^{-2\kappa}\big)/\kappa`, longitude uniform,
    evaluated as :math:`1 + \operatorname{log1p}\big((1-u)\operatorname{expm1}(-2\kappa)\big)/\kappa`
    so that small κ (10⁻⁸, 10⁻³⁰⁰) gives the uniform distribution (w = 2u − 1) to
    rounding and large κ (10⁶) neither overflows nor collapses; κ = 0 is uniform.

    Parameters
    ----------
    mu : array_like, shape (3,)
        Mean direction μ (normalised here).
    kappa : float
        Concentration κ ≥ 0.
    n : int
        Number of draws (≥ 0).
    rng : int, numpy.random.Generator or None
        Seed or generator for :func:`numpy.random.default_rng`.

    Returns
    -------
    ndarray, shape (n, 3)
        Unit vectors.
    """
    mu = _direction(mu, "mu")
    kappa = _validate.nonnegative(kappa, "kappa")
    n = _validate.integer(n, "n", minimum=0)
    rng = np.random.default_rng(rng)
    u = rng.random(int(n))
    if kappa < 1e-12:  # uniform to O(kappa): E[w] = A3(kappa) ~ kappa / 3
        w = 2 * u - 1
    else:
        with np.errstate(divide="ignore"):
            w = 1.0 + np.log1p((1 - u) * np.expm1(-2 * kappa)) / kappa
    w = np.clip(w, -1, 1)
    phi = rng.uniform(0, 2 * np.pi, int(n))
    s = np.sqrt(1 - w * w)
    local = np.column_stack([s * np.cos(phi), s * np.sin(phi), w])
    return local @ _frame(mu).T


def vmf_cap_area(kappa, level) -> np.ndarray:
    r"""Area (sr) of the μ-centred cap holding a fraction ``level`` of a vMF(κ): the theoretical cumulative isopleth.

    :math:`P(\mu\cdot x \ge t)=\frac{1-e^{-\kappa(1-t)}}{1-e^{-2\kappa}}`, and the cap
    area is :math:`2\pi(1-t) = -\frac{2\pi}{\kappa}\log\big(1-p(1-e^{-2\kappa})\big)`.
    κ = 0 (and its limit) gives the uniform :math:`4\pi p`, κ = ∞ (a point mass) 0.

    Parameters
    ----------
    kappa : float or array_like
        Concentration κ ≥ 0 (may be ∞).
    level : float or array_like
        Probability mass p of the cap, in (0, 1); broadcasts with ``kappa``.

    Returns
    -------
    float or ndarray
        Cap area (sr), in [0, 4π).

    Raises
    ------
    ValueError
        If ``level`` is not in (0, 1).
    """
    k = _kappa_array(kappa)
    p = np.asarray(level, float)
    bad = ~np.isfinite(p) | (p <= 0) | (p >= 1)
    if np.any(bad):
        raise ValueError(f"level must be in (0, 1), got {p[bad].ravel()[0]!r}")
    k, p = np.broadcast_arrays(k, p)
    with np.errstate(divide="ignore", invalid="ignore"):
        area = -2 * np.pi * np.log1p(-p * (-np.expm1(-2 * k))) / k
    small = k < 1e-8  # -log1p(-2kp)/k -> 2p (1 + k p)
    area = np.where(small, 4 * np.pi * p * (1 + k * (p - 1)), area)
    return area[()] if area.ndim == 0 else area


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

    Parameters
    ----------
    x : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Directions (normalised here), in time order for a block bootstrap.
    weights : array_like, shape (N,), optional
        Non-negative frequency weights; None for unweighted samples.
    n_boot : int
        Number of bootstrap replicates (≥ 2).
    level : float
        Confidence level, in (0, 1).
    block : int
        Block length (samples, ≥ 1); 1 is the i.i.d. bootstrap.
    block_s : float, optional
        Block length (s), instead of ``block``.
    fs : float, optional
        Sampling rate (Hz) of a plain array, needed with ``block_s``.
    rng : int, numpy.random.Generator or None
        Seed or generator for :func:`numpy.random.default_rng`.

    Returns
    -------
    ConfidenceCone
        Fitted μ and κ, cone half-angle (rad) at ``level``, κ percentile interval,
        ``level`` and the bootstrap angles (rad).

    Raises
    ------
    ValueError
        Fewer than 2 samples (or fewer than 2 directions with non-zero weight), or a
        block bootstrap with fewer than 2 blocks (``block > N / 2``): every replicate
        would then be the data themselves (up to a circular shift), and the cone a
        meaningless 0°. Also bad ``level``, ``n_boot``, ``block``, ``block_s`` or
        weights, and data without a mean direction (:func:`vmf_fit`).
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
    n_used = n if w is None else int(np.count_nonzero(w))
    if n_used < 2:
        what = "sample" if w is None else "direction with non-zero weight"
        raise ValueError(
            f"x has {n_used} {what}{'s' if n_used != 1 else ''}: a bootstrap needs at "
            "least 2 (every replicate would be the data themselves, a 0° cone)"
        )
    if w is None and 1 < block and n < 2 * block:
        raise ValueError(
            f"block = {block} samples leaves fewer than 2 blocks in the {n} samples of "
            f"x: every replicate would be the whole series (a 0° cone); use a block of "
            f"at most {n // 2} samples"
        )
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
