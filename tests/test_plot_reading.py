"""Figure details a reader relies on: axis colours agree between recipes, dashed legend
samples stay dashed, legends never cover data or threshold lines, a short log colour bar
has enough ticks, and simulated references say what their axes point to."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from tiltlab import filters, plot, simulate
from tiltlab.plot._common import AXIS_COLOURS
from tiltlab.plot.filters import plain_log_ticks
from tiltlab.plot.recording import _thicken


@pytest.fixture(autouse=True)
def _close():
    yield
    plt.close("all")


def test_series_panels_use_the_fixed_axis_colours():
    t = np.arange(50) / 10
    fig = plot.series_panels(
        {"rate": {"x (forward)": t, "y": t, "z": t, "optical": t}},
        time=t,
        units="deg/s",
        styles={"z": {"color": "k"}},
    )
    lines = {ln.get_label(): ln for ln in fig.axes[0].get_lines()}
    to_rgba = matplotlib.colors.to_rgba
    assert to_rgba(lines["x (forward)"].get_color()) == to_rgba(AXIS_COLOURS["x"])
    assert to_rgba(lines["y"].get_color()) == to_rgba(AXIS_COLOURS["y"])
    assert to_rgba(lines["z"].get_color()) == to_rgba("k")  # a style wins
    assert lines["optical"].get_color() not in AXIS_COLOURS.values()


@pytest.mark.parametrize("style", ["--", "-.", ":"])
def test_thickened_legend_samples_stay_patterned(style):
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1], ls=style, lw=0.8, label="a")
    ax.plot([0, 1], [1, 0], lw=0.8, label="b")
    legend = _thicken(ax.legend())
    fig.canvas.draw()
    handle = legend.get_lines()[0]
    assert handle.get_linewidth() >= 2.0
    _, pattern = handle._dash_pattern  # after scaling by the width, in points
    sample = legend.handlelength * legend._fontsize  # the legend sample's length
    assert sum(pattern) * 2 <= sample, (style, pattern, sample)
    assert legend.get_lines()[1]._dash_pattern[1] is None  # solid stays solid


def test_speed_histogram_legend_sits_beside_the_axes():
    rng = np.random.default_rng(0)
    ax = plot.speed_histogram(
        {"a": rng.lognormal(2, 1, 500), "b": rng.lognormal(1, 1, 500)}, thresholds=12.0
    )
    fig = ax.figure
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    box = ax.get_legend().get_window_extent(renderer)
    assert box.x0 >= ax.get_window_extent(renderer).x1


@pytest.mark.parametrize(("lo", "hi"), [(2.0, 9.0), (0.3, 0.8), (1.0, 1000.0)])
def test_plain_log_ticks_label_short_ranges(lo, hi):
    fig, ax = plt.subplots()
    ax.set_yscale("log")
    ax.set_ylim(lo, hi)
    plain_log_ticks(ax)
    fig.canvas.draw()
    ticks = [v for v in ax.get_yticks() if lo <= v <= hi]
    assert len(ticks) >= 3, ticks
    labels = [t.get_text() for t in ax.get_yticklabels() if t.get_text()]
    assert labels and not any("$" in s for s in labels), labels  # plain numbers


def test_simulated_reference_names_its_axes():
    rec = simulate.simulate_session(2.0, 50.0, seed=3)
    assert rec["q_ref"].attrs["axis_labels"] == rec.attrs["axis_labels"]
    tilt = filters.gravity(rec["q_ref"])
    assert tilt.attrs["axis_labels"][0].startswith("forward")
    ax = plot.tilt_trace(tilt)
    assert "nose (+x)" in ax.get_ylabel()


def _history(with_val: bool):
    def rows(offset):
        out = []
        for e, (tr, va) in enumerate(zip([5.0, 4.0, 3.5, 3.4], [9.0, 7.0, 7.5, 8.0])):
            r = {"epoch": e + 1, "qae_deg": tr + offset, "loss": 1.0}
            if with_val:
                r |= {"val_qae_deg": va + offset, "best": False}
            out.append(r)
        return out

    return {f"{v}/fold{k}": rows(k) for v in ("gain", "quaternion") for k in range(2)}


def test_learning_curves_show_validation_and_the_kept_epoch():
    fig = plot.learning_curves(_history(True))
    assert len(fig.axes) == 4  # training and validation rows, one column per variant
    val_ax = fig.axes[2]
    assert "validation" in val_ax.get_ylabel()
    stars = [ln for ln in val_ax.get_lines() if ln.get_marker() == "*"]
    assert len(stars) == 2  # one per fold
    assert all(list(s.get_xdata()) == [2] for s in stars)  # the lowest validation QAE
    plain = plot.learning_curves(_history(False))
    assert len(plain.axes) == 2 and "training" in plain.axes[0].get_ylabel()
