"""Marker gap filling (Fayat et al. 2021, §2.6.3: gaps of one or two frames filled by
quadratic interpolation, longer gaps left missing)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from tiltlab.calibration import fill_marker_gaps, marker_gaps

coef = st.floats(-50.0, 50.0, allow_nan=False)


def _parabola(n, c0, c1, c2):
    k = np.arange(n, dtype=float)
    return np.stack([c0 + c1 * k + c2 * k**2, c1 - c2 * k, c0 * np.ones(n)], axis=1)


@settings(max_examples=60, deadline=None)
@given(
    c=st.tuples(coef, coef, st.floats(-2.0, 2.0)),
    start=st.integers(1, 20),
    length=st.integers(1, 2),
    n=st.integers(25, 40),
)
def test_exact_on_quadratics(c, start, length, n):
    # every coordinate a quadratic in the frame index: the fill is exact
    truth = _parabola(n, *c)
    x = truth.copy()
    x[start : start + length] = np.nan
    res = fill_marker_gaps(x)
    np.testing.assert_allclose(res.markers, truth, rtol=1e-9, atol=1e-9)
    assert res.filled.sum() == length and not res.missing.any()


def test_three_support_frames_when_a_fourth_is_missing():
    truth = _parabola(12, 1.0, -2.0, 0.5)
    x = truth.copy()
    # gap 3 misses support frame 5, gap 5-6 misses support frame 3: three left each
    x[[3, 5, 6]] = np.nan
    res = fill_marker_gaps(x)
    np.testing.assert_allclose(res.markers, truth, atol=1e-9)
    assert res.filled.sum() == 3


def test_one_and_two_frame_gaps_filled_three_left():
    x = _parabola(30, 0.0, 1.0, 0.1)
    x[4] = np.nan
    x[10:12] = np.nan
    x[18:21] = np.nan
    res = fill_marker_gaps(x)
    assert res.filled.nonzero()[0].tolist() == [4, 10, 11]
    assert res.missing.nonzero()[0].tolist() == [18, 19, 20]
    assert np.isnan(res.markers[18:21]).all()
    # a larger max_gap reaches the three-frame gap; 0 fills nothing
    assert fill_marker_gaps(x, max_gap=3).filled.sum() == 6
    assert fill_marker_gaps(x, max_gap=0).filled.sum() == 0


def test_gaps_at_the_edges_stay_missing():
    x = _parabola(10, 0.0, 1.0, 0.1)
    x[0] = np.nan
    x[-2:] = np.nan
    res = fill_marker_gaps(x)
    assert not res.filled.any()
    assert res.missing.nonzero()[0].tolist() == [0, 8, 9]


def test_too_few_support_frames_stays_missing():
    x = _parabola(5, 0.0, 1.0, 0.1)
    x[[1, 3]] = np.nan  # frame 2 is alone between two gaps: two support frames each
    res = fill_marker_gaps(x)
    assert not res.filled.any()


def test_input_not_mutated_and_any_nan_coordinate_is_missing():
    x = _parabola(10, 0.0, 1.0, 0.1)
    x[5, 1] = np.nan  # one coordinate missing: the whole point is refitted
    before = x.copy()
    res = fill_marker_gaps(x)
    np.testing.assert_array_equal(x, before)
    assert res.markers is not x and res.filled[5]
    np.testing.assert_allclose(res.markers[5], _parabola(10, 0.0, 1.0, 0.1)[5])


def test_dataarray_markers_keep_dims_coords_and_attrs():
    n = 20
    data = np.stack([_parabola(n, 0.0, 1.0, 0.1), _parabola(n, 5.0, -1.0, 0.2)], 1)
    truth = data.copy()
    data[7, 0] = np.nan
    data[12:14, 1] = np.nan
    da = xr.DataArray(
        data,
        dims=("frame", "marker", "axis"),
        coords={"frame": np.arange(100, 100 + n), "marker": ["A", "B"]},
        attrs={"units": "mm"},
    )
    copy = da.copy(deep=True)
    res = fill_marker_gaps(da.transpose("marker", "axis", "frame"))
    assert res.markers.dims == ("marker", "axis", "frame")
    assert res.markers.attrs["units"] == "mm"
    np.testing.assert_allclose(
        res.markers.transpose("frame", "marker", "axis").values, truth, atol=1e-9
    )
    assert res.filled.sel(marker="B").sum() == 2 and res.filled.sel(
        marker="A", frame=107
    )
    xr.testing.assert_identical(da, copy)
    table = marker_gaps(da)
    assert table.values.tolist() == [["A", 107, 1, True], ["B", 112, 2, True]]
    assert table.attrs["units"]["length"] == "frames"


def test_gap_table_flags_what_fill_leaves():
    x = _parabola(20, 0.0, 1.0, 0.1)
    x[0] = np.nan
    x[5:8] = np.nan
    x[12] = np.nan
    table = marker_gaps(x)
    assert table[["first_frame", "length", "filled"]].values.tolist() == [
        [0, 1, False],
        [5, 3, False],
        [12, 1, True],
    ]
    assert table["filled"].sum() == fill_marker_gaps(x).filled.sum()


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"max_gap": -1}, "max_gap must be >= 0"),
        ({"max_gap": 1.5}, "max_gap must be a whole number"),
        ({"max_gap": True}, "max_gap must be a whole number"),
    ],
)
def test_bad_max_gap_named(kwargs, message):
    with pytest.raises(ValueError, match=message):
        fill_marker_gaps(np.zeros((5, 3)), **kwargs)


def test_bad_markers_named():
    with pytest.raises(ValueError, match="markers must be numeric"):
        fill_marker_gaps([["a", "b", "c"]])
    with pytest.raises(ValueError, match="markers must have a frame axis"):
        fill_marker_gaps(3.0)
    with pytest.raises(ValueError, match="markers: has no dimension 'frame'"):
        fill_marker_gaps(xr.DataArray(np.zeros((4, 3)), dims=("time", "axis")))
