r"""Estimate spherical kernel densities (Benhamou 2023, §7, Eqs. 14–16).

Equal-area grids, von Mises–Fisher kernels, reference bandwidth, cumulative isopleths,
location- and movement-based KDE, and a stationarity check.

Kernels
-------
A vMF kernel with concentration :math:`\kappa = 1/h^2` centred on :math:`\mu_i` (Eq. 14a)
can be written with the chord :math:`\lVert c-\mu_i\rVert^2 = 2(1-c\cdot\mu_i)` (Eq. 16):

.. math::
    K_{\rm vMF}(c) = \frac{1}{2\pi h^2(1-e^{-2/h^2})}\exp\Big(-\frac{\lVert c-\mu_i\rVert^2}{2h^2}\Big),
    \qquad
    K_{\rm G}(c) = \frac{1}{2\pi h^2}\exp\Big(-\frac{\lVert c-\mu_i\rVert^2}{2h^2}\Big)\ \text{(Eq. 15)}.

So Benhamou's Gaussian-on-chord kernel (Eq. 15) *is* the vMF kernel times the factor
:math:`1-e^{-2\kappa}` (1 − 6·10⁻⁶ for κ = 6); it integrates to :math:`1-e^{-2\kappa}`.
Both are offered (``kernel="vmf"`` exact, ``kernel="gauss"``). Kernels are truncated
where they fall below ``tol`` times their peak, i.e. beyond the angular radius
:math:`\arccos(1+\log(\mathrm{tol})/\kappa)`; the lost mass is ≈ ``tol``.

Quadrature
----------
The density is given at the cell centres. With ``quadrature="point"`` it is the kernel
sum evaluated there (Eq. 15 as printed); :math:`\sum_c U_c a_c` is then a midpoint-rule
quadrature, exact to rounding for kernels several cells wide on the grid's equator but
wrong by any amount for kernels narrower than the cells around them — a kernel of
h = 0.05 rad centred on the pole of a 1° grid keeps 21 % of its mass, one of
h = 0.003 rad on the equator 104 %. The default ``quadrature="mass"`` keeps the shape of
the point values but rescales each kernel so that it puts exactly its mass on the grid
(1 for ``"vmf"``, :math:`1-e^{-2\kappa}` for ``"gauss"``): values are taken relative to
the kernel's largest value on the grid (truncated at ``tol`` below it) and divided by
their sum times the cell area. Where the grid resolves the kernel the factor is 1 to
the quadrature's accuracy; a kernel much narrower than the cells goes to the nearest
cell centre(s) (shared equally between equidistant ones, e.g. the first ring of cells
around a grid pole). The integral of a ``"vmf"`` KDE is then 1 to rounding for every
bandwidth and position, and a kernel centred on a grid pole gets the exact mass of every
ring of cells. What no grid quadrature gives is the shape of a kernel inside a cell: for
a kernel narrower than the cells around it the density is not the cell average (its
mass goes to the nearest cell centres, which may lie one cell off where the cells are
tall); :func:`grid_for` (data on the grid's equator) or a finer grid avoids that.
The mass quadrature computes exp with a vectorised routine (within 2 ulp) and sums
each kernel's values in vectorised order: its density is the kernel sum above to
rounding (relative ~1e-15), not bit for bit that of a scalar loop.

Grid
----
Cells are regular in longitude :math:`\xi` (``n_lon`` bins) and in the sine of latitude
:math:`s=\sin\psi` (``n_lat`` bins), so every cell has the same area
:math:`a_c = \Delta\xi\,\Delta s = 4\pi/(n_{lon}n_{lat})` (Benhamou §7). A ``cell_deg``
grid has :math:`\Delta\xi = \Delta s = ` ``cell_deg`` in radians, i.e. square
cells of that size at the grid's equator. Near the grid's poles the cells become tall
in latitude (:math:`\Delta\psi = \Delta s/\cos\psi`; the first ring around a pole of a 1°
grid reaches 10.7° from it), and a point evaluation of a narrow kernel there is a poor
quadrature (see *Quadrature*); the grid can therefore be rotated (``pole``), and
:func:`grid_for` puts the pole 90° away from the data's mean direction.

Layout
------
This module holds the bandwidth rule, :func:`kde`, :func:`slerp_vectors` and
:func:`mkde`; the grid, the result type and the kernel sum are in
:mod:`tiltlab.sphere._kde_grid` (its numba loops in :mod:`tiltlab.sphere._kde_kernel`),
the isopleths and the stationarity check in
:mod:`tiltlab.sphere._kde_summaries`. Every public name is importable from here.

References
----------
.. [1] S. Benhamou, arXiv:2310.05820, 2023, §7 and App. C. doi:10.48550/arXiv.2310.05820
.. [2] B. W. Silverman, Density Estimation for Statistics and Data Analysis, Chapman &
   Hall, 1986.
.. [3] S. Benhamou, "Dynamic approach to space and habitat use based on biased random
   bridges", PLoS ONE 6(1):e14592, 2011. doi:10.1371/journal.pone.0014592
.. [4] S. Benhamou, "Of scales and stationarity in animal movements", Ecol. Lett.
   17:261–272, 2014. doi:10.1111/ele.12225
"""

from __future__ import annotations

import warnings

import numpy as np

from .. import _validate
from .._deprecate import alias
from ._kde_grid import (
    EqualAreaGrid,
    SphericalKDE,
    _check_cell_deg,
    _KDESettings,
    _scatter,
    _settings,
    _settings_grid,
    equal_area_grid,
    grid_for,
)
from ._kde_summaries import isopleth_mask, isopleths, stationarity_thirds
from .mesh import _series, as_unit_vectors
from .vmf import _check_weights, angle, vmf_fit

__all__ = [
    "EqualAreaGrid",
    "SphericalKDE",
    "equal_area_grid",
    "grid_for",
    "reference_bandwidth",
    "kde",
    "mkde",
    "isopleths",
    "isopleth_mask",
    "stationarity_thirds",
    "slerp_vectors",
    "slerp",
]

# ---------------------------------------------------------------------------
# bandwidth
# ---------------------------------------------------------------------------


def reference_bandwidth(
    vectors, weights=None, *, n: int | None = None, method: str = "mle"
) -> float:
    r"""Compute the reference bandwidth :math:`h_{ref}=\hat\kappa^{-1/2}\,n^{-1/6}`.

    Benhamou §7; Silverman's rule.

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        A labelled (time, axis) series, a Recording (its ``gravity``) or an array.
    weights : (N,), optional
        Weights for the mean resultant length :math:`\bar R`.
    n : int, optional
        Sample size in :math:`n^{-1/6}` (default N).
    method : {"mle", "benhamou"}
        κ̂ from :math:`A_3^{-1}(\bar R)` (MLE), or :math:`1/\hat\kappa = 1-\bar R`
        (Benhamou's printed form; the two agree to :math:`O(e^{-2\kappa})` once κ ≳ 3,
        because :math:`A_3(\kappa) = \coth\kappa - 1/\kappa \approx 1-1/\kappa`).

    Returns
    -------
    float
        The bandwidth h (rad).

    Raises
    ------
    ValueError
        When the rule gives no usable bandwidth: all samples identical (a single
        sample, or :math:`\bar R = 1`: κ̂ = ∞ and h = 0 — pass ``h`` yourself), or no
        mean direction (zero resultant, e.g. antipodal pairs: κ̂ = 0 and h = ∞).
    """
    if method not in ("mle", "benhamou"):
        raise ValueError(f"method must be 'mle' or 'benhamou', got {method!r}")
    x = as_unit_vectors(vectors, "vectors")
    n = x.shape[0] if n is None else _validate.integer(n, "n", minimum=1)
    rule = f"reference_bandwidth (method={method!r}, h = κ̂^(-1/2) n^(-1/6))"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            fit = vmf_fit(x, weights)
    except ValueError as err:
        if "resultant" not in str(err):
            raise
        raise ValueError(
            f"{rule}: the samples have no mean direction (zero resultant, κ̂ = 0), "
            "so the rule gives h = ∞; pass h explicitly"
        ) from None
    if method == "mle":
        inv_k = 1.0 / fit.kappa if fit.kappa > 0 else np.inf
    else:
        inv_k = 1.0 - fit.rbar
    if not inv_k > 0:
        what = (
            "a single sample"
            if x.shape[0] == 1
            else f"all {x.shape[0]} samples identical"
        )
        raise ValueError(
            f"{rule} gives h = 0 for vectors with {what} (mean resultant length 1, "
            "κ̂ = ∞); pass h explicitly"
        )
    return float(np.sqrt(inv_k) * n ** (-1.0 / 6.0))


def kde(
    vectors,
    *,
    grid: EqualAreaGrid | None = None,
    h: float | None = None,
    weights=None,
    kernel: str = "vmf",
    cell_deg: float = 1.0,
    tol: float = 1e-10,
    quadrature: str = "mass",
) -> SphericalKDE:
    r"""Estimate a location-based spherical KDE on an equal-area grid.

    Benhamou's Eq. 15 with vMF kernels:

    .. math:: U_c = \frac{\sum_i w_i K_h(c;\mu_i)}{\sum_i w_i}

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Locations on the sphere (normalised here; NaN rows dropped): a labelled (time,
        axis) series, a Recording (its ``gravity``) or an array.
    grid : EqualAreaGrid, optional
        Default :func:`grid_for` the data with ``cell_deg``.
    h : float, optional
        Bandwidth (rad); default :func:`reference_bandwidth`.
    weights : array_like (N,), optional
        Weights of the samples (finite, >= 0, not all zero).
    kernel : {"vmf", "gauss"}
        Exact vMF (Eq. 14a) or Benhamou's Gaussian-on-chord form (Eq. 15).
    cell_deg : float
        Cell size (°) of the default grid.
    tol : float
        Kernel truncation (relative to its peak), in (0, 1).
    quadrature : {"mass", "point"}
        ``"mass"`` (default): each kernel puts exactly its mass on the grid, so the
        KDE integrates to 1 for any bandwidth and position; ``"point"``: kernels
        evaluated at the cell centres (see the module notes, *Quadrature*).

    Returns
    -------
    SphericalKDE
        The density (sr⁻¹) on the grid, the grid and the bandwidth.

    Raises
    ------
    ValueError
        For zero vectors, bad ``weights`` (negative, non-finite, wrong shape, all zero),
        a non-positive or non-finite ``h``, and when the default bandwidth rule fails
        (all samples identical: :func:`reference_bandwidth`).

    Examples
    --------
    >>> from tiltlab import sphere
    >>> x = sphere.vmf_sample([0.0, 0.0, 1.0], 20.0, 500, rng=0)
    >>> est = sphere.kde(x, h=0.2, cell_deg=5.0)
    >>> est.density.shape, round(est.integral(), 6)
    ((23, 72), 1.0)
    """
    settings = _KDESettings(grid, kernel, cell_deg, tol, quadrature)
    x = as_unit_vectors(vectors, "vectors", allow_nan=True)
    ok = np.isfinite(x).all(axis=1)
    if h is not None:
        h = _validate.positive(h, "h")
    _check_cell_deg(cell_deg)
    w = (
        np.ones(x.shape[0])
        if weights is None
        else _check_weights(weights, x.shape[0], ok=ok)
    )
    x, w = x[ok], w[ok]
    if x.shape[0] == 0:
        raise ValueError("vectors has no finite rows (no data)")
    if w.sum() <= 0:
        raise ValueError("weights are all zero on the finite rows of vectors")
    if not np.isfinite(w.sum()):
        raise ValueError(f"weights sum to {w.sum()!r} (overflow); rescale them")
    if h is None:
        h = reference_bandwidth(x, w if weights is not None else None)
    grid = _settings_grid(settings, x, w)
    return SphericalKDE(_scatter(x, w, h, grid, settings), grid, float(h))


def _rows(v, name: str) -> np.ndarray:
    """Return directions (..., 3) normalised; zero or non-finite rows are an error."""
    a = _validate.vectors(v, name, width=3, ndim=None)
    n = np.linalg.norm(a, axis=-1, keepdims=True)
    if np.any(n == 0):
        raise ValueError(
            f"{name} contains {int((n == 0).sum())} zero vectors (no direction)"
        )
    return a / n


def slerp_vectors(a, b, t) -> np.ndarray:
    r"""Interpolate unit vectors along the great-circle arcs from ``a`` to ``b``.

    The point at fraction t of the orthodromic arc a→b (rows) is
    :math:`\frac{\sin((1-t)\omega)a+\sin(t\omega)b}{\sin\omega}`, ω the angle between
    them. (For rotations, see :func:`tiltlab.quaternion.slerp`.)

    Parameters
    ----------
    a, b : array_like, shape (..., 3)
        Directions (normalised here; zero or non-finite rows are an error).
    t : array_like
        Fractions along the arcs (finite), broadcast with the rows.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Unit vectors; identical ``a`` and ``b`` give that direction for every ``t``.

    Raises
    ------
    ValueError
        When ``a`` and ``b`` are opposite directions (angle within 10⁻¹² rad of π) in
        some row: every great circle through them is a shortest arc, so the path is
        undefined (no direction is chosen arbitrarily; before, the point jumped from
        ``a`` to ``b`` through NaN at t = 1/2). The message names the first row.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import sphere
    >>> p = sphere.slerp_vectors([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.5, 1.0])
    >>> np.round(p, 3)
    array([[1.   , 0.   , 0.   ],
           [0.707, 0.   , 0.707],
           [0.   , 0.   , 1.   ]])
    """
    a, b = _rows(a, "a"), _rows(b, "b")
    t = _validate.vectors(t, "t", width=None, ndim=None)[..., None]
    om = angle(a, b)[..., None]
    opposite = (np.sin(om) <= 1e-12) & (np.sum(a * b, axis=-1, keepdims=True) < 0)
    if np.any(opposite):
        k = np.argwhere(opposite[..., 0])
        where = f" (first at index {tuple(int(i) for i in k[0])})" if k.size else ""
        raise ValueError(
            f"a and b are opposite directions in {int(opposite.sum())} row(s){where}: "
            "the great-circle arc between antipodal points is not unique, so slerp is "
            "undefined there"
        )
    with np.errstate(invalid="ignore", divide="ignore"):
        so = np.sin(om)
        p = np.where(
            so > 1e-12,
            (np.sin((1 - t) * om) * a + np.sin(t * om) * b)
            / np.where(so > 1e-12, so, 1.0),
            (1 - t) * a + t * b,
        )
    return p / np.linalg.norm(p, axis=-1, keepdims=True)


def mkde(
    vectors,
    *,
    fs: float | None = None,
    times=None,
    h: float | None = None,
    step: float | None = None,
    diffusion: float = 0.0,
    max_gap: float = np.inf,
    **settings,
) -> SphericalKDE:
    r"""Estimate a movement-based spherical KDE from kernels along the path.

    The kernels are placed along the orthodromic arcs between successive samples. Each
    step :math:`x_k\to x_{k+1}` (duration :math:`\Delta t_k`, arc :math:`\omega_k`) is
    cut into :math:`m_k=\lceil\omega_k/\mathrm{step}\rceil` equal sub-arcs; a kernel sits
    at the middle of each (:func:`slerp_vectors` at :math:`\alpha=(j+\tfrac12)/m_k`) with
    weight :math:`\Delta t_k/m_k`, so the density is the fraction of *time* spent near
    each direction. With ``diffusion`` :math:`D` > 0 (rad²/s; variance :math:`2Dt` per
    axis, the convention of :func:`tiltlab.sphere.brb`) the bandwidth grows inside the
    step like a Brownian bridge, :math:`h^2(\alpha) = h^2 + 2\alpha(1-\alpha)D\Delta
    t_k` — a simplified, unbiased version of Benhamou's biased random bridges [3]_
    (:func:`tiltlab.sphere.brb` has the bridges with a minimal width, a fitted D and
    residence or visit weightings).

    At most 5·10⁷ kernels are placed (beyond that, an error names ``step``). Two
    successive samples in opposite directions are an error naming them (the arc
    between antipodal points is not unique, see :func:`slerp_vectors`).

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Time-ordered directions: a labelled (time, axis) series with ``attrs["fs"]`` (e.g.
        :func:`tiltlab.filters.gravity`), a Recording with a ``gravity`` variable, or a
        plain array.
    fs, times : float or array_like (N,), optional
        Sampling rate (Hz) or sample times (s) of a plain array (one is required).
        Labelled data use their ``time`` coordinate and ``fs``; an ``fs`` that
        contradicts ``attrs["fs"]`` is an error, and so is labelled data without ``fs``.
    h : float, optional
        Base bandwidth (rad), default :func:`reference_bandwidth` of the samples.
    step : float, optional
        Maximal sub-arc length (rad), default h/2.
    diffusion : float
        Brownian-bridge diffusion coefficient (rad²/s; variance 2Dt per axis), ≥ 0.
    max_gap : float
        Steps longer than this (s) are dropped (data gaps).
    **settings
        ``grid``, ``kernel``, ``cell_deg``, ``tol`` and ``quadrature``, as in
        :func:`kde`.

    Returns
    -------
    SphericalKDE
        The density (sr⁻¹: fraction of time per steradian), the grid and the base
        bandwidth ``h``.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import sphere
    >>> t = np.linspace(0.0, 1.0, 50)
    >>> path = np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])
    >>> est = sphere.mkde(path, fs=10.0, h=0.1, cell_deg=5.0)
    >>> round(est.integral(), 6), est.h
    (1.0, 0.1)
    """
    opts = _settings(settings, "mkde")
    x, t, _ = _series(vectors, fs, times)
    n = x.shape[0]
    if n < 2:
        raise ValueError(f"vectors needs at least 2 samples, got {n}")
    diffusion = _validate.nonnegative(diffusion, "diffusion")
    max_gap = _validate.positive(max_gap, "max_gap", allow_inf=True)
    _check_cell_deg(opts.cell_deg)
    h = reference_bandwidth(x) if h is None else _validate.positive(h, "h")
    step = h / 2 if step is None else _validate.positive(step, "step")
    a, b, dt, om = _steps(x, t, max_gap)
    pts, alpha, k, mk = _sub_arcs(a, b, om, step)
    w = dt[k] / mk
    hh = np.sqrt(h * h + 2.0 * alpha * (1 - alpha) * diffusion * dt[k])
    grid = _settings_grid(opts, x)
    return SphericalKDE(_scatter(pts, w, hh, grid, opts), grid, float(h))


def _steps(x, t, max_gap: float):
    """Return the starts, ends, durations and arcs of the steps up to ``max_gap`` long."""
    dt = np.diff(t)
    keep = dt <= max_gap
    a, b, dt = x[:-1][keep], x[1:][keep], dt[keep]
    if a.shape[0] == 0:
        raise ValueError("every step is longer than max_gap")
    om = angle(a, b)
    opposite = (np.sin(om) <= 1e-12) & (np.sum(a * b, axis=-1) < 0)
    if np.any(opposite):
        i = int(np.flatnonzero(keep)[np.argmax(opposite)])
        raise ValueError(
            f"vectors: samples {i} and {i + 1} are opposite directions: the path "
            "between them (a half-turn) has no defined great circle; drop the bad "
            "sample or give a max_gap that excludes that step"
        )
    return a, b, dt, om


def _sub_arcs(a, b, om, step: float):
    """Return the sub-arc midpoints, their fractions α, their step and its sub-arcs.

    Every step a→b (arc ``om``) is cut into m = ⌈ω/step⌉ equal sub-arcs (at least one).
    """
    m = np.maximum(1, np.ceil(om / step))
    if m.sum() > _MAX_KERNELS:
        raise ValueError(
            f"step = {step!r} rad cuts the trajectory into {m.sum():.3g} kernels "
            f"(more than {_MAX_KERNELS:.0e}); increase step"
        )
    m = m.astype(np.int64)
    k = np.repeat(np.arange(a.shape[0]), m)
    j = np.arange(k.size) - np.repeat(np.cumsum(m) - m, m)
    alpha = (j + 0.5) / m[k]
    return slerp_vectors(a[k], b[k], alpha), alpha, k, m[k]


slerp = alias(slerp_vectors, "slerp")


_MAX_KERNELS = 50_000_000
