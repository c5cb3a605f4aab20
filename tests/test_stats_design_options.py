"""design_tables passes the family sizes and the per-cell test choice to both tests."""

import warnings

import numpy as np
import pandas as pd

import tiltlab.stats as S

TIMEPOINTS = ["1h", "1d", "2d", "7d", "14d", "28d"]


def _cohort() -> pd.DataFrame:
    rng = np.random.default_rng(3)
    rows = []
    for g, shift in (("Lesion", 2.0), ("Sham", 0.5), ("Healthy", 0.0)):
        for i in range(6):
            for tp in ["baseline", *TIMEPOINTS]:
                v = round(rng.normal() + (0.0 if tp == "baseline" else shift), 1)
                rows.append({"subject": f"{g}{i}", "group": g, "timepoint": tp, "y": v})
    return pd.DataFrame(rows)


def _design(df):
    return S.study_design(
        df,
        control="Healthy",
        families={"lesion": [("Lesion", "Healthy"), ("Sham", "Healthy")]},
        directions={"y": "greater"},
    )


def test_defaults_are_unchanged_and_options_reach_both_tests():
    df = _cohort()
    design = _design(df)
    b0, w0 = S.design_tables(df, "y", design)
    b1, w1 = S.design_tables(df, "y", design, method="paper", family_size=12)
    assert set(b1["family_size"]) == {12} and set(b0["family_size"]) == {12}
    assert b1["method"].isin(["exact", "asymptotic-cc"]).all()
    assert "asymptotic-cc" in set(b1["method"])  # values rounded to 0.1 have ties
    exact = b1["method"] == "exact"
    assert np.allclose(b1.loc[exact, "p"], b0.loc[exact, "p"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _, w2 = S.design_tables(df, "y", design, baseline_family_size=6)
    assert set(w2["family_size"]) == {6}
    assert np.array_equal(w2["p"], w0["p"])
    assert S.family_caption(b1).startswith("Bonferroni famil")
