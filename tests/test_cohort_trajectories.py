"""Fig. 3e trajectories: each animal's baseline at the pole, angles kept, group means."""

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from tiltlab.cohort import pole_rotation, tilt_trajectories

unit = st.lists(st.floats(-1, 1, allow_nan=False), min_size=3, max_size=3).filter(
    lambda v: np.linalg.norm(v) > 1e-3
)


@settings(max_examples=200, deadline=None)
@given(unit)
def test_pole_rotation_is_a_rotation_taking_u_to_the_pole(u):
    u = np.asarray(u) / np.linalg.norm(u)
    R = pole_rotation(u)
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0)
    assert np.allclose(R @ u, [0, 0, 1], atol=1e-12)


def test_pole_rotation_edge_cases_and_bad_input():
    assert np.array_equal(pole_rotation([0, 0, 2.0]), np.eye(3))
    assert np.allclose(pole_rotation([0, 0, -1.0]) @ [0, 0, -1.0], [0, 0, 1])
    for bad in ([0, 0, 0], [np.nan, 0, 1], [1, 0]):
        with pytest.raises(ValueError, match="non-zero 3-vector"):
            pole_rotation(bad)


def _table(mu, subjects, groups, timepoints, status=None):
    mu = np.asarray(mu, float)
    data = {f"tilt_immobile_{a}": ("session", mu[:, i]) for i, a in enumerate("xyz")}
    if status is not None:
        data["status"] = ("session", np.array(status))
    return xr.Dataset(
        data,
        coords={
            "subject": ("session", subjects),
            "group": ("session", groups),
            "timepoint": ("session", timepoints),
        },
    )


def _random_units(rng, n):
    v = rng.normal(size=(n, 3)) + [0.3, 0.0, 1.5]
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_angles_from_the_pole_are_angles_from_each_baseline():
    rng = np.random.default_rng(4)
    mu = _random_units(rng, 9)
    subj = ["a"] * 3 + ["b"] * 3 + ["c"] * 3
    tps = ["baseline", "1d", "7d"] * 3
    traj = tilt_trajectories(_table(mu, subj, ["G"] * 6 + ["H"] * 3, tps))
    for i, s in enumerate("abc"):
        base = mu[3 * i]
        for j, t in enumerate(tps[:3]):
            want = np.degrees(np.arccos(np.clip(mu[3 * i + j] @ base, -1, 1)))
            assert float(traj["angle"].sel(subject=s, timepoint=t)) == pytest.approx(
                want, abs=1e-9
            )
    assert np.allclose(traj["point"].sel(timepoint="baseline"), [0, 0, 1])
    m = traj["mean"].sel(group="G").values
    assert np.allclose(np.linalg.norm(m, axis=1), 1.0)
    two = traj["point"].sel(subject=["a", "b"], timepoint="7d").values.sum(0)
    assert np.allclose(m[2], two / np.linalg.norm(two))
    assert traj["n_animals"].sel(group="G").values.tolist() == [2, 2, 2]
    assert list(traj["animal_group"].values) == ["G", "G", "H"]


def test_missing_and_failed_sessions_are_nan_not_errors():
    mu = [[0, 0, 1], [0, 0.2, 1], [0.1, 0, 1], [0, 0, 1]]
    traj = tilt_trajectories(
        _table(
            mu,
            ["a", "a", "b", "b"],
            ["G"] * 4,
            ["baseline", "1d", "1d", "7d"],
            status=["ok", "failed", "ok", "ok"],
        )
    )
    assert np.isnan(traj["angle"].sel(subject="a", timepoint="1d"))
    assert np.all(np.isnan(traj["angle"].sel(subject="b")))  # no baseline
    assert traj["n_animals"].sel(group="G", timepoint="baseline") == 1


def test_bad_tables_are_named():
    ds = _table([[0, 0, 1]], ["a"], ["G"], ["baseline"])
    with pytest.raises(ValueError, match="tilt_immobile_z"):
        tilt_trajectories(ds.drop_vars("tilt_immobile_z"))
    with pytest.raises(ValueError, match="'subject'"):
        tilt_trajectories(ds.drop_vars("subject"))
    with pytest.raises(ValueError, match="baseline 'pre'"):
        tilt_trajectories(ds, baseline="pre")


def test_figure_draws_one_panel_per_group_with_the_mean_in_equal_area_coordinates():
    import matplotlib

    matplotlib.use("Agg")
    from tiltlab import plot

    rng = np.random.default_rng(2)
    mu = _random_units(rng, 8)
    traj = tilt_trajectories(
        _table(mu, list("aabbccdd"), ["G"] * 4 + ["H"] * 4, ["baseline", "1d"] * 4)
    )
    fig = plot.tilt_trajectories_figure(traj, groups=["H", "G"])
    assert [ax.get_title() for ax in fig.axes if ax.get_visible()] == [
        "H (n = 2)",
        "G (n = 2)",
    ]
    m = traj["mean"].sel(group="H").values
    k = np.sqrt(2 / (1 + m[:, 2]))
    red = [ln for ln in fig.axes[0].lines if ln.get_color() == "tab:red"][0]
    assert np.allclose(red.get_xdata(), k * m[:, 0])
    assert np.allclose(red.get_ydata(), k * m[:, 1])
    with pytest.raises(ValueError, match="'K'"):
        plot.tilt_trajectories_figure(traj, groups=["K"])
