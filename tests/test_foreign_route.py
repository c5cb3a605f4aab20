"""The whole own-data route on real recordings made by other projects (TILTLAB_DATA_DIR/
foreign): mapping → ``tiltlab convert`` → ``tiltlab validate`` → ``filters.estimate`` →
tilt map → a small cohort of pieces cut from the converted files, through the command
line as a lab would use it."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pandas as pd
import pytest

from tiltlab import cli, cohort, filters, io, sphere

ROUTES = {
    # name: (template, source below foreign/, has a gyroscope)
    "board_moved": ("sunsided_board", "board_sunsided/roll-and-tilt-at-45-90", True),
    "board_still": (
        "sunsided_board",
        "board_sunsided/unmoved-with-x-pointing-forward",
        True,
    ),
    "tag": ("twlogger_tag", "tag_twlogger/T1D0711-00.CSV", False),
    "foot": ("gaitmap_foot", "foot_gaitmap/imu_sample.csv", True),
}


@pytest.fixture(scope="module")
def converted(foreign, tmp_path_factory):
    """Every foreign recording converted by the command line, as the README says."""
    out = tmp_path_factory.mktemp("converted")
    files = {}
    for name, (template, source, _) in ROUTES.items():
        mapping = out / f"{name}.json"
        mapping.write_text(json.dumps(io.mapping_template(template)))
        target = out / f"{name}.nc"
        args = ["convert", str(foreign / source), "--mapping", str(mapping)]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # quality warnings are printed, not raised
            status = cli.main([*args, "--out", str(target)])
        assert status == 0, f"tiltlab convert refused {source}"
        files[name] = target
    return files


@pytest.mark.realdata
@pytest.mark.parametrize("name", list(ROUTES))
def test_converted_recording_validates_and_estimates(converted, name, capsys):
    assert cli.main(["validate", str(converted[name])]) == 0
    assert "valid" in capsys.readouterr().out
    rec = io.load_netcdf(converted[name], validate=True)
    has_gyr = ROUTES[name][2]
    assert ("gyr" in rec) == has_gyr
    usable = filters.methods(needs=rec)
    method = "madgwick" if has_gyr else "lowpass"
    assert method in usable
    q = filters.estimate(rec, method, gaps="segments")
    g = filters.gravity(q).values
    ok = np.isfinite(g).all(axis=1)
    assert ok.mean() > 0.95
    np.testing.assert_allclose(np.linalg.norm(g[ok], axis=1), 1.0, atol=1e-9)
    if not has_gyr:
        with pytest.raises(Exception, match="gyroscope"):
            filters.estimate(rec, "madgwick")
    tmap = sphere.tilt_map(filters.gravity(q))
    assert float(tmap["count"].sum()) == pytest.approx(ok.sum())
    if name == "board_still":  # lying still, z up: the tilt stays at the pole
        assert np.median(g[ok, 2]) > 0.99


@pytest.mark.realdata
def test_a_small_cohort_of_pieces(converted, tmp_path, capsys):
    """Two groups (gyroscope / no gyroscope) of 15-s pieces: every session gives a row,
    the gyroscope-free ones with NaN and a reason where a feature needs a gyroscope."""
    study = tmp_path / "study"
    rows = []
    for name in ("board_moved", "tag", "foot"):
        rec = io.load_netcdf(converted[name])
        fs = float(rec.attrs["fs"])
        n = int(15 * fs)
        group = "with_gyr" if "gyr" in rec else "acc_only"
        for k in range(2):
            piece = rec.isel(time=slice(k * n, (k + 1) * n))
            if piece.sizes["time"] < n or not np.isfinite(piece.acc.values).all():
                continue
            path = study / group / f"{name}-{k}_t0.nc"
            io.save_netcdf(piece, path)
            rows.append(name)
    assert len(rows) >= 4
    assert (
        cli.main(
            [
                "cohort",
                "init",
                str(study),
                "--pattern",
                "{group}/{subject}_{timepoint}.nc",
                "--out",
                str(study / "manifest.csv"),
            ]
        )
        == 0
    )
    status = cli.main(
        [
            "cohort",
            "run",
            str(study / "manifest.csv"),
            "--out",
            str(tmp_path / "features.nc"),
            "--no-progress",
        ]
    )
    out = capsys.readouterr()
    assert status == 0, out.err
    features = io.load_netcdf(tmp_path / "features.nc")
    table = features.to_dataframe()
    assert len(table) == len(rows)
    assert set(table["group"].astype(str)) == {"with_gyr", "acc_only"}
    outcome = cohort.summary(features)
    assert outcome.n_failed == 0 and outcome.n_ok == len(rows), str(outcome)
    tilt_cols = [c for c in table.columns if "visited" in c or "immobile" in c]
    assert tilt_cols, "no tilt or immobility feature in the cohort table"
    assert pd.notna(table[tilt_cols[0]]).all()
