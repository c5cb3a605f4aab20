"""The ``fayat2021`` feature preset: Fayat et al.'s definitions beside the default.

Madgwick with β = 0.1, facets counted, the vMF mean of the immobility tilt map from
facet centroids weighted by counts (§2.8), and the unsigned angular distance to the
sagittal plane (Fig. 4c). Checked here: the preset's values, its round trip, that
each option changes only what it names, and how much (the unsigned distance is the
absolute signed angle; facet counts and areas differ by at most the facets' area
ratio; map and sample means agree to within a facet).
"""

import numpy as np
import pytest

from tiltlab import cohort, simulate, sphere
from tiltlab.cohort import FeatureConfig


@pytest.fixture(scope="module")
def session():
    return simulate.simulate_session(240.0, 200.0, seed=11)


def _features(rec, **kw):
    return cohort.session_features(rec, FeatureConfig(**kw))


def test_the_preset_holds_the_papers_choices():
    c = FeatureConfig.fayat2021()
    assert (c.method, c.method_params["beta"]) == ("madgwick", 0.1)
    assert (c.visited_by, c.tilt_mean, c.sagittal) == ("count", "map", "unsigned")
    assert (c.threshold_deg_s, c.merge_gap_s, c.min_duration_s) == (12.0, 0.1, 0.5)
    assert c.mesh_n == 5000
    assert FeatureConfig.from_json(c.to_json()) == c
    assert c.hash() != FeatureConfig().hash()
    assert FeatureConfig.fayat2021(lesion_side="right").lesion_side == "right"


def test_unsigned_distance_is_the_absolute_signed_angle(session):
    signed = _features(session, lesion_side="right")
    unsigned = _features(session, lesion_side="right", sagittal="unsigned")
    a = float(signed["tilt_immobile_sagittal_deg"])
    assert float(unsigned["tilt_immobile_sagittal_deg"]) == pytest.approx(abs(a))
    other = _features(session, lesion_side="left", sagittal="unsigned")
    assert float(other["tilt_immobile_sagittal_deg"]) == pytest.approx(abs(a))
    for k in ("immobile_fraction", "visited_fraction_moving", "circling_index"):
        assert float(unsigned[k]) == float(signed[k])  # nothing else changes


def test_facet_count_and_area_differ_by_at_most_the_area_ratio(session):
    area = float(_features(session)["visited_fraction_moving"])
    count = float(_features(session, visited_by="count")["visited_fraction_moving"])
    ratio = sphere.sphere_mesh(FeatureConfig().mesh_n).area_ratio()
    assert 0 < area < 1 and 0 < count < 1
    assert count / ratio <= area <= count * ratio


def test_map_mean_agrees_with_the_sample_mean_within_a_facet(session):
    keys = ["tilt_immobile_x", "tilt_immobile_y", "tilt_immobile_z"]
    a = np.array([float(_features(session)[k]) for k in keys])
    b = np.array([float(_features(session, tilt_mean="map")[k]) for k in keys])
    mesh = sphere.sphere_mesh(FeatureConfig().mesh_n)
    facet_radius = np.sqrt(mesh.areas.max() / np.pi)  # rad, a generous facet size
    angle = np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1))
    assert angle < facet_radius
    assert not np.array_equal(a, b)


def test_long_names_follow_the_definitions():
    default = cohort.feature_specs(FeatureConfig())
    paper = cohort.feature_specs(FeatureConfig.fayat2021())
    assert "area" in default["visited_fraction_moving"][1]
    assert "facets" in paper["visited_fraction_moving"][1]
    assert "positive toward" in default["tilt_immobile_sagittal_deg"][1]
    assert "angular distance" in paper["tilt_immobile_sagittal_deg"][1]


@pytest.mark.parametrize(
    "field, value",
    [("visited_by", "volume"), ("tilt_mean", "median"), ("sagittal", "absolute")],
)
def test_unknown_choices_are_named(field, value):
    with pytest.raises(ValueError, match=field):
        FeatureConfig(**{field: value})
