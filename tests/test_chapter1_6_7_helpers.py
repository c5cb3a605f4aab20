"""Helpers moved out of chapters 1, 6 and 7: source names, printed directions,
tried CSV mappings and anchored dead reckoning."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tiltlab import datasets, io, simulate, sphere, trig


@pytest.mark.parametrize(
    ("source", "name"),
    [
        ("broad:2", "broad:2"),
        ("fayat:example", "fayat:example"),
        ("/data/lab/rat7_day3.nc", "rat7_day3.nc"),
        (Path("lab") / "trial.hdf5", "trial.hdf5"),
        ("relative/folder", "relative/folder"),
    ],
)
def test_source_name(source, name):
    assert datasets.source_name(source) == name


def test_format_direction():
    assert (
        sphere.format_direction([0.0, -0.5, 0.866025]) == "(+0.0000, -0.5000, +0.8660)"
    )
    assert (
        sphere.format_direction(np.array([1, 0, 0]), digits=1) == "(+1.0, +0.0, +0.0)"
    )
    with pytest.raises(ValueError, match="1-D"):
        sphere.format_direction(np.eye(3))
    with pytest.raises(ValueError, match="digits"):
        sphere.format_direction([1, 0, 0], digits=-1)


def _csv(tmp_path):
    t = np.arange(200) / 100.0
    frame = pd.DataFrame({"time_s": t})
    for k, axis in enumerate("xyz"):
        frame[f"a{axis}"] = [0.0, 0.0, 1.0][k] + 0.001 * np.sin(t + k)
        frame[f"g{axis}"] = 0.5 * np.cos(t + k)
    path = tmp_path / "session.csv"
    frame.to_csv(path, index=False)
    mapping = {
        "columns": {"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]},
        "units": {"acc": "g", "gyr": "deg/s"},
        "time_column": "time_s",
        "time_units": "s",
    }
    return path, mapping


def test_try_read(tmp_path):
    path, mapping = _csv(tmp_path)
    assert io.try_read(path, mapping) is None
    wrong_column = {
        **mapping,
        "columns": {**mapping["columns"], "acc": ["a", "b", "c"]},
    }
    message = io.try_read(path, wrong_column)
    assert isinstance(message, str) and message.split(":")[0].endswith("Error")
    missing = io.try_read(tmp_path / "absent.csv", mapping)
    assert isinstance(missing, str) and "absent.csv" in missing


def test_anchor_steps():
    np.testing.assert_array_equal(trig.anchor_steps(10, 4), [0, 4, 8, 10])
    np.testing.assert_array_equal(trig.anchor_steps(8, 4), [0, 4, 8])
    np.testing.assert_array_equal(trig.anchor_steps(3, 10), [0, 3])
    with pytest.raises(ValueError, match="every"):
        trig.anchor_steps(10, 0)


def test_dead_reckon_every_ends_on_anchors_and_matches_dead_reckon():
    rng = np.random.default_rng(3)
    track = simulate.simulate_track(120, 1.0, rng=rng)
    az = track.azimuth + rng.normal(0, 0.1, 120)
    el = track.elevation + rng.normal(0, 0.05, 120)
    speed = 0.3 * track.speed
    steps, path = trig.dead_reckon_every(track.positions, speed, az, el, 50)
    np.testing.assert_array_equal(steps, [0, 50, 100, 120])
    assert path.shape == track.positions.shape
    np.testing.assert_allclose(path[steps], track.positions[steps], atol=1e-9)
    direct = trig.dead_reckon(speed, az, el, track.positions[steps], steps)
    np.testing.assert_allclose(path, direct)
    mean_err, _ = trig.anchored_errors(track.positions, speed, az, el, [50])
    err = np.linalg.norm(path - track.positions, axis=1).mean()
    assert err == pytest.approx(mean_err[0])
