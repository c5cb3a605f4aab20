"""Calibration and simulation after the option-record refactoring: old keywords keep
working (with a FutureWarning), option records equal the keywords they group, and the
head frame from markers has one implementation.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import tiltlab.calibration as C
from tiltlab import frames, simulate


def _gyr():
    rng = np.random.default_rng(3)
    gyr = rng.normal(0.0, 0.2, (800, 3)) + [6.0, -3.0, 2.0]
    gyr[300:400, 1] += 80.0 * np.sin(np.linspace(0.0, np.pi, 100))
    return gyr


def test_detect_static_old_offset_keyword_warns_and_gives_the_same_periods():
    gyr = _gyr()
    ref = C.detect_static(gyr, 100.0, gyr_offset=[6.0, -3.0, 2.0])
    assert ref.shape[0] == 2
    with pytest.warns(FutureWarning, match="'offset' was renamed 'gyr_offset'"):
        old = C.detect_static(gyr, 100.0, offset=[6.0, -3.0, 2.0])
    np.testing.assert_array_equal(old, ref)
    with pytest.raises(TypeError, match="gyr_offset"):
        C.detect_static(gyr, 100.0, offset=np.zeros(3), gyr_offset=np.zeros(3))


def test_still_criteria_record_equals_keywords():
    gyr = _gyr()
    kw = dict(threshold_deg_s=2.0, smooth_s=0.2, min_duration_s=0.5, merge_gap_s=0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # today's keyword calls warn nothing
        by_keywords = C.detect_static(gyr, 100.0, **kw)
    by_record = C.detect_static(gyr, 100.0, criteria=C.StillCriteria(**kw))
    np.testing.assert_array_equal(by_record, by_keywords)
    # keywords override the record's fields
    np.testing.assert_array_equal(
        C.detect_static(
            gyr, 100.0, criteria=C.StillCriteria(**kw), threshold_deg_s=3.0
        ),
        C.detect_static(gyr, 100.0, **dict(kw, threshold_deg_s=3.0)),
    )
    with pytest.raises(TypeError, match="threshold_dps"):
        C.detect_static(gyr, 100.0, threshold_dps=3.0)
    with pytest.raises(TypeError, match="StillCriteria"):
        C.detect_static(gyr, 100.0, criteria={"threshold_deg_s": 3.0})


def test_calibration_head_frame_is_the_frames_implementation():
    assert C.head_frame_from_markers is frames.head_frame_from_markers
    assert simulate.head_frame_from_markers is frames.head_frame_from_markers
    p1, p2, p3 = (
        np.array([0, 16.0, 30]),
        np.array([0, -16.0, 30]),
        np.array([35.0, -16, 30]),
    )
    np.testing.assert_allclose(C.tilt_from_markers(p1, p2, p3), [0.0, 0.0, 1.0])


def test_phone_export_old_recording_keyword_warns(tmp_path):
    rec = simulate.simulate_session(2.0, 50.0, seed=4)
    new = simulate.phone_export(rec, tmp_path / "new", seed=1)
    with pytest.warns(FutureWarning, match="'recording' was renamed 'rec'"):
        old = simulate.phone_export(recording=rec, folder=tmp_path / "old", seed=1)
    assert sorted(new) == sorted(old)
    for k in new:
        assert new[k].read_text() == old[k].read_text()


def test_simulate_exports_every_submodule_name_once():
    names = simulate.__all__
    assert len(names) == len(set(names))
    for n in (
        "simulate_session",
        "tumble_test",
        "phone_export",
        "PHONE_FILES",
        "Track",
    ):
        assert n in names and hasattr(simulate, n)


def test_sensor_truth_matches_the_drawn_model():
    rng = np.random.default_rng(5)
    true = {"acc": np.tile([0.0, 0.0, 1.0], (300, 1)), "gyr": np.zeros((300, 3))}
    out = simulate.apply_sensor_model(true, None, rng, 100.0)
    s, truth = out["sensor"], out["truth"]
    m = (np.eye(3) + np.diag(s.gyr_scale)) @ (np.eye(3) + np.asarray(s.gyr_misalign))
    np.testing.assert_array_equal(truth["true_gyr_matrix"], m)
    np.testing.assert_array_equal(truth["true_acc_offset"], s.acc_offset)
    assert list(truth)[:2] == ["true_acc_offset", "true_gyr_offset"]
    assert truth["n_saturated_acc"] == 0 and truth["n_saturated_gyr"] == 0
