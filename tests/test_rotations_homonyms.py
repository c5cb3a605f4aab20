"""One name, one behaviour: the angle conversions of frames and trig, and gravity.

``tiltlab.frames`` and ``tiltlab.trig`` export ``wrap_angle``, ``angles_from_quaternion``
and ``angles_from_matrix``; they are the same objects, labelled in and labelled out, and
refuse non-unit quaternions and non-rotations. ``tiltlab.quaternion.gravity`` labels a
DataArray with a ``quat`` dimension like ``tiltlab.filters.gravity``.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from tiltlab import filters, frames, quaternion, trig

NAMES = ["wrap_angle", "angles_from_quaternion", "angles_from_matrix"]


@pytest.mark.parametrize("name", NAMES)
def test_frames_and_trig_export_the_same_object(name):
    assert getattr(frames, name) is getattr(trig, name)


def test_trig_reexports_every_benhamou_name_of_frames():
    fayat = {"fibonacci_lattice", "stage_angles", "stage_quaternion"}
    benhamou = set(frames.__all__) - fayat - {"head_frame_from_markers"}
    assert benhamou <= set(trig.__all__)
    for name in benhamou:
        assert getattr(trig, name) is getattr(frames, name), name


def _q_da(q, fs=50.0):
    t = np.arange(len(q)) / fs + 3.0
    return xr.DataArray(
        q,
        dims=("time", "quat"),
        coords={"time": t, "quat": list("wxyz")},
        name="q",
        attrs={"fs": fs, "method": "madgwick", "units": "1"},
    )


def test_frames_angles_from_quaternion_labels_a_dataarray():
    q = quaternion.random_quaternions(7, np.random.default_rng(1))
    o = frames.angles_from_quaternion(_q_da(q))
    ref = frames.angles_from_quaternion(q)
    for v, r, name in zip(o, ref, ("azimuth", "elevation", "bank"), strict=True):
        assert isinstance(v, xr.DataArray) and v.name == name and v.dims == ("time",)
        assert v.attrs == {"fs": 50.0, "method": "madgwick", "units": "rad"}
        np.testing.assert_array_equal(v.values, r)
        np.testing.assert_array_equal(v.time.values, np.arange(7) / 50.0 + 3.0)


def test_frames_angles_from_matrix_labels_a_dataarray():
    q = quaternion.random_quaternions(5, np.random.default_rng(2))
    C = quaternion.to_matrix(q)
    da = xr.DataArray(
        C, dims=("time", "row", "col"), coords={"time": np.arange(5.0)}, name="C"
    )
    o = frames.angles_from_matrix(da)
    np.testing.assert_array_equal(o.elevation.values, frames.angles_from_matrix(C)[1])
    assert o.bank.dims == ("time",) and o.bank.attrs["units"] == "rad"


@pytest.mark.parametrize("scale", [2.0, 0.5, 1.0 + 2e-6])
def test_non_unit_quaternions_are_refused_by_both_names(scale):
    q = np.array([scale, 0.0, 0.0, 0.0])
    for mod in (frames, trig):
        with pytest.raises(ValueError, match=r"\bq\b.*unit quaternions.*normalise"):
            mod.angles_from_quaternion(q)


def test_zero_quaternion_is_refused_naming_q():
    with pytest.raises(ValueError, match=r"\bq\b.*zero quaternion is not a rotation"):
        frames.angles_from_quaternion([[1.0, 0, 0, 0], [0, 0, 0, 0]])


def test_near_unit_quaternions_are_renormalised_within_tolerance():
    q = quaternion.random_quaternions(4, np.random.default_rng(3))
    o = frames.angles_from_quaternion(q * (1 - 8e-7))
    np.testing.assert_allclose(
        np.asarray(o), np.asarray(frames.angles_from_quaternion(q)), atol=1e-14
    )


def test_wrap_angle_refuses_complex_and_text():
    with pytest.raises(ValueError, match=r"\bangle\b.*complex"):
        frames.wrap_angle(np.array([1.0 + 0.5j]))
    with pytest.raises(ValueError, match=r"\bangle\b.*numeric"):
        frames.wrap_angle("north")


def test_wrap_angle_of_a_dataarray_in_degrees_and_bad_units():
    da = xr.DataArray([190.0, -180.0, 540.0], dims="time", attrs={"units": "deg"})
    w = frames.wrap_angle(da)
    np.testing.assert_allclose(w.values, [-170.0, 180.0, 180.0])
    assert w.attrs == da.attrs
    with pytest.raises(ValueError, match=r"\bangle\b.*rad.*deg.*'m'"):
        frames.wrap_angle(da.assign_attrs(units="m"))


def test_angles_from_matrix_refuses_non_numeric_input():
    with pytest.raises(ValueError, match=r"\bmatrix\b.*numeric"):
        frames.angles_from_matrix([["a"] * 3] * 3)


# ---------------------------------------------------------------------------
# gravity: quaternion.gravity labels DataArrays like filters.gravity
# ---------------------------------------------------------------------------


def test_quaternion_gravity_labels_a_dataarray_like_filters_gravity():
    q = quaternion.random_quaternions(6, np.random.default_rng(5))
    da = _q_da(q).assign_attrs(param_beta=0.1)
    g = quaternion.gravity(da)
    ref = filters.gravity(da)
    xr.testing.assert_identical(g, ref)
    assert g.name == "gravity" and g.dims == ("time", "axis")
    assert list(g.axis.values) == ["x", "y", "z"]
    assert g.attrs["units"] == "1" and g.attrs["frame"] == "sensor"
    assert g.attrs["fs"] == 50.0 and g.attrs["param_beta"] == 0.1
    np.testing.assert_array_equal(g.values, quaternion.gravity(q))


def test_quaternion_gravity_moves_quat_last_and_keeps_nan_rows():
    q = quaternion.random_quaternions(4, np.random.default_rng(6))
    q[1] = np.nan
    g = quaternion.gravity(_q_da(q).transpose("quat", "time"))
    assert g.dims == ("time", "axis")
    assert np.all(np.isnan(g.values[1])) and np.isfinite(g.values[[0, 2, 3]]).all()


def test_quaternion_gravity_needs_a_quat_dimension():
    da = xr.DataArray(np.eye(4), dims=("time", "component"))
    with pytest.raises(ValueError, match=r"\bq\b.*'quat' dimension"):
        quaternion.gravity(da)
