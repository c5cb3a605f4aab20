"""Chapter 8 on a small simulated cohort with other groups and time points, its design
given as parameters as a lab would; on a two-group, one-time-point cohort cut from
another lab's accelerometer-only tag, with a session that fails; and on the small cohort
the chapter simulates itself when it is not given the paper-scale one."""

from __future__ import annotations

import re
from pathlib import Path

from ._common import glued, glued_float, printed
from ._foreign import foreign_cohort

SMALL = {"SEED": 3, "MAP_ANIMALS": 2, "POWER_N": [3, 4, 6, 8], "N_SIM_POWER": 100}


def prepare(tmp: Path) -> dict:
    """A cohort unlike chapter 8's default: three groups, three time points, 1-min
    sessions, read from its manifest (so Fayat et al.'s design is not assumed: the
    control group, the family and the directions are parameters)."""
    from tiltlab import simulate, stats

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
        **SMALL,
        "COHORT_MANIFEST": str(folder / "manifest.csv"),
        "CONTROL_GROUP": "Healthy",
        "FAMILIES": {
            "Arsanilate": [
                list(p) for p in stats.FAYAT_DESIGN["families"]["Arsanilate"]
            ]
        },
        "DIRECTIONS": stats.FAYAT_DESIGN["directions"],
        "FOCUS_GROUP": "Arsanilate",
    }


def _design_lines(nb_path: Path) -> tuple[dict[str, int], int, int, int]:
    """The groups with their animals, and the tests / features / compared time points
    the chapter printed."""
    found = printed(nb_path, r"\d+ groups: (.+); control: ", "design line")
    groups = {g: int(n) for g, n in re.findall(r"(\S+) \((\d+) animals?\)", found[0])}
    tests = printed(
        nb_path,
        r"(\d+) tests for (\d+) features, \d+ groups and (\d+) compared time point",
        "test count line",
    )
    n_tests, n_features, n_post = map(int, tests[0])
    return groups, n_tests, n_features, n_post


def _recomputed(params: dict):
    """The chapter's features (from the cohort run's cache) and design, rebuilt with the
    package from the same parameters."""
    from tiltlab import cohort, stats

    manifest = cohort.read_manifest(params["COHORT_MANIFEST"])
    features = cohort.run_cohort(manifest, cohort.FeatureConfig(), progress=False)
    design = stats.study_design(
        features,
        control=params.get("CONTROL_GROUP"),
        baseline="auto",
        families=params.get("FAMILIES"),
        directions=params.get("DIRECTIONS"),
    )
    return features, design


def _check_summary(nb_path: Path, params: dict) -> str:
    """The summary's glued counts of significant cells equal those of the Tables A1–A8
    analogues recomputed with the package; exercise 1's and exercise 2's glued answers
    equal their recomputation; on a longitudinal design, the glued agreement between
    the Wald and the permutation tests equals its recomputation."""
    from tiltlab import stats

    values = glued(nb_path)
    features, design = _recomputed(params)
    alpha = 0.05
    counts = {"cells_between": 0, "sig_between": 0, "cells_within": 0, "sig_within": 0}
    tables = {}
    for feature in stats.FAYAT_FEATURE_TABLES:
        between, within = stats.design_tables(features, feature, design)
        tables[feature] = between
        for name, tidy in (("between", between), ("within", within)):
            if tidy is not None:
                counts[f"cells_{name}"] += int(tidy["p"].notna().sum())
                counts[f"sig_{name}"] += int((tidy["p_paper"] < alpha).sum())
    recovery = _check_recovery(nb_path, params, features, design, tables)
    for name, count in counts.items():
        if int(glued_float(values, f"ch8_{name}")) != count:
            raise AssertionError(
                f"summary glues ch8_{name} = {values[f'ch8_{name}']}, the package "
                f"recomputes {count}"
            )
    auto = stats.design_tables(features, "immobile_fraction_auto", design)[0]
    for name, tidy in (("fixed", tables["immobile_fraction"]), ("valley", auto)):
        n = int((tidy["p_paper"] < alpha).sum())
        if int(glued_float(values, f"ch8_ex2_n_{name}")) != n:
            raise AssertionError(
                f"exercise 2 glues {name} = {values[f'ch8_ex2_n_{name}']}, recomputed {n}"
            )
    word = values.get("ch8_ex2_fewer", "").strip()
    n_fixed, n_valley = (
        int(glued_float(values, f"ch8_ex2_n_{k}")) for k in ("fixed", "valley")
    )
    expected = (
        "fewer" if n_valley < n_fixed else "more" if n_valley > n_fixed else "as many"
    )
    if word != expected:
        raise AssertionError(
            f"exercise 2 says {word!r} cells, the counts say {expected!r}"
        )
    mw = next(
        n for n in range(2, 30) if 18 * stats.exact_p_lattice(n, n)["p"].iloc[0] <= 0.01
    )
    sr = next(
        n
        for n in range(2, 30)
        if 6 * stats.signed_rank_p_lattice(n)["p"].iloc[0] <= 0.01
    )
    if (
        int(glued_float(values, "ch8_ex1_mw_n")),
        int(glued_float(values, "ch8_ex1_sr_n")),
    ) != (mw, sr):
        raise AssertionError(
            f"exercise 1 glues {values['ch8_ex1_mw_n']}, {values['ch8_ex1_sr_n']}; lattices give {mw}, {sr}"
        )
    agree = terms = 0
    focus = params.get("FOCUS_GROUP")
    if design.longitudinal and focus:
        control = design.control
        for feature in stats.FAYAT_FEATURE_TABLES:
            long = stats.long_table(features, feature)
            fit = stats.mixed_model(
                long, "value", reference_group=control, baseline=design.baseline
            )
            pair = long[long["group"].isin([focus, control])]
            perm = stats.permutation_interaction(
                pair,
                "value",
                reference_group=control,
                baseline=design.baseline,
                seed=params.get("SEED", 0),
            )
            wald = fit.table.set_index("term").reindex(perm["term"])["p"].to_numpy()
            ok = ~(_nonfinite(wald) | _nonfinite(perm["p"].to_numpy()))
            terms += int(ok.sum())
            agree += int(
                ((wald[ok] < alpha) == (perm["p"].to_numpy()[ok] < alpha)).sum()
            )
        glued_pair = (
            int(glued_float(values, "ch8_perm_terms")),
            int(glued_float(values, "ch8_perm_agree")),
        )
        if glued_pair != (terms, agree):
            raise AssertionError(
                f"§8 glues {glued_pair[1]} of {glued_pair[0]} Wald/permutation agreements, "
                f"recomputed {agree} of {terms}"
            )
    return (
        f"glued counts match the package: {counts}; Wald/permutation agree on "
        f"{agree} of {terms}; {recovery}"
    )


PLANTED = {
    "immobile_fraction": "immobility_planted",
    "tilt_immobile_sagittal_deg": "tilt_deg_planted",
    "circling_index": "circling_cpm_planted",
}


def _check_recovery(nb_path: Path, params: dict, features, design, tables) -> str:
    """§9: for every feature with a planted value, the glued count of found planted
    differences, and the smallest found and largest missed sizes, are those of
    ``stats.recovery_table`` recomputed from the cohort's ``truth.csv``."""
    import pandas as pd

    from tiltlab import cohort, stats

    truth_path = Path(params["COHORT_MANIFEST"]).parent / "truth.csv"
    if not truth_path.is_file():
        return "no planted truth"
    truth = pd.read_csv(truth_path).set_index("session")
    sessions = stats.session_table(features).query("status == 'ok'")
    sentence = glued(nb_path).get("ch8_recovery_sentence", "")
    said = []
    for feature, column in PLANTED.items():
        t = stats.recovery_table(
            tables[feature], truth[column], sessions, control=design.control, alpha=0.05
        )
        found, missed = t[t["found"]], t[~t["found"]]
        want = [f"{cohort.feature_name(feature)}, {len(found)} of {len(t)}"]
        if len(found) and len(missed) and missed["planted Δ"].abs().max() > 0:
            want += [
                f"{found['planted Δ'].abs().min():.4g}",
                f"{missed['planted Δ'].abs().max():.4g}",
            ]
        lost = [w for w in want if w not in sentence]
        if lost:
            raise AssertionError(f"§9 says {sentence!r}; recomputed {want}")
        said.append(want[0])
    return "recovery as recomputed: " + "; ".join(said)


def _check_not_paper_cohort(nb_path: Path) -> str:
    """§11 says it analyses another cohort than §§2–10 when the chapter ran on its own."""
    said = glued(nb_path).get("ch8_same_cohort_md", "").strip()
    if said != "not the cohort of §§2–10":
        raise AssertionError(f"§11 calls the paper-scale cohort {said!r} in this run")
    return "§11: another cohort than §§2–10"


def _nonfinite(a):
    import numpy as np

    return ~np.isfinite(np.asarray(a, dtype=float))


def check(nb_path: Path, params: dict) -> str:
    """The chapter analysed the prepared cohort (its groups and time points) and printed
    its tables: one Fayat block (lesion vs control, lesion vs sham, sham vs control)
    between groups and every group against baseline, per feature and time point. The
    circling index it printed for one session (§4) is the feature pipeline's, computed
    here directly from that session's file and its tumble test."""
    import pandas as pd

    from tiltlab import cohort

    manifest = pd.read_csv(params["COHORT_MANIFEST"])
    groups, tests, n_features, post = _design_lines(nb_path)
    n_post = manifest["timepoint"].nunique() - 1
    if sorted(groups) != sorted(manifest["group"].unique()) or post != n_post:
        raise AssertionError(
            f"chapter analysed {sorted(groups)} × {post} time points, the prepared cohort "
            f"has {sorted(manifest['group'].unique())} × {n_post}"
        )
    expected = n_features * n_post * (3 + len(groups))  # one family of 3, and baseline
    if tests != expected:
        raise AssertionError(f"chapter computed {tests} tests, expected {expected}")
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
        f"{tests} tests on {len(groups)} groups × {post} time points; "
        f"{subject} {timepoint} circling {index} /min (package: {circling:+.3f}); "
        + _check_summary(nb_path, params)
        + "; "
        + _check_paper_scale(nb_path)
        + "; "
        + _check_not_paper_cohort(nb_path)
    )


PAPER = Path(__file__).resolve().parents[2] / "data" / "cohort_fayat2021"


def _check_paper_scale(nb_path: Path) -> str:
    """§11: the glued count of cells whose decision matches the printed Tables A1–A8,
    recomputed from the committed paper-scale table with the paper's definitions."""
    from tiltlab import cohort, stats

    big = cohort.read_feature_archive(PAPER).features["fayat2021"]
    d = stats.FAYAT_DESIGN
    design = stats.study_design(
        big, control=d["control"], families=d["families"], directions=d["directions"]
    )
    same = cells = 0
    for feature, names in stats.FAYAT_FEATURE_TABLES.items():
        tidy = stats.design_tables(
            big, feature, design, method="paper", family_size=18, baseline_family_size=6
        )
        for name, t in zip(names, tidy):
            a = stats.published_agreement(t, stats.fayat_table(name))
            same, cells = same + int(a["agree"].sum()), cells + len(a)
    sentence = glued(nb_path).get("ch8_scale_sentence", "")
    if f"{same} of {cells} cells reach the same decision" not in sentence:
        raise AssertionError(f"§11 says {sentence!r}; recomputed {same} of {cells}")
    return f"paper scale: {same} of {cells} cells as printed"


def prepare_foreign(tmp: Path) -> dict:
    """Two groups of 1-min pieces of a real accelerometer-only tag deployment (NaN gaps
    kept), one time point, and one damaged session file."""
    return {
        **SMALL,
        "COHORT_MANIFEST": str(foreign_cohort(tmp)),
        "CONTROL_GROUP": "early",
        "POWER_N": [3, 4, 6],
    }


def check_foreign(nb_path: Path, params: dict) -> str:
    """The chapter took the design from the data (two groups with their animals, one
    time point: between-group tests only), listed the failed session, and ran one
    comparison per feature."""
    import pandas as pd

    manifest = pd.read_csv(params["COHORT_MANIFEST"])
    groups, tests, n_features, post = _design_lines(nb_path)
    ok = manifest[manifest["session"] != "broken"]
    expected = ok.groupby("group")["subject"].nunique().to_dict()
    if groups != expected or post != 1 or tests != n_features:
        raise AssertionError(
            f"chapter: groups {groups}, {post} time point(s), {tests} tests; the cohort: "
            f"{expected}, 1 time point, {n_features} tests"
        )
    printed(nb_path, r"between-group tests only", "single time point line")
    failed = printed(nb_path, r"left out: (.+)", "failed sessions")
    if "broken" not in failed[0]:
        raise AssertionError(f"the failed session is not listed: {failed[0]!r}")
    return (
        f"{groups}, one time point, {tests} tests, failed session listed; "
        + _check_summary(nb_path, params)
        + "; "
        + _check_not_paper_cohort(nb_path)
    )


N_SMALL = 6


def prepare_small(tmp: Path) -> dict:
    """No manifest, ``SIMULATE``: the chapter simulates Fayat et al.'s design with six
    animals per group and 1-min sessions in the run (§11 still reads the paper-scale
    cohort)."""
    return {
        **SMALL,
        "SIMULATE": True,
        "N_PER_GROUP": N_SMALL,
        "DURATION_S": 60.0,
        "POWER_N": [3, 4, 6],
    }


def check_small(nb_path: Path, params: dict) -> str:
    """The chapter simulated the five groups of the design with the requested animals
    and seven time points, said so, and ran the Fayat blocks of tests; §11's agreement
    count is the package's."""
    from tiltlab import stats

    groups, tests, n_features, post = _design_lines(nb_path)
    expected = {g: N_SMALL for g in ("Kainate", "ShamKainate", "Arsanilate")}
    expected |= {"ShamArsanilate": N_SMALL, "Healthy": N_SMALL}
    if groups != expected or post != 6:
        raise AssertionError(f"chapter analysed {groups} × {post} compared time points")
    families = stats.FAYAT_DESIGN["families"]
    n_between = sum(len(pairs) for pairs in families.values())
    want = n_features * post * (n_between + len(groups))
    if tests != want:
        raise AssertionError(f"chapter computed {tests} tests, expected {want}")
    said = glued(nb_path).get("ch8_cohort_md", "")
    if f"{N_SMALL} animals per group, 60-s sessions" not in said:
        raise AssertionError(f"the chapter says it analysed {said!r}")
    return (
        f"{tests} tests on the cohort simulated in the run ({said}); "
        + _check_paper_scale(nb_path)
        + "; "
        + _check_not_paper_cohort(nb_path)
    )


VARIANTS = {"foreign": prepare_foreign, "small": prepare_small}
