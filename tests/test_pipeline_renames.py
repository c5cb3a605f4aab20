"""The cohort and learn renames keep the old names working for one release."""

import warnings

import numpy as np
import pytest

from tiltlab import cohort
from tiltlab._validate import RecordingError
from tiltlab.simulate import simulate_session


@pytest.fixture(scope="module")
def rec():
    return simulate_session(20.0, 100.0, seed=3, keep_true=False)


def _same(a, b) -> bool:
    return a.attrs == b.attrs and all(
        np.array_equal(a[k].values, b[k].values, equal_nan=True) for k in a
    )


def test_session_features_takes_rec_and_the_old_keyword_with_a_warning(rec):
    config = cohort.FeatureConfig(mesh_n=500)
    new = cohort.session_features(rec=rec, config=config)
    with pytest.warns(FutureWarning, match="'recording' was renamed 'rec'"):
        old = cohort.session_features(recording=rec, config=config)
    assert _same(new, old)
    with pytest.raises(TypeError, match="pass 'rec' only"):
        cohort.session_features(rec=rec, recording=rec)


def test_session_tilt_takes_rec_and_the_old_keyword_with_a_warning(rec):
    config = cohort.FeatureConfig(mesh_n=500)
    corrected, tilt = cohort.session_tilt(rec=rec, config=config)
    with pytest.warns(FutureWarning, match="'recording' was renamed 'rec'"):
        _, tilt_old = cohort.session_tilt(recording=rec, config=config)
    np.testing.assert_array_equal(tilt.values, tilt_old.values)
    assert "gyr" in corrected


def test_save_features_names_its_argument_features(tmp_path, rec):
    features = cohort.empty_features(cohort.FeatureConfig(mesh_n=500))
    features = features.expand_dims(session=["s1"])
    path = cohort.save_features(features=features, path=tmp_path / "f.nc")
    with pytest.warns(FutureWarning, match="'ds' was renamed 'features'"):
        cohort.save_features(ds=features, path=tmp_path / "g.nc")
    assert path.read_bytes()[:4] == (tmp_path / "g.nc").read_bytes()[:4]


def _folder(tmp_path):
    for name in ("A/r1_d0.nc", "A/r1_d7.nc", "B/r2_d0.nc"):
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_text(name)
    return tmp_path


def test_init_manifest_declared_labels_and_the_old_keywords(tmp_path):
    folder = _folder(tmp_path)
    pattern = "{group}/{subject}_{timepoint}.nc"
    labels = cohort.StudyLabels(groups="A,B", timepoints=["d0", "d7"])
    new = cohort.init_manifest(folder, pattern, reader="netcdf", declared=labels)
    with pytest.warns(FutureWarning, match="groups= and timepoints= moved into"):
        old = cohort.init_manifest(
            folder, pattern, reader="netcdf", groups="A,B", timepoints=["d0", "d7"]
        )
    assert new.table.equals(old.table)
    with pytest.raises(cohort.ManifestError, match="unknown group 'B'"):
        cohort.init_manifest(
            folder,
            pattern,
            reader="netcdf",
            declared=cohort.StudyLabels(groups=["A"]),
        )
    with pytest.raises(TypeError, match="pass declared= only"):
        cohort.init_manifest(
            folder, pattern, reader="netcdf", declared=labels, groups="A,B"
        )


def test_init_manifest_without_warning_for_the_new_form(tmp_path):
    folder = _folder(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error", FutureWarning)
        m = cohort.init_manifest(
            folder, "{group}/{subject}_{timepoint}.nc", reader="netcdf"
        )
    assert m.sessions == ["r1_d0", "r1_d7", "r2_d0"]


learn = pytest.importorskip("tiltlab.learn")


def test_learn_old_names_are_warning_aliases():
    assert learn.load.__deprecated_alias_of__ is learn.load_model
    assert learn.run.__deprecated_alias_of__ is learn.closed_loop_estimate
    with pytest.warns(FutureWarning, match="load was renamed load_model"):
        with pytest.raises(FileNotFoundError):
            learn.load("no such model.pt", verify=False)


def test_sequence_refuses_an_accelerometer_only_recording(rec):
    with pytest.raises(RecordingError, match=r"need a gyroscope \('gyr'\)"):
        learn.sequence(rec.drop_vars("gyr"))


def test_sequence_names_every_missing_sensor(rec):
    with pytest.raises(RecordingError, match="gyroscope .* and a magnetometer"):
        learn.sequence(rec.drop_vars("gyr"))
    with pytest.raises(RecordingError, match=r"need a magnetometer \('mag'\)"):
        learn.sequence(rec)
    with pytest.warns(FutureWarning, match="'recording' was renamed 'rec'"):
        with pytest.raises(RecordingError, match="magnetometer"):
            learn.sequence(recording=rec)
