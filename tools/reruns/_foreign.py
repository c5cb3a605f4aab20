"""Recordings from other labs (the data mirror's ``foreign`` folder), converted by the
documented route: a shipped mapping and ``tiltlab convert``."""

from __future__ import annotations

import json
from pathlib import Path

SOURCES = {
    "board": ("sunsided_board", "board_sunsided/roll-and-tilt-at-45-90"),
    "tag": ("twlogger_tag", "tag_twlogger/T1D0711-00.CSV"),
    "foot": ("gaitmap_foot", "foot_gaitmap/imu_sample.csv"),
}


def convert(name: str, tmp: Path) -> Path:
    """``tiltlab convert`` one foreign recording into ``tmp/<name>.nc``."""
    from tiltlab import cli, datasets, io

    template, source = SOURCES[name]
    mirror = datasets.data_dir()
    if mirror is None or not (mirror / "foreign").is_dir():
        raise FileNotFoundError("the data mirror has no 'foreign' folder")
    mapping = tmp / f"{name}.json"
    mapping.write_text(json.dumps(io.mapping_template(template)))
    out = tmp / f"{name}.nc"
    args = [str(mirror / "foreign" / source), "--mapping", str(mapping), "--out"]
    if cli.main(["convert", *args, str(out), "--force"]) != 0:
        raise RuntimeError(f"tiltlab convert refused {source}")
    return out
