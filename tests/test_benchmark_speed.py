"""Tests of tiltlab.evaluate.speed: the error-vs-speed slope and the crossover speed
(the two numbers read from Fayat et al. 2021, Fig. 2f)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tiltlab import evaluate


def test_slope_exact_on_linear_data():
    s = np.linspace(0.0, 500.0, 101)
    out = evaluate.speed_slope({"a": 0.3 + 0.004 * s, "b": 2.0 - 0.001 * s}, s)
    # per 100 deg/s: 0.004 * 100 = 0.4, -0.001 * 100 = -0.1
    np.testing.assert_allclose(out["slope"].values, [0.4, -0.1], rtol=1e-12)
    np.testing.assert_allclose(out["intercept"].values, [0.3, 2.0], atol=1e-12)
    # every pairwise slope is equal: the interval collapses onto the slope
    np.testing.assert_allclose(out["slope_lo"].values, out["slope"].values, rtol=1e-12)
    np.testing.assert_allclose(out["slope_hi"].values, out["slope"].values, rtol=1e-12)
    assert out["slope"].attrs["units"] == "deg per 100 deg/s"
    assert all("long_name" in out[v].attrs for v in out.data_vars)
    assert list(out["n"].values) == [101, 101]


def test_slope_per_rescales_and_mask_selects():
    s = np.linspace(0.0, 300.0, 61)
    e = np.where(s > 12, 1.0 + 0.01 * s, 5.0)  # a different law while immobile
    out = evaluate.speed_slope({"a": e}, s, mask=s > 12, per=1.0)
    assert float(out["slope"][0]) == pytest.approx(0.01, rel=1e-12)
    assert int(out["n"][0]) == int((s > 12).sum())


def test_slope_ignores_outliers():
    s = np.linspace(0.0, 400.0, 201)
    e = 1.0 + 0.002 * s
    e[::20] += 50.0  # 5 % gross outliers
    out = evaluate.speed_slope({"a": e}, s)
    assert float(out["slope"][0]) == pytest.approx(0.2, rel=1e-9)


def test_slope_max_samples_caps_the_fit():
    s = np.linspace(0.0, 400.0, 5000)
    out = evaluate.speed_slope({"a": 0.01 * s}, s, max_samples=300)
    assert int(out["n"][0]) == 300
    assert float(out["slope"][0]) == pytest.approx(1.0, rel=1e-12)


@settings(max_examples=25, deadline=None)
@given(
    c=st.floats(-10, 10, allow_nan=False),
    seed=st.integers(0, 2**16),
)
def test_slope_invariant_to_added_constant(c, seed):
    rng = np.random.default_rng(seed)
    s = rng.uniform(0, 400, 80)
    e = rng.gamma(2.0, 1.0, 80) + 0.003 * s
    a = evaluate.speed_slope({"e": e}, s)
    b = evaluate.speed_slope({"e": e + c}, s)
    for v in ("slope", "slope_lo", "slope_hi"):
        assert float(b[v][0]) == pytest.approx(float(a[v][0]), rel=1e-9, abs=1e-9)
    assert float(b["intercept"][0]) == pytest.approx(
        float(a["intercept"][0]) + c, abs=1e-9
    )


def test_slope_nan_when_one_speed():
    out = evaluate.speed_slope({"a": [1.0, 2.0, 3.0]}, [5.0, 5.0, 5.0])
    assert np.isnan(float(out["slope"][0]))


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"errors": {}}, "errors"),
        ({"errors": {"a": [1.0, 2.0]}}, "errors['a']"),
        ({"mask": [True, False]}, "mask"),
        ({"per": 0.0}, "per"),
        ({"confidence": 1.5}, "confidence"),
        ({"max_samples": 2}, "max_samples"),
    ],
)
def test_slope_bad_inputs_named(kwargs, message):
    args = {"errors": {"a": [1.0, 2.0, 3.0]}, "speed": [0.0, 1.0, 2.0]} | kwargs
    errors, speed = args.pop("errors"), args.pop("speed")
    with pytest.raises(
        ValueError, match=message.replace("[", r"\[").replace("]", r"\]")
    ):
        evaluate.speed_slope(errors, speed, **args)


def test_crossover_known():
    # a - b = -1, -0.5, +1 : crosses between 100 and 200 at 100 + 100 * 0.5 / 1.5
    c = evaluate.crossover_speed([0.0, 100.0, 200.0], [1.0, 2.0, 3.0], [2.0, 2.5, 2.0])
    assert float(c) == pytest.approx(100.0 + 100.0 / 3.0, rel=1e-12)
    assert c.attrs["units"] == "deg/s" and "long_name" in c.attrs
    assert c.attrs["reason"] == "a goes above b"
    assert c.attrs["n_crossings"] == 1


def test_crossover_of_two_lines_is_their_intersection():
    x = np.array([10.0, 40.0, 90.0, 160.0])
    a, b = 0.5 + 0.01 * x, 1.2 + 0.002 * x  # meet at x = 0.7 / 0.008 = 87.5
    c = evaluate.crossover_speed(x, a, b)
    assert float(c) == pytest.approx(87.5, rel=1e-12)
    assert float(evaluate.crossover_speed(x, b, a)) == pytest.approx(87.5, rel=1e-12)
    assert evaluate.crossover_speed(x, b, a).attrs["reason"] == "a goes below b"


def test_crossover_skips_nan_bins_and_hits_bin_centre():
    c = evaluate.crossover_speed(
        [1.0, 2.0, 3.0, 4.0], [1.0, np.nan, 2.0, 3.0], [2.0, 0.0, 2.0, 1.0]
    )
    assert float(c) == 3.0
    assert c.attrs["n_crossings"] == 1


def test_no_crossover_is_nan_with_reason():
    c = evaluate.crossover_speed([1.0, 2.0, 3.0], [1.0, 1.0, 1.0], [2.0, 3.0, 4.0])
    assert np.isnan(float(c))
    assert "do not cross" in c.attrs["reason"] and "below" in c.attrs["reason"]
    c = evaluate.crossover_speed([1.0, 2.0], [np.nan, 1.0], [1.0, 2.0])
    assert np.isnan(float(c)) and "fewer than two" in c.attrs["reason"]


@pytest.mark.parametrize(
    "speeds, a, b, message",
    [
        ([1.0], [1.0], [1.0], "speeds"),
        ([2.0, 1.0], [1.0, 2.0], [2.0, 1.0], "speeds"),
        ([1.0, 2.0], [1.0, 2.0, 3.0], [2.0, 1.0], "a has"),
        ([1.0, 2.0], [1.0, 2.0], [2.0], "b has"),
    ],
)
def test_crossover_bad_inputs_named(speeds, a, b, message):
    with pytest.raises(ValueError, match=message):
        evaluate.crossover_speed(speeds, a, b)
