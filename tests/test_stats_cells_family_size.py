"""The Bonferroni family stated in every table: ``family_size`` of the table builders,
the family recorded in ``attrs``, and :func:`format_table`'s caption and column.

Fayat et al. (2021), Tables A1–A8, multiply by 18 between groups (3 comparisons × 6
time points) and by 6 against baseline; with untestable cells the default family
shrinks to the tested cells, an explicit ``family_size`` keeps m and says so.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest

import tiltlab.stats as S

TIMEPOINTS = ["1h", "1d", "2d", "7d", "14d", "28d"]
COMPARISONS = [
    ("Lesion", "Healthy", "greater"),
    ("Lesion", "Sham", "greater"),
    ("Sham", "Healthy", "greater"),
]


def _cohort(untested: bool = False) -> pd.DataFrame:
    """Three groups of 5 animals, a baseline and 6 time points; optionally every Sham
    value at 28d missing (2 between-group cells and 1 baseline cell untestable)."""
    rng = np.random.default_rng(7)
    rows = []
    for g, shift in (("Lesion", 2.0), ("Sham", 0.5), ("Healthy", 0.0)):
        for i in range(5):
            for tp in ["baseline", *TIMEPOINTS]:
                v = rng.normal() + (0.0 if tp == "baseline" else shift)
                rows.append({"subject": f"{g}{i}", "group": g, "timepoint": tp, "y": v})
    df = pd.DataFrame(rows)
    if untested:
        df.loc[(df.group == "Sham") & (df.timepoint == "28d"), "y"] = np.nan
    return df


def test_default_family_is_recorded_in_attrs():
    tidy = S.between_groups(_cohort(), "y", COMPARISONS)
    assert tidy.attrs["family_size"] == 18
    assert tidy.attrs["families"] == {
        "all": {"family_size": 18, "n_tested": 18, "n_cells": 18}
    }
    assert tidy.attrs["family_caption"] == (
        "Bonferroni family: m = 18 (18 of 18 cells tested)"
    )


def test_default_family_shrinks_to_the_tested_cells_and_says_so():
    tidy = S.between_groups(_cohort(untested=True), "y", COMPARISONS)
    assert set(tidy["family_size"].dropna()) == {16}
    assert tidy.attrs["families"]["all"] == {
        "family_size": 16,
        "n_tested": 16,
        "n_cells": 18,
    }
    assert "m = 16 (16 of 18 cells tested)" in tidy.attrs["family_caption"]


def test_explicit_family_size_keeps_m_and_warns_when_cells_are_untested():
    df = _cohort(untested=True)
    with pytest.warns(RuntimeWarning, match="family_size = 18 .* 16 of 18 cells"):
        tidy = S.between_groups(df, "y", COMPARISONS, family_size=18)
    tested = tidy["p"].notna()
    assert set(tidy.loc[tested, "family_size"]) == {18}
    np.testing.assert_array_equal(
        tidy.loc[tested, "p_paper"], 18 * tidy.loc[tested, "p"]
    )
    # the two untested cells enter Holm as p = 1 in a family of 18
    ref = S.adjust(tidy.loc[tested, "p"].to_numpy(), "holm", family=18)
    np.testing.assert_array_equal(tidy.loc[tested, "p_holm"], ref)
    assert tidy.attrs["family_size"] == 18
    assert tidy.attrs["families"]["all"]["n_tested"] == 16
    assert "m = 18 (16 of 18 cells tested)" in tidy.attrs["family_caption"]


def test_explicit_family_size_equal_to_the_tested_cells_is_silent_and_identical():
    df = _cohort()
    default = S.between_groups(df, "y", COMPARISONS)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        stated = S.between_groups(df, "y", COMPARISONS, family_size=18)
    pd.testing.assert_frame_equal(default, stated)


def test_family_size_below_the_tested_cells_is_refused_by_name():
    with pytest.raises(ValueError, match="family_size"):
        S.between_groups(_cohort(), "y", COMPARISONS, family_size=6)
    with pytest.raises(ValueError, match="family_size"):
        S.between_groups(_cohort(), "y", COMPARISONS, family_size=0)
    with pytest.raises(ValueError, match="family_size .* disagree"):
        S.between_groups(_cohort(), "y", COMPARISONS, family=18, family_size=20)


def test_against_baseline_states_a_family_per_group():
    df = _cohort(untested=True)
    default = S.against_baseline(df, "y", alternative="greater")
    fams = default.attrs["families"]
    assert fams["Sham"] == {"family_size": 5, "n_tested": 5, "n_cells": 6}
    assert fams["Lesion"] == {"family_size": 6, "n_tested": 6, "n_cells": 6}
    assert default.attrs["family_size"] == {"Lesion": 6, "Sham": 5, "Healthy": 6}
    assert "Sham: m = 5 (5 of 6 cells tested)" in default.attrs["family_caption"]
    with pytest.warns(RuntimeWarning, match="'Sham': 5 of 6 cells"):
        stated = S.against_baseline(df, "y", alternative="greater", family_size=6)
    assert stated.attrs["family_size"] == 6
    assert set(stated["family_size"].dropna()) == {6}
    sham = stated[(stated.group1 == "Sham") & stated.p.notna()]
    np.testing.assert_array_equal(sham["p_paper"], 6 * sham["p"])


def test_format_table_shows_the_family_in_caption_and_column():
    df = _cohort(untested=True)
    with pytest.warns(RuntimeWarning):
        tidy = S.between_groups(df, "y", COMPARISONS, family_size=18)
    text = S.format_table(tidy)
    assert list(text.columns) == TIMEPOINTS  # unchanged layout by default
    assert text.attrs["caption"] == "Bonferroni family: m = 18 (16 of 18 cells tested)"
    wide = S.format_table(tidy, family_column=True)
    assert wide.loc["Lesion vs. Healthy", "m"] == "18"
    assert wide.loc["Lesion vs. Sham", "m"] == "18 (5 of 6 tested)"
    assert wide.loc["Sham vs. Healthy", "m"] == "18 (5 of 6 tested)"
    html = S.format_table(tidy, output="styler", family_column=True).to_html()
    assert (
        "<caption>Bonferroni family: m = 18 (16 of 18 cells tested)</caption>" in html
    )
    frame = S.format_table(tidy, output="frame", family_column=True)
    assert frame.attrs["long_name"]["m"] == "family size m"
    assert frame.attrs["caption"].startswith("Bonferroni family: m = 18")


def test_format_table_reads_the_family_from_columns_when_attrs_are_lost():
    """A concatenated table (attrs dropped) still gets its caption from its columns."""
    tidy = S.between_groups(_cohort(), "y", COMPARISONS)
    bare = pd.DataFrame(tidy.to_dict("list"))
    assert S.family_caption(bare) == "Bonferroni family: m = 18 (18 of 18 cells tested)"


def test_add_adjustments_family_size_pads_with_p_equal_one():
    """Bonferroni over m = 4 with 2 tested p-values: m·p, Holm over 4 (statsmodels)."""
    table = pd.DataFrame({"p": [0.01, 0.04, np.nan]})
    with pytest.warns(RuntimeWarning, match="2 of 3 cells"):
        out = S.add_adjustments(table, family_size=4)
    np.testing.assert_allclose(out["p_paper"][:2], [0.04, 0.16])
    np.testing.assert_allclose(out["p_holm"][:2], [0.04, 0.12])
    assert out.attrs["families"]["all"] == {
        "family_size": 4,
        "n_tested": 2,
        "n_cells": 3,
    }


def test_caption_of_concatenated_families_reads_the_family_column():
    """Two lesion families side by side (as :func:`design_tables` builds them): the
    caption counts each family's cells, not the first table's."""
    parts = []
    for name in ("first", "second"):
        part = S.between_groups(_cohort(), "y", COMPARISONS)
        part.insert(0, "family", name)
        parts.append(part)
    both = pd.concat(parts, ignore_index=True)
    assert len(both) == 36
    assert S.family_caption(both) == (
        "Bonferroni families, each: m = 18 (18 of 18 cells tested)"
    )
    text = S.format_table(S.against_baseline(_cohort(), "y", alternative="greater"))
    assert text.attrs["caption"] == (
        "Bonferroni family per group1: m = 6 (6 of 6 cells tested)"
    )
