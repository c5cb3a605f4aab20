"""Saved feature tables of several configurations, read only when their digests match."""

import json

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from tiltlab import cohort, io
from tiltlab.io import IntegrityError


def _write(folder, names=("default", "fayat2021"), truth=True):
    lines = []
    for k, name in enumerate(names):
        ds = xr.Dataset(
            {"immobile_fraction": ("session", np.array([0.2, 0.3]) + k)},
            coords={"session": ["s1", "s2"], "group": ("session", ["A", "B"])},
            attrs={"feature_config": cohort.FeatureConfig().to_json()},
        )
        cohort.save_features(ds, folder / f"features_{name}.nc")
        lines.append(f"features_{name}.nc")
    if truth:
        pd.DataFrame({"session": ["s1", "s2"], "tilt_deg_planted": [0.0, 5.0]}).to_csv(
            folder / "truth.csv", index=False
        )
        lines.append("truth.csv")
    (folder / "run.json").write_text(json.dumps({"seed": 0}))
    io.write_sums(folder, {n: io.file_sha256(folder / n) for n in lines})


def test_round_trip_of_every_table_truth_and_run(tmp_path):
    _write(tmp_path)
    archive = cohort.read_feature_archive(tmp_path)
    assert list(archive.features) == ["default", "fayat2021"]
    assert archive.features["fayat2021"]["immobile_fraction"].values.tolist() == [
        1.2,
        1.3,
    ]
    assert archive.truth.loc["s2", "tilt_deg_planted"] == 5.0
    assert archive.run == {"seed": 0}
    bare = tmp_path / "bare"
    bare.mkdir()
    _write(bare, truth=False)
    assert cohort.read_feature_archive(bare).truth is None


def test_a_changed_or_missing_file_is_refused_by_name(tmp_path):
    _write(tmp_path)
    with open(tmp_path / "truth.csv", "a") as f:
        f.write("s3,1.0\n")
    with pytest.raises(IntegrityError, match="truth.csv: sha256"):
        cohort.read_feature_archive(tmp_path)
    _write(tmp_path)
    (tmp_path / "features_default.nc").unlink()
    with pytest.raises(IntegrityError, match="features_default.nc is listed"):
        cohort.read_feature_archive(tmp_path)


def test_bad_folders_are_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="no cohort archive folder"):
        cohort.read_feature_archive(tmp_path / "nope")
    with pytest.raises(IntegrityError, match="no SHA256SUMS"):
        cohort.read_feature_archive(tmp_path)
    (tmp_path / "SHA256SUMS").write_text("not a digest line\n")
    with pytest.raises(ValueError, match="line 1"):
        cohort.read_feature_archive(tmp_path)
    (tmp_path / "SHA256SUMS").write_text("")
    with pytest.raises(IntegrityError, match="empty checksum file"):
        cohort.read_feature_archive(tmp_path)
    (tmp_path / "notes.txt").write_text("no tables here")
    io.write_sums(tmp_path, {"notes.txt": io.file_sha256(tmp_path / "notes.txt")})
    with pytest.raises(ValueError, match="no features_"):
        cohort.read_feature_archive(tmp_path)
