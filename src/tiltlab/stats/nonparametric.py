r"""Rank tests: Mann–Whitney U (two groups) and Wilcoxon signed rank (paired / one sample).

One implementation of each, with the method used (exact, exact conditional, asymptotic)
chosen from the data and recorded in the result.

Exact null distributions
------------------------
Both tests are permutation tests on ranks. Let :math:`r_1,\dots,r_N` be the mid-ranks of
the pooled data (ties share the mean of their ranks), so :math:`w_i = 2 r_i` are
integers. Under :math:`H_0` (exchangeability) every subset :math:`S` of size
:math:`n_1` is equally likely to be the first sample, and the rank sum
:math:`W = \sum_{i\in S} r_i` has the conditional distribution

.. math::
    P(W = s) = \frac{c_{n_1}(2s)}{\binom{N}{n_1}}, \qquad
    c_k(t) = \#\{S : |S| = k,\ \textstyle\sum_{i\in S} w_i = t\},

computed by the subset-sum recursion :math:`c^{(j)}_k(t) = c^{(j-1)}_k(t) +
c^{(j-1)}_{k-1}(t - w_j)` over the observations :math:`j`. Without ties this is the
classical Mann–Whitney distribution (:math:`U = W - n_1(n_1+1)/2`); with ties it is the
*exact conditional* distribution given the tie pattern — what
``scipy.stats.mannwhitneyu(method=PermutationMethod(n_resamples=np.inf))`` computes by
enumerating all :math:`\binom{N}{n_1}` splits, in :math:`O(N n_1 \sum w)` operations.

For the signed-rank test every sign vector of the non-zero differences is equally
likely (:math:`2^{n}` configurations) and :math:`T^+ = \sum_{d_i > 0} r_i` has
:math:`P(T^+ = s) = c(2s) / 2^n` with :math:`c^{(j)}(t) = c^{(j-1)}(t) +
c^{(j-1)}(t - w_j)`.

Exact range
-----------
The counts are float64 numbers and the recursion fills an array of
:math:`(n_1 + 1) \times (\sum w + 1)` cells (Mann–Whitney) or :math:`\sum w + 1`
cells (signed rank). The exact method is used only where both stay sound: at most
:data:`EXACT_MAX_PAIRS` (1000) non-zero differences for the signed-rank test (the
:math:`2^n` sign vectors overflow float64 beyond :math:`n = 1023`, which made the
p-value NaN), and at most :data:`EXACT_MAX_CELLS` (2·10⁷) cells for Mann–Whitney
(computed for the smaller group; :math:`\binom{N}{n_1}` then never overflows). Beyond
that range — also when ``method="exact"`` was asked for — the asymptotic p-value is
returned: ``method`` says ``"asymptotic-cc"`` (or ``"asymptotic"``) and ``note`` says
why (with a :class:`RuntimeWarning` when the exact method was requested explicitly).

Asymptotic p-values (large groups) use the tie-corrected normal approximation with a
continuity correction of 1/2:

.. math::
    z = \frac{U - n_1 n_2/2 \mp 1/2}{\sigma_U},\qquad
    \sigma_U^2 = \frac{n_1 n_2}{12}\Big(N + 1 - \frac{\sum_g (t_g^3 - t_g)}{N(N-1)}\Big),

and for :math:`T^+`, :math:`\mu = n(n+1)/4`, :math:`\sigma^2 = n(n+1)(2n+1)/24 -
\sum_g (t_g^3 - t_g)/48` (:math:`t_g`: sizes of the tie groups).

The paper's practice (``method="paper"``)
-----------------------------------------
Fayat et al.'s tables mix exact and asymptotic p-values: where the two samples have
no ties their values sit on the exact lattice :math:`k/\binom{N}{n_1}`, but two cells
of their Table A3 (ShamArsanilate vs Healthy, 16.592 at 1 d and 13.204 at 7 d) sit on
no exact lattice of groups of at most 5 and 11 animals — with or without ties, every
permutation p-value is a multiple of :math:`1/\binom{N}{n_1}`; they would need more
animals than the paper allocated — and equal the tie-corrected, continuity-corrected
normal approximation with one tied pair across the groups. That is the rule of ``scipy.stats.mannwhitneyu(method="auto")`` (exact when one
sample has at most 8 values and there are no ties, asymptotic otherwise).
``method="paper"`` reproduces it per test: exact when there are no ties (and, for the
signed-rank test, no zero differences) within the ``exact_max_n`` rule of ``"auto"``,
the tie-corrected normal approximation otherwise; ``TestResult.method`` records which
one each test used. (``scipy.stats.wilcoxon``'s normal approximation has no continuity
correction by default: ``continuity=False`` matches it.)

References
----------
.. [1] H. B. Mann and D. R. Whitney, "On a test of whether one of two random variables
   is stochastically larger than the other", Ann. Math. Statist. 18:50–60, 1947.
   doi:10.1214/aoms/1177730491
.. [2] F. Wilcoxon, "Individual comparisons by ranking methods", Biometrics Bull.
   1:80–83, 1945. doi:10.2307/3001968
.. [3] M. Hollander, D. A. Wolfe and E. Chicken, *Nonparametric Statistical Methods*,
   3rd ed., Wiley, 2014, §3.1 and §4.1. doi:10.1002/9781119196037
.. [4] J. W. Pratt, "Remarks on zeros and ties in the Wilcoxon signed rank procedures",
   J. Am. Stat. Assoc. 54:655–667, 1959. doi:10.1080/01621459.1959.10501526
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import lru_cache
from math import comb

import numpy as np
import pandas as pd
from scipy import stats as _st

from .._stack import user_stacklevel
from .. import _validate
from .._labels import label_columns

__all__ = [
    "ALTERNATIVES",
    "ZERO_METHODS",
    "EXACT_MAX_PAIRS",
    "EXACT_MAX_CELLS",
    "TestResult",
    "mann_whitney",
    "wilcoxon_signed_rank",
    "mwu_null_distribution",
    "signed_rank_null_distribution",
    "exact_p_lattice",
    "signed_rank_p_lattice",
]

#: Alternatives accepted everywhere (scipy / pingouin names).
ALTERNATIVES = ("greater", "less", "two-sided")
#: Zero-difference rules of the signed-rank test.
ZERO_METHODS = ("wilcox", "pratt")
_METHODS = ("auto", "exact", "asymptotic", "paper")
#: Most non-zero differences of an exact signed-rank test (2^n must fit a float64).
EXACT_MAX_PAIRS = 1000
#: Most cells of the subset-sum array of an exact Mann–Whitney test (160 MB).
EXACT_MAX_CELLS = 20_000_000


@dataclass(frozen=True)
class TestResult:
    """One rank test.

    Attributes
    ----------
    test : str
        ``"mann-whitney"`` or ``"wilcoxon"``.
    statistic : float
        :math:`U` of the first sample (ties count 1/2) or :math:`T^+`.
    p : float
        p-value for ``alternative``.
    alternative : str
        ``"greater"``: the first sample (or the difference) tends to be larger.
    method : str
        ``"exact"``, ``"exact-conditional"`` (ties or zeros, all permutations) or
        ``"asymptotic-cc"`` (normal, tie- and continuity-corrected).
    n1, n2 : int
        Sample sizes (for the signed-rank test both are the number of pairs).
    ties : bool
        Whether the ranks had ties.
    n_zero : int
        Zero differences (signed-rank test; 0 for Mann–Whitney).
    zero_method : str
        The zero rule of the signed-rank test (``""`` for Mann–Whitney).
    note : str
        Why the method differs from the one asked for (an exact test beyond the exact
        range, see the module docstring); ``""`` otherwise.
    """

    __test__ = False  # not a pytest class

    test: str
    statistic: float
    p: float
    alternative: str
    method: str
    n1: int
    n2: int
    ties: bool
    n_zero: int = 0
    zero_method: str = ""
    note: str = ""


# ------------------------------------------------------------------ argument checks


def _alternative(alternative, name: str = "alternative") -> str:
    if alternative not in ALTERNATIVES:
        raise ValueError(f"{name} must be one of {ALTERNATIVES}, got {alternative!r}")
    return alternative


def _sample(x, name: str) -> np.ndarray:
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an array of numbers, got {x!r}") from None
    if a.ndim != 1:
        a = a.reshape(-1) if a.ndim == 0 else a
        if a.ndim != 1:
            raise ValueError(f"{name} must be one-dimensional, got shape {a.shape}")
    if a.size == 0:
        raise ValueError(f"{name} is empty")
    bad = ~np.isfinite(a)
    if bad.any():
        raise ValueError(
            f"{name} contains {int(bad.sum())} NaN or infinite value(s) at positions "
            f"{np.flatnonzero(bad)[:5].tolist()}; drop missing values first"
        )
    return a


def _method(method) -> str:
    if method not in _METHODS:
        raise ValueError(f"method must be one of {_METHODS}, got {method!r}")
    return method


# ------------------------------------------------------------------ exact machinery


def _subset_sum_counts(weights: np.ndarray, k: int) -> np.ndarray:
    """``c[t]``: number of ``k``-subsets of the integer ``weights`` summing to ``t``."""
    w = np.asarray(weights, dtype=np.int64)
    top = int(np.sort(w)[::-1][:k].sum())
    dp = np.zeros((k + 1, top + 1))
    dp[0, 0] = 1.0
    for j, wj in enumerate(w):
        hi = min(j + 1, k)  # rows that can be reached after j + 1 elements
        if wj == 0:
            dp[1 : hi + 1] = dp[1 : hi + 1] + dp[:hi]
        else:
            dp[1 : hi + 1, wj:] = dp[1 : hi + 1, wj:] + dp[:hi, : top + 1 - wj]
    return dp[k]


def _sign_flip_counts(weights: np.ndarray) -> np.ndarray:
    """``c[t]``: number of sign vectors whose positive ``weights`` sum to ``t``."""
    w = np.asarray(weights, dtype=np.int64)
    dp = np.zeros(int(w.sum()) + 1)
    dp[0] = 1.0
    for wj in w:
        dp[wj:] = dp[wj:] + dp[: dp.size - wj]
    return dp


@lru_cache(maxsize=256)
def _mwu_counts_noties(n1: int, n2: int) -> np.ndarray:
    """Count the ``U = 0 .. n1 n2`` without ties (cached)."""
    c = _subset_sum_counts(np.arange(1, n1 + n2 + 1), n1)
    return np.ascontiguousarray(c[n1 * (n1 + 1) // 2 :])


@lru_cache(maxsize=256)
def _signed_rank_counts_noties(n: int) -> np.ndarray:
    """Count the ``T+ = 0 .. n(n+1)/2`` without ties (cached)."""
    return _sign_flip_counts(np.arange(1, n + 1))


def mwu_null_distribution(n1: int, n2: int) -> np.ndarray:
    r"""Exact null probabilities :math:`P(U = u)`, :math:`u = 0,\dots,n_1 n_2` (no ties).

    Parameters
    ----------
    n1, n2 : int
        Group sizes (at least 1).

    Returns
    -------
    numpy.ndarray
        Probabilities, summing to 1.

    Raises
    ------
    ValueError
        Group sizes beyond the exact range (:data:`EXACT_MAX_CELLS`; the distribution
        is counted for the smaller group, as it is the same for both).
    """
    n1 = _validate.integer(n1, "n1", minimum=1)
    n2 = _validate.integer(n2, "n2", minimum=1)
    ranks = np.arange(1, n1 + n2 + 1)
    if _mwu_cells(ranks, n1) <= EXACT_MAX_CELLS:
        c = _mwu_counts_noties(n1, n2)
    elif _mwu_cells(ranks, n2) <= EXACT_MAX_CELLS:
        c = _mwu_counts_noties(n2, n1)  # P(U = u) is symmetric in n1, n2
    else:
        raise ValueError(
            f"mwu_null_distribution: n1 = {n1} and n2 = {n2} are beyond the exact "
            f"range (more than EXACT_MAX_CELLS = {EXACT_MAX_CELLS:.3g} cells); use the "
            "normal approximation"
        )
    return c / c.sum()


def signed_rank_null_distribution(n: int) -> np.ndarray:
    r"""Exact null probabilities :math:`P(T^+ = t)`, :math:`t = 0,\dots,n(n+1)/2`.

    Parameters
    ----------
    n : int
        Number of non-zero differences (no ties), at least 1.

    Returns
    -------
    numpy.ndarray (n(n+1)/2 + 1,)
        :math:`P(T^+ = t)` for :math:`t = 0, 1, \dots, n(n+1)/2`; sums to 1.

    Raises
    ------
    ValueError
        ``n`` above :data:`EXACT_MAX_PAIRS` (the :math:`2^n` sign vectors overflow
        float64).
    """
    n = _validate.integer(n, "n", minimum=1)
    if n > EXACT_MAX_PAIRS:
        raise ValueError(
            f"signed_rank_null_distribution: n = {n} is beyond the exact range "
            f"(EXACT_MAX_PAIRS = {EXACT_MAX_PAIRS}: the 2^{n} sign vectors overflow "
            "float64); use the normal approximation"
        )
    c = _signed_rank_counts_noties(n)
    return c / c.sum()


def _tail_p(counts: np.ndarray, obs: int, alternative: str) -> float:
    """Exact p of an observed (integer-indexed) statistic from null ``counts``."""
    total = counts.sum()
    upper = counts[obs:].sum() / total
    lower = counts[: obs + 1].sum() / total
    if alternative == "greater":
        return float(min(upper, 1.0))
    if alternative == "less":
        return float(min(lower, 1.0))
    return float(min(1.0, 2.0 * min(upper, lower)))


def _normal_p(stat: float, mu: float, sd: float, alternative: str, cc: float) -> float:
    if sd <= 0:
        return 1.0
    if alternative == "greater":
        return float(_st.norm.sf((stat - mu - cc) / sd))
    if alternative == "less":
        return float(_st.norm.cdf((stat - mu + cc) / sd))
    z = (abs(stat - mu) - cc) / sd
    return float(min(1.0, 2.0 * _st.norm.sf(z)))


def _tie_term(ranks: np.ndarray) -> float:
    _, t = np.unique(ranks, return_counts=True)
    return float(np.sum(t.astype(float) ** 3 - t))


def _beyond_exact(test: str, why: str, requested: str) -> str:
    """Write the note of an exact test replaced by the normal approximation.

    Warn too when ``method="exact"`` was asked for explicitly.
    """
    note = (
        f"exact null distribution not computed ({why}); normal approximation used "
        "instead"
    )
    if requested == "exact":
        warnings.warn(
            f"{test}: method='exact' is beyond the exact range ({why}); the asymptotic "
            "p-value is returned (result.method and result.note say so)",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    return note


def _mwu_cells(w: np.ndarray, k: int) -> int:
    """Cells of :func:`_subset_sum_counts` for ``k``-subsets of the weights ``w``."""
    return (k + 1) * (int(np.sort(w)[::-1][:k].sum()) + 1)


# ------------------------------------------------------------------ Mann–Whitney


def mann_whitney(
    x,
    y,
    *,
    alternative: str,
    method: str = "auto",
    exact_max_n: int = 8,
    continuity: bool = True,
) -> TestResult:
    r"""One- or two-sided Mann–Whitney U test of ``x`` against ``y``.

    Parameters
    ----------
    x, y : array_like
        The two independent samples (finite values; drop missing ones first).
    alternative : {"greater", "less", "two-sided"}
        ``"greater"``: values of ``x`` tend to exceed those of ``y``
        (:math:`P(X > Y) > 1/2`). No default: the direction must be stated.
    method : {"auto", "exact", "asymptotic", "paper"}
        ``"auto"`` is exact when :math:`\min(n_1, n_2) \le` ``exact_max_n`` (exact
        conditional on the ties when there are ties), asymptotic otherwise.
        ``"paper"`` is ``"auto"`` except that tied samples get the tie-corrected
        normal approximation instead of the exact conditional p-value (Fayat et al.'s
        practice, see the module docstring). Beyond the exact range
        (:data:`EXACT_MAX_CELLS`, see the module docstring) an exact request gives the
        asymptotic p-value, with ``method`` and ``note`` saying so.
    exact_max_n : int
        Threshold of ``"auto"`` and ``"paper"`` (8, scipy's rule, which reproduces
        the p-value lattice of Fayat et al.'s Tables A1–A7 for the 5-animal group).
    continuity : bool
        Continuity correction of the asymptotic p-value.

    Returns
    -------
    TestResult
        ``statistic`` is :math:`U_x = \#\{x_i > y_j\} + \tfrac12\#\{x_i = y_j\}`, as
        ``scipy.stats.mannwhitneyu`` and ``pingouin.mwu`` report.

    Raises
    ------
    ValueError
        Empty or non-finite samples, an unknown ``alternative`` or ``method``, or
        :math:`n_1 + n_2 < 3` (no one-sided p below 1/2 is attainable).

    Warns
    -----
    RuntimeWarning
        ``method="exact"`` beyond the exact range (the asymptotic p-value is returned).

    Notes
    -----
    See the module docstring for the exact (conditional) distribution and the normal
    approximation.
    """
    alternative = _alternative(alternative)
    method = _method(method)
    exact_max_n = _validate.integer(exact_max_n, "exact_max_n", minimum=0)
    x = _sample(x, "x")
    y = _sample(y, "y")
    n1, n2 = x.size, y.size
    if n1 + n2 < 3:
        raise ValueError(
            f"x and y have {n1} and {n2} values: n too small for a one-sided exact "
            "test (the smallest attainable p is 1/2); need n1 + n2 >= 3"
        )
    ranks = _st.rankdata(np.concatenate([x, y]))
    r1 = float(ranks[:n1].sum())
    u = r1 - n1 * (n1 + 1) / 2.0
    ties = bool(np.unique(ranks).size < ranks.size)
    requested, note = method, ""
    if method in ("auto", "paper"):
        small = min(n1, n2) <= exact_max_n
        method = "exact" if small and not (ties and method == "paper") else "asymptotic"
    if method == "exact":
        w = np.rint(2 * ranks).astype(np.int64) if ties else np.arange(1, n1 + n2 + 1)
        direct = _mwu_cells(w, n1)
        swapped = _mwu_cells(w, n2) if direct > EXACT_MAX_CELLS else direct
        if min(direct, swapped) > EXACT_MAX_CELLS:
            method = "asymptotic"
            note = _beyond_exact(
                "mann_whitney",
                f"n1 = {n1} and n2 = {n2} need {min(direct, swapped):.3g} cells, more "
                f"than EXACT_MAX_CELLS = {EXACT_MAX_CELLS:.3g}",
                requested,
            )
    if method == "exact":
        if direct <= EXACT_MAX_CELLS:  # as always (the smaller work array otherwise)
            if not ties:
                counts = _mwu_counts_noties(n1, n2)
                p = _tail_p(counts, int(round(u)), alternative)
            else:
                counts = _subset_sum_counts(w, n1)
                p = _tail_p(counts, int(round(2 * r1)), alternative)
        else:  # count the other group's subsets: W_y = total - W_x, direction flipped
            flip = {"greater": "less", "less": "greater"}.get(alternative, alternative)
            if not ties:
                counts = _mwu_counts_noties(n2, n1)
                p = _tail_p(counts, int(round(n1 * n2 - u)), flip)
            else:
                counts = _subset_sum_counts(w, n2)
                p = _tail_p(counts, int(w.sum() - round(2 * r1)), flip)
        label = "exact-conditional" if ties else "exact"
    else:
        nn = n1 + n2
        var = n1 * n2 / 12.0 * ((nn + 1) - _tie_term(ranks) / (nn * (nn - 1)))
        cc = 0.5 if continuity else 0.0
        p = _normal_p(u, n1 * n2 / 2.0, np.sqrt(max(var, 0.0)), alternative, cc)
        label = "asymptotic-cc" if continuity else "asymptotic"
    return TestResult("mann-whitney", u, p, alternative, label, n1, n2, ties, note=note)


# ------------------------------------------------------------------ signed rank


def wilcoxon_signed_rank(
    x,
    y=None,
    *,
    alternative: str,
    zero_method: str = "wilcox",
    method: str = "auto",
    exact_max_n: int = 50,
    continuity: bool = True,
) -> TestResult:
    r"""One- or two-sided Wilcoxon signed-rank test of ``x - y`` (or ``x``) against 0.

    Parameters
    ----------
    x : array_like
        Values (e.g. a time point), or the differences when ``y`` is None.
    y : array_like, optional
        Paired values (e.g. the same subjects' baseline), same length as ``x``.
    alternative : {"greater", "less", "two-sided"}
        ``"greater"``: the differences :math:`d = x - y` tend to be positive.
    zero_method : {"wilcox", "pratt"}
        Zero differences: ``"wilcox"`` drops them before ranking (Wilcoxon 1945, R's
        ``wilcox.test``, scipy's default); ``"pratt"`` ranks them with the others and
        then drops them (Pratt 1959).
    method : {"auto", "exact", "asymptotic", "paper"}
        ``"auto"`` is exact for :math:`n \le` ``exact_max_n`` non-zero differences
        (exact conditional with ties or zeros), asymptotic otherwise. ``"paper"`` is
        ``"auto"`` except that tied ranks or zero differences get the tie-corrected
        normal approximation (see the module docstring). Beyond
        :data:`EXACT_MAX_PAIRS` (1000) non-zero differences an exact request gives the
        asymptotic p-value, with ``method`` and ``note`` saying so.
    exact_max_n : int
        Threshold of ``"auto"`` and ``"paper"`` (50, as scipy and R).
    continuity : bool
        Continuity correction of the asymptotic p-value.

    Returns
    -------
    TestResult
        ``statistic`` is :math:`T^+`, the sum of the ranks of the positive
        differences (``scipy.stats.wilcoxon``'s statistic for one-sided tests).

    Raises
    ------
    ValueError
        Empty, non-finite or unequal-length samples, an unknown ``alternative``,
        ``zero_method`` or ``method``, or fewer than 2 non-zero differences (no
        one-sided p below 1/2 is attainable).

    Warns
    -----
    RuntimeWarning
        ``method="exact"`` with more than :data:`EXACT_MAX_PAIRS` non-zero differences
        (the asymptotic p-value is returned).

    Notes
    -----
    With :math:`n` non-zero differences and no ties the smallest attainable one-sided
    p-value is :math:`2^{-n}` — 1/32 for the five ShamArsanilate animals of Fayat et
    al., hence their Table A2's :math:`0.188 = 6 \times 1/32` after a factor-6
    Bonferroni correction (see :func:`signed_rank_p_lattice`).
    """
    alternative = _alternative(alternative)
    method = _method(method)
    if zero_method not in ZERO_METHODS:
        raise ValueError(
            f"zero_method must be one of {ZERO_METHODS}, got {zero_method!r}"
        )
    exact_max_n = _validate.integer(exact_max_n, "exact_max_n", minimum=0)
    d = _sample(x, "x")
    if y is not None:
        yy = _sample(y, "y")
        if yy.size != d.size:
            raise ValueError(
                f"x and y must be paired (same length), got {d.size} and {yy.size}"
            )
        d = d - yy
    n_pairs = d.size
    zero = d == 0
    n_zero = int(zero.sum())
    dn = d[~zero]
    if zero_method == "wilcox":
        ranks = _st.rankdata(np.abs(dn))
    else:  # pratt: rank with the zeros, then drop them
        ranks = _st.rankdata(np.abs(d))[~zero]
    n = dn.size
    if n < 2:
        raise ValueError(
            f"x has {n} non-zero difference(s) out of {n_pairs}: n too small for a "
            "one-sided exact test (the smallest attainable p is 1/2); need >= 2"
        )
    t_plus = float(ranks[dn > 0].sum())
    ties = bool(np.unique(ranks).size < ranks.size)
    requested, note = method, ""
    if method in ("auto", "paper"):
        plain = not (ties or n_zero) or method == "auto"
        method = "exact" if n <= exact_max_n and plain else "asymptotic"
    if method == "exact" and n > EXACT_MAX_PAIRS:
        method = "asymptotic"
        note = _beyond_exact(
            "wilcoxon_signed_rank",
            f"{n} non-zero differences, more than EXACT_MAX_PAIRS = "
            f"{EXACT_MAX_PAIRS}: the 2^{n} sign vectors overflow float64",
            requested,
        )
    if method == "exact":
        if not ties and not (zero_method == "pratt" and n_zero):
            p = _tail_p(_signed_rank_counts_noties(n), int(round(t_plus)), alternative)
            label = "exact" if n_zero == 0 else "exact-conditional"
        else:
            w = np.rint(2 * ranks).astype(np.int64)
            p = _tail_p(_sign_flip_counts(w), int(round(2 * t_plus)), alternative)
            label = "exact-conditional"
    else:
        mu = float(ranks.sum()) / 2.0
        var = float(np.sum(ranks**2)) / 4.0  # exact conditional variance of T+
        cc = 0.5 if continuity else 0.0
        p = _normal_p(t_plus, mu, np.sqrt(var), alternative, cc)
        label = "asymptotic-cc" if continuity else "asymptotic"
    out = (t_plus, p, alternative, label, n_pairs, n_pairs, ties, n_zero, zero_method)
    return TestResult("wilcoxon", *out, note=note)


# ------------------------------------------------------------------ p-value lattices


def _lattice(counts: np.ndarray, name: str) -> pd.DataFrame:
    total = counts.sum()
    if total >= 2.0**53:
        raise ValueError(f"{name}: too many arrangements for exact integer counts")
    k = np.rint(np.cumsum(counts[::-1])).astype(np.int64)  # k(s) = #{S >= s}
    s = np.arange(counts.size - 1, -1, -1)
    keep = counts[::-1] > 0
    table = pd.DataFrame({"statistic": s[keep], "k": k[keep], "p": k[keep] / total})
    return label_columns(
        table,
        units="1",
        long_name={
            "statistic": "test statistic",
            "k": "arrangements at least as extreme",
            "p": "exact one-sided p",
        },
        role={"p": "p-value"},
    )


def exact_p_lattice(n1: int, n2: int) -> pd.DataFrame:
    r"""List the attainable exact one-sided Mann–Whitney p-values for groups of ``n1``, ``n2``.

    Parameters
    ----------
    n1, n2 : int
        Group sizes.

    Returns
    -------
    pandas.DataFrame
        One row per attainable value, smallest p first: ``statistic`` (:math:`u`),
        ``k`` (number of splits with :math:`U \ge u`) and ``p`` :math:`= k /
        \binom{n_1+n_2}{n_1}` (the ``"greater"`` p-value of :math:`U = u`; by symmetry
        also the ``"less"`` p-value of :math:`U = n_1 n_2 - u`). ``attrs["total"]``
        holds :math:`\binom{n_1+n_2}{n_1}`.

    Notes
    -----
    Without ties, every split of the :math:`N = n_1 + n_2` ranks is equally likely,
    so p-values live on the lattice :math:`k/\binom{N}{n_1}`; the smallest one is
    :math:`1/\binom{N}{n_1}` (1/4368 for 5 vs 11 animals). Fayat et al.'s Table A1
    values for the ShamArsanilate comparisons are :math:`18k/4368` (e.g.
    :math:`16.376 = 18 \times 3974/4368`).
    """
    n1 = _validate.integer(n1, "n1", minimum=1)
    n2 = _validate.integer(n2, "n2", minimum=1)
    out = _lattice(_mwu_counts_noties(n1, n2), "exact_p_lattice")
    out.attrs["total"] = comb(n1 + n2, n1)
    return out


def signed_rank_p_lattice(n: int) -> pd.DataFrame:
    r"""List the attainable exact one-sided signed-rank p-values for ``n`` differences.

    Parameters
    ----------
    n : int
        How many differences (at least 1), none zero and none tied.

    Returns
    -------
    pandas.DataFrame
        ``statistic`` (:math:`t`), ``k`` (sign vectors with :math:`T^+ \ge t`) and
        ``p`` :math:`= k/2^n`, smallest first; ``attrs["total"]`` is :math:`2^n`.

    Notes
    -----
    The smallest value is :math:`2^{-n}`: 1/32 for :math:`n = 5`, so no one-sided
    exact Wilcoxon test on five animals can report less than :math:`6/32 = 0.1875`
    after multiplying by a family of 6 time points (Fayat et al., Table A2).
    """
    n = _validate.integer(n, "n", minimum=1)
    out = _lattice(_signed_rank_counts_noties(n), "signed_rank_p_lattice")
    out.attrs["total"] = 2**n
    return out
