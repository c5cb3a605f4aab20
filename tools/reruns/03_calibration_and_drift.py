"""Chapter 3 on a simulated tumble test (12 Fibonacci orientations, a trigger channel,
true offsets) instead of the real three-position test, with smaller simulated studies."""

from __future__ import annotations

from pathlib import Path

from ._common import printed

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
    return (
        f"{len(intervals)} still periods, first-pass gyro offset "
        f"{np.round(expected, 2).tolist()} deg/s (package agrees)"
    )


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
    return (
        f"{len(intervals)} still periods (accelerometer rule), offset fit rms norm "
        f"error {got:.5f} g (package: {expected:.5f} g)"
    )


VARIANTS = {"tag": prepare_tag}
