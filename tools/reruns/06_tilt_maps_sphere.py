"""Chapter 6 on another BROAD trial (rad/s gyroscope instead of the rat's deg/s), on a
coarser lattice and with the heading maps of another trial."""

from __future__ import annotations

import warnings
from pathlib import Path

from ._common import printed
from ._foreign import convert

PARAMS = {
    "SOURCE": "broad:2",
    "IMMOBILE_DEG_S": 12.0,
    "N_LATTICE": 2000,
    "N_BOOT": 200,
    "SIM_DURATION_S": 120.0,
    "HEADING_SOURCE": "broad:3",
}


def check(nb_path: Path, params: dict) -> str:
    """The immobile fraction the chapter prints (over the samples with a tilt) equals the
    package's immobility rule applied directly, and the rule it names is the one the
    recording allows (the gyroscope's, or the accelerometer's without one)."""
    from tiltlab import behavior, datasets, filters

    rec = datasets.load(params["SOURCE"])
    immobile = behavior.immobility(
        rec, threshold_deg_s=params["IMMOBILE_DEG_S"], gyr_offset="auto"
    )
    with warnings.catch_warnings():  # the chapter prints the gaps
        warnings.simplefilter("ignore", RuntimeWarning)
        q = filters.estimate(rec, "lowpass", cutoff_hz=2.0, gaps="segments")
    valid = q.notnull().all("quat").values
    expected = float(immobile[valid].mean())
    found = printed(nb_path, r"immobile ([0-9.]+)% of the time", "immobile fraction")
    got = float(found[0]) / 100
    if abs(got - expected) > 0.0005:
        raise AssertionError(
            f"chapter says {got:.1%} immobile, behavior.immobility gives {expected:.1%}"
        )
    rule = printed(nb_path, r"immobility: (.+)", "immobility rule")[0]
    if rule.strip() != immobile.attrs["rule_description"]:
        raise AssertionError(f"chapter used the rule {rule!r}")
    return f"immobile fraction {got:.1%} (package: {expected:.1%}; {rule.strip()})"


def prepare_foreign(tmp: Path) -> dict:
    """A hand-held board from another lab, converted by ``tiltlab convert``."""
    board = str(convert("board", tmp))
    return {**PARAMS, "SOURCE": board, "HEADING_SOURCE": board, "N_BOOT": 100}


check_foreign = check
VARIANTS = {"foreign": prepare_foreign}


def prepare_tag(tmp: Path) -> dict:
    """An accelerometer + magnetometer tag from another lab (no gyroscope, a jittery
    millisecond clock), converted by ``tiltlab convert``: tilt from the static
    acceleration, immobility from VeDBA, the gyroscope's sections skipped with a line."""
    tag = str(convert("tag", tmp))
    return {**PARAMS, "SOURCE": tag, "HEADING_SOURCE": tag, "N_BOOT": 100}


check_tag = check
VARIANTS["tag"] = prepare_tag
