r"""Power and sample size by simulation, for the rank tests of :mod:`tiltlab.stats`.

The data-generating model is a user callable ``simulate_groups(n, rng) -> (x, y)``
returning the two samples of one simulated experiment with ``n`` animals per group
(paired values for the signed-rank test). :mod:`tiltlab.stats` never imports the
simulator (layer rule); a chapter passes a callable built on :mod:`tiltlab.simulate`,
and :func:`normal_shift` is a fast stand-in.

Power at :math:`n` is estimated by the rejection rate over :math:`B` simulated
experiments, rejecting when the one-sided p-value is at most :math:`\alpha/m` (a
Bonferroni family of :math:`m` tests, e.g. Fayat et al.'s 18 or 6):

.. math::
    \widehat{\pi}(n) = \frac1B\sum_{b=1}^B \mathbf 1\{p_b \le \alpha/m\},\qquad
    \operatorname{se} = \sqrt{\widehat\pi(1-\widehat\pi)/B}.

With an exact test the attainable size is :math:`\max\{p \in \text{lattice}: p \le
\alpha/m\}` (:func:`~tiltlab.stats.exact_p_lattice`), so under no effect
:math:`\widehat\pi` estimates that size, not :math:`\alpha/m` itself; when the smallest
attainable p exceeds :math:`\alpha/m` the power is 0 whatever the effect (column
``attainable``).

Noether's approximation gives a closed form for the Mann–Whitney test with equal
groups: with :math:`p = P(X > Y)`,

.. math::
    n_{\text{per group}} \approx
    \frac{(z_{1-\alpha/m} + z_{1-\beta})^2}{6\,(p - 1/2)^2},

and for a normal shift :math:`\delta` with common SD :math:`\sigma`,
:math:`p = \Phi(\delta / (\sigma\sqrt2))`.

References
----------
.. [1] G. E. Noether, "Sample size determination for some common nonparametric
   tests", J. Am. Stat. Assoc. 82:645–647, 1987. doi:10.1080/01621459.1987.10478478
.. [2] A. Gelman and J. Hill, *Data Analysis Using Regression and
   Multilevel/Hierarchical Models*, Cambridge University Press, 2007, ch. 20.
   doi:10.1017/CBO9780511790942
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats as _st

from .. import _validate
from .nonparametric import (
    _alternative,
    _mwu_counts_noties,
    _signed_rank_counts_noties,
    mann_whitney,
    wilcoxon_signed_rank,
)

__all__ = [
    "normal_shift",
    "observed_shift",
    "power_by_simulation",
    "animals_needed",
    "PowerResult",
    "noether_n_per_group",
    "normal_shift_superiority",
]

Simulator = Callable[[int, np.random.Generator], tuple[np.ndarray, np.ndarray]]
_TESTS = ("mann-whitney", "wilcoxon")


def normal_shift(shift: float, *, sd: float = 1.0) -> Simulator:
    r"""A simulator of two normal groups: ``x ~ N(shift, sd²)``, ``y ~ N(0, sd²)``.

    Parameters
    ----------
    shift : float
        Location difference :math:`\delta` (in the units of ``sd``).
    sd : float
        Common standard deviation.

    Returns
    -------
    callable
        ``simulate_groups(n, rng) -> (x, y)``, each of length ``n``. For the
        signed-rank test the pair ``(x, y)`` is read as (after, before) of ``n``
        subjects, whose differences are :math:`N(\delta, 2\sigma^2)`.
    """
    shift = _validate.finite(shift, "shift")
    sd = _validate.positive(sd, "sd")

    def simulate_groups(n: int, rng: np.random.Generator):
        return rng.normal(shift, sd, n), rng.normal(0.0, sd, n)

    return simulate_groups


def observed_shift(x, y, *, scale: float = 1.0) -> Simulator:
    r"""A simulator built from two observed groups: their spread, and their difference
    in medians scaled by ``scale``.

    Each simulated experiment resamples ``n`` animals with replacement from each
    group's residuals about its median (:math:`x_i - \tilde x`, :math:`y_j - \tilde
    y`) and adds the medians back, the first group's moved to :math:`\tilde y + s\,
    (\tilde x - \tilde y)`. ``scale = 1`` replays the observed effect, ``0`` none
    (the false-positive rate), ``0.5`` half of it: a location-shift model with the
    observed shapes, for planning the next study from a pilot.

    Parameters
    ----------
    x, y : array_like
        The two groups' values (NaN dropped); at least 2 each.
    scale : float
        Multiplier of the observed difference in medians.

    Returns
    -------
    callable
        ``simulate_groups(n, rng) -> (x, y)``, with ``attrs``-like attributes
        ``shift`` (the simulated difference in medians) on the function.

    Examples
    --------
    >>> import numpy as np
    >>> draw = observed_shift([3.0, 4.0, 5.0], [1.0, 2.0, 3.0], scale=0.5)
    >>> draw.shift
    1.0
    >>> x, y = draw(4, np.random.default_rng(0))
    >>> x.shape, y.shape
    ((4,), (4,))
    """
    xs = np.asarray(x, float).ravel()
    ys = np.asarray(y, float).ravel()
    xs, ys = xs[np.isfinite(xs)], ys[np.isfinite(ys)]
    if xs.size < 2 or ys.size < 2:
        raise ValueError(
            f"observed_shift needs at least 2 finite values per group, got "
            f"{xs.size} and {ys.size}"
        )
    scale = _validate.finite(scale, "scale")
    mx, my = float(np.median(xs)), float(np.median(ys))
    rx, ry = xs - mx, ys - my
    shift = scale * (mx - my)

    def simulate_groups(n: int, rng: np.random.Generator):
        return my + shift + rng.choice(rx, n), my + rng.choice(ry, n)

    simulate_groups.shift = shift  # type: ignore[attr-defined]
    return simulate_groups


def normal_shift_superiority(shift: float, sd: float = 1.0) -> float:
    r""":math:`P(X > Y) = \Phi(\delta/(\sigma\sqrt2))` for two normal groups.

    Parameters
    ----------
    shift : float
        Difference of the group means :math:`\delta` (units of the data).
    sd : float, default 1.0
        Common standard deviation :math:`\sigma` of both groups (same units), > 0.

    Returns
    -------
    float
        Probability of superiority :math:`P(X > Y)`, in (0, 1).
    """
    shift = _validate.finite(shift, "shift")
    sd = _validate.positive(sd, "sd")
    return float(_st.norm.cdf(shift / (sd * math.sqrt(2))))


def noether_n_per_group(
    p_superiority: float, *, alpha: float = 0.05, power: float = 0.8, family: int = 1
) -> int:
    r"""Noether's (1987) animals per group for a one-sided Mann–Whitney test.

    Parameters
    ----------
    p_superiority : float
        :math:`P(X > Y)` under the alternative (not 1/2).
    alpha : float
        Family-wise level; the test runs at :math:`\alpha/m`.
    power : float
        Target power.
    family : int
        Bonferroni family size :math:`m`.

    Returns
    -------
    int
        :math:`\lceil (z_{1-\alpha/m} + z_{\text{power}})^2 / (6 (p - 1/2)^2) \rceil`.
    """
    p = _validate.fraction(
        p_superiority, "p_superiority", open_low=True, open_high=True
    )
    if p == 0.5:
        raise ValueError(
            f"p_superiority must differ from 1/2 (no effect, no sample size), got "
            f"{p_superiority!r}"
        )
    a = _validate.fraction(alpha, "alpha", open_low=True, open_high=True)
    pw = _validate.fraction(power, "power", open_low=True, open_high=True)
    m = _validate.integer(family, "family", minimum=1)
    z = _st.norm.isf(a / m) + _st.norm.ppf(pw)
    return int(math.ceil(z * z / (6.0 * (p - 0.5) ** 2)))


def _min_p(test: str, n: int) -> float:
    if test == "mann-whitney":
        c = _mwu_counts_noties(n, n)
    else:
        c = _signed_rank_counts_noties(n)
    return float(c[-1] / c.sum())


def _one_power(simulate_groups, n, test, alternative, threshold, n_sim, rng, method):
    hits = 0
    for _ in range(n_sim):
        x, y = simulate_groups(n, rng)
        try:
            if test == "mann-whitney":
                p = mann_whitney(x, y, alternative=alternative, method=method).p
            else:
                p = wilcoxon_signed_rank(x, y, alternative=alternative, method=method).p
        except ValueError as exc:
            if "n too small" not in str(exc):
                raise
            p = 1.0  # e.g. every difference zero: no evidence
        hits += p <= threshold * (1 + 1e-12)
    return hits / n_sim


def _checked(alpha, family, n_sim, test, alternative):
    a = _validate.fraction(alpha, "alpha", open_low=True, open_high=True)
    m = _validate.integer(family, "family", minimum=1)
    b = _validate.integer(n_sim, "n_sim", minimum=1)
    if test not in _TESTS:
        raise ValueError(f"test must be one of {_TESTS}, got {test!r}")
    return a, m, b, _alternative(alternative)


def power_by_simulation(
    simulate_groups: Simulator,
    n_per_group: int | Sequence[int],
    *,
    alpha: float = 0.05,
    family: int = 1,
    n_sim: int = 1000,
    rng: int | np.random.Generator | None = None,
    test: str = "mann-whitney",
    alternative: str = "greater",
    method: str = "auto",
    target_power: float = 0.8,
) -> pd.DataFrame:
    r"""Power of a one-sided rank test after a Bonferroni family, by simulation.

    Parameters
    ----------
    simulate_groups : callable
        ``simulate_groups(n, rng) -> (x, y)``: one simulated experiment with ``n``
        animals per group (paired samples for ``test="wilcoxon"``).
    n_per_group : int or sequence of int
        Group size(s) to evaluate (at least 2).
    alpha : float
        Family-wise level.
    family : int
        Bonferroni family size :math:`m`; each test runs at :math:`\alpha/m`.
    n_sim : int
        Simulated experiments per group size.
    rng : int, numpy.random.Generator or None
        Seed or generator.
    test : {"mann-whitney", "wilcoxon"}
        The test applied to ``(x, y)``.
    alternative : {"greater", "less", "two-sided"}
        Its alternative.
    method : {"auto", "exact", "asymptotic"}
        Passed to the test.
    target_power : float
        Power defining ``attrs["n_needed"]``.

    Returns
    -------
    pandas.DataFrame
        One row per group size: ``n_per_group``, ``power``, ``mc_se``, ``threshold``
        (:math:`\alpha/m`), ``min_p`` (smallest attainable exact p without ties),
        ``attainable`` (``min_p <= threshold``), ``n_sim``. ``attrs["n_needed"]`` is
        the smallest evaluated size reaching ``target_power`` (None if none does).
    """
    a, m, b, alternative = _checked(alpha, family, n_sim, test, alternative)
    target = _validate.fraction(target_power, "target_power", open_low=True)
    ns = [n_per_group] if np.ndim(n_per_group) == 0 else list(n_per_group)
    if not ns:
        raise ValueError("n_per_group is empty")
    ns = [_validate.integer(n, "n_per_group", minimum=2) for n in ns]
    gen = np.random.default_rng(rng)
    rows = []
    for n in ns:
        pw = _one_power(simulate_groups, n, test, alternative, a / m, b, gen, method)
        min_p = _min_p(test, n)
        rows.append(
            {
                "n_per_group": n,
                "power": pw,
                "mc_se": math.sqrt(max(pw * (1 - pw), 1e-300) / b),
                "threshold": a / m,
                "min_p": min_p,
                "attainable": min_p <= a / m,
                "n_sim": b,
            }
        )
    out = pd.DataFrame(rows)
    ok = out.loc[out["power"] >= target, "n_per_group"]
    out.attrs.update(
        n_needed=int(ok.min()) if len(ok) else None,
        target_power=target,
        alpha=a,
        family=m,
        test=test,
        alternative=alternative,
    )
    return out


@dataclass(frozen=True)
class PowerResult:
    """Animals per group needed: ``n`` (None if not reached by ``n_max``), its
    simulated ``power`` and the ``table`` of every size evaluated.
    """

    n: int | None
    power: float
    table: pd.DataFrame


def animals_needed(
    simulate_groups: Simulator,
    *,
    target_power: float = 0.8,
    alpha: float = 0.05,
    family: int = 1,
    n_min: int = 2,
    n_max: int = 100,
    n_sim: int = 1000,
    rng: int | np.random.Generator | None = None,
    test: str = "mann-whitney",
    alternative: str = "greater",
    method: str = "auto",
) -> PowerResult:
    r"""Smallest group size whose simulated power reaches ``target_power``.

    Doubles :math:`n` from ``n_min`` until the power reaches the target (or
    ``n_max``), then bisects between the last failing and the first passing size.
    Parameters are those of :func:`power_by_simulation`.

    Returns
    -------
    PowerResult
    """
    a, m, b, alternative = _checked(alpha, family, n_sim, test, alternative)
    target = _validate.fraction(target_power, "target_power", open_low=True)
    lo = _validate.integer(n_min, "n_min", minimum=2)
    hi_max = _validate.integer(n_max, "n_max", minimum=lo)
    gen = np.random.default_rng(rng)
    seen: dict[int, float] = {}

    def power(n: int) -> float:
        if n not in seen:
            seen[n] = _one_power(
                simulate_groups, n, test, alternative, a / m, b, gen, method
            )
        return seen[n]

    n, fail = lo, lo - 1
    while power(n) < target:
        if n >= hi_max:
            n = None
            break
        fail, n = n, min(2 * n, hi_max)
    if n is not None:
        while n - fail > 1:
            mid = (n + fail) // 2
            if power(mid) >= target:
                n = mid
            else:
                fail = mid
    table = pd.DataFrame(
        {"n_per_group": sorted(seen), "power": [seen[k] for k in sorted(seen)]}
    )
    table["mc_se"] = np.sqrt(table["power"] * (1 - table["power"]) / b)
    return PowerResult(n, seen[n] if n is not None else float("nan"), table)
