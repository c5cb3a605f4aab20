"""C3D reader: the real Vicon export of the foreign mirror, a file written by the
``c3d`` package's own writer, and the catalogue of bad inputs."""

from __future__ import annotations

import numpy as np
import pytest

from tiltlab import io
from tiltlab.io import ReadError, read_c3d

C3D_FILE = "c3d_biomechzoo/HC030A05.c3d"
HEAD = ["LFHD", "RFHD", "LBHD", "RBHD"]


def _write(path, frames, labels, *, rate=50.0, start=10):
    """Write points (frames × points × 3, NaN = not reconstructed) with py-c3d's writer."""
    import c3d

    w = c3d.Writer(point_rate=rate)
    for xyz in frames:
        p = np.zeros((len(labels), 5), np.float32)
        ok = np.isfinite(xyz).all(axis=1)
        p[:, :3] = np.where(ok[:, None], xyz, 0.0)
        p[:, 3] = np.where(ok, 1.0, -1.0)
        w.add_frames([(p, np.array([]))])
    w.set_point_labels(labels)
    w.set_start_frame(start)
    with open(path, "wb") as f:
        w.write(f)
    return path


@pytest.fixture(scope="module")
def walk(foreign):
    return read_c3d(foreign / C3D_FILE, computed=True)


@pytest.mark.realdata
def test_real_file_layout(walk, foreign):
    # the facts of the file as the data README and the C3D parameters state them
    assert walk.attrs["fs"] == 100.0
    assert walk.attrs["units"] == "mm"
    assert walk.attrs["first_frame"] == 286 and walk.attrs["last_frame"] == 482
    assert walk.sizes["frame"] == 197
    assert walk["frame"].values[0] == 286
    np.testing.assert_allclose(np.diff(walk["frame_time"].values), 0.01, atol=1e-12)
    assert walk.attrs["n_points"] == 291
    assert walk.sizes["marker"] + walk.sizes["channel"] == 291
    assert walk.attrs["source"] == "HC030A05.c3d"
    assert walk["markers"].dims == ("frame", "marker", "axis")
    assert walk["markers"].attrs["units"] == "mm"


@pytest.mark.realdata
def test_real_labels2_and_head_markers(walk):
    # POINT:LABELS holds 255 labels; the last 36 points are named in POINT:LABELS2
    names = list(walk["marker"].values) + list(walk["channel"].values)
    assert len(set(names)) == 291
    assert "RNormalisedGRF" in walk["channel"].values  # first label of LABELS2
    assert set(HEAD) <= set(walk["marker"].values)
    assert "JUG" in walk["marker"].values  # a modelled marker is a position
    assert "LKneeAngles" not in walk["marker"].values


@pytest.mark.realdata
def test_real_computed_channels_and_gaps(walk):
    kinds = dict(zip(walk["channel"].values, walk["channel_kind"].values))
    units = dict(zip(walk["channel"].values, walk["channel_units"].values))
    assert kinds["LKneeAngles"] == "angle" and units["LKneeAngles"] == "deg"
    assert kinds["LGroundReactionForce"] == "force" and units["LAnklePower"] == "W"
    assert sorted(walk.attrs["computed_channels"]) == sorted(walk["channel"].values)
    # the README: 54 computed channels have gaps (residual < 0), e.g. GRF in swing
    gappy = walk["computed"].isnull().any("axis").any("frame")
    assert int(gappy.sum()) == 54
    grf = walk["computed"].sel(channel="LGroundReactionForce")
    assert grf.isnull().any() and grf.notnull().any()
    # stored zeros are not returned as data
    assert not (grf.fillna(1.0) == 0.0).all("axis").any()


@pytest.mark.realdata
def test_real_selection_keeps_order_and_no_accelerometer(foreign):
    ds = read_c3d(foreign / C3D_FILE, markers=HEAD[::-1])
    assert list(ds["marker"].values) == HEAD[::-1]
    assert "computed" not in ds
    assert len(ds.attrs["analog_labels"]) == 24 and ds.attrs["analog_fs"] == 1000.0
    assert not set(ds.attrs["analog_units"]) & set(io.c3d.ACC_UNITS)


@pytest.mark.realdata
def test_real_unknown_names_listed_with_close_matches(foreign):
    with pytest.raises(ValueError, match=r"markers: 'LFHX' is not in the file.*LFHD"):
        read_c3d(foreign / C3D_FILE, markers=["LFHD", "LFHX"])
    with pytest.raises(
        ValueError, match="markers: 'LKneeAngles' is a computed channel"
    ):
        read_c3d(foreign / C3D_FILE, markers="LKneeAngles")
    with pytest.raises(ValueError, match="computed: 'LFHD' is a marker"):
        read_c3d(foreign / C3D_FILE, computed=["LFHD"])


@pytest.mark.realdata
def test_foreign_source_resolves_in_the_mirror(foreign, monkeypatch):
    assert io.c3d_path(f"foreign:{C3D_FILE}") == foreign / C3D_FILE
    monkeypatch.delenv("TILTLAB_DATA_DIR")
    assert io.c3d_path(f"foreign:{C3D_FILE}") is None
    with pytest.raises(ReadError, match="TILTLAB_DATA_DIR"):
        read_c3d(f"foreign:{C3D_FILE}")


def test_round_trip_with_the_c3d_writer(tmp_path):
    rng = np.random.default_rng(3)
    xyz = rng.normal(scale=100.0, size=(6, 3, 3))
    xyz[2, 1] = np.nan  # B not reconstructed in the third frame
    ds = read_c3d(_write(tmp_path / "t.c3d", xyz, ["A", "B", "C"]))
    np.testing.assert_allclose(ds["markers"].values, xyz.astype(np.float32), rtol=0)
    assert ds["residual"].isnull().values.tolist() == np.isnan(xyz[..., 0]).tolist()
    assert list(ds["frame"].values) == list(range(10, 16))
    np.testing.assert_allclose(ds["frame_time"].values, (np.arange(10, 16) - 1) / 50)
    assert ds.attrs["fs"] == 50.0 and ds.attrs["first_frame"] == 10


@pytest.mark.parametrize(
    "content, message",
    [
        (None, "no such file"),
        (b"frame,x,y,z\n1,2,3,4\n" * 40, "not a C3D file"),
        (b"\x02\x50" + b"\x00" * 100, "not a C3D file"),
        (b"\x02\x50" + b"\xff" * 2000, "not a readable C3D file"),
    ],
    ids=["missing", "csv", "truncated", "garbage"],
)
def test_bad_files_named(tmp_path, content, message):
    path = tmp_path / "walk.c3d"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(ReadError, match=message):
        read_c3d(path)


def test_folder_and_bad_source(tmp_path):
    with pytest.raises(ReadError, match="is a directory"):
        read_c3d(tmp_path)
    with pytest.raises(ValueError, match="source must be a path"):
        io.c3d_path(3)


def test_bad_names_in_a_written_file(tmp_path):
    path = _write(tmp_path / "t.c3d", np.zeros((2, 2, 3)), ["HEAD", "NECK"])
    with pytest.raises(ValueError, match=r"'HAED' is not in the file \(close: 'HEAD'"):
        read_c3d(path, markers=["HAED"])
    with pytest.raises(ValueError, match="markers: repeated names"):
        read_c3d(path, markers=["HEAD", "HEAD"])
    with pytest.raises(ValueError, match="markers: names must be strings"):
        read_c3d(path, markers=[1])
