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
        f"(package: {expected:.3f}°); {notes}"
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
        f"(package: {expected:.2f}°); {notes}"
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


VARIANTS = {"tag": prepare_tag}
