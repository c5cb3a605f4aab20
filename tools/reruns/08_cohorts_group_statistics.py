"""Chapter 8 on a small simulated cohort with other groups and time points."""

from __future__ import annotations

from pathlib import Path

from ._common import printed


def prepare(tmp: Path) -> dict:
    """A cohort unlike chapter 8's default: three groups, three time points, 1-min sessions."""
    from tiltlab import simulate

    design = simulate.CohortDesign.small().select(
        groups={"Arsanilate": 4, "ShamArsanilate": 4, "Healthy": 4},
        time_points=["baseline", "1d", "7d"],
    )
    folder = simulate.simulate_cohort(
        tmp / "cohort08",
        design=design,
        duration_s=60.0,
        fs=100.0,
        seed=3,
        workers=2,
        progress=False,
    )
    return {
        "COHORT_MANIFEST": str(folder / "manifest.csv"),
        "SEED": 3,
        "MAP_ANIMALS": 2,
        "POWER_N": [3, 4, 6, 8],
        "N_SIM_POWER": 100,
    }


def check(nb_path: Path, params: dict) -> str:
    """The chapter analysed the prepared cohort (its groups and time points) and printed
    its tables: one Fayat block (lesion vs control, lesion vs sham, sham vs control)
    between groups and every group against baseline, per feature and time point. The
    circling index it printed for one session (§4) is the feature pipeline's, computed
    here directly from that session's file and its tumble test."""
    import pandas as pd

    from tiltlab import cohort

    manifest = pd.read_csv(params["COHORT_MANIFEST"])
    n_groups = manifest["group"].nunique()
    n_post = manifest["timepoint"].nunique() - 1
    found = printed(
        nb_path,
        r"Computed (\d+) tables \((\d+) tests\) for (\d+) features, (\d+) groups, "
        r"(\d+) time points after",
        "table summary line",
    )
    tables, tests, n_features, groups, post = map(int, found[0])
    if (groups, post) != (n_groups, n_post):
        raise AssertionError(
            f"chapter analysed {groups} groups × {post} time points, the prepared cohort "
            f"has {n_groups} × {n_post}"
        )
    expected = n_features * n_post * (3 + n_groups)
    if tables != 2 * n_features or tests != expected:
        raise AssertionError(
            f"chapter computed {tables} tables / {tests} tests, expected "
            f"{2 * n_features} / {expected}"
        )
    lines = printed(
        nb_path,
        r"(\S+) (\S+): max \|ω_z\(gravity\) − ω·g\| = \S+ °/s; circling index ([-+0-9.]+) /min",
        "circling index (§4)",
    )
    subject, timepoint, index = lines[0]
    table = cohort.read_manifest(params["COHORT_MANIFEST"])
    rows = table.table
    row = rows[(rows["subject"] == subject) & (rows["timepoint"] == timepoint)].iloc[0]
    features = cohort.session_features(
        cohort.load_session(row, table.root),
        cohort.FeatureConfig(),
        calibration=cohort.load_calibration(row, table.root),
    )
    circling = float(features["circling_index"])
    if abs(float(index) - circling) > 0.0006:
        raise AssertionError(
            f"chapter says circling index {index} /min for {subject} {timepoint}, "
            f"the feature pipeline {circling:+.3f} /min"
        )
    return (
        f"{tables} tables, {tests} tests on {groups} groups × {post} time points; "
        f"{subject} {timepoint} circling {index} /min (package: {circling:+.3f})"
    )
