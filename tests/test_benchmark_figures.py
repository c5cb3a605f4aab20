"""Tests of tiltlab.plot.benchmark: gravity trajectories side by side (Fayat Fig. 2b)."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from tiltlab import plot  # noqa: E402


def _directions(n=50, seed=0):
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(n, 3)) + [0.0, 0.0, 2.0]
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _expected_xy(v):
    """Lambert azimuthal equal-area seen from +z, +x up and +y left."""
    k = np.sqrt(2.0 / (1.0 + v[:, 2]))
    return np.column_stack([-k * v[:, 1], k * v[:, 0]])


def test_one_panel_per_series_with_projected_line():
    series = {"mocap": _directions(seed=1), "madgwick": _directions(seed=2)}
    fig = plot.tilt_trajectories_panels(series)
    assert len(fig.axes) == 2
    for ax, (name, v) in zip(fig.axes, series.items()):
        assert ax.get_title() == name
        xy = ax.lines[-2].get_xydata()  # the trajectory, before the centre marker
        np.testing.assert_allclose(xy, _expected_xy(v), rtol=1e-12)
        # equal area: the projected radius of a direction at angle t from +z is 2 sin(t/2)
        t = np.arccos(v[:, 2])
        np.testing.assert_allclose(np.hypot(*xy.T), 2 * np.sin(t / 2), rtol=1e-12)
    plt.close(fig)


def test_unnormalised_input_is_normalised_and_time_colours():
    v = _directions(40)
    t = np.arange(40) / 10.0
    fig = plot.tilt_trajectories_panels({"raw": 9.81 * v, "unit": v}, time=t)
    assert len(fig.axes) == 3  # two panels and the colour bar
    for ax in fig.axes[:2]:
        seg = ax.collections[0].get_segments()
        assert len(seg) == 39
        np.testing.assert_allclose(np.array([s[0] for s in seg]), _expected_xy(v)[:-1])
    plt.close(fig)


def test_given_axes_are_used():
    fig, axes = plt.subplots(1, 3)
    out = plot.tilt_trajectories_panels(
        {k: _directions(seed=i) for i, k in enumerate("abc")}, axes=axes
    )
    assert out is fig and [a.get_title() for a in axes] == ["a", "b", "c"]
    plt.close(fig)


@pytest.mark.parametrize(
    "series, kwargs, message",
    [
        ({}, {}, "series"),
        ({"a": np.zeros((5, 2))}, {}, r"series\['a'\]"),
        ({"a": np.ones((5, 3))}, {"time": np.arange(4)}, "time"),
        ({"a": np.ones((5, 3))}, {"axes": [None, None]}, "axes"),
    ],
)
def test_bad_input_named(series, kwargs, message):
    with pytest.raises(ValueError, match=message):
        plot.tilt_trajectories_panels(series, **kwargs)
