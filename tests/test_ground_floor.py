"""The ground floor: building a Recording from grouped options, the ``rec`` vocabulary,
and the shared readers of :mod:`tiltlab._validate`."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import xarray as xr

from tiltlab import _validate as _v
from tiltlab import quality, schema

N, FS = 200, 50.0
ACC = np.tile([0.0, 0.0, 1.0], (N, 1))
GYR = np.zeros((N, 3))


def test_units_mapping_equals_shorthand_keywords():
    by_keyword = schema.make_recording(
        ACC, GYR, FS, acc_units="g", gyr_units="deg/s", acc_range=4, gyr_range=500
    )
    by_mapping = schema.make_recording(
        ACC,
        GYR,
        FS,
        units={"acc": "g", "gyr": "deg/s"},
        ranges={"acc": 4, "gyr": (-500, 500)},
    )
    xr.testing.assert_identical(by_keyword, by_mapping)
    assert by_mapping["acc"].attrs["range"] == 4.0
    assert by_mapping["gyr"].attrs["range"] == 500.0


def test_shorthand_none_means_not_given():
    rec = schema.make_recording(
        ACC, GYR, FS, units={"acc": "g", "gyr": "deg/s"}, gyr_units=None, mag_units=None
    )
    assert rec["gyr"].attrs["units"] == "deg/s"


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"units": {"acc": "g", "gyr": "deg/s"}, "acc_units": "g"}, "once"),
        ({"acc_units": "g", "gyr_units": "deg/s", "colour": "red"}, "colour"),
        ({"units": {"acc": "g", "gyr": "deg/s", "pressure": "Pa"}}, "pressure"),
        ({"acc_units": "g", "gyr_units": "deg/s", "ranges": {"temp": 85}}, "temp"),
    ],
)
def test_bad_options_are_type_errors(kwargs, match):
    with pytest.raises(TypeError, match=match):
        schema.make_recording(ACC, GYR, FS, **kwargs)


def test_other_options_still_reach_their_step():
    t0 = 12.5
    rec = schema.make_recording(
        ACC,
        GYR,
        FS,
        acc_units="g",
        gyr_units="deg/s",
        t0=t0,
        frame="sensor",
        axis_labels=["forward", "left", "up"],
        check_saturation=False,
    )
    assert float(rec["time"][0]) == t0
    assert rec.attrs["axis_labels"] == ["forward", "left", "up"]
    with pytest.raises(ValueError, match="max_jitter"):
        schema.make_recording(
            ACC, GYR, FS, acc_units="g", gyr_units="deg/s", max_jitter=-1
        )


@pytest.mark.parametrize(
    ("func", "targets"),
    [
        (schema.validate, {}),
        (schema.to_units, {"acc": "m/s^2"}),
        (schema.provenance, {}),
        (schema.describe, {}),
        (quality.assess, {}),
        (quality.plausibility, {}),
        (quality.check_saturation, {}),
    ],
)
def test_old_ds_keyword_warns_and_gives_the_same(func, targets):
    rec = schema.make_recording(
        ACC, GYR, FS, acc_units="g", gyr_units="deg/s", attrs={"session": "s1"}
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", FutureWarning)
        new = func(rec=rec, **targets)
    with pytest.warns(FutureWarning, match="'ds' was renamed 'rec'"):
        old = func(ds=rec, **targets)
    if isinstance(new, xr.Dataset):
        xr.testing.assert_identical(old, new)
    else:
        assert old == new


def test_signal_rejects_unknown_shape_keywords():
    with pytest.raises(TypeError, match="colour"):
        _v.signal(GYR, "gyr", fs=FS, colour="red")
    s = _v.signal(np.zeros(N), "speed", fs=FS, width=None, ndim=1)
    assert s.values.shape == (N,)


def test_windowed_labels_window_centres():
    da = xr.DataArray(
        GYR,
        dims=("time", "axis"),
        coords={"time": 3.0 + np.arange(N) / FS},
        attrs={"fs": FS, "units": "deg/s"},
    )
    like = _v.signal(da, "gyr")
    out = _v.windowed(
        np.ones((4, 3)), like, "w", centre_s=[0.5, 1.5, 2.5, 3.5], fs_out=1.0, units="1"
    )
    assert out.dims == ("time", "axis")
    np.testing.assert_array_equal(out["time"].values, [3.5, 4.5, 5.5, 6.5])
    assert out.attrs == {"fs": 1.0, "units": "1"}
    plain = _v.signal(GYR, "gyr", fs=FS)
    assert isinstance(
        _v.windowed(np.ones(4), plain, "w", centre_s=[0] * 4, fs_out=1), np.ndarray
    )


def test_scalar_checks_are_reexported_once():
    from tiltlab import _scalars

    for name in (
        "check_fs",
        "finite",
        "positive",
        "nonnegative",
        "integer",
        "fraction",
    ):
        assert getattr(_v, name) is getattr(_scalars, name)
    with pytest.raises(ValueError, match="must be an integer"):
        _v.integer(True, "n")
    with pytest.raises(ValueError, match="must be an integer"):
        _v.integer("x", "n")
    assert _v.integer(3.0, "n") == 3
