"""Chapter 1 on a lab-style NetCDF file: a simulated rat session (g, °/s, no
magnetometer, no ``movement`` mask), read through the file-path route of ``SOURCE``."""

from __future__ import annotations

from pathlib import Path

from ._common import printed
from ._foreign import convert


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
    """The median angle between a/|a| and the true tilt while still, as printed, equals
    the package's computation on the prepared file."""
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
    return (
        f"median angle a/|a| vs g_s while still {got:.2f}° (package: {expected:.2f}°)"
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
    """The sample count and rate the chapter prints are those of the converted file."""
    from tiltlab import datasets

    rec = datasets.load(params["SOURCE"])
    found = printed(nb_path, r": (\d+) samples, [0-9.]+ s at ([0-9.]+) Hz", "summary")
    n, fs = int(found[0][0]), float(found[0][1])
    if n != rec.sizes["time"] or abs(fs - float(rec.attrs["fs"])) > 0.01:
        raise AssertionError(f"chapter says {n} samples at {fs} Hz, the file differs")
    return f"converted file: {n} samples at {fs:g} Hz"


VARIANTS = {"foreign": prepare_foreign}


def prepare_tag(tmp: Path) -> dict:
    """An accelerometer + magnetometer tag from another lab (no gyroscope, raw counts
    scaled by the mapping, a jittery millisecond clock), converted by ``tiltlab convert``:
    the chapter's gyroscope sections say they are skipped."""
    return {**prepare_foreign(tmp), "SOURCE": str(convert("tag", tmp))}


check_tag = check_foreign
VARIANTS["tag"] = prepare_tag
