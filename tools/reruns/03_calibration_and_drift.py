"""Chapter 3 on a simulated tumble test (12 Fibonacci orientations, a trigger channel,
true offsets) instead of the real three-position test, with smaller simulated studies."""

from __future__ import annotations

from pathlib import Path

from ._common import glued, glued_float, printed

# still-period settings of the rerun; the simulated holds last 4 s
THRESHOLD, MIN_STILL_S = 3.0, 1.0


def prepare(tmp: Path) -> dict:
    """Simulate a 12-orientation tumble test, save it as NetCDF, shrink the studies."""
    from tiltlab import io, simulate

    rec = simulate.tumble_test(12, fs=100.0, seed=7, hold_s=4.0, move_s=1.0)
    path = io.save_netcdf(rec, tmp / "tumble_sim.nc")
    return {
        "SOURCE": str(path),
        "STILL_THRESHOLD": THRESHOLD,
        "MIN_STILL_S": MIN_STILL_S,
        "SEED": 7,
        "N_LATTICE": 20,
        "N_REPEATS": 2,
        "DRIFT_HOURS": 0.25,
        "MOCAP_S": 60.0,
    }


def check(nb_path: Path, params: dict) -> str:
    """The still-period count and the first-pass gyro offset the chapter prints equal
    the package's on the prepared file."""
    import numpy as np

    from tiltlab import calibration, datasets

    rec = datasets.load(params["SOURCE"])
    intervals = calibration.detect_static(
        rec,
        threshold_deg_s=params["STILL_THRESHOLD"],
        min_duration_s=params["MIN_STILL_S"],
    )
    found = printed(nb_path, r"still periods found: (\d+)", "still-period count")
    if int(found[0]) != len(intervals):
        raise AssertionError(
            f"chapter found {found[0]} still periods, detect_static gives {len(intervals)}"
        )
    off = printed(
        nb_path,
        r"first-pass gyro offset \([^)]*\): \[([^\]]+)\]",
        "first-pass gyro offset",
    )
    got = np.array(off[0].split(), float)
    expected = calibration.robust_gyro_offset(rec)
    if not np.allclose(got, expected, atol=1e-3):
        raise AssertionError(f"chapter offset {got}, robust_gyro_offset {expected}")
    values = glued(nb_path)
    _still_summary(values, len(intervals), np.linalg.norm(expected))
    _exercise_1(values, rec, params)
    notes = _summary_checks(nb_path, values, rec, intervals)
    return (
        f"{len(intervals)} still periods, first-pass gyro offset "
        f"{np.round(expected, 2).tolist()} deg/s (package agrees); {notes}; "
        f"{_check_lacanna(values)}; {_check_fig1(values, params)}"
    )


def _check_fig1(values: dict, params: dict) -> str:
    """Fig. 1b and 1e: the offset correction lowers the median norm error, the log
    holds one calibration per date asked, and each sensor's largest offset spread over
    the year equals its glued ratio times the fits' largest error against the truth."""
    raw = glued_float(values, "ch3_band_raw_mg")
    corr = glued_float(values, "ch3_band_corr_mg")
    if not corr < raw:
        raise AssertionError(f"corrected error {corr} mg is not below raw {raw} mg")
    n = int(glued_float(values, "ch3_log_n"))
    if n != params.get("LOG_DATES", n):
        raise AssertionError(f"the log holds {n} calibrations, LOG_DATES asked another")
    for s in ("acc", "gyr"):
        spread = glued_float(values, f"ch3_log_{s}_spread")
        ratio = glued_float(values, f"ch3_log_{s}_ratio_true")
        err = glued_float(values, f"ch3_log_{s}_fit_err")
        if abs(spread - ratio * err) > 1e-6 * max(1.0, abs(spread)):
            raise AssertionError(
                f"{s}: spread {spread} is not {ratio} x fit error {err}"
            )
    return f"Fig. 1b: {raw:.1f} -> {corr:.1f} mg; Fig. 1e: {n} calibrations"


def _check_lacanna(values: dict) -> str:
    """LaCanna's sections: the combined drift correction ends where the linear fit
    does (a least-squares slope is linear in the data) and starts below the prior
    alone; Table 6's summary is reproduced; the per-axis complementary filter agrees
    with the quaternion one."""
    end_c = glued_float(values, "ch3_comb_combined_end")
    end_l = glued_float(values, "ch3_comb_linear_fit_end")
    if abs(end_c - end_l) > 1e-9 * max(1.0, abs(end_l)):
        raise AssertionError(f"combined correction ends at {end_c}, linear fit {end_l}")
    if not glued_float(values, "ch3_comb_combined_early") < glued_float(
        values, "ch3_comb_prior_early"
    ):
        raise AssertionError("the combined correction is not below the prior early on")
    verdict = values.get("ch3_t6_verdict", "").strip()
    if verdict != "reproduce":
        raise AssertionError(f"Table 6 verdict {verdict!r}, expected 'reproduce'")
    gap = glued_float(values, "ch3_cf_gap")
    if not gap < 0.5:
        raise AssertionError(f"complementary filters differ by {gap} deg")
    return f"LaCanna: combined = linear fit at the end, Table 6 reproduced, gap {gap:.2g} deg"


def prepare_tag(tmp: Path) -> dict:
    """An accelerometer + magnetometer tag from another lab (no gyroscope, short NaN
    gaps), converted by ``tiltlab convert``, as the calibration recording: still periods
    come from the accelerometer, the gyroscope parts say they are skipped."""
    from ._foreign import convert

    return {**prepare(tmp), "SOURCE": str(convert("tag", tmp))}


def check_tag(nb_path: Path, params: dict) -> str:
    """The still-period count and the offset fit's rms norm error the chapter prints
    equal the package's: ``behavior.immobility`` (the accelerometer rule) and
    ``calibration.fit_offsets`` on the means of those periods."""
    import numpy as np

    from tiltlab import behavior, calibration, datasets, units

    rec = datasets.load(params["SOURCE"])
    if "gyr" in rec:
        raise AssertionError(f"{params['SOURCE']} has a gyroscope: not the tag")
    printed(nb_path, r"has no gyroscope: still periods from the accelerometer", "skip")
    still = behavior.immobility(rec, min_duration_s=params["MIN_STILL_S"])
    intervals = calibration.mask_to_intervals(still.values)
    found = printed(nb_path, r"still periods found: (\d+)", "still-period count")
    if int(found[0]) != len(intervals):
        raise AssertionError(
            f"chapter found {found[0]} still periods, the accelerometer rule gives "
            f"{len(intervals)}"
        )
    acc = units.acc_to_g(rec.acc.values, rec.acc.attrs["units"])
    means = np.array([acc[s:e].mean(axis=0) for s, e in intervals])
    sems = np.array(
        [acc[s:e].std(axis=0, ddof=1) / np.sqrt(e - s) for s, e in intervals]
    )
    fit = calibration.fit_offsets(means, sem=sems)
    expected = float(np.sqrt(np.mean(fit.residuals**2)))
    rms = printed(
        nb_path,
        r"rms norm error at the static means after the fit: ([0-9.]+) g",
        "rms norm error of the offset fit",
    )
    got = float(rms[0])
    if abs(got - expected) > 6e-6:
        raise AssertionError(
            f"chapter rms norm error {got} g, package {expected:.5f} g"
        )
    values = glued(nb_path)
    if "no gyroscope" not in values.get("ch3_still_summary", ""):
        raise AssertionError(
            "the still-period summary does not say the tag has no gyroscope"
        )
    if "skipped" not in values.get("ch3_ex1_answer", ""):
        raise AssertionError(
            "the answer to exercise 1 does not say the study is skipped"
        )
    notes = _summary_checks(nb_path, values, rec, intervals)
    return (
        f"{len(intervals)} still periods (accelerometer rule), offset fit rms norm "
        f"error {got:.5f} g (package: {expected:.5f} g); {notes}"
    )


def _near(a: float, b: float, what: str, tol: float) -> None:
    if abs(a - b) > tol:
        raise AssertionError(f"{what}: glued {a}, recomputed {b}")


def _still_summary(values: dict, n_still: int, offset_norm: float) -> None:
    """The glued still-period sentence states the detected count and offset norm."""
    text = values.get("ch3_still_summary", "")
    if f"finds {n_still} still periods" not in text:
        raise AssertionError(f"still-period summary {text!r} does not state {n_still}")
    if f"{offset_norm:.2f} °/s" not in text:
        raise AssertionError(
            f"still-period summary {text!r}: offset norm {offset_norm:.2f}"
        )
    if int(glued_float(values, "ch3_n_still")) != n_still:
        raise AssertionError("glued still-period count differs from detect_static")


def _exercise_1(values: dict, rec, params: dict) -> None:
    """The answer's "same number of periods at every threshold" matches detect_static."""
    from tiltlab import calibration

    counts = {
        len(
            calibration.detect_static(
                rec, threshold_deg_s=t, min_duration_s=params["MIN_STILL_S"]
            )
        )
        for t in (1.0, 3.0, 10.0, 30.0)
    }
    same = values.get("ch3_ex1_same", "") == "never stops"
    if same != (len(counts) == 1):
        raise AssertionError(
            f"exercise 1 says {values.get('ch3_ex1_same')!r}; period counts {counts}"
        )


def _summary_checks(nb_path: Path, values: dict, rec, intervals) -> str:
    """The summary's glued statements agree with the values they summarise."""
    import re

    import numpy as np

    from tiltlab import calibration, datasets
    from tiltlab.calibration.published import (
        LACANNA_REPORTED,
        LACANNA_TABLES,
        lacanna_drift_summary,
    )

    g = lambda name: glued_float(values, name)  # noqa: E731
    # section 2: pose count and "solved exactly" iff three poses
    res = calibration.tumble_calibration(rec, intervals=intervals)
    if int(g("ch3_n_poses")) != res.fit.n:
        raise AssertionError(f"glued {g('ch3_n_poses')} poses, fit uses {res.fit.n}")
    exact = "solved exactly" in values["ch3_offset_summary"]
    if exact != (res.fit.n == 3):
        raise AssertionError(f"offset summary {values['ch3_offset_summary']!r}")
    # "unmodelled scale and misalignment, not noise, bound the accuracy"
    ratio_text = re.search(r"is (\d+) to (\d+) times", values["ch3_offset_summary"])
    if ratio_text is None or int(ratio_text.group(1)) <= 1:
        raise AssertionError(
            f"systematic/statistical ratio {values['ch3_offset_summary']!r}"
        )
    # section 3: floor and ellipsoid statements
    if (values["ch3_ell_below"] == "goes below") != (
        g("ch3_ell_residual") < g("ch3_floor")
    ):
        raise AssertionError(
            "ellipsoid 'below the floor' word contradicts the glued values"
        )
    if g("ch3_floor_gap") > 0.25 * g("ch3_floor"):
        raise AssertionError(
            "predicted and observed floors differ: 'the floor is set by "
            "scale and misalignment' is not supported"
        )
    if g("ch3_three_point_gap") > 0.25 * g("ch3_three_point_max"):
        raise AssertionError("three-point offset error does not follow the scale error")
    # section 4: the temperature model beats a constant offset
    if not g("ch3_temp_res_model") < g("ch3_temp_res_const"):
        raise AssertionError("temperature model leaves more than the constant offset")
    # section 5: LaCanna's summaries recomputed with the package
    ours = np.asarray(lacanna_drift_summary())
    ratio = ours / np.asarray(LACANNA_REPORTED.rate_deg_s)
    n_ok = int(np.sum(np.abs(ratio - 1) < 0.02))
    if int(g("ch3_n_repro")) != n_ok or int(g("ch3_n_summaries")) != len(ours):
        raise AssertionError(
            f"glued {g('ch3_n_repro')} reproduced summaries, package {n_ok}"
        )
    axis = ours[list(LACANNA_REPORTED.index).index("axis to axis")]
    _near(g("ch3_axis_recomputed"), float(axis), "axis-to-axis rate", 1e-9)
    printed_axis = float(LACANNA_REPORTED.rate_deg_s["axis to axis"])
    reproduces = abs(axis / printed_axis - 1) < 0.02
    if (values["ch3_axis_verdict"] == "reproduces") != reproduces:
        raise AssertionError(f"axis verdict {values['ch3_axis_verdict']!r}")
    groups = [
        g(n)
        for n in values
        if n.startswith(("ch3_pair_", "ch3_ex3_t", "ch3_ex3_d", "ch3_ex3_p"))
    ]
    hit = any(abs(v / printed_axis - 1) < 0.02 for v in groups)
    if (values["ch3_grouping_verdict"] == "One grouping") != hit or len(groups) < 9:
        raise AssertionError(
            f"grouping verdict {values['ch3_grouping_verdict']!r}, {groups}"
        )
    flat = LACANNA_TABLES[LACANNA_TABLES.position_deg == 0]
    m = flat.set_index(["table", "device", "axis"]).mean_deg_s
    _near(
        g("ch3_prior_err_max"),
        float((m.loc[2] - m.loc[3]).abs().max()),
        "prior error",
        1e-9,
    )
    # section 5: Allan terms listed once, found or missed
    found, missed = values["ch3_allan_found"], values["ch3_allan_missed"]
    if (
        "angle random walk" not in found + missed
        or "rate random walk" not in found + missed
    ):
        raise AssertionError(f"Allan lists: found {found!r}, missed {missed!r}")
    # section 6: the magnetometer verdict follows the glued heading errors
    better = g("ch3_head_ell") < min(g("ch3_head_four"), g("ch3_head_minmax"))
    if (values["ch3_mag_verdict"] == "corrects") != better:
        raise AssertionError(f"magnetometer verdict {values['ch3_mag_verdict']!r}")
    if not g("ch3_mag_cal_max") - g("ch3_mag_cal_min") < g("ch3_mag_raw_max") - g(
        "ch3_mag_raw_min"
    ):
        raise AssertionError("the calibrated norms spread more than the raw ones")
    # section 7: the repaired pairing is no worse than the naive one
    if not g("ch3_ttl_repaired") <= g("ch3_ttl_naive") + 1e-9:
        raise AssertionError("TTL repair leaves larger lags than naive pairing")
    # section 9: the saved calibration applied what the tumble calibration corrects
    session = datasets.load("fayat:example")
    todo = [c for c in res.calibration.corrects() if c.split("_")[0] in session]
    if values["ch3_applied"] != ", ".join(todo):
        raise AssertionError(f"applied {values['ch3_applied']!r}, expected {todo}")
    printed(
        nb_path,
        r"same corrections as the fitted calibration: (yes)",
        "saved/loaded match",
    )
    printed(nb_path, r"CalibrationError: .*changed after saving", "tamper refusal")
    return f"{len(values)} glued values, summary statements consistent"


VARIANTS = {"tag": prepare_tag}
