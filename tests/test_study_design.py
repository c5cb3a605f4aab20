"""A study's design read from its cohort table (stats.study_design), the tables it
drives (stats.design_tables) and power from observed groups (stats.observed_shift)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tiltlab import stats


def _table(groups=("ctrl", "les"), tps=("baseline", "7d", "1d"), n=4, fail=()):
    rows = []
    rng = np.random.default_rng(0)
    for g in groups:
        for k in range(n):
            for t in tps:
                session = f"{g}_{k:03d}_{t}"
                rows.append(
                    {
                        "session": session,
                        "subject": f"{g}_{k:03d}",
                        "group": g,
                        "timepoint": t,
                        "status": "failed" if session in fail else "ok",
                        "error": "ReadError: truncated" if session in fail else "",
                        "x": rng.normal()
                        + (2.0 if g == "les" and t != "baseline" else 0),
                    }
                )
    return pd.DataFrame(rows)


def test_defaults_come_from_the_table():
    d = stats.study_design(_table(groups=("les", "ctrl")))
    assert d.groups == ("les", "ctrl")  # table order
    assert d.control == "les"  # the first, when not stated
    assert d.timepoints == ("baseline", "1d", "7d")  # durations in time order
    assert d.baseline == "baseline" and d.longitudinal
    assert d.compared_timepoints == ["1d", "7d"]
    assert d.families == {"vs. les": [("ctrl", "les")]}
    assert d.family_size("vs. les") == 2
    assert d.animals.loc["ctrl", "7d"] == 4
    assert d.direction("x") == "two-sided"


def test_single_time_point_gives_between_group_tests_only():
    d = stats.study_design(_table(tps=("day3",)), control="ctrl")
    assert d.baseline is None and not d.longitudinal
    assert d.compared_timepoints == ["day3"]
    assert "between-group tests only" in d.describe()
    between, within = stats.design_tables(
        _table(tps=("day3",)), "x", stats.study_design(_table(tps=("day3",)))
    )
    assert within is None
    assert list(between["timepoint"]) == ["day3"]


def test_without_a_baseline_label_the_first_of_several_time_points_is_the_baseline():
    d = stats.study_design(_table(tps=("pre", "post")))
    assert d.baseline == "pre" and d.compared_timepoints == ["post"]
    assert (
        stats.study_design(_table(tps=("pre", "post")), baseline=None).baseline is None
    )


def test_failed_sessions_are_listed_and_left_out():
    t = _table(fail=("les_001_7d",))
    d = stats.study_design(t, control="ctrl")
    assert d.failed == {"les_001_7d": "ReadError: truncated"}
    assert d.animals.loc["les", "7d"] == 3
    assert "les_001_7d" in d.describe()


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (
            {"groups": ["ctrl", "lesoin"]},
            r"groups \['lesoin'\] not in the cohort table",
        ),
        ({"control": "healthy"}, "check the spelling"),
        ({"timepoints": ["baseline", "2w"]}, r"time points \['2w'\]"),
        ({"directions": {"x": "bigger"}}, "greater, less, two-sided"),
        ({"families": {"f": [("ctrl", "other")]}}, r"names group\(s\) \['other'\]"),
        ({"families": {"f": [("ctrl",)]}}, "pairs"),
        ({"groups": ["ctrl"]}, "at least two groups"),
    ],
)
def test_bad_designs_are_refused_by_name(kwargs, message):
    with pytest.raises(ValueError, match=message):
        stats.study_design(_table(), **kwargs)


def test_design_tables_follow_the_design():
    t = _table(groups=("ctrl", "les", "sham"))
    d = stats.study_design(
        t,
        control="ctrl",
        directions={"x": "greater"},
        families={
            "lesion": [("les", "ctrl"), ("les", "sham")],
            "sham": [("sham", "ctrl")],
        },
    )
    between, within = stats.design_tables(t, "x", d)
    assert set(between["family"]) == {"lesion", "sham"}
    assert (between["alternative"] == "greater").all()
    assert len(between) == 3 * len(d.compared_timepoints)
    # Bonferroni within each family: m = comparisons × time points
    lesion = between[between["family"] == "lesion"]
    np.testing.assert_allclose(lesion["p_paper"], lesion["p"] * d.family_size("lesion"))
    assert within is not None and set(within["group1"]) == {"ctrl", "les", "sham"}


def test_ids_stay_strings():
    t = _table()
    t["subject"] = t["subject"].str.replace("ctrl_", "00")
    table = stats.session_table(t)
    assert table["subject"].iloc[0] == "00000"


# ------------------------------------------------------------------ power


def test_observed_shift_replays_the_shapes_and_scales_the_difference():
    x, y = np.array([5.0, 6.0, 9.0, np.nan]), np.array([1.0, 2.0, 4.0])
    draw = stats.observed_shift(x, y, scale=0.5)
    assert draw.shift == pytest.approx(0.5 * (6.0 - 2.0))
    sx, sy = draw(200, np.random.default_rng(1))
    assert set(np.round(sx - 2.0 - draw.shift, 9)) <= {-1.0, 0.0, 3.0}
    assert set(np.round(sy - 2.0, 9)) <= {-1.0, 0.0, 2.0}
    again = stats.observed_shift(x, y, scale=0.5)(200, np.random.default_rng(1))
    np.testing.assert_array_equal(again[0], sx)
    with pytest.raises(ValueError, match="at least 2 finite"):
        stats.observed_shift([1.0], [1.0, 2.0])


@settings(max_examples=40, deadline=None)
@given(
    scale=st.floats(-3, 3),
    x=st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=12),
    y=st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=12),
)
def test_observed_shift_moves_the_median_by_scale_times_the_difference(scale, x, y):
    draw = stats.observed_shift(x, y, scale=scale)
    assert draw.shift == pytest.approx(scale * (np.median(x) - np.median(y)), abs=1e-9)
    zero = stats.observed_shift(x, y, scale=0.0)
    sx, sy = zero(50, np.random.default_rng(0))
    # with no shift both groups are centred on the second group's median
    residuals = np.asarray(x) - np.median(x)
    close = np.isclose((sx - np.median(y))[:, None], residuals[None, :], atol=1e-6)
    assert close.any(axis=1).all()
    assert sy.shape == (50,)
