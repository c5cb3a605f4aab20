"""Chapter 4 on other data: a fast-translation BROAD trial for the first look, three other
BROAD trials with coarse grids, two short simulated rats, and a simulated rat saved as a
NetCDF file (a lab's own recording) in place of the real rat."""

from __future__ import annotations

from pathlib import Path

from ._common import printed


def prepare(tmp: Path) -> dict:
    """A 90-s simulated rat (100 Hz, with the simulator's sensor errors) written with
    ``tiltlab.io.save_netcdf``, as a reader would pass their own recording."""
    from tiltlab import io, simulate

    rat = simulate.simulate_session(90.0, 100.0, seed=11)
    path = io.save_netcdf(rat, tmp / "rat04.nc")
    return {
        "SOURCE": "broad:15",
        "RAT_SOURCE": str(path),
        "BROAD_UNDISTURBED": [3, 10, 21],
        "BROAD_DISTURBED": [24],
        "GRID": "coarse",
        "SHIFTS": [0.0, 0.75],
        "AHRS_TRIALS": [],
        "N_SIM": 2,
        "SIM_DURATION_S": 45.0,
        "SIM_SEED": 2022,
        "N_JOBS": 2,
    }


def check(nb_path: Path, params: dict) -> str:
    """The Madgwick error the chapter prints for ``SOURCE`` (§2) equals BROAD's inclination
    RMSE computed directly with ``tiltlab.evaluate``."""
    from tiltlab import datasets, evaluate, filters

    found = printed(
        nb_path,
        r"madgwick with default parameters \(beta = [0-9.]+\): tilt RMSE ([0-9.]+) deg",
        "Madgwick error for SOURCE",
    )
    rec = datasets.load(params["SOURCE"])
    expected = evaluate.tilt_rmse(filters.estimate(rec, "madgwick"), rec)
    got = float(found[0])
    if abs(got - expected) > 0.0006:
        raise AssertionError(
            f"chapter says Madgwick RMSE {got:.3f} deg on {params['SOURCE']}, "
            f"evaluate.tilt_rmse gives {expected:.3f} deg"
        )
    return (
        f"Madgwick RMSE on {params['SOURCE']} {got:.3f} deg (package: {expected:.3f})"
    )
