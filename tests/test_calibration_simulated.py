"""Issue bars for calibration, end to end on the simulator's tumble tests:
simulate.tumble_test -> still-period detection -> fits, scored against the simulated truth."""

import numpy as np
import pytest

import tiltlab.calibration as C
from tiltlab.simulate import SensorModel, tumble_test


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_ellipsoid_on_50_lattice_positions(seed):
    rec = tumble_test(
        50, seed=seed
    )  # realistic sensor: offsets, ~1 % scale, misalignment, noise, bias walk
    res = C.tumble_calibration(rec, model="ellipsoid", trigger=rec["trigger"].values)
    assert res.fit.n >= 50  # one still window before each rotation onset
    offset_true = np.asarray(rec.attrs["true_acc_offset_mean"])
    matrix_true = np.asarray(rec.attrs["true_acc_matrix"])
    assert np.max(np.abs(res.fit.offset - offset_true)) < 0.0005  # g
    assert (
        np.max(
            np.abs(res.fit.matrix - C.identifiable_matrix(np.linalg.inv(matrix_true)))
        )
        < 0.002
    )  # 0.2 %


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_offsets_from_three_orthogonal_positions(seed):
    # three positions determine three offsets exactly only if the sensor's scale is right:
    # here a simulated sensor with realistic offsets and noise but no scale/misalignment error
    ideal_gain = SensorModel(acc_scale=(0.0, 0.0, 0.0), acc_misalign=((0.0,) * 3,) * 3)
    rec = tumble_test(seed=seed, kind="three_point", sensor=ideal_gain)
    res = C.tumble_calibration(
        rec
    )  # still periods found from the gyroscope, no trigger
    assert res.fit.n >= 3
    assert (
        np.max(np.abs(res.fit.offset - np.asarray(rec.attrs["true_acc_offset_mean"])))
        < 0.002
    )


def test_three_positions_cannot_separate_offset_from_scale():
    # with the default (realistic) scale errors, the three-point offsets absorb them: the error is
    # of the order of the scale error, which only a >= 9-pose ellipsoid fit can separate
    rec = tumble_test(seed=3, kind="three_point")
    res = C.tumble_calibration(rec)
    err = np.abs(res.fit.offset - np.asarray(rec.attrs["true_acc_offset_mean"]))
    scale = np.abs(np.diag(np.asarray(rec.attrs["true_acc_matrix"])) - 1.0)
    assert np.max(err) > 0.002
    np.testing.assert_allclose(err, scale, atol=0.003)
    with pytest.raises(C.CalibrationError):
        C.tumble_calibration(rec, model="ellipsoid")
