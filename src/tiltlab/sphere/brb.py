r"""Movement-based KDE on the sphere with biased random bridges (Benhamou 2023, §7).

Benhamou extends the location-based KDE (LKDE) of directions to a movement-based one
(MKDE) by "setting kernels (with a variable smoothing parameter) on in-between
interpolated locations to simulate biased random bridges linking successive recorded
locations" [1]_ (§7), following the planar method of [2]_, and decomposes it by
weighting with the local residence time or number of visits ([1]_ §7 and App. C, [3]_).

Bridge
------
Between two fixes :math:`x_k` (time :math:`t_k`) and :math:`x_{k+1}` (step
:math:`\Delta t_k`, arc :math:`\omega_k`), model the movement in the tangent plane as a
diffusion of coefficient :math:`D` (mean squared displacement :math:`4Dt`, variance
:math:`2Dt` per axis) with a drift toward the next fix. Conditioned on reaching
:math:`x_{k+1}` at :math:`t_{k+1}`, the position at the fraction :math:`\alpha` of the
step is Gaussian, centred on the point at :math:`\alpha` of the arc (the drift only moves
the mean, and the conditioning fixes it), with the Brownian-bridge variance per axis

.. math::
    \operatorname{Var}[x(\alpha)] = 2D\,\Delta t_k\,\alpha(1-\alpha)

(:math:`W(\alpha\Delta t)-\alpha W(\Delta t)` for a Wiener process :math:`W` of
variance :math:`2D` per unit time: :math:`2D\Delta t[\alpha-2\alpha^2+\alpha^2]`).
It is zero at the fixes and largest, :math:`D\Delta t_k/2`, in the middle of the step.
Convolving with a kernel of width :math:`h_{\min}` (the location error and minimal
smoothing, which applies at the fixes themselves) adds the variances:

.. math::
    h^2(\alpha) = h_{\min}^2 + 2D\,\Delta t_k\,\alpha(1-\alpha).

As in [2]_, steps longer than ``t_max`` are dropped (gaps: no bridge is assumed) and
steps shorter than ``l_min`` are treated as no movement (:math:`h=h_{\min}` along
them). Each step is cut into :math:`m_k=\lceil\omega_k/\mathrm{step}\rceil` sub-arcs,
a kernel of width :math:`h(\alpha)` at the middle of each with weight
:math:`\Delta t_k/m_k`: the density is the fraction of time spent per steradian (the
utilisation distribution, "UD").

Diffusion coefficient
---------------------
:func:`brb_diffusion` chooses :math:`D` by maximum likelihood on independent triplets
:math:`(x_{2j}, x_{2j+1}, x_{2j+2})`: the middle fix, left out, should be distributed
as the bridge between its neighbours at :math:`\alpha=(t_{2j+1}-t_{2j})/(t_{2j+2}-t_{2j})`
— a 2-D Gaussian of variance :math:`\sigma_j^2=h_{\min}^2+2DT_j\alpha(1-\alpha)` per
axis about the arc point, :math:`T_j` the duration of the triplet. Its angular distance
:math:`d_j` to that point has log-likelihood
:math:`-\log(2\pi\sigma_j^2)-d_j^2/(2\sigma_j^2)` (a planar density of the tangent
plane; the method of Horne et al. [4]_ on the sphere).

Residence and visits
--------------------
With the cap of angular radius :math:`r` around every fix, :func:`residence` gives the
total time :math:`T_{\rm in}` spent inside it and the number of visits NV
(re-entries after more than :math:`T_{\rm out}` outside, App. C). Near a direction
:math:`c` the time-weighted MKDE adds up :math:`T(c)=\mathrm{NV}(c)\,\overline{RT}(c)`
(visits × mean residence time per visit). Weighting every kernel's time by

* ``"residence"``: :math:`1/\mathrm{NV}` — the sum becomes :math:`\overline{RT}(c)`,
  the *intensity* distribution (ID: how long the direction is kept at each visit);
* ``"visits"``: :math:`\mathrm{NV}/T_{\rm in}` — the sum becomes :math:`\mathrm{NV}(c)`,
  the *recursion* distribution (RD: how often the direction comes back);

so that, before normalisation, UD = ID × RD locally. The factors are computed at the
fixes and interpolated linearly in :math:`\alpha` along each step.

References
----------
.. [1] S. Benhamou, arXiv:2310.05820, 2023, §7 and App. C. doi:10.48550/arXiv.2310.05820
.. [2] S. Benhamou, "Dynamic approach to space and habitat use based on biased random
   bridges", PLoS ONE 6(1):e14592, 2011. doi:10.1371/journal.pone.0014592
.. [3] S. Benhamou, J. Riotte-Lambert, "Beyond the utilization distribution: identifying
   home range areas that are intensively exploited or repeatedly visited", Ecol. Model.
   227:112–116, 2012. doi:10.1016/j.ecolmodel.2011.12.015
.. [4] J. S. Horne et al., "Analyzing animal movements using Brownian bridges", Ecology
   88:2354–2363, 2007. doi:10.1890/06-0957.1
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.optimize import minimize_scalar

from .. import _validate
from ._kde_grid import (
    EqualAreaGrid,
    SphericalKDE,
    _check_cell_deg,
    _scatter,
    _settings,
    _settings_grid,
)
from .kde import _steps, _sub_arcs, reference_bandwidth, slerp_vectors
from .mesh import _series
from .residence import residence
from .vmf import angle

__all__ = [
    "ResidenceMap",
    "bridge_bandwidth",
    "brb_diffusion",
    "brb",
    "residence_map",
    "kde_distance",
]

_WEIGHTINGS = ("time", "residence", "visits")


def bridge_bandwidth(alpha, dt, h_min: float, diffusion: float) -> np.ndarray:
    r"""Compute the kernel width :math:`h(\alpha)` inside a random bridge.

    :math:`h^2(\alpha) = h_{\min}^2 + 2D\,\Delta t\,\alpha(1-\alpha)` (see the module
    notes, *Bridge*): :math:`h_{\min}` at the fixes, largest in the middle.

    Parameters
    ----------
    alpha : array_like
        Fractions of the step, in [0, 1].
    dt : array_like
        Step durations (s), ≥ 0, broadcast with ``alpha``.
    h_min : float
        Minimal kernel width (rad), > 0.
    diffusion : float
        Diffusion coefficient D (rad²/s; mean squared displacement 4Dt), ≥ 0.

    Returns
    -------
    numpy.ndarray
        Kernel widths (rad).

    Raises
    ------
    ValueError
        For ``alpha`` outside [0, 1], a negative or non-finite ``dt``, ``h_min`` ≤ 0 or
        a negative ``diffusion``.

    Examples
    --------
    >>> from tiltlab import sphere
    >>> sphere.bridge_bandwidth([0.0, 0.5, 1.0], 2.0, 0.1, 0.01).round(4)
    array([0.1   , 0.1414, 0.1   ])
    """
    a = np.asarray(alpha, float)
    if not np.all(np.isfinite(a)) or np.any((a < 0) | (a > 1)):
        raise ValueError("alpha must be fractions of the step, in [0, 1]")
    dt = np.asarray(dt, float)
    if not np.all(np.isfinite(dt)) or np.any(dt < 0):
        raise ValueError("dt must be finite step durations ≥ 0 (s)")
    h_min = _validate.positive(h_min, "h_min")
    diffusion = _validate.nonnegative(diffusion, "diffusion")
    return np.sqrt(h_min * h_min + 2.0 * diffusion * dt * a * (1.0 - a))


def brb_diffusion(
    vectors,
    *,
    fs: float | None = None,
    times=None,
    h_min: float,
    t_max: float = np.inf,
    bounds=(1e-9, 1e3),
) -> float:
    r"""Estimate the bridges' diffusion coefficient D by leave-one-out likelihood.

    See the module notes, *Diffusion coefficient*.

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Time-ordered directions (as in :func:`brb`).
    fs, times : float or array_like (N,), optional
        Sampling rate (Hz) or sample times (s) of a plain array.
    h_min : float
        Minimal kernel width (rad): the location error of a fix.
    t_max : float
        Triplets lasting longer than this (s) are left out.
    bounds : (float, float)
        Search interval of D (rad²/s), both > 0.

    Returns
    -------
    float
        D (rad²/s); at a bound when the likelihood is largest there.

    Raises
    ------
    ValueError
        With fewer than 3 samples, no triplet shorter than ``t_max``, or bad
        ``h_min``/``bounds``.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import sphere
    >>> rng = np.random.default_rng(0)
    >>> lon = np.cumsum(rng.normal(0.0, 0.02, 2001))  # random walk along the equator
    >>> x = np.column_stack([np.cos(lon), np.sin(lon), np.zeros_like(lon)])
    >>> d = sphere.brb_diffusion(x, fs=1.0, h_min=1e-4)
    >>> bool(0.5e-4 < d < 2e-4)  # per-axis variance 2D = 0.02² per step
    True
    """
    h_min = _validate.positive(h_min, "h_min")
    t_max = _validate.positive(t_max, "t_max", allow_inf=True)
    lo, hi = (_validate.positive(b, "bounds") for b in bounds)
    if not lo < hi:
        raise ValueError(f"bounds must be increasing, got {bounds!r}")
    x, t, _ = _series(vectors, fs, times)
    if x.shape[0] < 3:
        raise ValueError(f"vectors needs at least 3 samples, got {x.shape[0]}")
    i = np.arange(0, x.shape[0] - 2, 2)
    big_t = t[i + 2] - t[i]
    keep = big_t <= t_max
    if not np.any(keep):
        raise ValueError("every triplet of fixes lasts longer than t_max")
    i, big_t = i[keep], big_t[keep]
    al = (t[i + 1] - t[i]) / big_t
    a, b = x[i], x[i + 2]
    ok = np.sum(a * b, axis=1) > -1 + 1e-12  # antipodal ends: no defined bridge
    a, b, al, big_t, mid = a[ok], b[ok], al[ok], big_t[ok], x[i + 1][ok]
    d2 = angle(slerp_vectors(a, b, al), mid) ** 2
    v_geo = 2.0 * big_t * al * (1.0 - al)

    def nll(log_d):
        s2 = h_min * h_min + np.exp(log_d) * v_geo
        return float(np.sum(np.log(s2) + d2 / (2.0 * s2)))

    r = minimize_scalar(
        nll, bounds=(np.log(lo), np.log(hi)), method="bounded", options={"xatol": 1e-6}
    )
    return float(np.exp(r.x))


def _fix_factors(x, t, weighting, caps) -> np.ndarray:
    """Return the weighting factor of every fix (see *Residence and visits*)."""
    if weighting == "time":
        return np.ones(x.shape[0])
    if caps is None or np.shape(caps) != (2,):
        raise ValueError(
            f"weighting={weighting!r} needs caps=(radius, t_out), got {caps!r}"
        )
    radius, t_out = caps
    r = residence(x, x, radius, t_out, times=t)
    nv = np.maximum(r.n_visits, 1).astype(float)
    if weighting == "residence":
        return 1.0 / nv
    return nv / np.maximum(r.total, np.finfo(float).tiny)


def brb(
    vectors,
    *,
    fs: float | None = None,
    times=None,
    h_min: float | None = None,
    diffusion: float | None = None,
    l_min: float = 0.0,
    t_max: float = np.inf,
    step: float | None = None,
    weighting: str = "time",
    caps: tuple[float, float] | None = None,
    **settings,
) -> SphericalKDE:
    r"""Estimate a movement-based spherical KDE from biased random bridges.

    Kernels of width :math:`h(\alpha)=\sqrt{h_{\min}^2+2D\Delta t\,\alpha(1-\alpha)}`
    along the arc of every step, weighted by time (``"time"``, the UD), by time per
    visit (``"residence"``, ID) or by visits (``"visits"``, RD); see the module notes.

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Time-ordered directions: a labelled (time, axis) series with ``attrs["fs"]``, a
        Recording with a ``gravity`` variable, or a plain array with ``fs``/``times``.
    fs, times : float or array_like (N,), optional
        Sampling rate (Hz) or sample times (s) of a plain array.
    h_min : float, optional
        Minimal kernel width (rad); default :func:`reference_bandwidth` of the fixes.
    diffusion : float, optional
        Diffusion coefficient D (rad²/s); default :func:`brb_diffusion`.
    l_min : float
        Steps with an arc shorter than this (rad) are no movement (width ``h_min``).
    t_max : float
        Steps longer than this (s) are dropped.
    step : float, optional
        Maximal sub-arc length (rad), default ``h_min``/2.
    weighting : {"time", "residence", "visits"}
        UD, ID or RD (see above).
    caps : (float, float), optional
        ``(radius, t_out)``: the cap radius (rad) and the longest excursion (s) that
        does not end a visit, for ``"residence"`` and ``"visits"`` (:func:`residence`).
    **settings
        ``grid``, ``kernel``, ``cell_deg``, ``tol``, ``quadrature`` as in :func:`kde`.

    Returns
    -------
    SphericalKDE
        The density (sr⁻¹, integrating to 1), the grid and ``h = h_min``.

    Raises
    ------
    ValueError
        For fewer than 2 samples, a bad ``weighting`` (or one without ``caps``), bad
        widths, or steps all longer than ``t_max``.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import sphere
    >>> lon = np.linspace(0.0, 1.0, 11)
    >>> x = np.column_stack([np.cos(lon), np.sin(lon), np.zeros_like(lon)])
    >>> u = sphere.brb(x, fs=1.0, h_min=0.05, diffusion=0.001, cell_deg=4.0)
    >>> round(u.integral(), 6), u.h
    (1.0, 0.05)
    """
    if weighting not in _WEIGHTINGS:
        raise ValueError(f"weighting must be one of {_WEIGHTINGS}, got {weighting!r}")
    opts = _settings(settings, "brb")
    _check_cell_deg(opts.cell_deg)
    x, t, _ = _series(vectors, fs, times)
    if x.shape[0] < 2:
        raise ValueError(f"vectors needs at least 2 samples, got {x.shape[0]}")
    l_min = _validate.nonnegative(l_min, "l_min")
    t_max = _validate.positive(t_max, "t_max", allow_inf=True)
    h_min = (
        reference_bandwidth(x) if h_min is None else _validate.positive(h_min, "h_min")
    )
    if diffusion is None:
        diffusion = brb_diffusion(x, times=t, h_min=h_min, t_max=t_max)
    diffusion = _validate.nonnegative(diffusion, "diffusion")
    step = h_min / 2 if step is None else _validate.positive(step, "step")
    f = _fix_factors(x, t, weighting, caps)
    keep = np.diff(t) <= t_max
    a, b, dt, om = _steps(x, t, t_max)
    f0, f1 = f[:-1][keep], f[1:][keep]
    pts, al, k, mk = _sub_arcs(a, b, om, step)
    moving = (om >= l_min)[k]
    hh = bridge_bandwidth(al, np.where(moving, dt[k], 0.0), h_min, diffusion)
    w = dt[k] / mk * ((1.0 - al) * f0[k] + al * f1[k])
    grid = _settings_grid(opts, x)
    return SphericalKDE(_scatter(pts, w, hh, grid, opts), grid, float(h_min))


class ResidenceMap(NamedTuple):
    """Residence per cell of an equal-area grid (arrays of shape ``grid.shape``).

    ``total`` time inside the cap around the cell centre (s), ``n_visits``,
    ``mean_residence`` per visit (s, NaN where never visited), and the ``grid``.
    """

    total: np.ndarray
    n_visits: np.ndarray
    mean_residence: np.ndarray
    grid: EqualAreaGrid


def residence_map(
    vectors,
    grid: EqualAreaGrid,
    radius: float,
    t_out: float,
    *,
    fs: float | None = None,
    times=None,
) -> ResidenceMap:
    """Map the residence time and number of visits at the nodes of an equal-area grid.

    :func:`residence` with caps of angular ``radius`` centred on every cell centre
    (App. C of Benhamou 2023).

    Parameters
    ----------
    vectors : xarray.DataArray, xarray.Dataset or array_like, shape (N, 3)
        Time-ordered directions (see :func:`residence`).
    grid : EqualAreaGrid
        The grid, e.g. ``kde(...).grid``.
    radius : float
        Angular radius of the caps (rad), in (0, π/2).
    t_out : float
        Excursions no longer than this (s) do not end a visit.
    fs, times : float or array_like (N,), optional
        Sampling rate (Hz) or sample times (s) of a plain array.

    Returns
    -------
    ResidenceMap
        Total time (s), visits and mean residence per visit (s) per cell.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import sphere
    >>> x = np.tile([0.0, 0.0, 1.0], (11, 1))  # 10 s at the pole
    >>> m = sphere.residence_map(x, sphere.equal_area_grid(10.0), 0.5, 1.0, fs=1.0)
    >>> m.total.shape, float(m.total.max()), int(m.n_visits.sum())  # the top ring
    ((11, 36), 10.0, 36)
    """
    if not isinstance(grid, EqualAreaGrid):
        raise ValueError(f"grid must be an EqualAreaGrid, got {type(grid).__name__}")
    c = grid.centres().reshape(-1, 3)
    r = residence(vectors, c, radius, t_out, fs=fs, times=times)
    return ResidenceMap(
        r.total.reshape(grid.shape),
        r.n_visits.reshape(grid.shape),
        r.mean_residence.reshape(grid.shape),
        grid,
    )


def kde_distance(a: SphericalKDE, b: SphericalKDE) -> float:
    r"""Compute the :math:`L_1` distance :math:`\int|f_a-f_b|\,dA` of two KDEs on one grid.

    0 for identical densities, 2 for densities without overlap (each integrates to 1).

    Parameters
    ----------
    a, b : SphericalKDE
        Densities on the same grid (same shape and rotation).

    Returns
    -------
    float
        The distance, in [0, 2].

    Raises
    ------
    ValueError
        When the grids differ.

    Examples
    --------
    >>> from tiltlab import sphere
    >>> x = sphere.vmf_sample([0.0, 0.0, 1.0], 20.0, 100, rng=0)
    >>> k = sphere.kde(x, h=0.2, cell_deg=5.0)
    >>> sphere.kde_distance(k, k)
    0.0
    """
    ga, gb = a.grid, b.grid
    if ga.shape != gb.shape or not np.allclose(ga.rotation, gb.rotation, atol=1e-12):
        raise ValueError("a and b must be on the same grid (shape and rotation)")
    return float(np.abs(a.density - b.density).sum() * ga.cell_area)
