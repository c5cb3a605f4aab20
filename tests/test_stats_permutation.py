"""The subject-level permutation test of a group × time interaction."""

from __future__ import annotations

from itertools import permutations
from math import comb

import numpy as np
import pandas as pd
import pytest
from scipy.stats import binom

from tiltlab.stats import permutation_interaction


def _cohort(rng, n1=4, n2=4, times=("baseline", "1d"), effect=0.0, subject_sd=1.0):
    """Long table: groups L (n1) and C (n2), a random intercept per subject, and
    ``effect`` added to L after baseline."""
    rows = []
    for g, n in (("L", n1), ("C", n2)):
        for k in range(n):
            b = rng.normal(0, subject_sd)
            for j, t in enumerate(times):
                shift = effect if (g == "L" and j > 0) else 0.0
                rows.append(
                    {
                        "subject": f"{g}{k}",
                        "group": g,
                        "timepoint": t,
                        "value": b + shift + rng.normal(),
                    }
                )
    return pd.DataFrame(rows)


def test_exact_enumeration_equals_brute_force_count():
    d = _cohort(np.random.default_rng(1), n1=3, n2=3)
    out = permutation_interaction(d, "value", reference_group="C")
    wide = d.pivot(index="subject", columns="timepoint", values="value")
    change = (wide["1d"] - wide["baseline"]).to_dict()
    labels = d.groupby("subject")["group"].first().to_dict()
    subjects = sorted(change)

    def stat(lab):
        x = [change[s] for s in subjects if lab[s] == "L"]
        y = [change[s] for s in subjects if lab[s] == "C"]
        return np.mean(x) - np.mean(y)

    t = stat(labels)
    orders = list(permutations([labels[s] for s in subjects]))
    hits = sum(abs(stat(dict(zip(subjects, o)))) >= abs(t) - 1e-12 for o in orders)
    row = out.iloc[0]
    assert row["method"] == "exact" and row["n_relabellings"] == comb(6, 3)
    assert row["estimate"] == pytest.approx(t)
    assert row["p"] == pytest.approx(hits / len(orders))


def test_one_sided_alternatives_split_the_exact_distribution():
    d = _cohort(np.random.default_rng(2), n1=4, n2=3)
    kw = {"reference_group": "C"}
    greater = permutation_interaction(d, "value", alternative="greater", **kw)["p"][0]
    less = permutation_interaction(d, "value", alternative="less", **kw)["p"][0]
    # continuous data: only the observed value is counted on both sides
    assert greater + less == pytest.approx(1 + 1 / comb(7, 3))


def test_p_values_are_valid_under_the_null():
    rng = np.random.default_rng(3)
    n_sets = 200
    rejections = 0
    for _ in range(n_sets):
        d = _cohort(rng, n1=5, n2=5)
        rejections += (
            permutation_interaction(d, "value", reference_group="C")["p"][0] <= 0.05
        )
    low, high = binom.ppf([0.0005, 0.9995], n_sets, 0.05)
    assert low <= rejections <= high


def test_detects_a_planted_effect():
    d = _cohort(np.random.default_rng(4), n1=6, n2=6, effect=4.0, subject_sd=3.0)
    out = permutation_interaction(
        d, "value", reference_group="C", alternative="greater"
    )
    assert out["estimate"][0] > 2 and out["p"][0] < 0.01


def test_random_relabellings_reproducible_and_bounded():
    d = _cohort(np.random.default_rng(5), n1=8, n2=8, times=("baseline", "1d", "7d"))
    kw = {"reference_group": "C", "n_permutations": 499}
    a = permutation_interaction(d, "value", seed=7, **kw)
    b = permutation_interaction(d, "value", seed=7, **kw)
    pd.testing.assert_frame_equal(a, b)
    assert (a["method"] == "random").all() and (a["n_relabellings"] == 499).all()
    assert (a["p"] >= 1 / 500).all() and (a["p"] <= 1).all()
    exact = permutation_interaction(
        d, "value", reference_group="C", n_permutations=comb(16, 8)
    )
    assert (exact["method"] == "exact").all()
    assert np.allclose(a["p"], exact["p"], atol=0.08)


def test_invariant_to_subject_names_and_row_order_and_keeps_input():
    d = _cohort(np.random.default_rng(6), n1=4, n2=5, times=("baseline", "1d", "2d"))
    before = d.copy()
    out = permutation_interaction(d, "value", reference_group="C")
    pd.testing.assert_frame_equal(d, before)
    renamed = d.assign(subject=d["subject"].map(lambda s: f"rat_{s[::-1]}"))
    shuffled = renamed.sample(frac=1, random_state=0)
    again = permutation_interaction(shuffled, "value", reference_group="C")
    again = again.sort_values("term", ignore_index=True)
    pd.testing.assert_frame_equal(out, again)
    assert list(out["term"]) == ["group[L]:timepoint[1d]", "group[L]:timepoint[2d]"]


def test_labels_and_missing_sessions():
    d = _cohort(np.random.default_rng(7), n1=4, n2=4, times=("baseline", "1d", "7d"))
    d.attrs["units"] = {"value": "deg"}
    d.loc[(d["subject"] == "L0") & (d["timepoint"] == "7d"), "value"] = np.nan
    out = permutation_interaction(d, "value", reference_group="C")
    assert out.attrs["units"]["estimate"] == "deg"
    assert all(c in out.attrs["units"] and out.attrs["long_name"][c] for c in out)
    assert out.attrs["role"]["p"] == "p-value"
    assert out.attrs["reference_group"] == "C" and out.attrs["baseline"] == "baseline"
    assert out.set_index("timepoint")["n1"].to_dict() == {"1d": 4, "7d": 3}


@pytest.mark.parametrize(
    ("change", "kwargs", "message"),
    [
        (lambda d: d.drop(columns="group"), {}, "no column"),
        (lambda d: d[d["subject"] != "L1"], {}, "at least 2 per group"),
        (
            lambda d: d.assign(group=d["group"].where(d.index != 0, "C")),
            {},
            "more than one group",
        ),
        (lambda d: d[d["timepoint"] != "baseline"], {}, "baseline time point"),
        (lambda d: pd.concat([d, d.iloc[:1]]), {}, "several rows"),
        (lambda d: d, {"reference_group": "X"}, "reference_group"),
        (lambda d: d, {"alternative": "bigger"}, "alternative"),
        (lambda d: d, {"n_permutations": 0}, "at least 1"),
    ],
)
def test_bad_input_is_refused_with_the_reason(change, kwargs, message):
    d = _cohort(np.random.default_rng(8), n1=2, n2=3)
    kwargs = {"reference_group": "C", **kwargs}
    with pytest.raises(ValueError, match=message):
        permutation_interaction(change(d), "value", **kwargs)


def test_not_a_dataframe():
    with pytest.raises(TypeError, match="DataFrame"):
        permutation_interaction({"value": [1.0]}, "value")
