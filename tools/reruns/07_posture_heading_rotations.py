"""Chapter 7 on a simulated head recording with a magnetometer (NetCDF), and shorter tracks."""

from __future__ import annotations

from pathlib import Path

from ._common import printed


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
    return {
        "SOURCE": str(path),
        "HEAD_SOURCE": str(path),
        "WINDOW_S": 1.0,
        "GYRO_STEP_S": 0.25,
        "N_CHECK": 300,
        "TRACK_STEPS": 1200,
        "ANCHOR_INTERVALS": [30, 120, 600],
        "N_TRACKS": 4,
        "FLAP_PERIOD_S": 0.25,
        "SEED": 1,
    }


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
