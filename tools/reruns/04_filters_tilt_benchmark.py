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


def prepare_tag(tmp: Path) -> dict:
    """The rerun's parameters with an accelerometer + magnetometer tag from another lab
    (no gyroscope, short NaN gaps), converted by ``tiltlab convert``, as the user's own
    recording of §6: only the low-pass tilt and the accelerometer immobility rule run."""
    from ._foreign import convert

    return {**prepare(tmp), "RAT_SOURCE": str(convert("tag", tmp))}


def check_tag(nb_path: Path, params: dict) -> str:
    """The immobile fraction the chapter prints for the tag (§6, summary) equals
    ``behavior.immobility`` (the accelerometer rule) on the converted file."""
    from tiltlab import behavior, datasets

    rat = datasets.load(params["RAT_SOURCE"])
    if "gyr" in rat:
        raise AssertionError(f"{params['RAT_SOURCE']} has a gyroscope: not the tag")
    printed(nb_path, r"has no gyroscope: of these methods only lowpass runs", "skip")
    found = printed(
        nb_path,
        r"no gyroscope\): accelerometer rule -> ([0-9.]+)% immobile",
        "immobile fraction of the tag",
    )
    got = float(found[0])
    expected = 100 * float(behavior.immobility(rat).mean())
    if abs(got - expected) > 0.051:
        raise AssertionError(
            f"chapter says {got:.1f} % immobile, behavior.immobility gives {expected:.1f} %"
        )
    return f"tag immobile {got:.1f} % by the accelerometer rule (package: {expected:.1f} %)"


VARIANTS = {"tag": prepare_tag}
