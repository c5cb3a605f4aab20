"""The command line wraps the package; errors are reported, not raised."""

import numpy as np

from tiltlab import cli, io, schema


def test_info_and_validate_on_saved_recording(tmp_path, capsys):
    rng = np.random.default_rng(0)
    rec = schema.make_recording(
        np.tile([0, 0, 1.0], (100, 1)),
        rng.normal(0, 0.1, (100, 3)),
        50.0,
        attrs={"session": "s1"},
    )
    path = io.save_netcdf(rec, tmp_path / "r.nc")
    assert cli.main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "samples: 100" in out and "fs_hz: 50.0" in out
    assert cli.main(["validate", str(path)]) == 0
    bad = rec.copy()
    bad.attrs.pop("fs")
    io.save_netcdf(bad, tmp_path / "bad.nc")
    assert cli.main(["validate", str(tmp_path / "bad.nc")]) == 1
    assert "'fs'" in capsys.readouterr().err


def test_fetch_verifies_mirror(data_mirror, capsys):
    assert cli.main(["fetch", "fayat2021/example_imu.csv"]) == 0
    assert "verified" in capsys.readouterr().out
    assert cli.main(["fetch", "nope.csv"]) == 1
