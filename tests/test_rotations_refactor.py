"""Behaviour kept through the rotations clean-up: warnings point at the caller, and the
shared input checks of tiltlab.quaternion name the argument."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from tiltlab import quaternion, trig


@pytest.mark.parametrize("func", [trig.azimuth, trig.heading])
def test_undefined_azimuth_warning_points_at_the_caller(func):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = func(
            np.array([[0.0, 0, 1], [0, 0, 1]]), np.array([[0.0, 0, 0], [1, 0, 0]])
        )
    assert [w.filename for w in caught] == [__file__]
    assert "1 of 2 samples set to NaN" in str(caught[0].message)
    az = out if func is trig.azimuth else out.azimuth
    assert np.isnan(az[0]) and np.isfinite(az[1])


@pytest.mark.parametrize(
    "call, message",
    [
        (
            lambda: quaternion.mul([1.0, 0, 0], [1.0, 0, 0, 0]),
            r"\bp\b.*last dimension 4",
        ),
        (lambda: quaternion.mul([1.0, 0, 0, 0], [np.inf, 0, 0, 0]), r"\bq\b.*infinite"),
        (lambda: quaternion.inv([0.0, 0, 0, 0]), r"\bq\b.*zero"),
        (lambda: quaternion.rotate([1.0, 0, 0, 0], [np.inf, 0, 0]), r"\bv\b.*infinite"),
        (lambda: quaternion.rotate([0.0, 0, 0, 0], [1.0, 0, 0]), r"\bq\b.*zero"),
        (lambda: quaternion.from_rotvec([1.0, 0]), r"\br\b.*last dimension 3"),
        (lambda: quaternion.angle_between([1.0, 0, 0], [1j, 0, 0]), r"\bv\b.*complex"),
        (
            lambda: quaternion.error_angles([1.0, 0, 0, 0], [0.0, 0, 0, 0]),
            r"\bq_ref\b.*zero",
        ),
        (lambda: quaternion.normalize([np.inf, 0, 0, 0]), r"\bq\b.*infinite"),
    ],
)
def test_shared_quaternion_checks_name_the_argument(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_shared_checks_let_missing_samples_through():
    q = quaternion.random_quaternions(3, np.random.default_rng(0))
    q[1] = np.nan
    g = quaternion.gravity(q)
    e = quaternion.error_angles(q, quaternion.identity(3))
    assert np.isnan(g[1]).all() and np.isfinite(g[[0, 2]]).all()
    assert np.isnan(e[1]).all() and np.isfinite(e[[0, 2]]).all()
