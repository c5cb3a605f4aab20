"""MATLAB files: v5 written here, v7.3 (HDF5) from a real foreign recording."""

from pathlib import Path

import numpy as np
import pytest
import scipy.io

from tiltlab.io import ReadError
from tiltlab.io.mat import describe_mat, list_variables, mat_version, read_matrix


@pytest.fixture(scope="module")
def board_dir(foreign) -> Path:
    return foreign / "board_sunsided"


def test_v5_roundtrip_keeps_matlab_shape(tmp_path):
    rng = np.random.default_rng(0)
    acc = rng.normal(size=(50, 3))
    flags = rng.random(7) > 0.5
    p = tmp_path / "rec.mat"
    scipy.io.savemat(p, {"acc": acc, "label": "not numeric", "flags": flags})
    assert mat_version(p) == "5"
    np.testing.assert_array_equal(read_matrix(p, "acc"), acc)
    # a 1-D vector comes back as MATLAB saw it: a 1×N row
    assert read_matrix(p, "flags").shape == (1, flags.size)
    names = [v[0] for v in list_variables(p)]
    assert set(names) == {"acc", "label", "flags"}


def test_v5_choice_of_variable(tmp_path):
    p = tmp_path / "two.mat"
    scipy.io.savemat(p, {"a": np.ones((2, 2)), "b": np.zeros((3, 1)), "s": "txt"})
    with pytest.raises(ReadError, match="several numeric variables.*a\\(2×2"):
        read_matrix(p)
    with pytest.raises(ReadError, match="no variable 'c'.*b\\(3×1"):
        read_matrix(p, "c")
    with pytest.raises(ReadError, match="'s' is a MATLAB char"):
        read_matrix(p, "s")
    one = tmp_path / "one.mat"
    scipy.io.savemat(one, {"only": np.arange(4.0)[:, None], "note": "x"})
    assert read_matrix(one).shape == (4, 1)


def test_damaged_and_foreign_files(tmp_path):
    p = tmp_path / "x.mat"
    scipy.io.savemat(p, {"a": np.random.default_rng(1).normal(size=(400, 4))})
    cut = tmp_path / "cut.mat"
    cut.write_bytes(p.read_bytes()[: p.stat().st_size // 2])
    with pytest.raises(ReadError, match="cut.mat"):
        read_matrix(cut)
    text = tmp_path / "text.mat"
    text.write_text("time,ax\n0,1\n")
    with pytest.raises(ReadError):
        read_matrix(text)
    with pytest.raises(ReadError, match="no such file"):
        read_matrix(tmp_path / "absent.mat")


def test_v73_real_board_file(board_dir):
    p = board_dir / "unmoved-with-x-pointing-forward" / "mpu6050_accelerometer.mat"
    assert mat_version(p) == "7.3"
    a = read_matrix(p)  # the only numeric variable: accelBuffer
    import h5py

    with h5py.File(p, "r") as f:
        raw = f["accelBuffer"][()]
    # h5py shows the HDF5 (transposed) view; read_matrix returns MATLAB's
    assert a.shape == raw.shape[::-1]
    np.testing.assert_array_equal(a, raw.T)
    t, xyz = a[:, 0], a[:, 1:]
    assert a.shape[1] == 4
    assert np.all(np.diff(t) >= 0), "column 0 is time in s, non-decreasing"
    # static board, z up with the documented negative sign: |a| ≈ 1 g
    assert abs(np.median(np.linalg.norm(xyz, axis=1)) - 1.0) < 0.1
    assert np.median(xyz[:, 2]) < -0.9
    assert "accelBuffer" in describe_mat(p) and "v7.3" in describe_mat(p)


def test_v73_truncated(board_dir, tmp_path):
    p = board_dir / "roll-and-tilt-at-45-90" / "mpu6050_gyroscope.mat"
    cut = tmp_path / "cut73.mat"
    cut.write_bytes(p.read_bytes()[:3000])
    with pytest.raises(ReadError, match="truncated or corrupt"):
        read_matrix(cut)
