r"""Effect sizes with confidence intervals.

Rank-biserial correlation, probability of superiority and the Hodges–Lehmann shift with its exact distribution-free interval.

Two samples
-----------
With :math:`U_x = \#\{x_i > y_j\} + \frac12 \#\{x_i = y_j\}`,

.. math::
    \hat p = P(X > Y) + \tfrac12 P(X = Y) \approx \frac{U_x}{mn}, \qquad
    r_{rb} = 2\hat p - 1 = \frac{U_x - U_y}{mn},

(Wendt 1972; ``pingouin.mwu``'s ``RBC``, positive when ``x`` tends to be larger). The
confidence interval of :math:`\hat p` is the Brunner–Munzel interval of
``statsmodels.stats.nonparametric.rank_compare_2indep`` (t distribution with
Welch–Satterthwaite degrees of freedom), clipped to [0, 1] and mapped to
:math:`r_{rb}` by :math:`2p - 1`. It is undefined (NaN) under complete separation,
where the Brunner–Munzel variance estimate is 0.

The Hodges–Lehmann shift is the median of the :math:`mn` differences
:math:`D_{(1)} \le \dots \le D_{(mn)}` of :math:`x_i - y_j`. Its exact
:math:`1-\alpha` interval (Hollander, Wolfe & Chicken §4.3; Bauer 1972) inverts the
rank-sum test: with :math:`q` the smallest integer such that
:math:`P_0(U \le q) \ge \alpha/2` under the exact null distribution of :math:`U`
(R's ``qwilcox``; :math:`q \ge 1`),

.. math::
    [\,D_{(q)},\ D_{(mn - q + 1)}\,], \qquad
    \text{achieved level } 1 - 2 P_0(U \le q - 1).

One sample / paired
-------------------
For differences :math:`d_1..d_n`, the :math:`M = n(n+1)/2` Walsh averages
:math:`W_{(1)} \le \dots \le W_{(M)}` of :math:`(d_i + d_j)/2, i \le j`, give the
pseudo-median :math:`\operatorname{median}(W)` and, with :math:`q` the smallest integer
such that :math:`P_0(T^+ \le q) \ge \alpha/2` (R's ``qsignrank``), the interval
:math:`[W_{(q)}, W_{(M - q + 1)}]` (HWC §3.3). One-sided intervals use :math:`\alpha`
in place of :math:`\alpha/2` and one end only. These are R's
``wilcox.test(conf.int = TRUE)`` exact intervals; R switches to a normal
approximation when there are ties or zeros, whereas here the order-statistic interval
is kept (the test-inversion of the exact test for continuous data).

Checked against published worked examples: Hollander, Wolfe & Chicken's Hamilton
depression-scale data (n = 9) give the printed pseudo-median −0.46 and 96.1 % interval
(−0.786, −0.010). On SAS's NPAR1WAY Hodges–Lehmann example (heavily tied reaction
times) the shift 0.35 agrees; the interval (0.00, 0.82) equals the shifts accepted by
the exact conditional (tie-aware) rank-sum test, whereas SAS's "exact" limits
(0.00, 1.33) take one order statistic further out on each side.

The matched-pairs rank-biserial correlation is :math:`(T^+ - T^-)/(T^+ + T^-)`
(Kerby 2014; ``pingouin.wilcoxon``'s ``RBC`` for ``alternative != "less"``), and the
paired probability of superiority is :math:`P(D > 0) + \frac12 P(D = 0)` with a Wilson
score interval.

References
----------
.. [1] J. L. Hodges and E. L. Lehmann, "Estimates of location based on rank tests",
   Ann. Math. Statist. 34:598–611, 1963. doi:10.1214/aoms/1177704172
.. [2] D. F. Bauer, "Constructing confidence sets using rank statistics", J. Am. Stat.
   Assoc. 67:687–690, 1972. doi:10.1080/01621459.1972.10481279
.. [3] M. Hollander, D. A. Wolfe and E. Chicken, *Nonparametric Statistical Methods*,
   3rd ed., Wiley, 2014, §3.3 and §4.3. doi:10.1002/9781119196037
.. [4] E. Brunner and U. Munzel, "The nonparametric Behrens–Fisher problem", Biom. J.
   42:17–25, 2000. doi:10.1002/(SICI)1521-4036(200001)42:1<17::AID-BIMJ17>3.0.CO;2-U
.. [5] H. W. Wendt, "Dealing with a common problem in social science: a simplified
   rank-biserial coefficient of correlation based on the U statistic", Eur. J. Soc.
   Psychol. 2:463–465, 1972. doi:10.1002/ejsp.2420020412
.. [6] D. S. Kerby, "The simple difference formula: an approach to teaching
   nonparametric correlation", Compr. Psychol. 3:11.IT.3.1, 2014.
   doi:10.2466/11.IT.3.1
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats as _st
from statsmodels.stats.nonparametric import rank_compare_2indep

from .. import _validate
from .nonparametric import (
    ZERO_METHODS,
    _alternative,
    _mwu_counts_noties,
    _sample,
    _signed_rank_counts_noties,
)

__all__ = [
    "Interval",
    "hodges_lehmann",
    "prob_superiority",
    "rank_biserial",
    "paired_rank_biserial",
    "paired_prob_superiority",
]


@dataclass(frozen=True)
class Interval:
    """An estimate with its confidence interval.

    Attributes
    ----------
    estimate, low, high : float
        Point estimate and interval ends (``-inf`` / ``inf`` for one-sided intervals,
        NaN where undefined).
    conf_level : float
        Requested level.
    achieved : float
        Achieved level of an exact interval (NaN where not applicable).
    """

    estimate: float
    low: float
    high: float
    conf_level: float
    achieved: float = float("nan")


def _q_lower(counts: np.ndarray, a: float) -> int:
    """Smallest q with P(S <= q) >= a (R's qwilcox / qsignrank), at least 1."""
    cdf = np.cumsum(counts) / counts.sum()
    q = int(np.searchsorted(cdf, a * (1 - 1e-12), side="left"))
    return max(q, 1)


def _order_interval(values: np.ndarray, counts: np.ndarray, conf_level, alternative):
    """Exact interval from sorted ``values`` and the null ``counts`` of the statistic."""
    alpha = 1.0 - conf_level
    m = values.size
    cdf = np.cumsum(counts) / counts.sum()
    two = alternative == "two-sided"
    q = _q_lower(counts, alpha / 2 if two else alpha)
    q = min(q, (m + 1) // 2)
    reject = cdf[q - 1] if q - 1 < cdf.size else 1.0  # P(S <= q - 1)
    low, high = values[q - 1], values[m - q]
    if alternative == "greater":
        return low, np.inf, 1.0 - reject
    if alternative == "less":
        return -np.inf, high, 1.0 - reject
    return low, high, 1.0 - 2.0 * reject


def _conf(conf_level) -> float:
    return _validate.fraction(conf_level, "conf_level", open_low=True, open_high=True)


def hodges_lehmann(
    x,
    y=None,
    *,
    paired: bool = False,
    conf_level: float = 0.95,
    alternative: str = "two-sided",
) -> Interval:
    r"""Hodges–Lehmann shift (two samples) or pseudo-median (paired / one sample).

    Parameters
    ----------
    x : array_like
        First sample, or the differences when ``y`` is None.
    y : array_like, optional
        Second sample (independent, or paired with ``x`` when ``paired``).
    paired : bool
        Use the differences ``x - y`` and the signed-rank (Walsh average) interval.
    conf_level : float
        Confidence level in (0, 1).
    alternative : {"two-sided", "greater", "less"}
        ``"greater"`` gives :math:`[L, \infty)`, ``"less"`` :math:`(-\infty, U]`.

    Returns
    -------
    Interval
        ``estimate`` = median of the pairwise differences (or Walsh averages), the
        exact distribution-free interval and its achieved level.

    Notes
    -----
    See the module docstring. When the requested level is not attainable (tiny
    samples), the widest interval :math:`[D_{(1)}, D_{(mn)}]` is returned and
    ``achieved`` is below ``conf_level`` (R warns "requested conf.level not
    achievable").

    References
    ----------
    Hollander, Wolfe & Chicken (2014) §3.3, §4.3; Bauer (1972)
    doi:10.1080/01621459.1972.10481279.
    """
    conf_level = _conf(conf_level)
    alternative = _alternative(alternative)
    a = _sample(x, "x")
    if y is None:
        d, two_sample = a, False
    else:
        b = _sample(y, "y")
        if paired:
            if a.size != b.size:
                raise ValueError(
                    f"x and y must be paired (same length), got {a.size} and {b.size}"
                )
            d, two_sample = a - b, False
        else:
            two_sample = True
    if two_sample:
        values = np.sort((a[:, None] - b[None, :]).ravel())
        counts = _mwu_counts_noties(a.size, b.size)
    else:
        n = d.size
        i, j = np.triu_indices(n)
        values = np.sort((d[i] + d[j]) / 2.0)
        counts = _signed_rank_counts_noties(n)
    low, high, achieved = _order_interval(values, counts, conf_level, alternative)
    return Interval(
        float(np.median(values)), float(low), float(high), conf_level, achieved
    )


def prob_superiority(x, y, *, conf_level: float = 0.95) -> Interval:
    r"""Probability of superiority :math:`P(X > Y) + \frac12 P(X = Y)` with its CI.

    Uses ``statsmodels.stats.nonparametric.rank_compare_2indep(x, y)`` (Brunner–Munzel
    variance, t-based interval), clipped to [0, 1]; NaN ends under complete
    separation (zero variance estimate).

    Parameters
    ----------
    x, y : array_like
        Independent samples.
    conf_level : float
        Confidence level.

    Returns
    -------
    Interval
    """
    conf_level = _conf(conf_level)
    a = _sample(x, "x")
    b = _sample(y, "y")
    diff = a[:, None] - b[None, :]
    est = float(np.mean((diff > 0) + 0.5 * (diff == 0)))
    low = high = np.nan
    if a.size >= 2 and b.size >= 2:
        with np.errstate(all="ignore"):
            res = rank_compare_2indep(a, b)
            lo, hi = res.conf_int(alpha=1.0 - conf_level)
        if np.isfinite(lo) and np.isfinite(hi) and hi > lo:
            low, high = float(np.clip(lo, 0, 1)), float(np.clip(hi, 0, 1))
    return Interval(est, low, high, conf_level)


def rank_biserial(x, y, *, conf_level: float = 0.95) -> Interval:
    r"""Rank-biserial correlation :math:`r_{rb} = 2\hat p - 1 = (U_x - U_y)/(mn)`.

    Same sign convention as ``pingouin.mwu``'s ``RBC`` (positive when ``x`` tends to
    be larger); the interval is :math:`2\,[p_L, p_U] - 1` from
    :func:`prob_superiority`.

    Parameters
    ----------
    x, y : array_like
        Independent samples.
    conf_level : float, default 0.95
        Confidence level of the interval, in (0, 1).

    Returns
    -------
    Interval
        Estimate and interval ends, in [-1, 1].
    """
    ps = prob_superiority(x, y, conf_level=conf_level)
    return Interval(2 * ps.estimate - 1, 2 * ps.low - 1, 2 * ps.high - 1, ps.conf_level)


def _signed_ranks(d: np.ndarray, zero_method: str):
    zero = d == 0
    if zero_method == "pratt":
        r = _st.rankdata(np.abs(d))[~zero]
    else:
        r = _st.rankdata(np.abs(d[~zero]))
    return r, d[~zero]


def paired_rank_biserial(x, y=None, *, zero_method: str = "wilcox") -> float:
    r"""Matched-pairs rank-biserial correlation :math:`(T^+ - T^-)/(T^+ + T^-)`.

    Positive when ``x - y`` tends to be positive; equals ``pingouin.wilcoxon``'s
    ``RBC`` for ``alternative="greater"`` or ``"two-sided"`` (pingouin flips its sign
    for ``"less"``). NaN when every difference is zero.

    Parameters
    ----------
    x : array_like (n,)
        Values, or the paired differences themselves when ``y`` is None.
    y : array_like (n,), optional
        Paired values, same length as ``x``; the differences are ``x - y``.
    zero_method : {"wilcox", "pratt"}, default "wilcox"
        Zero differences: ``"wilcox"`` drops them before ranking; ``"pratt"`` ranks them
        with the others and then drops them.

    Returns
    -------
    float
        Correlation in [-1, 1]; NaN when every difference is zero.

    Raises
    ------
    ValueError
        If ``zero_method`` is not one of ``"wilcox"``, ``"pratt"``.
    """
    if zero_method not in ZERO_METHODS:
        raise ValueError(
            f"zero_method must be one of {ZERO_METHODS}, got {zero_method!r}"
        )
    d = _sample(x, "x")
    if y is not None:
        d = d - _sample(y, "y")
    r, dn = _signed_ranks(d, zero_method)
    total = r.sum()
    if total == 0:
        return float("nan")
    return float((r[dn > 0].sum() - r[dn < 0].sum()) / total)


def paired_prob_superiority(x, y=None, *, conf_level: float = 0.95) -> Interval:
    r"""Paired probability of superiority :math:`P(D > 0) + \frac12 P(D = 0)`.

    The interval is Wilson's score interval for a proportion :math:`\hat p` out of
    :math:`n` pairs,
    :math:`\big(\hat p + \frac{z^2}{2n} \pm z\sqrt{\hat p(1-\hat p)/n + z^2/4n^2}\big)
    / (1 + z^2/n)`.

    Parameters
    ----------
    x : array_like (n,)
        Values, or the paired differences :math:`D` themselves when ``y`` is None.
    y : array_like (n,), optional
        Paired values, same length as ``x``; :math:`D = x - y`.
    conf_level : float, default 0.95
        Confidence level of the Wilson interval, in (0, 1).

    Returns
    -------
    Interval
        Estimate :math:`\hat p` and interval ends, clipped to [0, 1].

    References
    ----------
    E. B. Wilson, J. Am. Stat. Assoc. 22:209–212, 1927. doi:10.2307/2276774
    """
    conf_level = _conf(conf_level)
    d = _sample(x, "x")
    if y is not None:
        d = d - _sample(y, "y")
    n = d.size
    p = float(np.mean((d > 0) + 0.5 * (d == 0)))
    z = float(_st.norm.isf((1 - conf_level) / 2))
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return Interval(p, max(0.0, centre - half), min(1.0, centre + half), conf_level)
