"""The chapter-8 recipes moved into the package: feature labels, group quantiles, the
significant cells, our p-values next to the printed tables, planted-vs-estimated
recovery and the manifest lookups."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from tiltlab import cohort, stats


# -- feature labels ---------------------------------------------------------------------


def test_feature_labels_from_the_specs():
    assert cohort.feature_name("immobile_fraction") == "immobile fraction"
    assert cohort.feature_name("dba_mean") == "dba_mean"  # no short name: itself
    assert cohort.feature_units("immobile_fraction") == ""
    assert cohort.feature_units("tilt_immobile_sagittal_deg") == "°"
    assert cohort.feature_units("circling_index") == "circles/min"
    assert cohort.feature_units("dba_mean") == "g"  # other units as stored
    assert (
        cohort.feature_label("circling_index", prefix="Δ ")
        == "Δ circling index (circles/min)"
    )
    assert cohort.feature_label("visited_fraction_moving") == "sphere visited, moving"
    # every feature of a configuration has a label
    config = cohort.FeatureConfig(speed_quantiles=(0.5,))
    specs = cohort.feature_specs(config)
    assert cohort.feature_units("angular_speed_moving_q50", config) == "°/s"
    assert all(cohort.feature_label(f, config) for f in specs)


def test_feature_units_refuses_an_unknown_feature():
    with pytest.raises(ValueError, match="immobile_fractoin"):
        cohort.feature_units("immobile_fractoin")


# -- group quantiles --------------------------------------------------------------------


def _table():
    rng = np.random.default_rng(0)
    rows = [
        {
            "session": f"{g}{i}_{t}",
            "subject": f"{g}{i}",
            "group": g,
            "timepoint": t,
            "x": rng.normal(),
            "status": "ok",
        }
        for g in ("Healthy", "Lesion")
        for i in range(5)
        for t in ("baseline", "1d")
    ]
    df = pd.DataFrame(rows)
    df.loc[0, "status"] = "failed"  # left out
    return df


def test_group_quantiles_are_the_cells_quantiles():
    df = _table()
    q = stats.group_quantiles(df, "x")
    assert list(q.columns) == [0.25, 0.5, 0.75]
    assert q.index.names == ["group", "timepoint"] and len(q) == 4
    ok = df[df["status"] == "ok"]
    for (g, t), r in q.iterrows():
        v = ok.loc[(ok["group"] == g) & (ok["timepoint"] == t), "x"]
        np.testing.assert_allclose(r.to_numpy(), np.quantile(v, [0.25, 0.5, 0.75]))
    assert list(stats.group_quantiles(df, "x", q=[0.1]).columns) == [0.1]
    with pytest.raises(ValueError, match="q must"):
        stats.group_quantiles(df, "x", q=[1.5])


# -- significant cells and printed tables -----------------------------------------------


def _tidy():
    return pd.DataFrame(
        {
            "comparison": ["A vs. C"] * 3 + ["B vs. C"] * 3,
            "timepoint": ["1h", "1d", "2d"] * 2,
            "p_paper": [0.01, 0.2, 0.04, 1.5, 0.06, 0.0004],
            "p_holm": [0.01, 0.2, 0.04, 1.0, 0.06, 0.0004],
        }
    )


def test_significant_cells():
    tidy = _tidy()
    assert (
        stats.significant_cells(tidy, "p_paper", 0.05) == "A vs. C: 1h, 2d; B vs. C: 2d"
    )
    assert stats.significant_cells(tidy, "p_paper", 0.01) == "B vs. C: 2d"
    assert stats.significant_cells(tidy, "p_paper", 1e-6) == ""
    with pytest.raises(ValueError, match="p_bh"):
        stats.significant_cells(tidy, "p_bh")


def test_with_published_interleaves_the_sources():
    tidy = _tidy()
    printed = pd.DataFrame(
        {"1h": ["0.500", "0.900"], "1d": ["0.100", "0.800"], "28d": ["1", "1"]},
        index=["A vs. C", "Z vs. C"],
    )
    table = stats.with_published(tidy, printed)
    sources = ["Fayat et al. (printed)", "m·p (ours)", "Holm (ours)"]
    assert list(table.index) == [
        (c, s) for c in ("A vs. C", "B vs. C") for s in sources
    ]
    assert table.index.names == ["comparison", "p-values"]
    assert list(table.columns) == ["1h", "1d", "2d"]  # ours; printed 28d left out
    assert table.loc[("A vs. C", "Fayat et al. (printed)"), "1d"] == "0.100"
    assert table.loc[("B vs. C", "Fayat et al. (printed)"), "1h"] == ""  # not printed
    assert table.loc[("A vs. C", "m·p (ours)")].tolist() == (
        stats.format_table(tidy, "p_paper").loc["A vs. C"].tolist()
    )
    assert table.loc[("B vs. C", "m·p (ours)"), "1h"].startswith("1.500")  # uncapped
    # no printed table, or none of our comparisons in it: ours only
    for other in (None, printed.rename(index={"A vs. C": "Y vs. C"})):
        only = stats.with_published(tidy, other)
        assert only.index.get_level_values(1).unique().tolist() == sources[1:]


# -- recovery of planted differences ----------------------------------------------------


def test_recovery_table_planted_and_estimated():
    sessions = pd.DataFrame(
        {
            "group": ["L"] * 3 + ["C"] * 3 + ["L"] * 3 + ["C"] * 3,
            "timepoint": ["1d"] * 6 + ["7d"] * 6,
        },
        index=pd.Index([f"s{i}" for i in range(12)], name="session"),
    )
    planted = pd.Series(
        [0.5, 0.6, 0.7, 0.1, 0.2, 0.3, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 9.0],
        index=[*sessions.index, "not tested"],
    )
    between = pd.DataFrame(
        {
            "comparison": ["L vs. C", "L vs. C", "L vs. X"],
            "group1": ["L", "L", "L"],
            "group2": ["C", "C", "X"],
            "timepoint": ["1d", "7d", "1d"],
            "hl": [0.38, 0.01, 9.0],
            "p_paper": [0.01, 0.7, 0.0],
        }
    )
    t = stats.recovery_table(between, planted, sessions, control="C", alpha=0.05)
    assert list(t.columns) == [
        "comparison",
        "time point",
        "planted Δ",
        "estimated Δ",
        "p (m·p)",
        "found",
    ]
    assert t["time point"].tolist() == ["1d", "7d"]  # only the rows against C
    np.testing.assert_allclose(t["planted Δ"], [0.4, 0.0], atol=1e-12)
    assert t["estimated Δ"].tolist() == [0.38, 0.01]
    assert t["found"].tolist() == [True, False]
    none = stats.recovery_table(between, planted, sessions, control="nobody")
    assert none.empty and list(none.columns) == list(t.columns)


def test_fayat_feature_tables():
    assert stats.FAYAT_FEATURE_TABLES["immobile_fraction"] == ("A1", "A2")
    assert stats.FAYAT_FEATURE_TABLES["circling_index"] == ("A7", "A8")
    numbers = [int(n[1:]) for pair in stats.FAYAT_FEATURE_TABLES.values() for n in pair]
    assert numbers == list(range(1, 9))


# -- manifest lookups -------------------------------------------------------------------


def _manifest(root):
    table = pd.DataFrame(
        {
            "session": ["a_base", "a_1d", "a_1d_bis", "b_1d"],
            "subject": ["a", "a", "a", "b"],
            "group": ["G", "G", "G", "H"],
            "timepoint": ["baseline", "1d", "1d", "1d"],
            "file": ["a0.nc", "a1.nc", "a1b.nc", "b1.nc"],
        }
    )
    return cohort.Manifest(table=table, root=root)


def test_session_row_first_usable_session(tmp_path):
    m = _manifest(tmp_path)
    assert cohort.session_row(m, "a", "1d")["session"] == "a_1d"
    usable = pd.DataFrame(
        {"subject": ["a", "b"], "timepoint": ["1d", "1d"]},
        index=pd.Index(["a_1d_bis", "b_1d"], name="session"),
    )
    row = cohort.session_row(m, "a", "1d", usable)
    assert row["session"] == "a_1d_bis" and row["file"] == "a1b.nc"
    with pytest.raises(KeyError, match="'a'.*'7d'"):
        cohort.session_row(m, "a", "7d")
    with pytest.raises(KeyError):
        cohort.session_row(m, "a", "baseline", usable)  # not a usable session


def test_load_session_tilt_is_the_pipelines(tmp_path):
    from tiltlab import simulate

    design = simulate.CohortDesign.small(2).select(
        groups={"Healthy": 2}, time_points=["baseline"]
    )
    folder = simulate.simulate_cohort(
        tmp_path / "c",
        design=design,
        duration_s=20.0,
        fs=50.0,
        seed=1,
        workers=1,
        progress=False,
    )
    m = cohort.read_manifest(folder / "manifest.csv")
    subject = str(m.table["subject"].iloc[0])
    row = cohort.session_row(m, subject, "baseline")
    rec, g = cohort.load_session_tilt(row, m.root)
    expected_rec, expected = cohort.session_tilt(
        cohort.load_session(row, m.root),
        calibration=cohort.load_calibration(row, m.root),
    )
    assert g.dims == ("time", "axis")
    np.testing.assert_array_equal(g.values, expected.values)
    np.testing.assert_array_equal(rec["acc"].values, expected_rec["acc"].values)
