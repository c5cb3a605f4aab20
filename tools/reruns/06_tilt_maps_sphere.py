"""Chapter 6 on another BROAD trial (rad/s gyroscope instead of the rat's deg/s), on a
coarser lattice and with the heading maps of another trial."""

from __future__ import annotations

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
    """The immobile fraction the chapter prints equals Fayat's rules applied directly."""
    from tiltlab import behavior, datasets

    rec = datasets.load(params["SOURCE"])
    expected = float(
        behavior.immobility(
            rec, threshold_deg_s=params["IMMOBILE_DEG_S"], gyr_offset="auto"
        ).mean()
    )
    found = printed(nb_path, r"immobile ([0-9.]+)% of the time", "immobile fraction")
    got = float(found[0]) / 100
    if abs(got - expected) > 0.0005:
        raise AssertionError(
            f"chapter says {got:.1%} immobile, behavior.immobility gives {expected:.1%}"
        )
    return f"immobile fraction {got:.1%} (package: {expected:.1%})"


def prepare_foreign(tmp: Path) -> dict:
    """A hand-held board from another lab, converted by ``tiltlab convert``."""
    board = str(convert("board", tmp))
    return {**PARAMS, "SOURCE": board, "HEADING_SOURCE": board, "N_BOOT": 100}


check_foreign = check
VARIANTS = {"foreign": prepare_foreign}
