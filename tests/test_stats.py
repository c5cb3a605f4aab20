"""Tests of tiltlab.stats: rank tests against brute-force enumeration, scipy and pingouin;
multiple-comparison arithmetic; Hodges–Lehmann intervals against their definition and
R's documented examples; mixed model; power by simulation; cohort tables; bad inputs."""

import itertools
import warnings

import numpy as np
import pandas as pd
import pingouin as pg
import pytest
import scipy.stats as st
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as hst
from statsmodels.stats.multitest import multipletests

import tiltlab.stats as S

ALTS = ("greater", "less", "two-sided")

# R's ?wilcox.test examples (Hollander & Wolfe 1973, pp. 29f and 69f)
DEP_X = np.array([1.83, 0.50, 1.62, 2.48, 1.68, 1.88, 1.55, 3.06, 1.30])
DEP_Y = np.array([0.878, 0.647, 0.598, 2.05, 1.06, 1.29, 1.06, 3.14, 1.29])
PERM_X = np.array([0.80, 0.83, 1.89, 1.04, 1.45, 1.38, 1.91, 1.64, 0.73, 1.46])
PERM_Y = np.array([1.15, 0.88, 0.90, 0.74, 1.21])


# ------------------------------------------------------------------ brute force


def _u(x, y):
    d = np.subtract.outer(x, y)
    return float(np.sum(d > 0) + 0.5 * np.sum(d == 0))


def _tails(perm, obs, alternative):
    ge = np.mean(perm >= obs - 1e-9)
    le = np.mean(perm <= obs + 1e-9)
    return {"greater": ge, "less": le, "two-sided": min(1.0, 2 * min(ge, le))}[
        alternative
    ]


def brute_mwu(x, y, alternative):
    """p of U_x over all C(N, n1) splits of the pooled data (ties kept)."""
    pooled = np.concatenate([x, y])
    idx = np.arange(pooled.size)
    perm = []
    for s in itertools.combinations(idx, x.size):
        mask = np.zeros(pooled.size, bool)
        mask[list(s)] = True
        perm.append(_u(pooled[mask], pooled[~mask]))
    return _tails(np.array(perm), _u(x, y), alternative)


def brute_signed_rank(d, alternative, zero_method):
    """p of T+ over all 2^n sign flips of the non-zero differences."""
    zero = d == 0
    if zero_method == "pratt":
        r = st.rankdata(np.abs(d))[~zero]
    else:
        r = st.rankdata(np.abs(d[~zero]))
    obs = r[d[~zero] > 0].sum()
    perm = [
        np.dot(r, signs)
        for signs in itertools.product((0, 1), repeat=r.size)  # 1 = positive
    ]
    return _tails(np.array(perm, float), obs, alternative)


SMALL_TWO_SAMPLE = [
    (np.array([1.2, 3.4, 5.0]), np.array([0.1, 2.2, 2.5, 4.0])),  # no ties
    (np.array([1.0, 2.0, 2.0, 3.0]), np.array([2.0, 3.0, 3.0, 4.0])),  # ties
    (np.array([5.0, 5.0, 6.0]), np.array([1.0, 5.0, 2.0, 2.0, 7.0])),  # ties across
    (np.array([1.0, 1.0]), np.array([1.0, 2.0, 2.0, 1.0, 3.0, 3.0])),  # heavy ties
]


@pytest.mark.parametrize("x,y", SMALL_TWO_SAMPLE)
@pytest.mark.parametrize("alternative", ALTS)
def test_mann_whitney_equals_enumeration(x, y, alternative):
    res = S.mann_whitney(x, y, alternative=alternative)
    assert res.statistic == pytest.approx(_u(x, y))
    assert res.p == pytest.approx(brute_mwu(x, y, alternative), abs=1e-12)
    ties = np.unique(np.concatenate([x, y])).size < x.size + y.size
    assert res.method == ("exact-conditional" if ties else "exact")
    assert res.alternative == alternative


def test_mann_whitney_random_small_vs_enumeration_and_scipy_permutation():
    rng = np.random.default_rng(5)
    for _ in range(6):
        n1, n2 = rng.integers(2, 5, size=2)
        x = rng.integers(0, 4, n1).astype(float)  # many ties
        y = rng.integers(0, 4, n2).astype(float) + 0.5 * rng.integers(0, 2, n2)
        for alt in ALTS:
            p = S.mann_whitney(x, y, alternative=alt).p
            assert p == pytest.approx(brute_mwu(x, y, alt), abs=1e-12)
            perm = st.mannwhitneyu(
                x, y, alternative=alt, method=st.PermutationMethod(n_resamples=np.inf)
            ).pvalue
            assert p == pytest.approx(perm, abs=1e-12)


SMALL_DIFFS = [
    np.array([1.5, -0.5, 2.0, 3.0, -1.0, 4.0, 0.7]),  # no ties, no zeros
    np.array([1.0, -1.0, 2.0, 2.0, -3.0, 4.0, 0.5, 2.0]),  # ties
    np.array([1.0, 0.0, 2.0, -2.0, 0.0, 3.0, 1.0]),  # zeros and ties
    np.array([0.0, 0.3, -0.1, 0.0, 0.0, 0.8]),  # many zeros
]


@pytest.mark.parametrize("d", SMALL_DIFFS)
@pytest.mark.parametrize("zero_method", ("wilcox", "pratt"))
@pytest.mark.parametrize("alternative", ALTS)
def test_signed_rank_equals_enumeration(d, zero_method, alternative):
    res = S.wilcoxon_signed_rank(d, alternative=alternative, zero_method=zero_method)
    assert res.p == pytest.approx(brute_signed_rank(d, alternative, zero_method))
    assert res.n_zero == int(np.sum(d == 0))
    assert res.method in ("exact", "exact-conditional")
    if np.any(d == 0) or res.ties:
        assert res.method == "exact-conditional"
    # scipy's all-sign-flip permutation agrees
    perm = st.wilcoxon(
        d,
        alternative=alternative,
        zero_method=zero_method,
        method=st.PermutationMethod(n_resamples=np.inf),
    ).pvalue
    assert res.p == pytest.approx(perm)


def test_paired_form_equals_differences():
    a = S.wilcoxon_signed_rank(DEP_X, DEP_Y, alternative="greater")
    b = S.wilcoxon_signed_rank(DEP_X - DEP_Y, alternative="greater")
    assert a.p == b.p and a.statistic == b.statistic


def test_asymptotic_matches_scipy():
    rng = np.random.default_rng(2)
    x = np.round(rng.normal(0.4, 1, 30), 1)  # ties
    y = np.round(rng.normal(0, 1, 25), 1)
    for alt in ALTS:
        r = S.mann_whitney(x, y, alternative=alt)
        assert r.method == "asymptotic-cc"
        s = st.mannwhitneyu(x, y, alternative=alt, method="asymptotic")
        assert r.p == pytest.approx(s.pvalue, rel=1e-10)
        d = np.round(rng.normal(0.3, 1, 60), 1)
        for zm in ("wilcox", "pratt"):
            r = S.wilcoxon_signed_rank(d, alternative=alt, zero_method=zm)
            assert r.method == "asymptotic-cc"
            s = st.wilcoxon(
                d, alternative=alt, zero_method=zm, method="asymptotic", correction=True
            )
            assert r.p == pytest.approx(s.pvalue, rel=1e-10)


# ------------------------------------------------------------------ pingouin


@pytest.mark.parametrize("alternative", ALTS)
def test_mwu_agrees_with_pingouin(alternative):
    rng = np.random.default_rng(11)
    x, y = rng.normal(0.8, 1, 6), rng.normal(0, 1, 11)  # exact (n1 <= 8, no ties)
    ours = S.mann_whitney(x, y, alternative=alternative)
    ref = pg.mwu(x, y, alternative=alternative, method="exact")
    assert ours.statistic == pytest.approx(ref["U_val"].iloc[0])
    assert ours.p == pytest.approx(ref["p_val"].iloc[0])
    # pingouin's RBC = (U_x - U_y) / (n1 n2), independent of the alternative
    assert S.rank_biserial(x, y).estimate == pytest.approx(ref["RBC"].iloc[0])
    # pingouin's CLES is P(X > Y) for "greater"/"two-sided", P(X < Y) for "less"
    ps = S.prob_superiority(x, y).estimate
    cles = ref["CLES"].iloc[0]
    assert (1 - ps if alternative == "less" else ps) == pytest.approx(cles)
    # asymptotic with ties (pingouin passes through to scipy, continuity on)
    xa, ya = np.round(rng.normal(0.5, 1, 20), 1), np.round(rng.normal(0, 1, 20), 1)
    ours = S.mann_whitney(xa, ya, alternative=alternative)
    ref = pg.mwu(xa, ya, alternative=alternative, method="asymptotic")
    assert ours.p == pytest.approx(ref["p_val"].iloc[0], rel=1e-10)


@pytest.mark.parametrize("alternative", ALTS)
def test_wilcoxon_agrees_with_pingouin(alternative):
    rng = np.random.default_rng(3)
    before = rng.normal(0, 1, 12)
    after = before + rng.normal(0.5, 1, 12)
    ours = S.wilcoxon_signed_rank(after, before, alternative=alternative)
    ref = pg.wilcoxon(after, before, alternative=alternative, method="exact")
    assert ours.p == pytest.approx(ref["p_val"].iloc[0])
    if alternative != "two-sided":  # scipy reports min(T+, T-) for two-sided
        assert ours.statistic == pytest.approx(ref["W_val"].iloc[0])
    # pingouin flips the matched-pairs RBC sign for "less"; ours is always T+ - T-
    rbc = S.paired_rank_biserial(after, before)
    sign = -1 if alternative == "less" else 1
    assert sign * rbc == pytest.approx(ref["RBC"].iloc[0])


# ------------------------------------------------------------------ R's examples


def test_r_wilcox_test_documented_p_values():
    """R's ``?wilcox.test`` examples (data from Hollander & Wolfe 1973, pp. 29f, 69f).

    R prints ``V = 40, p-value = 0.01953`` for ``wilcox.test(x, y, paired = TRUE,
    alternative = "greater")``, ``p-value = 0.01908`` for the large-sample version
    ``wilcox.test(y - x, alternative = "less", exact = FALSE, correct = FALSE)``,
    ``W = 35, p-value = 0.1272`` for ``wilcox.test(x, y, alternative = "g")`` and
    ``p-value = 0.1103`` with ``exact = FALSE, correct = FALSE``.
    """
    r = S.wilcoxon_signed_rank(DEP_X, DEP_Y, alternative="greater")
    assert r.statistic == 40 and r.method == "exact"
    assert r.p == pytest.approx(10 / 512) and round(r.p, 5) == 0.01953
    r = S.wilcoxon_signed_rank(
        DEP_Y - DEP_X, alternative="less", method="asymptotic", continuity=False
    )
    assert r.statistic == 5 and round(r.p, 5) == 0.01908
    r = S.mann_whitney(PERM_X, PERM_Y, alternative="greater")
    assert r.statistic == 35 and r.method == "exact" and round(r.p, 4) == 0.1272
    r = S.mann_whitney(
        PERM_X, PERM_Y, alternative="greater", method="asymptotic", continuity=False
    )
    assert round(r.p, 4) == 0.1103


def test_r_printed_normal_approximation_with_ties():
    """R output printed at https://endmemo.com/r/wilcoxon.php (``wilcox.test(x, y)``
    with ties: "W = 51.5, p-value = 0.5966" and "W = 0, p-value = 0.001364")."""
    x = np.array([1, 5, 9, 24, 56, 21, 3, 7, 21, 4.0])
    y = np.array([12, 15, 5, 9, 9, 14, 56, 22, 3, 7, 32, 5.0])
    r = S.mann_whitney(x, y, alternative="two-sided", method="asymptotic")
    assert r.statistic == 51.5 and round(r.p, 4) == 0.5966
    y2 = np.array([1233, 4356, 987, 39999, 1111, 200000.0])
    r = S.mann_whitney(x, y2, alternative="two-sided", method="asymptotic")
    assert r.statistic == 0 and round(r.p, 6) == 0.001364


# ------------------------------------------------------------------ Hodges–Lehmann


def _inverted_interval(values_between, stat_of, null, alpha):
    """Test-inversion interval by brute force: accept shift θ when the exact
    two-sided test (rejecting S <= c or S >= M - c with 2 P(S <= c) <= α) does not
    reject; return the data points bounding the accepted shifts."""
    null = np.sort(null)
    c = -1
    while 2 * np.mean(null <= c + 1) <= alpha + 1e-12:
        c += 1
    top = null.max()
    pts = np.unique(values_between)
    mids = np.concatenate([[pts[0] - 1], (pts[1:] + pts[:-1]) / 2, [pts[-1] + 1]])
    ok = [m for m in mids if c < stat_of(m) < top - c]
    lo = pts[pts < min(ok)].max()
    hi = pts[pts > max(ok)].min()
    return lo, hi


def test_hodges_lehmann_two_sample_from_definition():
    """Two-sample HL interval = inversion of the exact rank-sum test (HWC §4.3,
    Bauer 1972), computed by enumerating all C(15, 5) splits for R's
    permeability example."""
    x, y = PERM_X, PERM_Y
    pooled = np.arange(15)
    null = np.array(
        [
            sum(1 for i in s for j in set(pooled) - set(s) if i > j)
            for s in itertools.combinations(pooled, 10)
        ]
    )  # U of the 10-sample over all splits of distinct ranks
    diffs = np.subtract.outer(x, y).ravel()
    lo, hi = _inverted_interval(diffs, lambda t: np.sum(diffs > t), null, 0.05)
    res = S.hodges_lehmann(x, y, conf_level=0.95)
    assert res.estimate == pytest.approx(np.median(diffs))
    assert (res.low, res.high) == pytest.approx((lo, hi))
    assert res.estimate == pytest.approx(0.305)
    assert (res.low, res.high) == pytest.approx((-0.15, 0.76))


def test_hodges_lehmann_paired_from_definition():
    """Paired HL (pseudo-median of the Walsh averages) and its interval = inversion
    of the exact signed-rank test (HWC §3.3), by enumerating the 2^9 sign flips of
    R's depression example."""
    d = DEP_X - DEP_Y
    n = d.size
    null = np.array(
        [np.dot(np.arange(1, n + 1), s) for s in itertools.product((0, 1), repeat=n)]
    )
    i, j = np.triu_indices(n)
    walsh = (d[i] + d[j]) / 2

    def t_plus(theta):
        e = d - theta
        r = st.rankdata(np.abs(e))
        return r[e > 0].sum()

    lo, hi = _inverted_interval(walsh, t_plus, null, 0.05)
    res = S.hodges_lehmann(DEP_X, DEP_Y, paired=True, conf_level=0.95)
    assert res.estimate == pytest.approx(np.median(walsh))
    assert (res.low, res.high) == pytest.approx((lo, hi))
    assert res.estimate == pytest.approx(0.46)
    assert (res.low, res.high) == pytest.approx((0.01, 0.786))
    assert res.achieved == pytest.approx(1 - 2 * 10 / 512)


def test_hodges_lehmann_matches_hollander_wolfe_worked_example():
    """Published worked example: Hollander, Wolfe & Chicken (2014), Chapter 3,
    Hamilton depression scale (factor IV) before/after tranquilliser, n = 9.
    The book finds the pseudo-median of the differences (second − first visit)
    θ̂ = −0.46 and, with t = 40 from its signed-rank table (C = 46 − 40 = 6), the
    96.1 % interval [W(6), W(40)] = (−0.786, −0.010)."""
    res = S.hodges_lehmann(DEP_Y - DEP_X, conf_level=0.96)
    assert res.estimate == pytest.approx(-0.46)
    assert res.low == pytest.approx(-0.786)
    assert res.high == pytest.approx(-0.010)
    assert round(res.achieved, 3) == 0.961
    paired = S.hodges_lehmann(DEP_Y, DEP_X, paired=True, conf_level=0.96)
    assert (paired.estimate, paired.low, paired.high) == pytest.approx(
        (res.estimate, res.low, res.high)
    )


# SAS/STAT User's Guide, PROC NPAR1WAY, "Hodges-Lehmann Estimation" example:
# reaction times under two stimulants (13 and 6 subjects, heavily tied).
REACT_1 = np.array(
    [1.94, 1.94, 2.92, 2.92, 2.92, 2.92, 3.27, 3.27, 3.27, 3.27, 3.70, 3.70, 3.74]
)
REACT_2 = np.array([3.27, 3.27, 3.27, 3.70, 3.70, 3.74])


def test_hodges_lehmann_sas_npar1way_example_with_ties():
    """SAS prints the shift 0.35 and 98 % limits (0.00, 0.82) (asymptotic, Moses)
    and (0.00, 1.33) ("exact"). Our exact interval is (0.00, 0.82): it is the set of
    shifts that the exact *conditional* rank-sum test (mid-ranks, all C(19, 6)
    splits of the tied scores) does not reject at 1 % per side, checked here by
    brute force. SAS's exact limits step one order statistic further out
    (D(12), D(67) instead of D(13), D(66)), a more conservative choice under ties."""
    res = S.hodges_lehmann(REACT_2, REACT_1, conf_level=0.98)
    assert res.estimate == pytest.approx(0.35)
    assert (res.low, res.high) == pytest.approx((0.0, 0.82))

    n = REACT_2.size
    splits = np.array(list(itertools.combinations(range(n + REACT_1.size), n)))

    def not_rejected(shift):
        z = np.round(np.r_[REACT_2 - shift, REACT_1], 9)
        r = st.rankdata(z)
        null = r[splits].sum(axis=1)
        obs = r[:n].sum()
        return min(np.mean(null >= obs - 1e-9), np.mean(null <= obs + 1e-9)) > 0.01

    diffs = np.unique(np.round(np.subtract.outer(REACT_2, REACT_1).ravel(), 9))
    grid = np.unique(np.r_[diffs, (diffs[1:] + diffs[:-1]) / 2])
    accepted = grid[[not_rejected(s) for s in grid]]
    assert (accepted.min(), accepted.max()) == pytest.approx((res.low, res.high))


def test_hodges_lehmann_one_sided_and_unreachable_level():
    res = S.hodges_lehmann(PERM_X, PERM_Y, alternative="greater", conf_level=0.9)
    two = S.hodges_lehmann(PERM_X, PERM_Y, conf_level=0.8)
    assert res.high == np.inf and res.low == pytest.approx(two.low)
    tiny = S.hodges_lehmann([1.0, 2.0, 3.0], conf_level=0.95)  # 2^3 = 8 outcomes
    assert tiny.achieved < 0.95
    assert (tiny.low, tiny.high) == (1.0, 3.0)


_floats = hst.floats(-100, 100, allow_nan=False, allow_subnormal=False)
_samples = hst.lists(_floats, min_size=1, max_size=9)


@settings(max_examples=60, deadline=None)
@given(_samples, _samples, hst.floats(-50, 50))
def test_hodges_lehmann_properties(x, y, shift):
    x, y = np.array(x), np.array(y)
    levels = (0.5, 0.8, 0.9, 0.95, 0.99)
    ivs = [S.hodges_lehmann(x, y, conf_level=c) for c in levels]
    for iv in ivs:
        assert iv.low <= iv.estimate <= iv.high
    for a, b in zip(ivs, ivs[1:]):  # nested: higher level, wider interval
        assert b.low <= a.low and a.high <= b.high
    moved = S.hodges_lehmann(x + shift, y + shift, conf_level=0.9)
    ref = ivs[2]
    tol = 1e-9 * (1 + np.abs(shift) + np.abs(np.r_[x, y]).max())
    assert moved.estimate == pytest.approx(ref.estimate, abs=tol)
    assert moved.low == pytest.approx(ref.low, abs=tol)
    assert moved.high == pytest.approx(ref.high, abs=tol)
    one = S.hodges_lehmann(x, conf_level=0.9)
    assert one.low <= one.estimate <= one.high
    one_moved = S.hodges_lehmann(x + shift, conf_level=0.9)
    assert one_moved.estimate == pytest.approx(one.estimate + shift, abs=tol)


def test_prob_superiority_and_rbc_intervals():
    rng = np.random.default_rng(4)
    x, y = rng.normal(0.5, 1, 15), rng.normal(0, 1, 12)
    ps = S.prob_superiority(x, y, conf_level=0.95)
    from statsmodels.stats.nonparametric import rank_compare_2indep

    ref = rank_compare_2indep(x, y)
    assert ps.estimate == pytest.approx(ref.prob1)
    assert (ps.low, ps.high) == pytest.approx(ref.conf_int(alpha=0.05))
    rbc = S.rank_biserial(x, y)
    assert rbc.estimate == pytest.approx(2 * ps.estimate - 1)
    assert rbc.low == pytest.approx(2 * ps.low - 1)
    sep = S.prob_superiority([5.0, 6, 7], [1.0, 2, 3])  # complete separation
    assert sep.estimate == 1.0 and np.isnan(sep.low)
    pp = S.paired_prob_superiority(DEP_X, DEP_Y)
    assert pp.estimate == pytest.approx(np.mean(DEP_X > DEP_Y))
    assert 0 <= pp.low <= pp.estimate <= pp.high <= 1


# ------------------------------------------------------------------ lattices


def test_p_lattices_explain_fayat_table_values():
    lat = S.signed_rank_p_lattice(5)
    assert lat["p"].iloc[0] == 1 / 32 and lat["k"].iloc[0] == 1
    assert f"{6 * lat['p'].iloc[0]:.3f}" == "0.188"  # Table A2, ShamArsanilate
    assert {6 * k for k in (3, 13, 29)} <= {6 * k for k in lat["k"]}
    mw = S.exact_p_lattice(5, 11)
    assert mw.attrs["total"] == 4368 and mw["p"].iloc[0] == 1 / 4368
    for printed, k in [(16.376, 3974), (14.032, 3405), (1.990, 483), (17.753, 4308)]:
        assert k in set(mw["k"])
        assert f"{18 * k / 4368:.3f}" == f"{printed:.3f}"
    np.testing.assert_allclose(S.mwu_null_distribution(5, 11).sum(), 1.0)
    assert S.signed_rank_null_distribution(5)[-1] == 1 / 32


# ------------------------------------------------------------------ multiplicity


def test_adjustments_hand_built_example():
    p = np.array([0.01, 0.04, 0.03, 0.2, 0.02, 0.6])
    # paper convention: m p, uncapped (family 18 as in Tables A1, A3, A5, A7)
    np.testing.assert_allclose(
        S.adjust(p, "paper", family=18), [0.18, 0.72, 0.54, 3.6, 0.36, 10.8]
    )
    np.testing.assert_allclose(S.paper_bonferroni(p), 6 * p)
    np.testing.assert_allclose(
        S.adjust(p, "bonferroni"), [0.06, 0.24, 0.18, 1.0, 0.12, 1.0]
    )
    # Holm by hand: sorted 0.01*6, 0.02*5, 0.03*4, 0.04*3, 0.2*2, 0.6*1, running max
    np.testing.assert_allclose(S.adjust(p, "holm"), [0.06, 0.12, 0.12, 0.4, 0.10, 0.6])
    # BH by hand: m p / rank = .06 .06 .06 .06 .24 .6, running min from the top
    np.testing.assert_allclose(S.adjust(p, "bh"), [0.06, 0.06, 0.06, 0.24, 0.06, 0.6])
    for ours, sm in [("bonferroni", "bonferroni"), ("holm", "holm"), ("bh", "fdr_bh")]:
        np.testing.assert_allclose(S.adjust(p, ours), multipletests(p, method=sm)[1])
    # a larger family = missing tests with p = 1
    np.testing.assert_allclose(
        S.adjust(p, "holm", family=8),
        multipletests(np.r_[p, 1, 1], method="holm")[1][:6],
    )
    assert S.FAYAT_FAMILIES == {"mann-whitney": 18, "wilcoxon": 6}


def test_add_adjustments_families():
    t = pd.DataFrame(
        {"group": list("aaabbb"), "p": [0.01, 0.02, np.nan, 0.3, 0.01, 0.5]}
    )
    out = S.add_adjustments(t, "group")
    assert out["family_size"].tolist()[:2] == [2, 2] and np.isnan(out["family_size"][2])
    np.testing.assert_allclose(out["p_paper"][3:], [0.9, 0.03, 1.5])
    out = S.add_adjustments(t, 18)
    np.testing.assert_allclose(out["p_paper"][[0, 1]], [0.18, 0.36])


# ------------------------------------------------------------------ cohort tables


GROUPS = {"Lesion": 6, "Sham": 5, "Healthy": 7}
TPS = ["baseline", "1h", "1d", "2d", "7d", "14d", "28d"]


def _cohort(seed=0, as_frame=False):
    rng = np.random.default_rng(seed)
    rows = []
    for g, n in GROUPS.items():
        for i in range(n):
            base = rng.normal(0.3, 0.05)
            for t in TPS:
                eff = 0.3 if (g == "Lesion" and t in ("1d", "2d")) else 0.0
                rows.append(
                    {
                        "session": f"{g}{i}_{t}",
                        "subject": f"{g}{i}",
                        "group": g,
                        "timepoint": t,
                        "immobility": base + eff + rng.normal(0, 0.03),
                        "status": "ok",
                    }
                )
    df = pd.DataFrame(rows).sample(frac=1, random_state=1)  # shuffled order
    df.loc[df["session"] == "Lesion0_7d", ["status", "immobility"]] = ["failed", np.nan]
    df.loc[df["session"] == "Healthy0_1h", "immobility"] = np.nan
    if as_frame:
        return df
    ds = xr.Dataset(
        {
            "immobility": ("session", df["immobility"].to_numpy()),
            "status": ("session", df["status"].to_numpy()),
        },
        coords={
            c: ("session", df[c].to_numpy())
            for c in ("session", "subject", "group", "timepoint")
        },
    )
    return ds


COMPARISONS = [
    ("Lesion", "Healthy", "greater"),
    ("Lesion", "Sham", "greater"),
    ("Sham", "Healthy", "greater"),
]


def test_between_groups_table():
    tidy = S.between_groups(_cohort(), "immobility", COMPARISONS)
    assert len(tidy) == 18 and set(tidy["family_size"]) == {18}
    assert list(dict.fromkeys(tidy["timepoint"])) == TPS[1:]  # sorted by duration
    np.testing.assert_allclose(tidy["p_paper"], 18 * tidy["p"])
    row = tidy[(tidy.comparison == "Lesion vs. Sham") & (tidy.timepoint == "1d")].iloc[
        0
    ]
    assert row.alternative == "greater" and row.method == "exact"
    assert row.n1 == 6 and row.n2 == 5 and row.p == pytest.approx(1 / 462)
    assert row.hl > 0 and row.hl_low <= row.hl <= row.hl_high
    failed = tidy[(tidy.comparison == "Lesion vs. Healthy") & (tidy.timepoint == "7d")]
    assert failed.n1.iloc[0] == 5 and failed.n_missing.iloc[0] == 0  # skipped, not NaN
    nan = tidy[(tidy.comparison == "Lesion vs. Healthy") & (tidy.timepoint == "1h")]
    assert nan.n2.iloc[0] == 6 and nan.n_missing.iloc[0] == 1
    direct = S.mann_whitney(
        *[
            _cohort(as_frame=True)
            .query("group == @g and timepoint == '2d'")["immobility"]
            .to_numpy()
            for g in ("Sham", "Healthy")
        ],
        alternative="greater",
    )
    got = tidy[(tidy.comparison == "Sham vs. Healthy") & (tidy.timepoint == "2d")]
    assert got.p.iloc[0] == pytest.approx(direct.p)
    frame = S.between_groups(_cohort(as_frame=True), "immobility", COMPARISONS)
    pd.testing.assert_frame_equal(frame, tidy)


def test_against_baseline_table_and_format():
    alt = {"Lesion": "greater", "Sham": "greater", "Healthy": "less"}
    tidy = S.against_baseline(_cohort(), "immobility", list(GROUPS), alternative=alt)
    assert len(tidy) == 18 and set(tidy["family_size"]) == {6}
    assert tidy.loc[0, "comparison"] == "Lesion vs. Lesion baseline"
    assert set(tidy.loc[tidy.group1 == "Healthy", "alternative"]) == {"less"}
    row = tidy[(tidy.group1 == "Lesion") & (tidy.timepoint == "1d")].iloc[0]
    assert row.p == pytest.approx(1 / 64) and row.p_paper == pytest.approx(6 / 64)
    assert row.method == "exact" and row.hl > 0 and row.rbc == 1.0
    lesion7 = tidy[(tidy.group1 == "Lesion") & (tidy.timepoint == "7d")].iloc[0]
    assert lesion7.n1 == 5  # failed session skipped
    text = S.format_table(tidy, "p_paper")
    assert list(text.columns) == TPS[1:]
    assert text.loc["Lesion vs. Lesion baseline", "1d"] == "0.094"
    tiny = tidy.assign(p_paper=np.where(tidy.index == 0, 0.0004, tidy.p_paper))
    t2 = S.format_table(tiny, "p_paper")
    assert t2.iloc[0, 0] == "<0.001***"
    html = S.format_table(tiny, "p_paper", output="styler").to_html()
    assert S.COLOURS[2] in html
    grid = S.format_table(tidy, "hl", output="frame")
    assert grid.shape == (3, 6) and "*" not in S.format_table(tidy, "hl").iloc[0, 0]


def test_format_stars_thresholds():
    t = pd.DataFrame(
        {
            "comparison": ["a"] * 5,
            "timepoint": list("vwxyz"),
            "p_paper": [0.2, 0.04, 0.009, 0.0009, 17.753],
        }
    )
    out = S.format_table(t).iloc[0].tolist()
    assert out == ["0.200", "0.040*", "0.009**", "<0.001***", "17.753"]


# ------------------------------------------------------------------ mixed model


def _longitudinal(seed=0, effect=1.5, n=10):
    rng = np.random.default_rng(seed)
    rows = []
    for g in ("Healthy", "Lesion"):
        for i in range(n):
            b = rng.normal(0, 1.0)
            for t in ("baseline", "1d", "7d"):
                planted = effect if (g == "Lesion" and t == "7d") else 0.0
                y = 2.0 + 0.3 * (t == "1d") + b + planted + rng.normal(0, 0.4)
                rows.append(
                    {"subject": f"{g}{i}", "group": g, "timepoint": t, "value": y}
                )
    return pd.DataFrame(rows)


def test_mixed_model_recovers_planted_interaction():
    res = S.mixed_model(_longitudinal(), "value", reference_group="Healthy")
    assert res.converged and res.table["converged"].all()
    row = res.table.set_index("term").loc["group[Lesion]:timepoint[7d]"]
    assert row.ci_low < 1.5 < row.ci_high and row.p < 1e-4
    other = res.table.set_index("term").loc["group[Lesion]:timepoint[1d]"]
    assert abs(other.estimate) < 3 * other.se
    assert res.group_var > 0.3 and res.optimizer == "lbfgs"


def test_mixed_model_degenerate_reports_non_convergence():
    d = _longitudinal().assign(value=1.0)  # no variance at all
    with pytest.warns(RuntimeWarning, match="did not converge"):
        res = S.mixed_model(d, "value")
    assert res.converged is False
    assert not res.table["converged"].any()
    assert res.warnings  # what statsmodels said is kept


# ------------------------------------------------------------------ power


def test_power_increases_with_n_and_effect():
    sim = S.normal_shift(1.0)
    tab = S.power_by_simulation(sim, [4, 8, 16], n_sim=300, rng=1)
    assert tab["power"].is_monotonic_increasing and tab["power"].iloc[-1] > 0.85
    weak = S.power_by_simulation(S.normal_shift(0.4), 16, n_sim=300, rng=1)
    assert weak["power"].iloc[0] < tab["power"].iloc[-1]
    fam = S.power_by_simulation(sim, 16, n_sim=300, rng=1, family=18)
    assert fam["power"].iloc[0] < tab["power"].iloc[-1]
    assert tab.attrs["n_needed"] == 16


def test_power_without_effect_is_the_test_size():
    n, n_sim = 7, 3000
    tab = S.power_by_simulation(
        S.normal_shift(0.0), n, n_sim=n_sim, rng=7, method="exact"
    )
    lat = S.exact_p_lattice(n, n)
    size = lat.loc[lat["p"] <= 0.05, "p"].max()  # attainable size <= alpha
    se = np.sqrt(size * (1 - size) / n_sim)
    assert abs(tab["power"].iloc[0] - size) < 4 * se
    assert size <= 0.05
    paired = S.power_by_simulation(
        S.normal_shift(0.0), 10, n_sim=2000, rng=8, test="wilcoxon"
    )
    lat = S.signed_rank_p_lattice(10)
    size = lat.loc[lat["p"] <= 0.05, "p"].max()
    assert abs(paired["power"].iloc[0] - size) < 4 * np.sqrt(size * (1 - size) / 2000)


def test_power_flags_unattainable_and_finds_n():
    tab = S.power_by_simulation(S.normal_shift(3.0), 3, n_sim=50, rng=0, family=18)
    assert not tab["attainable"].iloc[0] and tab["power"].iloc[0] == 0.0
    res = S.animals_needed(S.normal_shift(1.5), family=6, n_sim=200, rng=3, n_max=40)
    assert res.n is not None and res.power >= 0.8
    below = res.table.loc[res.table.n_per_group < res.n, "power"]
    assert (below < 0.8).all()
    noether = S.noether_n_per_group(S.normal_shift_superiority(1.5), family=6)
    assert abs(res.n - noether) <= 4


# ------------------------------------------------------------------ bad inputs


def test_bad_inputs_name_the_argument():
    with pytest.raises(ValueError, match="y is empty"):
        S.mann_whitney([1.0, 2.0], [], alternative="greater")
    with pytest.raises(ValueError, match="x contains 1 NaN"):
        S.mann_whitney([1.0, np.nan], [1.0, 2.0], alternative="greater")
    with pytest.raises(ValueError, match="x contains"):
        S.wilcoxon_signed_rank([1.0, np.nan, 2.0], alternative="greater")
    with pytest.raises(ValueError, match="n too small for a one-sided exact test"):
        S.mann_whitney([1.0], [2.0], alternative="less")
    with pytest.raises(ValueError, match="n too small for a one-sided exact test"):
        S.wilcoxon_signed_rank([0.0, 0.0, 1.0], alternative="greater")
    with pytest.raises(ValueError, match="alternative must be one of"):
        S.mann_whitney([1.0, 2.0], [3.0, 4.0], alternative="larger")
    with pytest.raises(ValueError, match="alternative must be one of"):
        S.wilcoxon_signed_rank([1.0, 2.0], alternative="two.sided")
    with pytest.raises(ValueError, match="zero_method"):
        S.wilcoxon_signed_rank([1.0, 2.0], alternative="greater", zero_method="zsplit")
    with pytest.raises(ValueError, match="method must be one of"):
        S.mann_whitney([1.0, 2.0], [3.0], alternative="greater", method="permutation")
    with pytest.raises(ValueError, match="paired"):
        S.wilcoxon_signed_rank([1.0, 2.0], [1.0], alternative="greater")
    with pytest.raises(ValueError, match="conf_level"):
        S.hodges_lehmann([1.0, 2.0], [3.0], conf_level=1.5)
    with pytest.raises(ValueError, match="family"):
        S.adjust([0.1, 0.2, 0.3], "paper", family=2)
    with pytest.raises(ValueError, match="method must be one of"):
        S.adjust([0.1], "sidak")
    with pytest.raises(ValueError, match="p must hold probabilities"):
        S.adjust([0.1, np.nan], "holm")
    with pytest.raises(ValueError, match="n_per_group"):
        S.power_by_simulation(S.normal_shift(1.0), 1, n_sim=10)
    with pytest.raises(ValueError, match="test must be one of"):
        S.power_by_simulation(S.normal_shift(1.0), 5, n_sim=10, test="t")


def test_bad_cohort_inputs():
    ds = _cohort()
    with pytest.raises(ValueError, match="comparisons names group 'Nope'"):
        S.between_groups(ds, "immobility", [("Nope", "Healthy", "greater")])
    with pytest.raises(ValueError, match="comparisons: no alternative"):
        S.between_groups(ds, "immobility", [("Lesion", "Healthy")])
    with pytest.raises(ValueError, match="alternative"):
        S.between_groups(ds, "immobility", [("Lesion", "Healthy", "up")])
    with pytest.raises(ValueError, match="feature 'speed'"):
        S.between_groups(ds, "speed", COMPARISONS)
    with pytest.raises(ValueError, match="alternative gives no direction"):
        S.against_baseline(ds, "immobility", alternative={"Lesion": "greater"})
    with pytest.raises(ValueError, match="baseline 'pre'"):
        S.against_baseline(ds, "immobility", baseline="pre", alternative="greater")
    # an empty cell is reported, not raised: every Sham value at 28d missing
    df = _cohort(as_frame=True)
    df.loc[(df.group == "Sham") & (df.timepoint == "28d"), "immobility"] = np.nan
    tidy = S.between_groups(df, "immobility", COMPARISONS)
    cell = tidy[(tidy.comparison == "Lesion vs. Sham") & (tidy.timepoint == "28d")]
    assert np.isnan(cell.p.iloc[0]) and "y is empty" in cell.note.iloc[0]
    assert cell.note.iloc[0].startswith("not tested") and cell.n2.iloc[0] == 0
    assert set(tidy["family_size"].dropna()) == {16}  # 2 untested cells left out
    text = S.format_table(tidy)
    assert text.loc["Lesion vs. Sham", "28d"] == ""


def test_import_does_not_pull_the_simulator():
    import subprocess
    import sys

    code = "import sys, tiltlab.stats; print('tiltlab.simulate' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.stdout.strip() == "False"


def test_no_warnings_in_ordinary_use():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        S.between_groups(_cohort(), "immobility", COMPARISONS)


def test_published_fayat_tables_sit_on_the_exact_lattices():
    """Fayat et al. (2021) Table A2's ShamArsanilate row (n = 5 pairs, family of 6):
    printed values are multiples of 6/32, the exact one-sided signed-rank lattice."""
    a2 = S.fayat_table("A2")
    row = a2.loc["ShamArsanilate vs. ShamArsanilate baseline"]
    for printed in row:
        k = float(printed) / (6 / 32)
        if abs(k - round(k)) > 0.02:  # 3.469 needs n = 6 pairs (see the chapter)
            assert (
                abs(float(printed) / (6 / 64) - round(float(printed) / (6 / 64))) < 0.02
            )
    assert list(a2.columns) == list(S.FAYAT_TIME_POINTS)
    with pytest.raises(ValueError, match="name"):
        S.fayat_table("A9")
