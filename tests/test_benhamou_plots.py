"""Figure recipes of the Benhamou additions: they draw what they are given."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from tiltlab import plot, simulate, sphere, trig  # noqa: E402


def test_heading_change_figure_has_a_map_and_a_polar_density():
    rng = np.random.default_rng(0)
    d, w = rng.vonmises(1.0, 3.0, 300), np.abs(rng.normal(0.0, 0.1, 300))
    k = sphere.heading_change_kde(d, w, cell_deg=2.0)
    ang, dens = sphere.circular_kde(d, h=0.3, weights=w)
    fig = plot.heading_change_figure(
        k, ang, dens, max_size=0.3, direction_labels={0.0: "left", np.pi: "right"}
    )
    polar = [a for a in fig.axes if a.name == "polar"]
    assert len(polar) == 1
    line = polar[0].lines[0]
    np.testing.assert_allclose(line.get_ydata()[:-1], dens)  # closed curve
    assert [t.get_text() for t in polar[0].get_xticklabels()] == ["left", "right"]
    plt.close(fig)


def test_flight_classes_figure_shades_every_window():
    heave = simulate.simulate_heave(6.0, 100.0, rng=0)
    c = trig.classify_flight(heave, np.zeros(heave.size), level=1.0, window_s=1.0)
    fig = plot.flight_classes_figure(heave, c, level=1.0)
    trace, plane = fig.axes
    assert len(trace.patches) == c.sizes["time"]
    shown = sum(
        len(line.get_xdata()) for line in plane.lines if line.get_marker() == "o"
    )
    assert shown == c.sizes["time"]
    plt.close(fig)
