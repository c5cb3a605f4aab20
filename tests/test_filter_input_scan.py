"""The filters read their inputs once, without copying what is already in shape."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tiltlab import filters as F
from tiltlab.filters._common import samples, sensor_inputs


def test_contiguous_float64_is_read_in_place_and_others_are_converted():
    x = np.random.default_rng(0).standard_normal((50, 3))
    assert samples(x, "gyr") is x
    fortran = np.asfortranarray(x)
    got = samples(fortran, "gyr")
    assert got.flags["C_CONTIGUOUS"] and np.array_equal(got, x)
    ints = samples(np.ones((4, 3), dtype=np.int32), "acc")
    assert ints.dtype == np.float64 and np.array_equal(ints, np.ones((4, 3)))


def test_filters_leave_their_inputs_unchanged():
    rng = np.random.default_rng(1)
    acc = rng.standard_normal((300, 3)) + [0.0, 0.0, 9.81]
    gyr = 0.1 * rng.standard_normal((300, 3))
    a0, g0 = acc.copy(), gyr.copy()
    for method in (F.madgwick, F.mahony, F.complementary, F.ekf):
        method(acc, gyr, 100.0)
        assert np.array_equal(acc, a0) and np.array_equal(gyr, g0)


@settings(max_examples=60, deadline=None)
@given(
    n_nan=st.integers(0, 4),
    n_inf=st.integers(0, 4),
    seed=st.integers(0, 10_000),
)
def test_non_finite_values_are_counted_by_kind(n_nan, n_inf, seed):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((20, 3))
    cells = rng.choice(60, n_nan + n_inf, replace=False)
    x.reshape(-1)[cells[:n_nan]] = np.nan
    x.reshape(-1)[cells[n_nan:]] = rng.choice([np.inf, -np.inf], n_inf)
    if n_inf:
        with pytest.raises(ValueError, match=rf"gyr has {n_inf} infinite values"):
            samples(x, "gyr")
    elif n_nan:
        with pytest.raises(ValueError, match=rf"gyr has {n_nan} NaN values"):
            samples(x, "gyr")
    else:
        assert samples(x, "gyr") is x


def test_the_gyroscope_limit_and_a_zero_accelerometer_are_refused():
    acc = np.tile([0.0, 0.0, 9.81], (10, 1))
    gyr = np.zeros((10, 3))
    gyr[3, 1] = -2e4
    with pytest.raises(ValueError, match="gyr reaches 2e\\+04 rad/s"):
        sensor_inputs(acc, gyr)
    with pytest.raises(ValueError, match="acc is zero in all 10 samples"):
        sensor_inputs(np.zeros((10, 3)), np.zeros((10, 3)))
