r"""Kernel densities of changes of heading (Benhamou 2023, §4 and §7).

A change of heading is an orthodromic arc: a size :math:`\omega \in [0, \pi]` and a
direction, the arc's (initial) inclination :math:`\delta` counter-clockwise from the
horizontal of the frontal plane (Eqs. 7), or its mean inclination :math:`\bar\eta`
relative to the body's coronal plane from the gyroscope (Eq. 12). Benhamou notes that
"initial arc inclination :math:`\delta^i` … behave[s] as [a] longitude" and "arc size
:math:`\omega` … as [a] colatitude" [1]_ (§7), so a change of heading is the unit vector

.. math::
    u = (\sin\omega\cos\delta,\ \sin\omega\sin\delta,\ \cos\omega),

the new heading seen from the old one placed at the pole with the frontal plane's
horizontal along :math:`+x`. Its spherical KDE (:func:`heading_change_kde`, vMF kernels
as in :func:`tiltlab.sphere.kde`) is the joint distribution of turn direction and
size; no turn is the pole. The marginal distribution of the direction alone is a
circular KDE with von Mises kernels (:func:`circular_kde`),

.. math::
    f(\delta) = \frac{1}{\sum_i w_i}\sum_i w_i
    \frac{e^{\kappa\cos(\delta-\delta_i)}}{2\pi I_0(\kappa)},\qquad \kappa = 1/h^2,

which integrates to 1 over :math:`(-\pi, \pi]` (the von Mises normalisation) and tends
to a Gaussian of standard deviation :math:`h` for small :math:`h`. Weighting it by
:math:`\omega` gives the distribution of the *amount* of turning per direction.

References
----------
.. [1] S. Benhamou, arXiv:2310.05820, 2023, §4 and §7. doi:10.48550/arXiv.2310.05820
.. [2] K. V. Mardia, P. E. Jupp, Directional Statistics, Wiley, 2000, §3.5.4.
"""

from __future__ import annotations

import numpy as np
from scipy.special import i0e

from .. import _validate
from ._kde_grid import SphericalKDE
from .kde import kde

__all__ = ["heading_change_vectors", "heading_change_kde", "circular_kde"]


def _angles(v, name: str) -> np.ndarray:
    a = np.asarray(getattr(v, "values", v), float).ravel()
    return a


def heading_change_vectors(direction, size) -> np.ndarray:
    r"""Place changes of heading on the unit sphere (size = colatitude).

    :math:`u = (\sin\omega\cos\delta, \sin\omega\sin\delta, \cos\omega)`.

    Parameters
    ----------
    direction : array_like
        Direction (inclination) of each change δ (rad, any range).
    size : array_like
        Arc size ω (rad), in [0, π]; same shape as ``direction``.

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        Unit vectors; NaN rows where an input is NaN.

    Raises
    ------
    ValueError
        For shapes that differ, or a size outside [0, π].

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import sphere
    >>> sphere.heading_change_vectors([0.0, np.pi / 2], [0.0, np.pi / 2]).round(3)
    array([[0., 0., 1.],
           [0., 1., 0.]])
    """
    d, w = _angles(direction, "direction"), _angles(size, "size")
    if d.shape != w.shape:
        raise ValueError(
            f"direction and size must have the same shape, got {d.shape} and {w.shape}"
        )
    ok = np.isfinite(w)
    if np.any((w[ok] < 0) | (w[ok] > np.pi)):
        raise ValueError("size must be arc sizes in [0, π] rad")
    s = np.sin(w)
    u = np.column_stack([s * np.cos(d), s * np.sin(d), np.cos(w)])
    return u


def heading_change_kde(
    direction, size, *, h: float | None = None, **settings
) -> SphericalKDE:
    """Estimate the spherical KDE of changes of heading (direction, size).

    :func:`heading_change_vectors` then :func:`tiltlab.sphere.kde` (NaN rows dropped).

    Parameters
    ----------
    direction, size : array_like
        As in :func:`heading_change_vectors` (rad).
    h : float, optional
        Bandwidth (rad); default the reference bandwidth.
    **settings
        ``grid``, ``weights``, ``kernel``, ``cell_deg``, ``tol``, ``quadrature`` of
        :func:`tiltlab.sphere.kde`.

    Returns
    -------
    SphericalKDE
        Density (sr⁻¹) of the changes of heading on the grid.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import sphere
    >>> rng = np.random.default_rng(0)
    >>> k = sphere.heading_change_kde(rng.uniform(-np.pi, np.pi, 200),
    ...                               rng.uniform(0.0, 0.3, 200), h=0.1, cell_deg=5.0)
    >>> round(k.integral(), 6)
    1.0
    """
    return kde(heading_change_vectors(direction, size), h=h, **settings)


def circular_kde(angles, *, h: float, weights=None, n_grid: int = 360):
    r"""Estimate a circular KDE with von Mises kernels of width ``h``.

    See the module notes for the formula.

    Parameters
    ----------
    angles : array_like
        Angles (rad); NaN values are dropped.
    h : float
        Bandwidth (rad), > 0: κ = 1/h².
    weights : array_like, optional
        Weights (finite, ≥ 0, not all zero), same shape as ``angles``.
    n_grid : int
        Number of evaluation angles, regularly spaced on (−π, π].

    Returns
    -------
    grid : numpy.ndarray, shape (n_grid,)
        Evaluation angles (rad).
    density : numpy.ndarray, shape (n_grid,)
        Density (rad⁻¹), integrating to 1 over the circle.

    Raises
    ------
    ValueError
        For a bad ``h``, ``n_grid`` or ``weights``, or no finite angle.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import sphere
    >>> g, f = sphere.circular_kde([0.0, 0.1, -0.1], h=0.3)
    >>> round(float(f.sum() * (g[1] - g[0])), 6)
    1.0
    """
    h = _validate.positive(h, "h")
    n_grid = _validate.integer(n_grid, "n_grid", minimum=8)
    a = _angles(angles, "angles")
    w = np.ones_like(a) if weights is None else _angles(weights, "weights")
    if w.shape != a.shape:
        raise ValueError(f"weights must have shape {a.shape}, got {w.shape}")
    ok = np.isfinite(a)
    a, w = a[ok], w[ok]
    if a.size == 0:
        raise ValueError("angles has no finite value")
    if not np.all(np.isfinite(w)) or np.any(w < 0) or w.sum() <= 0:
        raise ValueError("weights must be finite, ≥ 0 and not all zero")
    kappa = 1.0 / (h * h)
    grid = -np.pi + 2 * np.pi * (np.arange(n_grid) + 1) / n_grid
    dens = np.zeros(n_grid)
    # exp(κ(cos − 1)) / (2π I0e(κ)) = exp(κ cos) / (2π I0(κ)), without overflow
    norm = 2.0 * np.pi * i0e(kappa)
    for lo in range(0, a.size, 4096):
        d = grid[:, None] - a[None, lo : lo + 4096]
        dens += np.exp(kappa * (np.cos(d) - 1.0)) @ w[lo : lo + 4096]
    return grid, dens / (norm * w.sum())
