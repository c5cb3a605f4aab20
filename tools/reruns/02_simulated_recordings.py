"""Chapter 2 with another seed, smaller sizes and a BROAD trial (m/s², rad/s, 285.7 Hz)
as the real recording of the realism check; variant "tag": an accelerometer + magnetometer
bio-logging tag without a gyroscope as that recording.

Both checks also read the chapter's glued statements back and assert that each agrees
with what it summarises: the parameters it names, the printed counts, the recovery table
behind the cohort verdict, the realism table recomputed with the package, and the
comparison words of the exercise answers."""

from __future__ import annotations

import math
import re
from pathlib import Path

from ._common import glued, glued_float, printed
from ._foreign import convert

PARAMS = {
    "SOURCE": "broad:3",
    "SEED": 5,
    "DURATION_S": 120.0,
    "N_TUMBLE": 20,
    "MOCAP_DURATION_S": 20.0,
    "COHORT_N_PER_GROUP": 1,
    "COHORT_DURATION_S": 60.0,
    "WORKERS": 1,
    "THRESHOLD_DEG_S": 10.0,
}
FS_DEFAULT = 100.0  # the chapter's FS (not changed by either rerun)
_REALISM_ROWS = {
    "still": "still mode (deg/s)",
    "valley": "valley (deg/s)",
    "moving": "moving mode (deg/s)",
    "depth": "valley depth (rel. to lower mode)",
    "hf": "gyro power share > 10 Hz",
}
_NO_GYR = "not computed (the real recording has no gyroscope)"


def _close(
    a: float, b: float, rel: float = 1e-6, what: str = "", tol: float = 1e-12
) -> None:
    if not math.isclose(a, b, rel_tol=rel, abs_tol=tol):
        raise AssertionError(f"{what}: the chapter says {a!r}, expected {b!r}")


def _word(values: dict, name: str, expected: str) -> None:
    if name not in values:
        raise AssertionError(f"the chapter glued no {name}")
    if values[name].strip() != expected:
        raise AssertionError(
            f"{name} reads {values[name]!r}, its numbers say {expected!r}"
        )


def _check_parameters(values: dict, params: dict) -> None:
    """Glued parameters are the ones the run used; glued model identities hold."""
    from tiltlab import simulate

    _close(
        glued_float(values, "ch2_threshold"),
        params["THRESHOLD_DEG_S"],
        what="threshold",
    )
    _close(glued_float(values, "ch2_duration_s"), params["DURATION_S"], what="duration")
    _close(
        glued_float(values, "ch2_cohort_duration_s"),
        params["COHORT_DURATION_S"],
        what="cohort session length",
    )
    n = params["COHORT_N_PER_GROUP"]
    design = simulate.CohortDesign() if n is None else simulate.CohortDesign.small(n)
    n_sessions = sum(design.groups.values()) * len(design.time_points)
    _close(glued_float(values, "ch2_n_sessions"), n_sessions, what="sessions")
    _close(
        glued_float(values, "ch2_paper_n_animals"),
        sum(simulate.FAYAT_GROUPS.values()),
        what="animals of the paper's design",
    )
    if not glued_float(values, "ch2_zoh_err_rad") < 1e-9:
        raise AssertionError(
            "q_ref is not the zero-order-hold integral to rounding error"
        )
    if not glued_float(values, "ch2_acc_identity_err_g") < 1e-9:
        raise AssertionError("the ideal accelerometer differs from R^T (e_z + a_lin)")
    if not glued_float(values, "ch2_tumble_window_ms") / 1e3 < glued_float(
        values, "ch2_tumble_hold_s"
    ):
        raise AssertionError("the static window before a trigger is longer than a hold")
    # the marker distance the prose says Fayat et al.'s 0.38 deg and 0.21 mm imply
    d12 = glued_float(values, "ch2_d12_mm")
    if abs(math.degrees(math.atan(0.21 / d12)) - 0.38) > 0.005:
        raise AssertionError(f"a marker distance of {d12} mm does not give 0.38 deg")


def _check_counts(nb_path: Path, values: dict) -> str:
    """The glued clock-slip counts are the printed TTL interval counts; the recovery
    verdict names exactly the features whose glued error ratio is under a tenth."""
    counts = {
        int(k): int(v)
        for k, v in printed(nb_path, r"(\d+) samples × (\d+)", "TTL interval counts")
    }
    regular = int(glued_float(values, "ch2_ttl_samples"))
    slips = sum(v for k, v in counts.items() if k != regular)
    _close(glued_float(values, "ch2_n_slips"), slips, what="clock slips")
    _close(
        glued_float(values, "ch2_n_ttl_intervals"),
        sum(counts.values()),
        what="TTL intervals",
    )
    ratios = {
        name: glued_float(values, f"ch2_recovery_{key}_pct")
        for key, name in (("imm", "immobility"), ("tilt", "tilt"), ("circ", "circling"))
    }
    verdict = values.get("ch2_recovery_verdict", "")
    came_back, _, did_not = verdict.partition(" came back within a tenth")
    named_ok = set(re.findall(r"immobility|tilt|circling", came_back))
    named_not = set(re.findall(r"immobility|tilt|circling", did_not))
    if named_ok != {n for n, r in ratios.items() if r < 10} or named_not != {
        n for n, r in ratios.items() if not r < 10
    }:
        raise AssertionError(f"recovery verdict {verdict!r} against ratios {ratios}")
    return f"{slips} clock slips; recovery {verdict!r}"


def _check_realism(values: dict, params: dict, has_gyr: bool) -> str:
    """The realism statements are the package's table, recomputed, read correctly."""
    import numpy as np

    from tiltlab import behavior, datasets, simulate

    rec = simulate.simulate_session(
        params["DURATION_S"], params.get("FS", FS_DEFAULT), seed=params["SEED"]
    )
    speed = behavior.recording_speed(rec)
    below = 100 * float((speed < params["THRESHOLD_DEG_S"]).mean())
    _close(
        glued_float(values, "ch2_below_sim_pct"), below, what="simulated share below"
    )
    state = 100 * float((rec["state"] == simulate.STATES.index("immobile")).mean())
    _close(glued_float(values, "ch2_state_imm_pct"), state, what="immobile-state share")
    _word(values, "ch2_below_vs_state", "lower than" if below < state else "at least")
    if not has_gyr:
        for key in _REALISM_ROWS:
            for part in ("sim", "real", "cmp"):
                _word(values, f"ch2_cmp_{key}_{part}", _NO_GYR)
        if "no gyroscope" not in values.get("ch2_speed_summary", ""):
            raise AssertionError(
                "the speed summary does not say that there is no gyroscope"
            )
        return "gyroscope statements say that they were not computed"
    real = datasets.load(params["SOURCE"])
    table = behavior.realism_table(
        {"real": real, "simulated": rec}, threshold_deg_s=params["THRESHOLD_DEG_S"]
    )
    for key, label in _REALISM_ROWS.items():
        sim, rl = table.loc[label, ["simulated", "real"]]
        _word(values, f"ch2_cmp_{key}_sim", "n/a" if sim != sim else f"{sim:.3g}")
        _word(values, f"ch2_cmp_{key}_real", "n/a" if rl != rl else f"{rl:.3g}")
        cmp = "higher than" if sim > rl else "lower than"
        _word(values, f"ch2_cmp_{key}_cmp", cmp if sim != rl else "the same as")
    valleys = table.loc["valley (deg/s)"]
    bimodal = bool(np.isfinite(valleys).all())
    _word(
        values,
        "ch2_cmp_bimodal",
        "Both are bimodal" if bimodal else "They are not both bimodal",
    )
    summary = values.get("ch2_speed_summary", "")
    if bimodal and not (
        f"{valleys['simulated']:.1f} °/s (simulated)" in summary
        and f"{valleys['real']:.1f} °/s (real)" in summary
    ):
        raise AssertionError(
            f"speed summary {summary!r} against valleys {dict(valleys)}"
        )
    _close(
        glued_float(values, "ch2_real_duration_s"),
        float(table.loc["duration (s)", "real"]),
        what="real duration",
    )
    return f"realism statements match the recomputed table (valleys {dict(valleys.round(1))})"


def _check_exercises(nb_path: Path, values: dict) -> str:
    """Exercise answers: each comparison word follows from the glued numbers, which are
    the printed ones."""
    state, planted = (
        glued_float(values, "ch2_ex1_state"),
        glued_float(values, "ch2_ex1_planted"),
    )
    below = glued_float(values, "ch2_ex1_below")
    _word(
        values, "ch2_ex1_state_cmp", "falls short of" if state < planted else "reaches"
    )
    _word(
        values,
        "ch2_ex1_below_cmp",
        "lower still than" if below < state else "not lower than",
    )
    errors = [
        abs(float(e))
        for e in printed(nb_path, r"error ([+-][0-9.]+) °/s", "offset errors")
    ]
    _close(glued_float(values, "ch2_ex2_max_miss"), max(errors), 0, "offset miss", 6e-4)
    removed = glued_float(values, "ch2_ex2_removed_pct")
    _word(values, "ch2_ex2_verdict", "enough" if removed >= 90 else "not enough")
    raw, fixed = (
        glued_float(values, "ch2_ex3_raw_max"),
        glued_float(values, "ch2_ex3_fixed_max"),
    )
    _close(glued_float(values, "ch2_ex3_factor"), raw / fixed, what="drift factor")
    residual = glued_float(values, "ch2_ex3_residual")
    _word(
        values,
        "ch2_ex3_vs_residual",
        "more than" if fixed > residual else "no more than",
    )
    largest = [
        float(x) for x in printed(nb_path, r"largest ([0-9.]+)°", "largest drift")
    ]
    _close(max(largest), raw, rel=1e-3, what="largest raw drift")
    return f"exercise words agree (offset removed ≥ {removed:.0f} %)"


def _check_summary(nb_path: Path, params: dict, has_gyr: bool) -> str:
    values = glued(nb_path)
    _check_parameters(values, params)
    notes = [
        _check_counts(nb_path, values),
        _check_realism(values, params, has_gyr),
        _check_exercises(nb_path, values),
    ]
    return "; ".join(notes)


def check(nb_path: Path, params: dict) -> str:
    """The realism check analysed SOURCE: its fraction of time below the threshold, as
    printed, equals the package's computation on that recording; the glued summary
    statements agree with what they summarise."""
    from tiltlab import behavior, datasets

    real = datasets.load(params["SOURCE"])
    expected = float(
        (behavior.recording_speed(real) < params["THRESHOLD_DEG_S"]).mean()
    )
    found = printed(
        nb_path,
        r"([0-9.]+)% of the time below ([0-9.]+) °/s",
        "fraction below the threshold",
    )
    got, threshold = float(found[0][0]) / 100, float(found[0][1])
    if threshold != params["THRESHOLD_DEG_S"] or abs(got - expected) > 0.0006:
        raise AssertionError(
            f"chapter says {got:.1%} below {threshold:g} °/s, the package gives "
            f"{expected:.1%} below {params['THRESHOLD_DEG_S']:g} °/s"
        )
    summary = _check_summary(nb_path, params, has_gyr=True)
    return (
        f"{got:.1%} of {params['SOURCE']} below {threshold:g} °/s "
        f"(package: {expected:.1%}); {summary}; {_check_a3(nb_path, real, params)}"
    )


def _check_a3(nb_path: Path, real, params: dict) -> str:
    """Fig. A3: the printed shares of samples that the immobility rules reclassify
    (below the threshold but moving, above it but immobile), recomputed with
    ``behavior.detect_immobility`` on the recording's angular speed."""
    import numpy as np

    from tiltlab import behavior

    thr = params["THRESHOLD_DEG_S"]
    speed = behavior.recording_speed(real)
    gaps = ~np.isfinite(speed.values)
    still = np.asarray(
        behavior.detect_immobility(speed.fillna(1e9), threshold_deg_s=thr)
    )
    below = (speed.values < thr) & ~gaps
    above = (speed.values >= thr) & ~gaps
    want = (
        100 * float((below & ~still).sum() / max(below.sum(), 1)),
        100 * float((above & still).sum() / max(above.sum(), 1)),
    )
    found = printed(
        nb_path,
        r"([0-9.]+) % of the samples below the threshold are moving after the rules, "
        r"([0-9.]+) % of those above it immobile",
        "Fig. A3 reclassification line",
    )
    got = tuple(float(v) for v in found[0])
    if any(abs(a - b) > 0.051 for a, b in zip(got, want)):
        raise AssertionError(f"Fig. A3 line says {got} %, recomputed {want} %")
    return f"Fig. A3: {got[0]:.1f} % / {got[1]:.1f} % reclassified (package agrees)"


def prepare_tag(tmp: Path) -> dict:
    """An accelerometer + magnetometer tag from another lab (no gyroscope, a few short NaN
    gaps), converted by ``tiltlab convert``, as the real recording of the realism check:
    immobility from the accelerometer's VeDBA rule, the gyroscope's comparisons skipped
    with a line."""
    return {**PARAMS, "SOURCE": str(convert("tag", tmp))}


def check_tag(nb_path: Path, params: dict) -> str:
    """The immobile fraction the chapter prints for the tag equals ``behavior.immobility``
    applied directly, with the rule it names (the accelerometer's, without a gyroscope),
    the chapter says what it skips, and its glued summary statements agree with what they
    summarise (the gyroscope's say that they were not computed)."""
    from tiltlab import behavior, datasets

    real = datasets.load(params["SOURCE"])
    immobile = behavior.immobility(real)
    expected = float(immobile.mean())
    found = printed(nb_path, r"immobile ([0-9.]+)% of the time", "immobile fraction")
    got = float(found[0]) / 100
    if abs(got - expected) > 0.0005:
        raise AssertionError(
            f"chapter says {got:.1%} immobile, behavior.immobility gives {expected:.1%}"
        )
    rule = printed(nb_path, r"immobility: (.+)", "immobility rule")[0].strip()
    if rule != immobile.attrs["rule_description"]:
        raise AssertionError(f"chapter used the rule {rule!r}")
    printed(nb_path, r"has no gyroscope: .+ skipped", "line saying what is skipped")
    summary = _check_summary(nb_path, params, has_gyr=False)
    return f"immobile fraction {got:.1%} (package: {expected:.1%}; {rule}); {summary}"


VARIANTS = {"tag": prepare_tag}
