"""Renamed names keep working for one release, and every warning names the user's line."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from tiltlab import filters, learn, simulate, sphere
from tiltlab._deprecate import alias, renamed


def test_renamed_keyword_warns_and_passes_through():
    @renamed(b0="gyr_offset")
    def f(x, *, gyr_offset=0.0):
        return x + gyr_offset

    with pytest.warns(FutureWarning, match="'b0' was renamed 'gyr_offset'"):
        assert f(1.0, b0=2.0) == 3.0
    with pytest.raises(TypeError, match="pass 'gyr_offset' only"):
        f(1.0, b0=2.0, gyr_offset=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert f(1.0, gyr_offset=2.0) == 3.0


def test_alias_warns_and_calls_the_new_function():
    def new(x):
        return 2 * x

    old = alias(new, "old")
    with pytest.warns(FutureWarning, match="old was renamed new"):
        assert old(2) == 4
    assert old.__deprecated_alias_of__ is new


@pytest.mark.parametrize(
    "old, new",
    [
        (filters.run, filters.run_method),
        (learn.load, learn.load_model),
        (learn.run, learn.closed_loop_estimate),
        (sphere.slerp, sphere.slerp_vectors),
    ],
)
def test_package_aliases_point_at_the_new_functions(old, new):
    assert old.__deprecated_alias_of__ is new


def test_warnings_point_at_the_callers_line():
    """A warning raised deep inside tiltlab, through a renaming wrapper, names this file."""
    rec = simulate.simulate_session(duration_s=5.0, fs=50.0, seed=1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        filters.estimate(rec, "mahony", b0=np.zeros(3))
    assert caught, "expected at least the FutureWarning of the old keyword"
    assert {w.filename for w in caught} == {__file__}
