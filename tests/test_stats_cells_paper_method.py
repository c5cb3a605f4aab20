"""``method="paper"``: Fayat et al.'s per-cell mix of exact and asymptotic p-values.

References are scipy's tests (``scipy.stats.mannwhitneyu``, ``scipy.stats.wilcoxon``),
and the lattice argument on Fayat et al. (2021) Table A3 (ShamArsanilate vs Healthy,
1 d and 7 d): those two printed values are no exact permutation p-value of the
paper's group sizes, and are the tie-corrected normal approximation with one tie.
"""

from __future__ import annotations

from math import comb

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats as sps

import tiltlab.stats as S

small_ints = st.lists(st.integers(0, 12), min_size=2, max_size=8)


def _has_ties(*samples) -> bool:
    pooled = np.concatenate([np.asarray(s, dtype=float) for s in samples])
    return np.unique(pooled).size < pooled.size


@settings(max_examples=60, deadline=None)
@given(small_ints, small_ints, st.sampled_from(["greater", "less", "two-sided"]))
def test_mann_whitney_paper_is_exact_without_ties_asymptotic_with(x, y, alternative):
    res = S.mann_whitney(x, y, alternative=alternative, method="paper")
    if not _has_ties(x, y):
        ref = sps.mannwhitneyu(x, y, alternative=alternative, method="exact")
        exact = S.mann_whitney(x, y, alternative=alternative, method="exact")
        assert res.method == "exact" and res.p == exact.p
    else:
        ref = sps.mannwhitneyu(x, y, alternative=alternative, method="asymptotic")
        assert res.method == "asymptotic-cc"
    assert res.p == pytest.approx(ref.pvalue, rel=1e-10, abs=1e-14)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.integers(-6, 6), min_size=3, max_size=12),
    st.sampled_from(["greater", "less", "two-sided"]),
)
def test_wilcoxon_paper_is_exact_without_ties_or_zeros(d, alternative):
    d = np.asarray(d, dtype=float)
    if np.count_nonzero(d) < 2:
        return
    res = S.wilcoxon_signed_rank(d, alternative=alternative, method="paper")
    nz = d[d != 0]
    if np.unique(np.abs(nz)).size == nz.size and nz.size == d.size:
        ref = sps.wilcoxon(d, alternative=alternative, method="exact")
        assert res.method == "exact"
    else:
        ref = sps.wilcoxon(
            d, alternative=alternative, method="asymptotic", correction=True
        )
        assert res.method == "asymptotic-cc"
    assert res.p == pytest.approx(ref.pvalue, rel=1e-10, abs=1e-14)


def test_paper_method_without_continuity_is_scipys_default_wilcoxon():
    """scipy's ``wilcoxon`` defaults to no continuity correction."""
    d = [1.0, 2.0, 2.0, 3.5, -0.5, 4.0, 5.0]  # tied |d|
    res = S.wilcoxon_signed_rank(
        d, alternative="greater", method="paper", continuity=False
    )
    ref = sps.wilcoxon(d, alternative="greater", method="asymptotic")
    assert res.method == "asymptotic" and res.p == pytest.approx(ref.pvalue, rel=1e-12)


def test_paper_method_keeps_the_size_rule_of_auto():
    """Beyond ``exact_max_n`` both are asymptotic (scipy's rule for large groups)."""
    rng = np.random.default_rng(3)
    x, y = rng.normal(size=10), rng.normal(size=12)
    paper = S.mann_whitney(x, y, alternative="greater", method="paper")
    auto = S.mann_whitney(x, y, alternative="greater")
    assert paper == auto and paper.method == "asymptotic-cc"
    small = S.mann_whitney(x[:5], y, alternative="greater", method="paper")
    assert small.method == "exact"


def test_unknown_method_is_refused_by_name():
    with pytest.raises(ValueError, match="method must be one of"):
        S.mann_whitney([1, 2], [3, 4], alternative="less", method="papers")


# --------------------------------------------------------------- tables, per cell


def _two_cells() -> pd.DataFrame:
    """Two groups at two time points: tied values at 1d, distinct values at 7d."""
    rows = []
    values = {
        ("lesion", "1d"): [3.0, 4.0, 4.0, 6.0, 7.0],
        ("sham", "1d"): [1.0, 2.0, 4.0, 5.0, 2.0],
        ("lesion", "7d"): [3.1, 4.2, 5.3, 6.4, 7.5],
        ("sham", "7d"): [1.0, 2.5, 3.6, 4.7, 0.8],
    }
    for (group, tp), vals in values.items():
        for i, v in enumerate(vals):
            rows.append(
                {"subject": f"{group}{i}", "group": group, "timepoint": tp, "x": v}
            )
    for i in range(5):  # a baseline for the signed-rank table
        for group, base in (("lesion", [3.0, 2.0, 4.0, 4.5, 6.0]), ("sham", [1.0] * 5)):
            rows.append(
                {
                    "subject": f"{group}{i}",
                    "group": group,
                    "timepoint": "baseline",
                    "x": base[i] + (0.01 * i if group == "sham" else 0.0),
                }
            )
    return pd.DataFrame(rows)


def test_between_groups_records_the_method_of_each_cell():
    df = _two_cells()
    tidy = S.between_groups(df, "x", [("lesion", "sham", "greater")], method="paper")
    by_tp = tidy.set_index("timepoint")
    assert by_tp.loc["1d", "method"] == "asymptotic-cc"  # ties: normal approximation
    assert by_tp.loc["7d", "method"] == "exact"
    for tp, method in (("1d", "asymptotic"), ("7d", "exact")):
        x = df.query("group == 'lesion' and timepoint == @tp")["x"]
        y = df.query("group == 'sham' and timepoint == @tp")["x"]
        ref = sps.mannwhitneyu(x, y, alternative="greater", method=method)
        assert by_tp.loc[tp, "p"] == pytest.approx(ref.pvalue, rel=1e-12)
    assert tidy.attrs["long_name"]["method"] == "p-value method"


def test_default_tables_are_unchanged_by_the_paper_option():
    """Default arguments still give the exact conditional p-value on ties."""
    df = _two_cells()
    tidy = S.between_groups(df, "x", [("lesion", "sham", "greater")])
    x = df.query("group == 'lesion' and timepoint == '1d'")["x"].to_numpy()
    y = df.query("group == 'sham' and timepoint == '1d'")["x"].to_numpy()
    direct = S.mann_whitney(x, y, alternative="greater", method="exact")
    assert tidy.loc[0, "method"] == "exact-conditional" and tidy.loc[0, "p"] == direct.p


def test_against_baseline_paper_method_per_cell():
    df = _two_cells()
    tidy = S.against_baseline(
        df, "x", ["lesion"], alternative="greater", method="paper", continuity=False
    )
    by_tp = tidy.set_index("timepoint")
    x = df.query("group == 'lesion' and timepoint == '1d'")["x"].to_numpy()
    b = df.query("group == 'lesion' and timepoint == 'baseline'")["x"].to_numpy()
    ref = sps.wilcoxon(x, b, alternative="greater", method="asymptotic")  # zero, tie
    assert by_tp.loc["1d", "method"] == "asymptotic"
    assert by_tp.loc["1d", "p"] == pytest.approx(ref.pvalue, rel=1e-12)
    x7 = df.query("group == 'lesion' and timepoint == '7d'")["x"].to_numpy()
    ref7 = sps.wilcoxon(x7, b, alternative="greater", method="exact")
    assert by_tp.loc["7d", "method"] == "exact"
    assert by_tp.loc["7d", "p"] == pytest.approx(ref7.pvalue, rel=1e-12)


def test_unknown_test_option_names_the_options():
    with pytest.raises(TypeError, match="continuity"):
        S.between_groups(_two_cells(), "x", [("lesion", "sham", "greater")], exact=True)


# --------------------------------------------------------------- Table A3 lattice


TABLE_A3_TIED = {"1d": "16.592", "7d": "13.204"}
M_BETWEEN = S.FAYAT_FAMILIES["mann-whitney"]  # 18


def _exact_lattice_strings(n1: int, n2: int) -> set[str]:
    """Every exact permutation p-value k/C(n1+n2, n1), times 18, as printed."""
    total = comb(n1 + n2, n1)
    return {f"{M_BETWEEN * k / total:.3f}" for k in range(total + 1)}


def test_exact_p_values_with_ties_stay_on_the_split_lattice():
    """With ties too, an exact (conditional) p-value counts equally likely splits:
    p·C(16, 5) is an integer (scipy's full permutation test as the reference)."""
    x = [5.0, 11.5, 12.5, 7.5, 3.5]
    y = list(range(11))
    ours = S.mann_whitney(x, y, alternative="less", method="exact")
    ref = sps.mannwhitneyu(
        x, y, alternative="less", method=sps.PermutationMethod(n_resamples=np.inf)
    )
    assert ours.method == "exact-conditional"
    assert ours.p == pytest.approx(ref.pvalue, rel=1e-12)
    k = ours.p * comb(16, 5)
    assert k == pytest.approx(round(k), abs=1e-6)


@pytest.mark.parametrize("timepoint", ["1d", "7d"])
def test_table_A3_cell_is_on_no_exact_lattice_of_the_paper_groups(timepoint):
    """Fayat et al. (2021) Table A3, ShamArsanilate vs. Healthy: the group sizes are
    5 and 11 (§2.4); no exact p-value of any n1 ≤ 5 vs n2 ≤ 11 split, × 18, prints
    as this cell (a sixth ShamArsanilate or twelfth Healthy animal, beyond the
    allocation, would be needed), whereas the row's 1 h, 2 d and 28 d cells sit on the
    5-vs-11 lattice."""
    row = S.fayat_table("A3").loc["ShamArsanilate vs. Healthy"]
    printed = row[timepoint]
    assert printed == TABLE_A3_TIED[timepoint]
    n1_max = S.FAYAT_GROUP_SIZES["ShamArsanilate"]
    n2_max = S.FAYAT_GROUP_SIZES["Healthy"]
    for n1 in range(1, n1_max + 1):
        for n2 in range(1, n2_max + 1):
            assert printed not in _exact_lattice_strings(n1, n2), (n1, n2)
    on = _exact_lattice_strings(n1_max, n2_max)
    assert {row["1h"], row["2d"], row["28d"]} <= on  # 16.376, 2.407, 5.951


@pytest.mark.parametrize(
    ("timepoint", "sham"),
    [
        ("1d", [5.0, 11.5, 12.5, 7.5, 3.5]),  # U = 39.5: one value tied with Healthy
        ("7d", [5.0, 11.5, 7.5, 5.5, 1.5]),  # U = 32.5
    ],
)
def test_table_A3_cell_is_the_normal_approximation_with_one_tie(timepoint, sham):
    """Fayat et al. (2021) Table A3, ShamArsanilate vs. Healthy: 5 vs 11 animals with
    one tied pair across the groups reproduce the printed 18·p with the tie- and
    continuity-corrected normal approximation (scipy's ``asymptotic``) in the paper's
    direction (less mobile), and ``method="paper"`` picks that approximation."""
    healthy = np.arange(11.0)
    alternative = S.FAYAT_DESIGN["directions"]["visited_fraction_moving"]
    ref = sps.mannwhitneyu(sham, healthy, alternative=alternative, method="asymptotic")
    assert f"{M_BETWEEN * ref.pvalue:.3f}" == TABLE_A3_TIED[timepoint]
    ours = S.mann_whitney(sham, healthy, alternative=alternative, method="paper")
    assert ours.method == "asymptotic-cc" and ours.ties
    assert ours.p == pytest.approx(ref.pvalue, rel=1e-12)
    exact = S.mann_whitney(sham, healthy, alternative=alternative, method="exact")
    assert f"{M_BETWEEN * exact.p:.3f}" != TABLE_A3_TIED[timepoint]
