"""Group-averaged tilt maps and Fig. A5's angular velocity of a cohort (cohort.maps)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from tiltlab import cohort, io, simulate, sphere


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """Two groups × two animals × two time points, 20-s sessions at 50 Hz."""
    design = simulate.CohortDesign.small(2).select(
        groups={"Arsanilate": 2, "Healthy": 2}, time_points=["baseline", "1d"]
    )
    folder = simulate.simulate_cohort(
        tmp_path_factory.mktemp("maps") / "c",
        design=design,
        duration_s=20.0,
        fs=50.0,
        seed=1,
        progress=False,
    )
    manifest = cohort.read_manifest(folder / "manifest.csv")
    config = cohort.FeatureConfig(mesh_n=500)
    features = cohort.run_cohort(manifest, config, progress=False)
    return manifest, config, features


def test_maps_are_the_mean_of_the_sessions_maps(tiny):
    manifest, config, features = tiny
    maps = cohort.group_tilt_maps(manifest, features, config)
    assert maps["fraction"].dims == ("group", "timepoint", "facet")
    assert set(maps["group"].values) == {"Arsanilate", "Healthy"}
    assert (maps["n_animals"] == 2).all()
    # every session's fractions sum to 1, so their mean does too
    np.testing.assert_allclose(maps["fraction"].sum("facet"), 1.0, rtol=1e-12)
    sessions = features.to_dataframe()
    cell = sessions[(sessions["group"] == "Healthy") & (sessions["timepoint"] == "1d")]
    by_hand = []
    for subject in sorted(cell["subject"]):
        row = cohort.session_row(manifest, subject, "1d")
        _, g = cohort.load_session_tilt(row, manifest.root, config)
        by_hand.append(sphere.tilt_map(g, mesh=sphere.sphere_mesh(500))["fraction"])
    np.testing.assert_array_equal(
        maps["fraction"].sel(group="Healthy", timepoint="1d"),
        np.mean(by_hand, axis=0),
    )
    assert maps.attrs["mesh_n"] == 500
    assert maps.attrs["axis_labels"][0].startswith("forward")


def test_maps_subset_max_animals_and_failed_sessions(tiny):
    manifest, config, features = tiny
    one = cohort.group_tilt_maps(
        manifest,
        features,
        config,
        groups=["Healthy"],
        timepoints=["1d"],
        max_animals=1,
    )
    assert one["fraction"].shape[:2] == (1, 1)
    assert one["n_animals"].values.tolist() == [[1]]
    status = features["status"].values.copy()
    first = int(np.flatnonzero(features["group"].values == "Healthy")[0])
    status[first] = "failed"
    broken = features.assign(status=("session", status))
    maps = cohort.group_tilt_maps(manifest, broken, config, groups=["Healthy"])
    counts = maps["n_animals"].sel(group="Healthy").values
    assert sorted(counts.tolist()) == [1, 2]


def test_maps_on_processes_equal_serial(tiny):
    manifest, config, features = tiny
    kw = {"groups": ["Arsanilate"], "timepoints": ["1d"]}
    serial = cohort.group_tilt_maps(manifest, features, config, **kw)
    pool = cohort.group_tilt_maps(
        manifest, features, config, scheduler="processes", workers=2, **kw
    )
    xr.testing.assert_identical(serial, pool)


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"groups": ["Kainate"]}, "group"),
        ({"timepoints": ["3d"]}, "time point"),
        ({"max_animals": 0}, "max_animals"),
    ],
)
def test_maps_bad_input_names_the_problem(tiny, kw, message):
    manifest, config, features = tiny
    with pytest.raises(ValueError, match=message):
        cohort.group_tilt_maps(manifest, features, config, **kw)


def _table(values: dict) -> xr.Dataset:
    """A feature table from {(group, subject, timepoint): circling index}."""
    keys = list(values)
    return xr.Dataset(
        {"circling_index": ("session", [values[k] for k in keys])},
        coords={
            "session": [f"{s}_{t}" for _, s, t in keys],
            "group": ("session", [g for g, _, _ in keys]),
            "subject": ("session", [s for _, s, _ in keys]),
            "timepoint": ("session", [t for _, _, t in keys]),
        },
    )


def test_circling_example_picks_the_largest_increase_at_the_peak():
    table = _table(
        {
            ("A", "a1", "base"): 0.0,
            ("A", "a1", "1d"): 1.0,
            ("A", "a1", "7d"): 2.0,
            ("A", "a2", "base"): -1.0,
            ("A", "a2", "1d"): 0.5,
            ("A", "a2", "7d"): 3.5,
            ("B", "b1", "base"): 0.0,
            ("B", "b1", "1d"): 9.0,
            ("B", "b1", "7d"): 0.0,
        }
    )
    # group A circles most at 7d (median 2.75); a2 rose by 4.5 there, a1 by 2
    assert cohort.circling_example(table, "A", "base", ["1d", "7d"]) == ("a2", "7d")
    assert cohort.circling_example(table, "B", "base", ["1d", "7d"]) == ("b1", "1d")
    assert cohort.circling_example(table, "A", "base", ["28d"]) == (None, None)
    no_gyro = table.drop_vars("circling_index")
    assert cohort.circling_example(no_gyro, "A", "base", ["1d"]) == (None, None)


def test_gravity_frame_velocity_and_quantiles(tiny):
    manifest, config, features = tiny
    v = cohort.gravity_frame_velocity(
        manifest, "Healthy01", "baseline", features, config
    )
    assert v["moving"].any()
    assert v["omega"].dims == ("frame", "time", "axis")
    assert v.attrs["max_check_deg_s"] < 1e-9
    assert v.attrs["circling_index"] == pytest.approx(
        v.attrs["circling_index_table"], abs=1e-9
    )
    # the rotation to the gravity frame keeps the angular speed
    norms = np.linalg.norm(v["omega"].values, axis=-1)
    np.testing.assert_allclose(norms[0], norms[1], rtol=1e-9, atol=1e-9)
    q = cohort.velocity_quantiles(v, n=11)
    moving = v["omega"].values[:, v["moving"].values]
    np.testing.assert_allclose(q["omega"].sel(quantile=0.0), moving.min(axis=1))
    np.testing.assert_allclose(q["omega"].sel(quantile=1.0), moving.max(axis=1))
    assert q.attrs["n_moving"] == int(v["moving"].sum())
    assert q["omega"].attrs["units"] == "deg/s"
    with pytest.raises(ValueError, match="n must be"):
        cohort.velocity_quantiles(v, n=1)
    still = v.assign(moving=v["moving"] & False)
    assert np.isnan(cohort.velocity_quantiles(still, n=5)["omega"]).all()


def test_circling_examples_and_the_archive(tiny, tmp_path):
    manifest, config, features = tiny
    ex = cohort.circling_examples(
        manifest,
        features,
        config,
        groups=["Arsanilate", "Healthy"],
        baseline="baseline",
        compared=["1d"],
        n=21,
    )
    assert ex["omega"].shape == (2, 2, 2, 21, 3)
    for group in ("Arsanilate", "Healthy"):
        animal, late = cohort.circling_example(features, group, "baseline", ["1d"])
        assert str(ex["subject"].sel(group=group).values) == animal
        v = cohort.gravity_frame_velocity(manifest, animal, late, features, config)
        np.testing.assert_array_equal(
            ex["omega"].sel(group=group, visit="late"),
            cohort.velocity_quantiles(v, n=21)["omega"],
        )
    # saved beside a feature table, the archive reads and checks them
    cohort.save_features(features, tmp_path / "features_default.nc")
    io.save_netcdf(ex, tmp_path / "velocity_default.nc")
    maps = cohort.group_tilt_maps(manifest, features, config, max_animals=1)
    io.save_netcdf(maps, tmp_path / "maps_default.nc")
    names = ["features_default.nc", "velocity_default.nc", "maps_default.nc"]
    io.write_sums(tmp_path, {n: io.file_sha256(tmp_path / n) for n in names})
    archive = cohort.read_feature_archive(tmp_path)
    xr.testing.assert_identical(archive.maps["default"], maps)
    xr.testing.assert_identical(archive.velocity["default"], ex)
    with open(tmp_path / "maps_default.nc", "r+b") as f:
        f.seek(-9, 2)
        f.write(b"tampered!")
    with pytest.raises(io.IntegrityError, match="maps_default.nc"):
        cohort.read_feature_archive(tmp_path)
