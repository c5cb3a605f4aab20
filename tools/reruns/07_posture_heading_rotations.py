"""Chapter 7 on a simulated head recording with a magnetometer (NetCDF), and shorter tracks;
variant "tag": an accelerometer + magnetometer bio-logging tag without a gyroscope."""

from __future__ import annotations

from pathlib import Path

from ._common import printed
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
    return f"median |yaw| per {params['GYRO_STEP_S']:g} s step {got:.3f}° (package: {expected:.3f}°)"


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
    return f"circular mean magnetic azimuth {got:.2f}° over {n} samples (package: {expected:.2f}°)"


VARIANTS = {"tag": prepare_tag}
