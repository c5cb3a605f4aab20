"""Chapter 7 on a simulated head recording with a magnetometer (NetCDF), and shorter tracks;
variant "tag": an accelerometer + magnetometer bio-logging tag without a gyroscope."""

from __future__ import annotations

from pathlib import Path

from ._common import glued, glued_float, printed
from ._foreign import convert

#: the smaller numerical checks and tracks of every rerun
SMALL = {
    "WINDOW_S": 1.0,
    "GYRO_STEP_S": 0.25,
    "N_CHECK": 300,
    "TRACK_STEPS": 1200,
    "ANCHOR_INTERVALS": [30, 120, 600],
    "N_TRACKS": 4,
    "FLAP_PERIOD_S": 0.25,
    "SEED": 1,
}


def prepare(tmp: Path) -> dict:
    """A 2-min simulated session with a magnetometer, saved as the reader's own NetCDF file;
    it replaces both the BROAD trial and the rat recording (no BROAD ``movement`` flag, so
    rest comes from the immobility rules), with smaller numerical checks and tracks."""
    from tiltlab import io, simulate

    rec = simulate.simulate_session(
        120.0,
        100.0,
        seed=7,
        sensor=simulate.SensorModel(magnetometer=True),
        attrs={"subject": "simulated rat with a magnetometer"},
    )
    path = io.save_netcdf(rec, tmp / "simulated_head_mag.nc")
    return {"SOURCE": str(path), "HEAD_SOURCE": str(path), **SMALL}


def check(nb_path: Path, params: dict) -> str:
    """The median |yaw| per gyroscope step the chapter prints equals trig.body_rotations
    applied directly to the prepared recording."""
    import numpy as np

    from tiltlab import datasets, trig

    rec = datasets.load(params["SOURCE"])
    rot = trig.body_rotations(rec, window_s=params["GYRO_STEP_S"])
    expected = float(np.median(np.abs(np.degrees(rot.yaw))))
    found = printed(
        nb_path, r"median \|yaw\| per step ([0-9.]+)°", "median yaw per step"
    )
    got = float(found[0])
    if abs(got - expected) > 0.0005:
        raise AssertionError(
            f"chapter says median |yaw| {got:.3f}°, trig.body_rotations gives {expected:.3f}°"
        )
    notes = _prose(nb_path, params)
    return (
        f"median |yaw| per {params['GYRO_STEP_S']:g} s step {got:.3f}° "
        f"(package: {expected:.3f}°); {notes}; {_check_kestrel(nb_path, params)}"
    )


def prepare_tag(tmp: Path) -> dict:
    """An accelerometer + magnetometer tag from another lab (no gyroscope, no reference
    orientation, a few short NaN gaps), converted by ``tiltlab convert``, as both
    recordings: DBA, posture and the magnetic heading are computed, the gyroscope's
    sections say they are skipped."""
    tag = str(convert("tag", tmp))
    return {"SOURCE": tag, "HEAD_SOURCE": tag, **SMALL}


def check_tag(nb_path: Path, params: dict) -> str:
    """The circular mean of the magnetic azimuth the chapter prints (Eqs. 3 and 5 on the
    WINDOW_S means, no reference to compare with) equals trig.heading applied directly
    to the tag, and the chapter says that the body rotations are skipped."""
    import numpy as np

    from tiltlab import behavior, datasets, trig

    rec = datasets.load(params["SOURCE"])
    acc = behavior.static_acceleration(rec, window_s=params["WINDOW_S"])
    mag = behavior.static_acceleration(
        rec.mag.assign_attrs(fs=rec.fs), window_s=params["WINDOW_S"]
    )
    az = np.asarray(trig.heading(acc, mag).azimuth)
    az = az[np.isfinite(az)]
    expected = float(np.degrees(np.angle(np.mean(np.exp(1j * az)))))
    found = printed(
        nb_path,
        r"magnetic azimuth θ, circular mean (-?[0-9.]+)° over (\d+) samples",
        "magnetic azimuth",
    )
    got, n = float(found[0][0]), int(found[0][1])
    if abs(got - expected) > 0.005 or n != az.size:
        raise AssertionError(
            f"chapter says circular mean azimuth {got:.2f}° over {n} samples, "
            f"trig.heading gives {expected:.2f}° over {az.size}"
        )
    printed(nb_path, r"has no gyroscope: the body rotations are skipped", "skip line")
    notes = _prose(nb_path, params)
    return (
        f"circular mean magnetic azimuth {got:.2f}° over {n} samples "
        f"(package: {expected:.2f}°); {notes}; {_check_kestrel(nb_path, params)}"
    )


def _close(got: float, expected: float, what: str, rel: float = 1e-6) -> None:
    import numpy as np

    if not np.isclose(got, expected, rtol=rel, atol=1e-12):
        raise AssertionError(f"chapter glued {what} = {got}, recomputed {expected}")


def _prose(nb_path: Path, params: dict) -> str:
    """The glued summary statements against what they summarise: the worked examples of
    Figs. 2 and 3 recomputed, the round-off residuals small, the head's median elevation,
    the flapping/gliding medians and the exercises' counts and comparison words."""
    import re

    import numpy as np

    from tiltlab import behavior, datasets, simulate, trig

    v = glued(nb_path)
    # worked examples: the number of caption values reproduced to the printed digits
    a = trig.arc(np.pi / 6, np.pi / 6, np.pi / 2, np.pi / 3)
    apex = trig.great_circle_apex(np.pi / 6, np.pi / 6, a.initial)
    ours = np.pi / np.array([a.size, a.initial, a.final, *apex])
    paper = ["3.637", "3.256", "19.023", "2.978", "1.784"]
    n2 = sum(f"{o:.{len(p.split('.')[1])}f}" == p for o, p in zip(ours, paper))
    w3, eta3 = trig.sequential_arc_from_yaw_pitch(np.pi / 3, np.pi / 6)
    n3 = sum(f"{np.pi / x:.2f}" == p for x, p in zip([w3, eta3], ["2.80", "5.34"]))
    if (glued_float(v, "ch7_fig2_n_agree"), glued_float(v, "ch7_fig3_n_agree")) != (
        n2,
        n3,
    ):
        raise AssertionError("the chapter's count of reproduced caption values is off")
    for name in ("ch7_bridge_max", "ch7_eq5_max", "ch7_eq12_13_max"):
        if glued_float(v, name) > 1e-10:
            raise AssertionError(f"{name} is called round-off but is {v[name]}")
    if glued_float(v, "ch7_vedba_rot_diff") > 1e-10:
        raise AssertionError("VeDBA is said to be rotation invariant")
    # the head recording's median elevation quoted in §4
    head = datasets.load(params["HEAD_SOURCE"])
    post = trig.posture(behavior.static_acceleration(head, window_s=params["WINDOW_S"]))
    elev = float(np.degrees(np.nanmedian(post.elevation)))
    _close(glued_float(v, "ch7_head_median_elev"), elev, "median elevation")
    # §11: flapping and gliding medians of the simulated heave
    heave = simulate.simulate_heave(
        20.0, 100.0, period_s=params["FLAP_PERIOD_S"], rng=params["SEED"]
    )
    osc = trig.oscillation_stats(heave, level=1.0, window_s=1.0)
    flap = np.asarray(osc.cv.time < 10.0)
    cv = np.asarray(osc.cv)
    _close(glued_float(v, "ch7_cv_flapping"), float(np.median(cv[flap])), "flapping CV")
    _close(glued_float(v, "ch7_cv_gliding"), float(np.median(cv[~flap])), "gliding CV")
    # the step-error sentence: its word matches its two numbers
    m = re.search(
        r"(grows|does not grow).*from ([0-9.]+)° to ([0-9.]+)°", v["ch7_step_error"]
    )
    if m and (m.group(1) == "grows") != (float(m.group(3)) > float(m.group(2))):
        raise AssertionError(f"step error sentence: {v['ch7_step_error']!r}")
    # exercises: VeDBA grows with the window; the count of tracks below the target
    means = [float(behavior.dba(head, window_s=w).mean()) for w in (0.1, 0.5, 2.0)]
    grow = "grow" if np.all(np.diff(means) > 0) else "do not all grow"
    if v["ch7_ex1_grow"] != grow:
        raise AssertionError(f"exercise 1 says {v['ch7_ex1_grow']!r}, means {means}")
    errors = [
        float(e) for e in printed(nb_path, r"([0-9.]+) m(?:,|$|\n)", "errors")[-3:]
    ]
    below = sum(e < glued_float(v, "ch7_ex_target") for e in errors)
    if glued_float(v, "ch7_ex3_n_below") != below:
        raise AssertionError(f"exercise 3 counts {v['ch7_ex3_n_below']} of {errors}")
    return (
        f"prose: Fig. 2 {n2}/5, Fig. 3 {n3}/2, median elevation {elev:.1f}°, "
        f"CV flapping/gliding {np.median(cv[flap]):.2f}/{np.median(cv[~flap]):.2f}"
    )


def _html_table(nb_path: Path, marker: str, before_glue: str) -> dict[str, list[str]]:
    """Row label → cell texts of the last HTML table with a header cell ``marker``
    that the chapter displays before the cell that glues ``before_glue``; the header
    row under the key ``""``."""
    import html
    import json
    import re

    found = None
    for cell in json.loads(nb_path.read_text())["cells"]:
        outs = cell.get("outputs", []) if cell["cell_type"] == "code" else []
        names = {o.get("metadata", {}).get("scrapbook", {}).get("name") for o in outs}
        for o in outs:
            page = "".join(o.get("data", {}).get("text/html", ""))
            if f">{marker}<" in page:
                found = page
        if before_glue in names:
            break
    if found is None:
        raise AssertionError(f"the chapter shows no table with a column {marker!r}")
    rows = {}
    for tr in re.findall(r"<tr[^>]*>(.*?)</tr>", found, flags=re.S):
        cells = re.findall(r"<t[hd][^>]*>(.*?)</t[hd]>", tr, flags=re.S)
        cells = [html.unescape(re.sub(r"<[^>]+>", "", c)).strip() for c in cells]
        rows.setdefault(cells[0], cells[1:])
    return rows


def _check_kestrel(nb_path: Path, params: dict) -> str:
    """§11, kestrel behaviours: the glued agreements, the misclassified windows (glued
    and printed) and the time-budget table equal ``trig.classify_flight`` and
    ``trig.flight_time_budget`` recomputed on the same simulated heave and session.

    The chapter adds a 2° posture noise drawn from its shared generator, whose state
    this check cannot replay; the labels depend on φ only through each window's mean
    against ``LEVEL_TOL_DEG``, so the check uses the noise-free φ and first asserts that
    every window mean lies more than ten standard errors of that noise from the
    tolerance (then no draw of the noise can change a label)."""
    import numpy as np
    import pandas as pd
    import xarray as xr

    from tiltlab import simulate, trig

    p = {
        "FLAP_PERIOD_S": 0.18,
        "KESTREL_SEG_S": 10.0,
        "PERCH_DEG": 40.0,
        "LEVEL_TOL_DEG": 20.0,
        "SEED": 0,
    } | params
    fs, heave_s, seed = 100.0, 20.0, p["SEED"]  # as in the chapter's §11
    heave = simulate.simulate_heave(heave_s, fs, period_s=p["FLAP_PERIOD_S"], rng=seed)
    cls_fg = trig.classify_flight(heave, 0.0 * heave.values, level=1.0, window_s=1.0)
    n_seg = int(p["KESTREL_SEG_S"] * fs)
    beats = np.repeat([True, False], n_seg)
    sim_a = simulate.simulate_heave(
        2 * p["KESTREL_SEG_S"],
        fs,
        flapping=beats,
        period_s=0.11,
        glide_sd=0.05,
        rng=seed,
    )
    sim_b = simulate.simulate_heave(
        2 * p["KESTREL_SEG_S"],
        fs,
        flapping=beats,
        period_s=p["FLAP_PERIOD_S"],
        rng=seed + 1,
    )
    kestrel = xr.concat(
        [sim_a, sim_b.assign_coords(time=sim_b.time + 2 * p["KESTREL_SEG_S"])], "time"
    )
    truth = np.repeat(["hover", "perched", "flap", "glide"], n_seg)
    phi = np.where(truth == "perched", np.radians(p["PERCH_DEG"]), 0.0)
    cls = trig.classify_flight(
        kestrel, phi, level=1.0, window_s=1.0, level_tol_deg=p["LEVEL_TOL_DEG"]
    )
    margin = np.abs(np.abs(np.degrees(cls.elevation.values)) - p["LEVEL_TOL_DEG"])
    if margin.min() < 10 * 2.0 / np.sqrt(fs):
        raise AssertionError(
            f"a window's mean elevation lies {margin.min():.2f}° from LEVEL_TOL_DEG: "
            "the chapter's posture noise could change its label, this check cannot say"
        )
    labels = cls.behavior.values
    win_truth = truth[: labels.size * int(fs)][:: int(fs)]
    fg_truth = np.where(cls_fg.time.values < heave_s / 2, "flap", "glide")
    v = glued(nb_path)
    for name, want in (
        ("ch7_kestrel_agree", 100 * float(np.mean(labels == win_truth))),
        ("ch7_fg_agree", 100 * float(np.mean(cls_fg.behavior.values == fg_truth))),
    ):
        _close(glued_float(v, name), want, f"{name} (trig.classify_flight)")
    pairs = pd.Series(list(zip(win_truth, labels)))
    miss = pairs[pairs.str[0] != pairs.str[1]].value_counts()
    want = {f"{n} {a} window(s) labelled {b}" for (a, b), n in miss.items()}
    said = v["ch7_kestrel_miss"]
    said = set() if said == "none is misclassified" else set(said.split("; "))
    shown = printed(nb_path, r"misclassified windows: (.*)", "misclassified windows")
    shown = set() if shown[0] == "none" else set(shown[0].split("; "))
    if said != want or shown != want:
        raise AssertionError(
            f"§11 glues misclassified windows {sorted(said)} and prints {sorted(shown)}; "
            f"trig.classify_flight gives {sorted(want)}"
        )
    table = _html_table(nb_path, "classified (s)", "ch7_kestrel_agree")
    expected = {
        "simulated (s)": pd.Series(truth).value_counts() / fs,
        "classified (s)": trig.flight_time_budget(cls)["duration (s)"],
        "classified, flap/glide heave (s)": trig.flight_time_budget(cls_fg)[
            "duration (s)"
        ],
    }
    for j, col in enumerate(table[""]):
        for cls_name in trig.FLIGHT_CLASSES:
            got = float(table[cls_name][j])
            want_s = float(expected[col].get(cls_name, 0.0))
            if abs(got - want_s) > 1e-6 * max(1.0, abs(want_s)):
                raise AssertionError(
                    f"§11 time budget: {cls_name}, {col} = {got:g}; "
                    f"trig.flight_time_budget gives {want_s:g}"
                )
    n_bad = int(miss.sum())
    return (
        f"kestrel: {n_bad} of {labels.size} windows misclassified, budget as "
        "trig.flight_time_budget"
    )


VARIANTS = {"tag": prepare_tag}
