"""The data registry: generated from the manifest, checksums enforced, loaders."""

import json
import shutil

import numpy as np
import pytest

import tiltlab.datasets as d


def test_registry_matches_manifest(data_mirror):
    manifest = json.loads((data_mirror / "MANIFEST.json").read_text())
    files = {f["file"]: f for ds in manifest["datasets"].values() for f in ds["files"]}
    reg = d.registry()
    assert set(reg) == set(files)
    for name, f in files.items():
        assert reg[name]["sha256"] == f["sha256"] and reg[name]["url"] == f["url"]
        assert reg[name]["bytes"] == f["bytes"]
    assert "doi:10.3390/data6070072" in d.citation("broad")


def test_registry_lists_trials():
    trials = d.broad_trials()
    assert len(trials) == 30 and 2 in trials and 13 not in trials
    assert trials[2].endswith(".hdf5") and trials[1].endswith(".mat")


def test_load_broad_trials(data_mirror):
    r = d.load_broad_trial(2)
    assert r.sizes["time"] == 53240
    assert r.attrs["fs"] == pytest.approx(2000 / 7)
    r1 = d.load_broad_trial("01_undisturbed_slow_rotation_A")
    assert r1.sizes["time"] == 56940 and r1.attrs["fs"] == pytest.approx(2000 / 7)
    groups = d.broad_trial_groups()
    assert sum("undisturbed" in g for g in groups.values()) == 17
    with pytest.raises(d.DataError, match="not available"):
        d.load_broad_trial(13)


def test_load_fayat(data_mirror):
    assert d.load_fayat_example().sizes["time"] == 4893
    assert d.load_fayat_tumble().attrs["fs"] == 300.0


def _mirror_copy(tmp_path, data_mirror, name):
    mirror = tmp_path / "mirror"
    (mirror / name).parent.mkdir(parents=True)
    shutil.copy(data_mirror / name, mirror / name)
    return mirror


def test_checksum_mismatch_names_the_file(tmp_path, monkeypatch, data_mirror):
    name = "fayat2021/example_imu.csv"
    mirror = _mirror_copy(tmp_path, data_mirror, name)
    monkeypatch.setenv(d.ENV_DATA_DIR, str(mirror))
    assert d.fetch(name) == mirror / name
    with open(mirror / name, "ab") as f:
        f.write(b"1,2,3,4,5,6,7\n")
    with pytest.raises(
        d.DataError, match=r"checksum mismatch for fayat2021/example_imu\.csv"
    ):
        d.load_fayat_example()


def test_missing_file_in_mirror_is_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setenv(d.ENV_DATA_DIR, str(tmp_path))
    with pytest.raises(d.DataError, match="not in the local data mirror"):
        d.load_broad_trial(2)
    with pytest.raises(d.DataError, match="not in the tiltlab data registry"):
        d.fetch("broad/99_nothing.hdf5")


def test_offline_without_cache_never_downloads(tmp_path, monkeypatch):
    monkeypatch.delenv(d.ENV_DATA_DIR, raising=False)
    monkeypatch.setenv(d.ENV_CACHE_DIR, str(tmp_path))
    monkeypatch.setenv(d.ENV_OFFLINE, "1")
    with pytest.raises(d.DataError, match="forbids downloading"):
        d.fetch("fayat2021/example_imu.csv")


def test_offline_cache_is_verified(tmp_path, monkeypatch, data_mirror):
    name = "fayat2021/example_imu.csv"
    cache = _mirror_copy(tmp_path, data_mirror, name)
    monkeypatch.delenv(d.ENV_DATA_DIR, raising=False)
    monkeypatch.setenv(d.ENV_CACHE_DIR, str(cache))
    monkeypatch.setenv(d.ENV_OFFLINE, "1")
    assert d.fetch(name) == cache / name
    (cache / name).write_text("counter,ax\n")
    with pytest.raises(d.DataError, match="checksum mismatch"):
        d.fetch(name)


def test_loaded_recordings_are_independent(data_mirror):
    a = d.load_fayat_example()
    a["acc"][:] = np.nan
    b = d.load_fayat_example()
    assert np.isfinite(b.acc.values).all()


def test_broad_coverage_partitions_the_39_trials(data_mirror):
    """Every trial of trials.json is either registered or listed as missing, by kind."""
    from tiltlab import datasets

    cov = datasets.broad_coverage()
    every = [n for v in cov.values() for n in v]
    assert sorted(every) == list(range(1, 40))
    assert set(cov["undisturbed"]) | set(cov["disturbed"]) == set(
        datasets.broad_trials()
    )
    groups = datasets.broad_trial_groups()
    assert all("undisturbed" in groups[n] for n in cov["undisturbed"])
    assert not any("undisturbed" in groups[n] for n in cov["disturbed"])
