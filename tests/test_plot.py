"""Light tests of the figure recipes in tiltlab.plot (Agg backend): each recipe draws,
labels its axes with units, adds legends to multi-line plots and colour bars to maps."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
import xarray as xr  # noqa: E402

from tiltlab import plot  # noqa: E402
from tiltlab import sphere as S  # noqa: E402

FS = 50.0


@pytest.fixture(autouse=True)
def _close():
    yield
    plt.close("all")


@pytest.fixture
def no_cartopy_data(monkeypatch, tmp_path):
    """Maps must draw with cartopy's data directories empty and no downloaders (no Natural Earth)."""
    cartopy = pytest.importorskip("cartopy")
    monkeypatch.setitem(cartopy.config, "data_dir", tmp_path)
    monkeypatch.setitem(cartopy.config, "pre_existing_data_dir", tmp_path)
    monkeypatch.setitem(cartopy.config, "downloaders", {})
    return cartopy


@pytest.fixture(scope="module")
def tilt():
    g = S.vmf_sample([0.2, 0.1, 1.0], 15, 1500, np.random.default_rng(0))
    return xr.DataArray(
        g,
        dims=("time", "axis"),
        name="gravity",
        coords={"time": np.arange(len(g)) / FS, "axis": list("xyz")},
        attrs={"fs": FS, "units": "1", "method": "lowpass"},
    )


@pytest.fixture(scope="module")
def mesh():
    return S.sphere_mesh(500)


def has_colorbar(ax) -> bool:
    return any(
        getattr(a, "colorbar", None) is not None for a in [*ax.collections, *ax.images]
    )


def legend_texts(ax) -> list[str]:
    leg = ax.get_legend()
    return [t.get_text() for t in leg.get_texts()] if leg is not None else []


# ---------------------------------------------------------------------------
# time series
# ---------------------------------------------------------------------------


def test_plot_recording_shades_a_mask_and_labels_units():
    t = np.arange(200) / FS
    rec = xr.Dataset(
        {
            "acc": (
                ("time", "axis"),
                np.random.default_rng(1).normal(size=(200, 3)),
                {"units": "g"},
            ),
            "gyr": (("time", "axis"), np.zeros((200, 3)), {"units": "deg/s"}),
        },
        coords={"time": t, "axis": list("xyz")},
        attrs={"fs": FS},
    )
    fig = plot.plot_recording(rec, shade=t < 1.0, shade_label="still")
    a0, a1 = fig.axes
    assert (
        a0.get_ylabel() == "acc (g)"
        and a1.get_ylabel() == "gyr (°/s)"
        and a1.get_xlabel() == "time (s)"
    )
    assert "still" in legend_texts(a0) and len(a0.patches) >= 1


def test_series_panels_reads_time_and_units():
    t = np.arange(100) / FS
    ref = xr.DataArray(
        np.sin(t), dims="time", coords={"time": t}, attrs={"units": "deg"}
    )
    fig = plot.series_panels(
        {
            "azimuth": {"optical": ref, "estimate": ref + 0.1},
            "bank": {"estimate": np.cos(t)},
        },
        styles={"optical": dict(lw=2, color="0.7")},
    )
    a0, a1 = fig.axes
    assert a0.get_ylabel() == "azimuth (°)" and a1.get_xlabel() == "time (s)"
    assert legend_texts(a0) == ["optical", "estimate"]
    np.testing.assert_allclose(a0.lines[0].get_xdata(), t)
    with pytest.raises(ValueError):
        plot.series_panels({"a": {"x": np.ones(5)}}, time=np.arange(4))


def test_speed_trace_and_histogram():
    t = np.arange(500) / FS
    speed = xr.DataArray(
        np.exp(np.random.default_rng(2).normal(2, 1, 500)),
        dims="time",
        coords={"time": t},
        attrs={"units": "deg/s"},
    )
    ax = plot.speed_trace(speed, threshold=12.0, mask=speed.values < 12.0)
    assert ax.get_ylabel() == "angular speed (°/s)" and ax.get_yscale() == "log"
    assert len(legend_texts(ax)) == 3
    ax = plot.speed_histogram(
        {"real": speed, "simulated": speed * 1.1}, thresholds={"12": 12.0, "auto": 8.0}
    )
    assert ax.get_xlabel() == "log10 angular speed (°/s)" and len(legend_texts(ax)) == 4


# ---------------------------------------------------------------------------
# scores
# ---------------------------------------------------------------------------


def test_score_heatmap_and_curves():
    s = xr.DataArray(
        np.arange(12.0).reshape(3, 4) + 1,
        dims=("kp", "ki"),
        coords={"kp": [0.1, 0.3, 1.0], "ki": [0, 0.01, 0.1, 1]},
        attrs={"units": "deg"},
    )
    ax = plot.score_heatmap(s, log=True)
    # parameter axes carry the filters' parameter units; the log colour bar plain numbers
    assert has_colorbar(ax) and ax.get_xlabel() == "ki (rad/s²)"
    assert ax.get_ylabel() == "kp (rad/s)"
    cbar = ax.images[0].colorbar
    assert cbar.ax.get_ylabel() == "mean error (°), log scale"
    ax.figure.canvas.draw()
    labels = [t.get_text() for t in cbar.ax.get_yticklabels() if t.get_text()]
    assert labels and all("10^" not in t and "$" not in t for t in labels), labels
    s_units = s.assign_coords(kp=s["kp"].assign_attrs(units="1/s"))
    ax = plot.score_heatmap(s_units, param_units={})
    assert ax.get_ylabel() == "kp (1/s)" and ax.get_xlabel() == "ki"
    with pytest.raises(ValueError, match="positive"):
        plot.score_heatmap(s - 5, log=True)
    assert [t.get_text() for t in ax.get_xticklabels()] == ["0", "0.01", "0.1", "1"]
    ax = plot.score_curves(s, "kp", hue="ki")
    assert (
        ax.get_ylabel() == "mean error (°)"
        and len(legend_texts(ax)) == 4
        and ax.get_xscale() == "log"
    )


def test_trial_bars_ecdf_and_binned_errors():
    table = pd.DataFrame(
        {"ekf": [0.5, 0.7], "madgwick": [0.9, 1.1]},
        index=["1 rotation", "2 translation"],
    )
    ax = plot.trial_bars(table, logy=True)
    assert ax.get_ylabel() == "RMSE, log scale (°)" and legend_texts(ax) == [
        "ekf",
        "madgwick",
    ]
    rng = np.random.default_rng(3)
    errs = {"ekf": rng.gamma(2, 1, 300), "lowpass": rng.gamma(3, 1, 300)}
    ax = plot.ecdf_plot(
        errs, mask=np.arange(300) < 200, vline=1.0, vline_label="optical uncertainty"
    )
    assert ax.get_xlabel() == "tilt error (°)" and len(legend_texts(ax)) == 3
    assert ax.lines[0].get_ydata()[-1] == 1.0 and len(ax.lines[0].get_xdata()) == 200
    bins = xr.Dataset(
        {
            k: (("estimator", "speed"), v)
            for k, v in {
                "median": np.ones((2, 3)),
                "q25": 0.5 * np.ones((2, 3)),
                "q75": 2 * np.ones((2, 3)),
            }.items()
        },
        coords={"estimator": ["ekf", "lowpass"], "speed": [6.0, 18.0, 37.5]},
    )
    ax = plot.binned_errors(bins)
    assert ax.get_xlabel() == "angular speed (°/s)" and legend_texts(ax) == [
        "ekf",
        "lowpass",
    ]


# ---------------------------------------------------------------------------
# cohort
# ---------------------------------------------------------------------------


def test_tukey_boxplot_and_group_lines():
    rng = np.random.default_rng(4)
    df = pd.DataFrame(
        {
            "group": np.repeat(["sham", "lesion"], 12),
            "timepoint": np.tile(["pre", "d1", "d7"], 8),
            "tilt": rng.normal(0, 5, 24),
        }
    )
    ax = plot.tukey_boxplot(df, "tilt", by="timepoint", hue="group", units="deg")
    assert ax.get_ylabel() == "tilt (°)" and ax.get_xlabel() == "timepoint"
    assert legend_texts(ax) == ["sham", "lesion"]
    assert [t.get_text() for t in ax.get_xticklabels()] == ["pre", "d1", "d7"]
    ds = xr.Dataset.from_dataframe(df.set_index(pd.RangeIndex(24, name="session")))
    ds["tilt"].attrs["units"] = "deg"
    ax = plot.group_lines(ds, "tilt", x="timepoint", hue="group")
    assert ax.get_ylabel() == "tilt (°)" and legend_texts(ax) == ["sham", "lesion"]


# ---------------------------------------------------------------------------
# maps
# ---------------------------------------------------------------------------


def test_tilt_heatmap_from_labelled_tilt_has_a_colorbar_in_seconds(
    no_cartopy_data, tilt, mesh
):
    ax = plot.tilt_heatmap(tilt, mesh=mesh, quantity="time", log=False)
    assert has_colorbar(ax)
    assert ax.collections[0].colorbar.ax.get_ylabel() == "time (s)"
    ax = plot.tilt_heatmap(
        S.tilt_map(tilt, mesh=mesh)
    )  # a map: the mesh comes from its n_vertices
    assert ax.collections[0].colorbar.ax.get_ylabel() == "log10 time fraction"
    ax.figure.canvas.draw()
    with pytest.raises(ValueError, match="fs"):
        plot.tilt_heatmap(tilt.values, mesh=mesh, quantity="time")


def test_tilt_overview_and_facet_map(no_cartopy_data, tilt, mesh):
    fig = plot.tilt_overview(tilt, mesh=mesh)
    assert any(
        a.get_ylabel() == "log10 time fraction" for a in fig.axes
    )  # the colour bar
    fig.canvas.draw()
    vals = xr.DataArray(
        np.arange(mesh.n_faces, dtype=float),
        dims="facet",
        attrs={"units": "s", "long_name": "dwell"},
    )
    fig, axes = plot.map_grid(2, centre=[[0, 0, 1], [1, 0, 0]])
    assert len(axes) == 2
    ax = plot.facet_map(vals, mesh, ax=axes[1])
    assert ax.collections[0].colorbar.ax.get_ylabel() == "dwell (s)"
    with pytest.raises(ValueError, match="map axes"):
        plot.facet_map(vals, mesh, ax=plt.figure().add_subplot())


def test_visited_map_and_points(no_cartopy_data, tilt, mesh):
    imm = (np.arange(tilt.sizes["time"]) // 100) % 3 == 0  # immobile bouts of 2 s
    ax = plot.visited_map({"active": tilt[~imm], "immobile": tilt[imm]}, mesh=mesh)
    texts = legend_texts(ax)
    assert (
        len(texts) == 2
        and texts[0].startswith("active (")
        and "% of the sphere" in texts[0]
    )
    mus = {"t0": [0.0, 0.0, 1.0], "t1": [0.0, -0.3, 1.0], "t2": [0.1, -0.2, 1.0]}
    ax = plot.tilt_points_map(mus, baseline="t0")
    assert legend_texts(ax) == ["t0", "t1", "t2"]
    ax.figure.canvas.draw()
    ax = plot.tilt_trace(tilt, title="rat")
    assert ax.get_xlabel() and ax.get_ylabel() and len(legend_texts(ax)) == 2


def test_kde_map_has_isopleth_legend_and_colorbar(no_cartopy_data, tilt):
    k = S.kde(tilt, cell_deg=4.0)
    ax = plot.kde_map(
        k, cut=0.95, points=tilt, centre="mean", extent=0.6, scale="linear"
    )
    assert ax.collections[0].colorbar.ax.get_ylabel() == "density (sr⁻¹)"
    assert legend_texts(ax) == ["50 % isopleth", "95 % isopleth", "samples"]
    ax.figure.canvas.draw()
    ax = plot.kde_map(k, labels={})
    assert "√density" in ax.collections[0].colorbar.ax.get_ylabel()
    with pytest.raises(ValueError, match="scale"):
        plot.kde_map(k, scale="cubic")


def test_residence_figure(no_cartopy_data, tilt, mesh):
    res = S.residence(tilt, mesh.centroids, np.radians(15), 1.0)
    idx, rt, nv = S.residence_series(tilt, np.radians(15), 1.0, stride=50)
    fig = plot.residence_figure(res, mesh, series=(idx / FS, rt, nv))
    labels = [a.get_ylabel() for a in fig.axes]
    assert "mean residence time (s)" in labels and "number of visits" in labels
    line_ax = [a for a in fig.axes if a.get_xlabel() == "time (s)"][0]
    assert len(legend_texts(line_ax)) == 2
    fig.canvas.draw()


def test_old_spheremaps_module_is_gone():
    with pytest.raises(ImportError):
        import tiltlab.spheremaps  # noqa: F401


def test_group_lines_median_and_iqr():
    import pandas as pd

    df = pd.DataFrame(
        {
            "group": ["a"] * 6 + ["b"] * 6,
            "t": ["0", "0", "0", "1", "1", "1"] * 2,
            "v": [1.0, 2.0, 9.0, 2.0, 3.0, 4.0, 0.0, 0.0, 1.0, 5.0, 6.0, 7.0],
        }
    )
    ax = plot.group_lines(df, "v", x="t", hue="group", err="iqr")
    line = ax.get_lines()[0]
    np.testing.assert_allclose(line.get_ydata(), [2.0, 3.0])  # medians, not means
    assert len(legend_texts(ax)) == 2
    with pytest.raises(ValueError, match="err"):
        plot.group_lines(df, "v", x="t", hue="group", err="ci")


# ---------------------------------------------------------------------------
# several estimates of one recording
# ---------------------------------------------------------------------------


def test_estimates_overview_one_legend_log_errors():
    from tiltlab import quaternion as Q

    n = 600
    t = np.arange(n) / FS
    rng = np.random.default_rng(2)
    q = Q.integrate_gyro(0.5 * rng.normal(size=(n, 3)), FS, np.array([1.0, 0, 0, 0]))
    est = {"a": q, "b": Q.normalize(q + 0.01 * rng.normal(size=q.shape))}
    errs = {"a": np.full(n, 0.5), "b": np.abs(rng.normal(size=n)) + 0.1}
    fig = plot.estimates_overview(est, reference=q, errors=errs, time=t)
    top, bottom = fig.axes
    assert fig.get_figwidth() <= 8.4
    assert len(fig.legends) == 1 and top.get_legend() is None
    assert [x.get_text() for x in fig.legends[0].get_texts()] == ["a", "b", "reference"]
    assert "°" in top.get_ylabel() and "(s)" in bottom.get_xlabel()
    assert bottom.get_yscale() == "log"
    # a constant error has a constant running RMS; no reference: one panel
    assert np.allclose(plot.running_rms(errs["a"], 25), 0.5)
    assert len(plot.estimates_overview(est, time=t).axes) == 1
    # the error axis is labelled with plain numbers, not powers of ten
    fig.canvas.draw()
    labels = [x.get_text() for x in bottom.get_yticklabels() if x.get_text()]
    assert labels and not any("10^" in x or "times" in x for x in labels)
    angle = plot.tilt_angle_deg(np.array([[1.0, 0, 0, 0], [np.nan] * 4]))
    assert angle[0] == pytest.approx(0.0) and np.isnan(angle[1])
