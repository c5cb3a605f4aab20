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
from .._labels import label_columns
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
    r"""Make a simulator of two normal groups: ``x ~ N(shift, sd²)``, ``y ~ N(0, sd²)``.

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
    r"""Make a simulator from two observed groups.

    It keeps their spread, and their difference in medians scaled by ``scale``.

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


@dataclass(frozen=True)
class _Setup:
    """One simulated study design: the test, its level after the family, and B."""

    test: str
    alternative: str
    threshold: float
    n_sim: int
    method: str

    def power(self, simulate_groups: Simulator, n: int, rng) -> float:
        """Return the rejection rate over ``n_sim`` experiments of ``n`` animals."""
        hits = 0
        test = mann_whitney if self.test == "mann-whitney" else wilcoxon_signed_rank
        for _ in range(self.n_sim):
            x, y = simulate_groups(n, rng)
            try:
                p = test(x, y, alternative=self.alternative, method=self.method).p
            except ValueError as exc:
                if "n too small" not in str(exc):
                    raise
                p = 1.0  # e.g. every difference zero: no evidence
            hits += p <= self.threshold * (1 + 1e-12)
        return hits / self.n_sim


#: The simulation options shared by :func:`power_by_simulation` and
#: :func:`animals_needed`, with their defaults.
SIMULATION_OPTIONS = {
    "alpha": 0.05,
    "family": 1,
    "n_sim": 1000,
    "rng": None,
    "test": "mann-whitney",
    "alternative": "greater",
    "method": "auto",
}


def _setup(options: dict, target_power) -> tuple[_Setup, float, int, float]:
    """Check the simulation options; return the setup, alpha, m and the target."""
    unknown = sorted(set(options) - set(SIMULATION_OPTIONS))
    if unknown:
        raise TypeError(
            f"unknown option(s) {unknown}; the options are {list(SIMULATION_OPTIONS)}"
        )
    o = {**SIMULATION_OPTIONS, **options}
    a = _validate.fraction(o["alpha"], "alpha", open_low=True, open_high=True)
    m = _validate.integer(o["family"], "family", minimum=1)
    b = _validate.integer(o["n_sim"], "n_sim", minimum=1)
    if o["test"] not in _TESTS:
        raise ValueError(f"test must be one of {_TESTS}, got {o['test']!r}")
    alternative = _alternative(o["alternative"])
    target = _validate.fraction(target_power, "target_power", open_low=True)
    return _Setup(o["test"], alternative, a / m, b, o["method"]), a, m, target


_POWER_LABELS = {
    "n_per_group": ("animals per group", "1"),
    "power": ("power", "1"),
    "mc_se": ("Monte Carlo standard error of the power", "1"),
    "threshold": ("level of each test α/m", "1"),
    "min_p": ("smallest attainable exact p", "1"),
    "attainable": ("α/m attainable", ""),
    "n_sim": ("simulated experiments", "1"),
}


def _power_table(rows) -> pd.DataFrame:
    table = pd.DataFrame(rows)
    return label_columns(
        table,
        units={c: _POWER_LABELS[c][1] for c in table.columns},
        long_name={c: _POWER_LABELS[c][0] for c in table.columns},
        role={c: "p-value" for c in ("threshold", "min_p") if c in table.columns},
    )


def power_by_simulation(
    simulate_groups: Simulator,
    n_per_group: int | Sequence[int],
    *,
    target_power: float = 0.8,
    **options,
) -> pd.DataFrame:
    r"""Estimate the power of a one-sided rank test after a Bonferroni family.

    Parameters
    ----------
    simulate_groups : callable
        ``simulate_groups(n, rng) -> (x, y)``: one simulated experiment with ``n``
        animals per group (paired samples for ``test="wilcoxon"``).
    n_per_group : int or sequence of int
        Group size(s) to evaluate (at least 2).
    target_power : float
        Power defining ``attrs["n_needed"]``.
    **options
        The simulation options (defaults in :data:`SIMULATION_OPTIONS`):
        ``alpha`` (family-wise level, 0.05), ``family`` (Bonferroni family size
        :math:`m`, 1; each test runs at :math:`\alpha/m`), ``n_sim`` (simulated
        experiments per group size, 1000), ``rng`` (seed or generator), ``test``
        (``"mann-whitney"`` or ``"wilcoxon"``, applied to ``(x, y)``),
        ``alternative`` (``"greater"``, ``"less"`` or ``"two-sided"``) and
        ``method`` (``"auto"``, ``"exact"`` or ``"asymptotic"``, passed to the test).

    Returns
    -------
    pandas.DataFrame
        One row per group size: ``n_per_group``, ``power``, ``mc_se``, ``threshold``
        (:math:`\alpha/m`), ``min_p`` (smallest attainable exact p without ties),
        ``attainable`` (``min_p <= threshold``), ``n_sim``, labelled
        (``attrs["units"]``, ``attrs["long_name"]``). ``attrs["n_needed"]`` is the
        smallest evaluated size reaching ``target_power`` (None if none does).

    Raises
    ------
    TypeError
        An unknown option.
    """
    setup, a, m, target = _setup(options, target_power)
    ns = [n_per_group] if np.ndim(n_per_group) == 0 else list(n_per_group)
    if not ns:
        raise ValueError("n_per_group is empty")
    ns = [_validate.integer(n, "n_per_group", minimum=2) for n in ns]
    gen = np.random.default_rng(options.get("rng"))
    rows = []
    for n in ns:
        pw = setup.power(simulate_groups, n, gen)
        min_p = _min_p(setup.test, n)
        rows.append(
            {
                "n_per_group": n,
                "power": pw,
                "mc_se": math.sqrt(max(pw * (1 - pw), 1e-300) / setup.n_sim),
                "threshold": setup.threshold,
                "min_p": min_p,
                "attainable": min_p <= setup.threshold,
                "n_sim": setup.n_sim,
            }
        )
    out = _power_table(rows)
    ok = out.loc[out["power"] >= target, "n_per_group"]
    out.attrs.update(
        n_needed=int(ok.min()) if len(ok) else None,
        target_power=target,
        alpha=a,
        family=m,
        test=setup.test,
        alternative=setup.alternative,
    )
    return out


@dataclass(frozen=True)
class PowerResult:
    """Animals per group needed (made by :func:`animals_needed`).

    Attributes
    ----------
    n : int or None
        Animals per group needed; None if not reached by ``n_max``.
    power : float
        Its simulated power.
    table : pandas.DataFrame
        Every size evaluated: ``n_per_group``, ``power``, ``mc_se`` (labelled).
    """

    n: int | None
    power: float
    table: pd.DataFrame


def animals_needed(
    simulate_groups: Simulator,
    *,
    target_power: float = 0.8,
    n_min: int = 2,
    n_max: int = 100,
    **options,
) -> PowerResult:
    r"""Find the smallest group size whose simulated power reaches ``target_power``.

    Doubles :math:`n` from ``n_min`` until the power reaches the target (or
    ``n_max``), then bisects between the last failing and the first passing size.

    Parameters
    ----------
    simulate_groups : callable
        ``simulate_groups(n, rng) -> (x, y)``, as for :func:`power_by_simulation`.
    target_power : float
        The power to reach.
    n_min, n_max : int
        Smallest and largest group sizes tried.
    **options
        The simulation options of :func:`power_by_simulation` (``alpha``, ``family``,
        ``n_sim``, ``rng``, ``test``, ``alternative``, ``method``).

    Returns
    -------
    PowerResult
        The size needed, its power, and the table of every size evaluated.

    Raises
    ------
    TypeError
        An unknown option.
    """
    setup, _, _, target = _setup(options, target_power)
    lo = _validate.integer(n_min, "n_min", minimum=2)
    hi_max = _validate.integer(n_max, "n_max", minimum=lo)
    gen = np.random.default_rng(options.get("rng"))
    seen: dict[int, float] = {}

    def power(n: int) -> float:
        if n not in seen:
            seen[n] = setup.power(simulate_groups, n, gen)
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
    sizes = sorted(seen)
    pw = np.array([seen[k] for k in sizes])
    table = _power_table(
        {
            "n_per_group": sizes,
            "power": pw,
            "mc_se": np.sqrt(pw * (1 - pw) / setup.n_sim),
        }
    )
    return PowerResult(n, seen[n] if n is not None else float("nan"), table)
