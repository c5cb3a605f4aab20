"""Tests of the highlighted region of tiltlab.plot.tilt_trajectories_panels.

The region is the covariance ellipse, on the equal-area map, of the points that the
reference visits during the masked samples (the dashed ellipse of Fayat et al. 2021,
Fig. 2b, around a belly-grooming episode).
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.patches import Ellipse  # noqa: E402

from tiltlab import plot  # noqa: E402


def _from_map(xy):
    """Directions whose equal-area projection seen from +z (+x up, +y left) is ``xy``."""
    r2 = np.sum(xy**2, axis=1)
    s = np.sqrt(1.0 - r2 / 4.0)
    return np.column_stack([xy[:, 1] * s, -xy[:, 0] * s, 1.0 - r2 / 2.0])


def _gaussian_map_points(n, seed, centre=(0.4, -0.3), angle_deg=30.0, sds=(0.25, 0.06)):
    rng = np.random.default_rng(seed)
    a = np.radians(angle_deg)
    rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    return np.asarray(centre) + (rng.normal(size=(n, 2)) * sds) @ rot.T


def _ellipses(ax):
    return [p for p in ax.patches if isinstance(p, Ellipse)]


def _inside(patch, xy):
    path = patch.get_path().transformed(patch.get_patch_transform())
    return path.contains_points(xy)


def test_inverse_projection_helper_round_trips():
    xy = _gaussian_map_points(100, 0)
    fig = plot.tilt_trajectories_panels({"a": _from_map(xy)})
    np.testing.assert_allclose(fig.axes[0].lines[-2].get_xydata(), xy, atol=1e-12)
    plt.close(fig)


def test_dashed_ellipse_on_every_panel_with_label():
    n = 400
    xy = _gaussian_map_points(n, 1)
    mask = np.zeros(n, bool)
    mask[100:300] = True
    series = {
        "reference": _from_map(xy),
        "estimate": _from_map(xy + 0.05),
        "other": _from_map(xy[::-1]),
    }
    fig = plot.tilt_trajectories_panels(
        series, highlight=mask, highlight_label="grooming"
    )
    for ax in fig.axes:
        (patch,) = _ellipses(ax)
        assert patch.get_linestyle() == "--"
        assert not patch.get_fill()
        assert "grooming" in [t.get_text() for t in ax.texts]
    # the same region (that of the first series) on every panel
    first = _ellipses(fig.axes[0])[0]
    for ax in fig.axes[1:]:
        e = _ellipses(ax)[0]
        np.testing.assert_allclose(e.center, first.center)
        assert (e.width, e.height, e.angle) == (first.width, first.height, first.angle)
    plt.close(fig)


@pytest.mark.parametrize("seed", [2, 3, 4])
def test_two_sd_ellipse_encloses_most_gaussian_points(seed):
    # for Gaussian points, P(Mahalanobis distance <= 2) = 1 - exp(-2) = 0.865
    n = 3000
    xy = _gaussian_map_points(n, seed)
    fig = plot.tilt_trajectories_panels({"ref": _from_map(xy)}, highlight=np.ones(n))
    frac = _inside(_ellipses(fig.axes[0])[0], xy).mean()
    assert frac >= 0.80
    assert abs(frac - (1 - np.exp(-2))) < 0.03  # > 4 binomial SDs at n = 3000
    plt.close(fig)


def test_ellipse_is_the_mahalanobis_contour_of_the_masked_points():
    n = 500
    xy = _gaussian_map_points(n, 5, angle_deg=-55.0)
    far = _gaussian_map_points(n, 6, centre=(-0.8, 0.9))
    mask = np.r_[np.ones(n, bool), np.zeros(n, bool)]
    fig = plot.tilt_trajectories_panels(
        {"ref": _from_map(np.r_[xy, far])}, highlight=mask, highlight_sd=3.0
    )
    patch = _ellipses(fig.axes[0])[0]
    # an Ellipse patch is the unit circle mapped by its patch transform
    t = np.linspace(0, 2 * np.pi, 73)
    edge = patch.get_patch_transform().transform(
        np.column_stack([np.cos(t), np.sin(t)])
    )
    d = edge - xy.mean(axis=0)
    m2 = np.einsum("ij,jk,ik->i", d, np.linalg.inv(np.cov(xy, rowvar=False)), d)
    np.testing.assert_allclose(m2, 9.0, rtol=1e-9)
    assert not _inside(patch, far).any()  # unmasked samples do not shape the region
    plt.close(fig)


def test_highlight_series_picks_the_region_source():
    n = 300
    a, b = _gaussian_map_points(n, 7), _gaussian_map_points(n, 8, centre=(-0.5, 0.5))
    fig = plot.tilt_trajectories_panels(
        {"a": _from_map(a), "b": _from_map(b)},
        highlight=np.ones(n, bool),
        highlight_series="b",
    )
    np.testing.assert_allclose(_ellipses(fig.axes[0])[0].center, b.mean(axis=0))
    plt.close(fig)


def test_no_highlight_draws_no_ellipse():
    xy = _gaussian_map_points(50, 9)
    fig = plot.tilt_trajectories_panels({"a": _from_map(xy), "b": _from_map(xy)})
    for ax in fig.axes:
        assert not _ellipses(ax)
        assert len(ax.texts) == 2  # only the +x and +y markers
    plt.close(fig)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"highlight": np.ones(9, bool)}, "highlight"),
        ({"highlight": np.ones((10, 1), bool)}, "highlight"),
        ({"highlight": np.full(10, 2)}, "highlight must hold booleans"),
        ({"highlight": np.r_[np.ones(2), np.zeros(8)]}, "fewer than 3 samples"),
        (
            {"highlight": np.ones(10, bool), "highlight_series": "missing"},
            "highlight_series",
        ),
        ({"highlight": np.ones(10, bool), "highlight_sd": 0.0}, "highlight_sd"),
        ({"highlight": np.ones(10, bool), "highlight_sd": np.nan}, "highlight_sd"),
    ],
)
def test_bad_highlight_named(kwargs, message):
    xy = _gaussian_map_points(10, 10)
    with pytest.raises(ValueError, match=message):
        plot.tilt_trajectories_panels({"a": _from_map(xy)}, **kwargs)
    plt.close("all")


def test_highlight_needs_equal_lengths():
    with pytest.raises(ValueError, match="highlight"):
        plot.tilt_trajectories_panels(
            {"a": _from_map(_gaussian_map_points(10, 11)), "b": np.ones((12, 3))},
            highlight=np.ones(10, bool),
        )
