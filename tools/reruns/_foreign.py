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


def foreign_cohort(tmp: Path, *, piece_s: float = 60.0, per_group: int = 4) -> Path:
    """A two-group, one-time-point cohort cut from the tag recording of another lab:
    consecutive ``piece_s`` pieces of the converted deployment, the first
    ``per_group`` as group ``early`` and the last ``per_group`` as ``late`` (their NaN
    gaps kept), plus one damaged session file that fails in the cohort run. Returns the
    manifest (written by hand, as a lab would)."""
    import pandas as pd

    from tiltlab import io

    rec = io.load_netcdf(convert("tag", tmp), validate=False)
    n = int(piece_s * float(rec.attrs["fs"]))
    count = rec.sizes["time"] // n
    starts = {"early": range(per_group), "late": range(count - per_group, count)}
    rows = []
    for group, ks in starts.items():
        for k in ks:
            path = tmp / "cohort" / group / f"piece{k:02d}.nc"
            io.save_netcdf(rec.isel(time=slice(k * n, (k + 1) * n)), path)
            rows.append((f"piece{k:02d}", f"tag-{k:02d}", group, path))
    broken = tmp / "cohort" / "late" / "broken.nc"
    broken.write_bytes(b"not a NetCDF file")
    rows.append(("broken", "tag-99", "late", broken))
    manifest = tmp / "cohort" / "manifest.csv"
    pd.DataFrame(
        [
            {
                "session": s,
                "subject": sub,
                "group": g,
                "timepoint": "day1",
                "file": str(p.relative_to(manifest.parent)),
                "reader": "netcdf",
            }
            for s, sub, g, p in rows
        ]
    ).to_csv(manifest, index=False)
    return manifest
