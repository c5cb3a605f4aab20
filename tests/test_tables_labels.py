"""Every table-producing function labels its columns: units and long names.

The convention (``df.attrs["units"]`` and ``df.attrs["long_name"]``, dicts column →
string; a Dataset's variable attributes) lets :func:`tiltlab.plot.table` render any of
them without the chapter saying what the columns are.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from tiltlab import behavior as B
from tiltlab import evaluate as E
from tiltlab import quaternion as Q
from tiltlab import schema
from tiltlab import stats as S
from tiltlab._labels import format_p, label_columns
from tiltlab.calibration.drift import AllanNoise
from tiltlab.calibration.summaries import allan_noise_table


def _assert_labelled(df: pd.DataFrame, where: str) -> None:
    units, long = df.attrs.get("units"), df.attrs.get("long_name")
    assert isinstance(units, dict) and isinstance(long, dict), where
    for c in df.columns:
        assert c in units, f"{where}: column {c!r} has no units entry"
        assert isinstance(units[c], str), f"{where}: units of {c!r}"
        assert long.get(c), f"{where}: column {c!r} has no long name"


def _assert_dataset_labelled(ds: xr.Dataset, where: str) -> None:
    for v in ds.data_vars:
        assert "units" in ds[v].attrs, f"{where}: {v} has no units"
        assert ds[v].attrs.get("long_name"), f"{where}: {v} has no long name"


def _cohort() -> pd.DataFrame:
    rng = np.random.default_rng(0)
    n = 6
    subjects = [f"s{i}" for i in range(2 * n)]
    rows = []
    for tp, shift in (("baseline", 0.0), ("7d", 1.5)):
        for i, s in enumerate(subjects):
            group = "lesion" if i < n else "sham"
            value = rng.normal() + (shift if group == "lesion" else 0.0)
            rows.append({"subject": s, "group": group, "timepoint": tp, "x": value})
    df = pd.DataFrame(rows)
    df.attrs["units"] = {"x": "deg"}
    return df


@pytest.fixture(scope="module")
def cohort() -> pd.DataFrame:
    return _cohort()


@pytest.fixture(scope="module")
def between(cohort) -> pd.DataFrame:
    return S.between_groups(cohort, "x", [("lesion", "sham", "greater")])


def test_label_columns_returns_a_labelled_copy_and_leaves_the_input():
    df = pd.DataFrame({"a": [1.0], "b": [2]})
    df.attrs["units"] = {"a": "deg"}
    out = label_columns(df, units={"b": "1"}, long_name={"a": "angle", "b": "count"})
    assert out.attrs["units"] == {"a": "deg", "b": "1"}
    assert out.attrs["long_name"] == {"a": "angle", "b": "count"}
    assert df.attrs == {"units": {"a": "deg"}}  # the input is untouched
    assert out is not df
    with pytest.raises(ValueError, match="'c'"):
        label_columns(df, units={"c": "s"})
    legacy = pd.DataFrame({"a": [1.0], "b": [2.0]})
    legacy.attrs["units"] = "deg"  # an older table: one unit for all
    assert label_columns(legacy).attrs["units"] == {"a": "deg", "b": "deg"}


def test_format_p_writes_small_values_once():
    assert format_p(0.0004) == "<0.001"
    assert format_p(0.0123) == "0.012"
    assert format_p(0.0123, 2) == "0.01"
    assert format_p(np.nan) == ""


def test_stats_tables_are_labelled(cohort, between):
    _assert_labelled(between, "between_groups")
    assert between.attrs["units"]["hl"] == "deg"
    assert between.attrs["role"]["p_holm"] == "p-value"
    within = S.against_baseline(cohort, "x", alternative="greater")
    _assert_labelled(within, "against_baseline")
    _assert_labelled(S.long_table(cohort, "x"), "long_table")
    _assert_labelled(S.group_quantiles(cohort, "x"), "group_quantiles")
    _assert_labelled(S.format_table(between, output="frame"), "format_table frame")
    _assert_labelled(S.with_published(between), "with_published")
    _assert_labelled(S.session_table(cohort), "session_table")
    _assert_labelled(S.add_adjustments(between[["p"]]), "add_adjustments")
    _assert_labelled(S.exact_p_lattice(3, 4), "exact_p_lattice")
    _assert_labelled(S.signed_rank_p_lattice(4), "signed_rank_p_lattice")
    _assert_labelled(S.fayat_table("A1"), "fayat_table")
    design = S.study_design(cohort, control="sham", directions={"x": "greater"})
    _assert_labelled(design.animals, "StudyDesign.animals")
    b, w = S.design_tables(cohort, "x", design)
    _assert_labelled(b, "design_tables between")
    _assert_labelled(w, "design_tables within")
    sessions = S.session_table(cohort.assign(session=[f"e{i}" for i in range(24)]))
    planted = pd.Series(np.arange(24, dtype=float), index=sessions.index)
    rec = S.recovery_table(b, planted, sessions, control="sham")
    _assert_labelled(rec, "recovery_table")
    assert rec.attrs["units"]["planted Δ"] == "deg"


def test_power_and_mixed_tables_are_labelled(cohort):
    sim = S.normal_shift(1.0)
    power = S.power_by_simulation(sim, [4, 5], n_sim=20, rng=1)
    _assert_labelled(power, "power_by_simulation")
    needed = S.animals_needed(sim, n_sim=20, rng=1, n_max=8)
    _assert_labelled(needed.table, "animals_needed")
    with pytest.raises(TypeError, match="unknown option"):
        S.power_by_simulation(sim, 4, n_simulations=20)
    fit = S.mixed_model(cohort, "x")
    _assert_labelled(fit.table, "mixed_model")
    assert fit.table.attrs["units"]["estimate"] == "deg"


def _two_estimates(n=200):
    rng = np.random.default_rng(2)
    q_ref = Q.from_rotvec(0.3 * rng.normal(size=(n, 3)))
    noisy = Q.from_rotvec(0.3 * rng.normal(size=(n, 3)) + 0.01)
    acc = Q.gravity(q_ref)
    rec = schema.make_recording(acc, fs=100.0, q_ref=q_ref, units={"acc": "g"})
    return rec, {"a": q_ref, "b": noisy}


def test_evaluate_tables_are_labelled():
    rec, est = _two_estimates()
    _assert_labelled(E.error_summary(est, rec), "error_summary")
    errors = {k: E.tilt_errors(v, rec["q_ref"].values) for k, v in est.items()}
    immobile = np.arange(rec.sizes["time"]) % 2 == 0
    _assert_labelled(E.table1(errors, immobile), "table1")
    _assert_labelled(E.FAYAT_TABLE1, "FAYAT_TABLE1")
    speed = np.linspace(0.0, 100.0, rec.sizes["time"])
    _assert_dataset_labelled(E.binned_by_speed(errors, speed, [0, 50, 100]), "binned")
    pair = E.pairwise_tilt_rms(est)
    assert pair.attrs["units"] == "deg" and pair.attrs["long_name"]
    grid = xr.DataArray(
        [[3.0, 2.0, 2.5], [1.0, 1.5, 1.2]],
        dims=("beta", "recording"),
        coords={"beta": [0.01, 0.1]},
        attrs={"units": "deg", "long_name": "tilt RMSE"},
    )
    held = E.loto(grid)
    _assert_dataset_labelled(held, "loto")
    assert held["score"].attrs["units"] == "deg"
    _assert_labelled(E.loto_summary({"m": grid}), "loto_summary")


def test_calibration_learn_and_realism_tables_are_labelled():
    noise = AllanNoise(arw=0.0141, bias_instability=0.0012, tau_min=90.0, rrw=2.1e-4)
    _assert_labelled(allan_noise_table(noise), "allan_noise_table")
    truth = {"arw": 0.0141, "rrw": 2e-4, "bias_instability": None}
    _assert_labelled(allan_noise_table(noise, truth), "allan_noise_table (truth)")
    rng = np.random.default_rng(5)
    n = 3000
    acc = np.tile([0.0, 0.0, 1.0], (n, 1)) + 0.01 * rng.normal(size=(n, 3))
    gyr = 20.0 * rng.normal(size=(n, 3))
    rec = schema.make_recording(acc, gyr, fs=100.0, units={"acc": "g", "gyr": "deg/s"})
    _assert_labelled(B.realism_table({"one": rec}), "realism_table")


def test_learn_tables_are_labelled():
    torch = pytest.importorskip("torch")
    from tiltlab.learn.tables import config_table, layer_table
    from tiltlab.learn.training import TrainConfig

    net = torch.nn.Sequential(torch.nn.Linear(3, 2), torch.nn.Tanh())
    _assert_labelled(layer_table(net), "layer_table")
    _assert_labelled(config_table(TrainConfig()), "config_table")


def test_evaluate_states_renamed_with_the_old_name_warning():
    assert E.MOTION_STATES == ("immobile", "moving")
    with pytest.warns(FutureWarning, match="MOTION_STATES"):
        assert E.STATES == E.MOTION_STATES
