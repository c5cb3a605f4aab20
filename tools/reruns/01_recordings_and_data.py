"""Chapter 1 on a lab-style NetCDF file: a simulated rat session (g, °/s, no
magnetometer, no ``movement`` mask), read through the file-path route of ``SOURCE``."""

from __future__ import annotations

import re
from pathlib import Path

from ._common import glued, glued_float, printed
from ._foreign import convert


def _close(a: float, b: float, tol: float, what: str) -> None:
    if abs(a - b) > tol:
        raise AssertionError(f"{what}: the chapter says {a:g}, it should be {b:g}")


def _check_tilt_sentence(values: dict) -> str:
    """Section 4's glued sentence: its numbers are the glued ones and the printed median,
    and the accelerometer departs further from the tilt when the sensor moves."""
    sentence = values.get("ch1_tilt_agreement", "")
    if "ch1_rest_median" not in values:  # no ground truth: the sentence says it skips
        if "skipped" not in sentence:
            raise AssertionError(f"no ground truth, yet section 4 says: {sentence!r}")
        return "section 4 skipped (no q_ref)"
    rest = glued_float(values, "ch1_rest_median")
    moving = glued_float(values, "ch1_moving_p95")
    said = re.findall(r"([0-9.]+)°", sentence)
    if len(said) != 3:
        raise AssertionError(f"section 4's sentence lost its numbers: {sentence!r}")
    _close(float(said[0]), round(rest, 2), 0.006, "median angle at rest (sentence)")
    _close(float(said[2]), round(moving, 1), 0.06, "95th percentile moving (sentence)")
    if moving <= float(said[1]):
        raise AssertionError(
            f"the prose says the direction departs from the tilt during movement, but "
            f"its 95th percentile moving ({moving:.2f}°) is not above the one at rest "
            f"({said[1]}°)"
        )
    return f"rest median {rest:.2f}° < moving 95th percentile {moving:.1f}°"


def _check_summary(nb_path: Path, params: dict) -> str:
    """The chapter's glued statements agree with what they summarise, on any data."""
    import numpy as np

    from tiltlab import datasets

    values = glued(nb_path)
    notes = [_check_tilt_sentence(values)]
    # section 5: the rat's counter steps, recounted from the file
    steps = datasets.load("fayat:example")["counter"].diff("time").to_series()
    counts = steps.value_counts()
    mode = int(counts.idxmax())
    if int(values["ch1_rat_mode_step"]) != mode:
        raise AssertionError("the rat's usual counter step is not the glued one")
    if int(values["ch1_rat_n_steps"]) != len(steps):
        raise AssertionError("the glued number of rat intervals is not the file's")
    if int(values["ch1_rat_n_other"]) != len(steps) - int(counts[mode]):
        raise AssertionError("the glued number of unusual rat intervals is wrong")
    others = sorted(int(v) for v in counts.index if int(v) != mode)
    if values["ch1_rat_other_steps"].strip() != (
        " or ".join(map(str, others)) or "other"
    ):
        raise AssertionError("the glued unusual counter steps are not the file's")
    rat_fs = glued_float(values, "ch1_rat_fs")
    _close(glued_float(values, "ch1_rat_counter_hz"), mode * rat_fs, 1e-9, "counter")
    # exercise 1: the glued median is the printed one, and it is close to g
    median = glued_float(values, "ch1_ex1_median")
    shown = float(printed(nb_path, r"median ‖a‖: ([0-9.]+) m/s²", "exercise 1")[0])
    _close(shown, round(median, 2), 0.006, "exercise 1 median (printed)")
    if abs(median - 9.81) > 0.5:
        raise AssertionError(f"exercise 1 says {median:.2f} m/s² is close to g")
    # exercise 2: the comparison word follows the glued numbers
    largest, half = (glued_float(values, f"ch1_ex2_{k}") for k in ("largest", "half"))
    _close(half, 0.5 / 8192, 1e-12, "half a count")
    word = "less" if largest < half else "more"
    if values["ch1_ex2_vs_half"].strip() != word:
        raise AssertionError(f"exercise 2 says {values['ch1_ex2_vs_half']!r}")
    fs_counts = float(printed(nb_path, r"\nfs ([0-9.]+) Hz; largest", "exercise 2")[0])
    same = "the same" if fs_counts == float(params["CSV_FS"]) else "another"
    if values["ch1_ex2_same_fs"].strip() != same:
        raise AssertionError(f"exercise 2 says {values['ch1_ex2_same_fs']!r} rate")
    # exercise 3: the missing estimates are the samples the logger lost, at the gap
    n_drop = int(values["ch1_n_dropped"])
    if int(values["ch1_ex3_missing"]) != n_drop or int(values["ch1_ex3_warnings"]) < 1:
        raise AssertionError(
            "exercise 3: missing estimates differ from the lost samples"
        )
    period = 1.0 / float(params["CSV_FS"])
    first, gap_t = (
        glued_float(values, "ch1_ex3_first"),
        glued_float(values, "ch1_gap_t"),
    )
    if not 0 <= first - gap_t < period + 1e-9:
        raise AssertionError(
            f"exercise 3: estimate missing from {first}, gap at {gap_t}"
        )
    _close(glued_float(values, "ch1_fallback_s"), 30.0, 1e-9, "the raw-signal fallback")
    if not np.isfinite(glued_float(values, "ch1_phone_fs")):
        raise AssertionError("the phone export's rate is not glued")
    notes.append(f"rat counter x{mode}; {n_drop} lost samples = missing estimates")
    return "; ".join(notes)


def prepare(tmp: Path) -> dict:
    """Write a 90-s simulated session with its ground truth as ``sim_session.nc``."""
    from tiltlab import io, simulate

    rec = simulate.simulate_session(90.0, 100.0, seed=11)
    path = io.save_netcdf(rec, tmp / "sim_session.nc")
    return {
        "SOURCE": str(path),
        "MAT_SOURCE": "broad:4",
        "WINDOW": [10.0, 30.0],
        "STILL_DEG_S": 8.0,
        "COHORT_TRIALS": [5],
        "CSV_DURATION_S": 40.0,
        "CSV_FS": 200.0,
    }


def check(nb_path: Path, params: dict) -> str:
    """The median angle between a/|a| and the true tilt while still, as printed and
    glued, equals the package's computation on the prepared file; the chapter's glued
    statements agree with what they summarise (``_check_summary``)."""
    import numpy as np

    from tiltlab import behavior, datasets, filters, quaternion

    rec = datasets.load(params["SOURCE"])
    g = filters.gravity(rec["q_ref"])
    still = g.notnull().all("axis") & (
        behavior.recording_speed(rec) < params["STILL_DEG_S"]
    )
    expected = float(
        np.median(np.degrees(quaternion.angle_between(rec["acc"][still], g[still])))
    )
    found = printed(
        nb_path,
        r"angle between a/\|a\| and g_s: median ([0-9.]+)°",
        "median angle (section 4)",
    )
    got = float(found[0])
    if abs(got - expected) > 0.006:
        raise AssertionError(
            f"chapter says median {got:.2f}°, the package gives {expected:.2f}°"
        )
    rest = glued_float(glued(nb_path), "ch1_rest_median")
    _close(round(rest, 2), got, 0.006, "glued median angle at rest vs printed")
    return (
        f"median angle a/|a| vs g_s while still {got:.2f}° (package: {expected:.2f}°); "
        + _check_summary(nb_path, params)
    )


def prepare_foreign(tmp: Path) -> dict:
    """A hand-held board from another lab (one MATLAB file per sensor, bursty clocks),
    converted by ``tiltlab convert``; the second recording a foot IMU's two-row CSV."""
    return {
        "SOURCE": str(convert("board", tmp)),
        "MAT_SOURCE": str(convert("foot", tmp)),
        "WINDOW": [0.0, 30.0],
        "STILL_DEG_S": 8.0,
        "COHORT_TRIALS": [5],
        "CSV_DURATION_S": 40.0,
        "CSV_FS": 200.0,
    }


def check_foreign(nb_path: Path, params: dict) -> str:
    """The sample count and rate the chapter prints are those of the converted file,
    and the chapter's glued statements agree with what they summarise."""
    from tiltlab import datasets

    rec = datasets.load(params["SOURCE"])
    found = printed(nb_path, r": (\d+) samples, [0-9.]+ s at ([0-9.]+) Hz", "summary")
    n, fs = int(found[0][0]), float(found[0][1])
    if n != rec.sizes["time"] or abs(fs - float(rec.attrs["fs"])) > 0.01:
        raise AssertionError(f"chapter says {n} samples at {fs} Hz, the file differs")
    return f"converted file: {n} samples at {fs:g} Hz; " + _check_summary(
        nb_path, params
    )


VARIANTS = {"foreign": prepare_foreign}


def prepare_tag(tmp: Path) -> dict:
    """An accelerometer + magnetometer tag from another lab (no gyroscope, raw counts
    scaled by the mapping, a jittery millisecond clock), converted by ``tiltlab convert``:
    the chapter's gyroscope sections say they are skipped."""
    return {**prepare_foreign(tmp), "SOURCE": str(convert("tag", tmp))}


check_tag = check_foreign
VARIANTS["tag"] = prepare_tag
