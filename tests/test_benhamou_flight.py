"""Benhamou 2023 §9: kestrel flight classes from heave crossings and elevation."""

from __future__ import annotations

import numpy as np
import pytest

from tiltlab import simulate, trig

FS, DUR = 100.0, 20.0
N = int(FS * DUR)


def _heave(kind: str, rng=0):
    """Simulated heave of one behaviour (hover: fast regular beats; perched: small noise)."""
    beats = np.ones(N, bool)
    kw = {
        "hover": dict(flapping=beats, period_s=0.11),
        "flap": dict(flapping=beats, period_s=0.18),
        "glide": dict(flapping=~beats),
        "perched": dict(flapping=~beats, glide_sd=0.05),
    }[kind]
    return simulate.simulate_heave(DUR, FS, rng=rng, **kw)


ELEVATION_DEG = {"hover": 0.0, "flap": 2.0, "glide": -3.0, "perched": 45.0}


@pytest.mark.parametrize("kind", ["hover", "flap", "glide", "perched"])
def test_each_simulated_behaviour_is_recognised(kind):
    heave = _heave(kind)
    el = np.full(N, np.radians(ELEVATION_DEG[kind]))
    c = trig.classify_flight(heave, el, level=1.0, window_s=1.0)
    assert (c.behavior.values == kind).mean() >= 0.95
    assert c.sizes["time"] == DUR


def test_the_published_thresholds_are_the_defaults():
    # Benhamou 2023 §9: CV 0.5, hover T < 150 ms, flapping T in [150, 220] ms
    c = trig.classify_flight(_heave("flap"), np.zeros(N), level=1.0, window_s=1.0)
    assert c.attrs["cv_max"] == 0.5
    assert c.attrs["hover_max_s"] == 0.150
    assert c.attrs["flap_range_s"] == (0.150, 0.220)


def test_elevation_separates_gliding_from_perching():
    heave = _heave("glide")
    for deg, kind in [(10.0, "glide"), (30.0, "perched"), (-30.0, "none")]:
        c = trig.classify_flight(
            heave, np.full(N, np.radians(deg)), level=1.0, window_s=1.0
        )
        assert (c.behavior.values == kind).mean() >= 0.95, deg
    # the tolerance is a parameter: 10° is "φ ≫ 0" once it is 5°
    c = trig.classify_flight(
        heave, np.full(N, np.radians(10.0)), level=1.0, window_s=1.0, level_tol_deg=5.0
    )
    assert (c.behavior.values == "perched").mean() >= 0.95


def test_a_slow_regular_oscillation_is_unclassified():
    # regular (CV < 0.5) but T = 300 ms: no class of the paper
    heave = simulate.simulate_heave(
        DUR, FS, flapping=np.ones(N, bool), period_s=0.3, rng=0
    )
    c = trig.classify_flight(heave, np.zeros(N), level=1.0, window_s=1.0)
    assert (c.behavior.values == "none").mean() >= 0.95


def test_period_boundaries_follow_the_thresholds():
    heave = _heave("flap")  # T ≈ 180 ms
    c = trig.classify_flight(
        heave, np.zeros(N), level=1.0, window_s=1.0, flap_range_s=(0.19, 0.25)
    )
    assert (c.behavior.values == "none").mean() >= 0.95
    c = trig.classify_flight(
        heave, np.zeros(N), level=1.0, window_s=1.0, hover_max_s=0.2
    )
    assert (c.behavior.values == "hover").mean() >= 0.95


def test_time_budget_sums_to_the_classified_duration():
    heave = np.concatenate([_heave("flap").values, _heave("glide").values])
    el = np.zeros(heave.size)
    c = trig.classify_flight(heave, el, FS, level=1.0, window_s=0.5)
    tab = trig.flight_time_budget(c)
    assert list(tab.index) == list(trig.FLIGHT_CLASSES)
    assert tab["duration (s)"].sum() == pytest.approx(2 * DUR)
    assert tab["fraction"].sum() == pytest.approx(1.0)
    assert tab.loc["flap", "duration (s)"] == pytest.approx(DUR, abs=1.0)
    assert tab.loc["glide", "duration (s)"] == pytest.approx(DUR, abs=1.0)


def test_labelled_input_keeps_its_clock():
    heave = _heave("flap")
    heave = heave.assign_coords(time=heave.time + 100.0)
    c = trig.classify_flight(heave, np.zeros(N), level=1.0, window_s=1.0)
    assert float(c.time[0]) == pytest.approx(100.5)
    assert c.cv.attrs["units"] == "1" and c.period.attrs["units"] == "s"


def test_classify_flight_does_not_mutate_its_inputs():
    heave = _heave("glide")
    el = np.zeros(N)
    before = heave.values.copy()
    trig.classify_flight(heave, el, level=1.0, window_s=1.0)
    np.testing.assert_array_equal(heave.values, before)
    assert np.all(el == 0)


@pytest.mark.parametrize(
    "kw, word",
    [
        ({"cv_max": 0.0}, "cv_max"),
        ({"hover_max_s": -1.0}, "hover_max_s"),
        ({"flap_range_s": (0.2, 0.1)}, "flap_range_s"),
        ({"level_tol_deg": 90.0}, "level_tol_deg"),
        ({"level_tol_deg": -1.0}, "level_tol_deg"),
        ({"window_s": -1.0}, "window_s"),
    ],
)
def test_bad_thresholds_name_the_problem(kw, word):
    args = {"level": 1.0, "window_s": 1.0, **kw}
    with pytest.raises(ValueError, match=word):
        trig.classify_flight(_heave("flap"), np.zeros(N), **args)


def test_elevation_length_must_match():
    with pytest.raises(ValueError, match="elevation"):
        trig.classify_flight(_heave("flap"), np.zeros(N - 1), level=1.0, window_s=1.0)


def test_budget_refuses_other_tables():
    with pytest.raises(ValueError, match="classify_flight"):
        trig.flight_time_budget(np.zeros(3))
