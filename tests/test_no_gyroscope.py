"""Recordings without a gyroscope (accelerometer, maybe magnetometer) are first-class:
orientation, immobility, cohort features and figures work on them or refuse by name."""

from __future__ import annotations

import warnings

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import xarray as xr  # noqa: E402

from tiltlab import behavior as B  # noqa: E402
from tiltlab import cohort  # noqa: E402
from tiltlab import filters as F  # noqa: E402
from tiltlab import quaternion as Q  # noqa: E402
from tiltlab import schema, sphere  # noqa: E402
from tiltlab._validate import RecordingError  # noqa: E402
from tiltlab.simulate import simulate_session  # noqa: E402

FS = 100.0
RAT = ["forward (nose)", "left", "up (dorsal)"]


def _session(duration_s=60.0, seed=3):
    return simulate_session(duration_s, FS, seed=seed, keep_true=False)


def _acc_only(rec):
    return rec.drop_vars([v for v in ("gyr", "mag") if v in rec])


def _with_mag(n=600, seed=0):
    """acc + mag of a slowly tumbling sensor, with the true orientation."""
    t = np.arange(n) / FS
    rv = np.stack([0.4 * np.sin(0.7 * t), 0.3 * np.cos(0.5 * t), 0.8 * t], axis=1)
    q = Q.from_rotvec(rv)
    acc = Q.gravity(q)
    mag = Q.rotate_inverse(q, np.tile([0.0, 20.0, -40.0], (n, 1)))
    rec = schema.make_recording(
        acc, fs=FS, acc_units="g", mag=mag, mag_units="uT", axis_labels=RAT
    )
    return rec, q


def _angle_deg(p, q):
    return np.degrees(np.linalg.norm(Q.to_rotvec(Q.mul(Q.conj(p), q)), axis=1))


# ------------------------------------------------------------------ filters


def test_registry_says_what_each_method_needs():
    for name, m in F.METHODS.items():
        assert m.needs[0] == "acc", name
        assert ("gyr" in m.needs) == m.uses_gyr, name
        assert set(m.needs) <= set(F.SENSORS), name
    no_gyro = F.methods(needs="acc")
    assert "lowpass" in no_gyro
    assert all(not F.METHODS[n].uses_gyr for n in no_gyro)
    # more sensors never remove a method; all three sensors allow every method
    assert set(no_gyro) <= set(F.methods(needs=("acc", "mag")))
    assert set(F.methods(needs="acc+mag")) == set(F.methods(needs=("acc", "mag")))
    assert set(F.methods(needs=("acc", "gyr", "mag"))) == set(F.methods())
    rec, _ = _with_mag()
    assert F.methods(needs=rec) == F.methods(needs=("acc", "mag"))
    with pytest.raises(ValueError, match="needs: unknown sensor.*'baro'"):
        F.methods(needs="baro")


def test_estimate_without_gyroscope_runs_the_methods_that_need_none():
    rec, q = _with_mag()
    for method in F.methods(needs=rec):
        qe = F.estimate(rec, method)
        assert qe.dims == ("time", "quat") and qe.sizes["time"] == rec.sizes["time"]
        assert np.allclose(Q.norm(qe.values), 1.0, atol=1e-9)
        assert qe.attrs["axis_labels"] == RAT
    # Davenport's q-method recovers the full orientation of noise-free acc + mag
    qd = F.estimate(rec, "davenport")
    assert qd.attrs["world_frame"] == "ENU" and qd.attrs["use_mag"] == 1
    assert np.max(_angle_deg(qd.values, q)) < 1e-6
    # the low-pass of a slowly moving sensor: tilt close to the truth
    g = F.gravity(F.estimate(rec, "lowpass", cutoff_hz=5.0)).values
    cos = np.clip(np.sum(g * Q.gravity(q), axis=1), -1.0, 1.0)
    assert np.median(np.degrees(np.arccos(cos))) < 2.0


@pytest.mark.parametrize("with_mag", [False, True])
def test_every_gyroscope_method_is_refused_by_name(with_mag):
    rec, _ = _with_mag()
    if not with_mag:
        rec = rec.drop_vars("mag")
    runnable = F.methods(needs=rec)
    for method in F.methods():
        if method in runnable:
            continue
        with pytest.raises(RecordingError) as err:
            F.estimate(rec, method)
        msg = str(err.value)
        assert repr(method) in msg
        missing = "gyroscope" if F.METHODS[method].uses_gyr else "magnetometer"
        assert missing in msg
        for ok in runnable:  # the message lists what would run
            assert repr(ok) in msg
    # the prepare/run path used by parameter searches refuses the same way
    inputs = F.prepare(rec)
    assert inputs.gyr is None
    with pytest.raises(RecordingError, match="'madgwick' needs a gyroscope"):
        F.run_method("madgwick", inputs)
    assert F.run_method("lowpass", inputs).shape == (rec.sizes["time"], 4)


def test_estimate_ignores_a_broken_gyroscope_it_does_not_use():
    rec = _session(10.0)
    gyr = rec["gyr"].values.copy()
    gyr[100:150] = np.nan
    broken = rec.assign(gyr=(rec["gyr"].dims, gyr, rec["gyr"].attrs))
    a = F.estimate(broken, "lowpass")
    b = F.estimate(_acc_only(rec), "lowpass")
    np.testing.assert_array_equal(a.values, b.values)
    with pytest.raises(RecordingError, match="gap"):
        F.estimate(broken, "madgwick")


# ------------------------------------------------------------------ behavior


def test_immobility_picks_the_rule_from_the_data_and_records_it():
    rec = _session(60.0)
    gyro = B.immobility(rec)
    acc = B.immobility(_acc_only(rec))
    assert gyro.attrs["rule"] == "gyroscope"
    assert gyro.attrs["threshold_units"] == "deg/s"
    assert acc.attrs["rule"] == "accelerometer"
    assert acc.attrs["threshold_units"] == "g"
    assert acc.attrs["threshold"] == acc.attrs["threshold_g"] > 0
    assert "VeDBA" in acc.attrs["rule_description"]
    # forcing the accelerometer rule on a Recording with a gyroscope is the same
    forced = B.immobility(rec, rule="accelerometer")
    np.testing.assert_array_equal(forced.values, acc.values)
    # units tell the sensor of plain arrays and DataArrays
    plain = B.immobility(rec["acc"].values, FS, units="g")
    np.testing.assert_array_equal(plain, acc.values)
    labelled = rec["acc"].assign_attrs(fs=FS)
    np.testing.assert_array_equal(B.immobility(labelled).values, acc.values)
    # the same acceleration in m/s^2 gives the same mask
    ms2 = B.immobility(rec["acc"].values * 9.80665, FS, units="m/s^2")
    np.testing.assert_array_equal(ms2, acc.values)
    with pytest.raises(RecordingError, match="gyroscope"):
        B.immobility(_acc_only(rec), rule="gyroscope")
    with pytest.raises(ValueError, match="rule"):
        B.immobility(rec, rule="magic")
    with pytest.raises(RecordingError, match="units"):
        B.immobility(rec["acc"].values, FS)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_accelerometer_rule_agrees_with_the_gyroscope_rule(seed):
    # invariant: on simulated freely moving sessions where both sensors exist, the
    # acceleration-only rule labels more than 85 % of the samples as the gyroscope rule
    # does, and finds immobility when the gyroscope does
    rec = _session(120.0, seed=seed)
    gyro = np.asarray(B.immobility(rec, gyr_offset="auto"))
    acc = np.asarray(B.immobility(rec, rule="accelerometer"))
    assert np.mean(gyro == acc) > 0.85
    assert gyro.any() and acc.any() and (~acc).any()
    # most samples the accelerometer calls still are still for the gyroscope too
    assert np.mean(gyro[acc]) > 0.8


def test_accelerometer_rule_on_still_and_moving_extremes():
    rng = np.random.default_rng(0)
    n = 1000
    still = np.tile([0.0, 0.0, 1.0], (n, 1)) + rng.normal(0.0, 0.004, (n, 3))
    assert np.asarray(B.acc_immobility(still, FS, units="g")).all()
    t = np.arange(n) / FS
    shaking = still + 0.3 * np.sin(2 * np.pi * 3.0 * t)[:, None]
    assert not np.asarray(B.acc_immobility(shaking, FS, units="g")).any()
    # the input is never modified
    before = still.copy()
    B.acc_immobility(still, FS, units="g")
    np.testing.assert_array_equal(still, before)


def test_gyroscope_read_outs_refuse_an_accelerometer_only_recording_by_name():
    rec = _acc_only(_session(10.0))
    g = F.gravity(F.estimate(rec, "lowpass"))
    calls = {
        "angular_speed": lambda: B.angular_speed(rec),
        "recording_speed": lambda: B.recording_speed(rec),
        "gyro_spectrum": lambda: B.gyro_spectrum(rec),
        "azimuthal_speed": lambda: B.azimuthal_speed(rec, g),
        "circling_index": lambda: B.circling_index(rec, g),
    }
    for name, call in calls.items():
        with pytest.raises(RecordingError, match="needs a gyroscope") as err:
            call()
        assert name in str(err.value)
    # activity needs the accelerometer only
    assert np.isfinite(np.asarray(B.dba(rec, window_s=1.0))).all()
    assert np.isfinite(np.asarray(B.odba(rec, window_s=1.0))).all()


# ------------------------------------------------------------------ cohort features

CONFIG = cohort.FeatureConfig(mesh_n=500)


def _reasons(ds):
    return {k: ds[k].attrs["reason"] for k in ds.data_vars if "reason" in ds[k].attrs}


def test_features_of_an_accelerometer_only_session():
    rec = _session(60.0)
    full = cohort.session_features(rec, CONFIG)
    acc = cohort.session_features(_acc_only(rec), CONFIG)
    assert list(acc.data_vars) == list(full.data_vars)
    assert acc.attrs["tilt_method"] == CONFIG.no_gyro_method
    assert acc.attrs["immobility_rule"].startswith("accelerometer")
    assert acc.attrs["sensors"] == "acc"
    reasons = _reasons(acc)
    assert acc.attrs["reasons"] == reasons
    # every NaN feature says why; every feature with a reason is NaN
    for k in acc.data_vars:
        assert np.isnan(acc[k].values) == (k in reasons), k
    gyro_only = ["gyr_offset_x", "circling_index", "immobility_threshold_auto"]
    gyro_only += [k for k in acc.data_vars if k.startswith("angular_speed_moving")]
    for k in gyro_only:
        assert "gyroscope" in reasons[k], k
    computable = ["immobile_fraction", "visited_fraction", "dba_mean", "odba_mean"]
    computable += ["tilt_immobile_z", "tilt_immobile_kappa", "tilted_fraction_20deg"]
    for k in computable:
        assert np.isfinite(acc[k].values), k
    # activity does not depend on the gyroscope; immobility roughly agrees
    assert acc["dba_mean"].values == pytest.approx(float(full["dba_mean"].values))
    assert abs(acc["immobile_fraction"] - full["immobile_fraction"]) < 0.15
    assert 0.0 < acc["visited_fraction"].values <= 1.0


@pytest.mark.parametrize("state", ["still", "moving"])
def test_all_still_and_all_moving_sessions_never_crash(state):
    rng = np.random.default_rng(4)
    n = int(20 * FS)
    t = np.arange(n) / FS
    acc = np.tile([0.1, 0.0, 0.995], (n, 1)) + rng.normal(0.0, 0.003, (n, 3))
    gyr = rng.normal(0.0, 0.3, (n, 3))
    if state == "moving":
        rv = np.stack([0.6 * np.sin(2 * np.pi * 1.5 * t), 0.5 * np.cos(3 * t), t], 1)
        q = Q.from_rotvec(rv)
        acc = Q.gravity(q) + 0.2 * np.sin(2 * np.pi * 2.0 * t)[:, None]
        gyr = np.degrees(np.gradient(rv, t, axis=0)) + 60.0
    for rec in (
        schema.make_recording(
            acc, gyr, FS, acc_units="g", gyr_units="deg/s", check_units=False
        ),
        schema.make_recording(acc, fs=FS, acc_units="g", check_units=False),
    ):
        config = cohort.FeatureConfig(mesh_n=500, method="lowpass")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = cohort.session_features(rec, config)
        reasons = _reasons(ds)
        for k in ds.data_vars:
            assert np.isnan(ds[k].values) == (k in reasons), k
        imm = float(ds["immobile_fraction"].values)
        if state == "still":
            assert imm == 1.0
            assert "no moving samples" in reasons["visited_fraction_moving"]
        else:
            assert imm == 0.0
            assert "immobile" in reasons["tilt_immobile_kappa"]


def test_an_empty_tilt_map_is_nan_with_a_reason():
    g = F.gravity(F.estimate(_acc_only(_session(10.0)), "lowpass"))
    mesh = sphere.sphere_mesh(200)
    none = np.zeros(g.sizes["time"], dtype=bool)
    with pytest.warns(RuntimeWarning, match="no valid samples"):
        tmap = sphere.tilt_map(g, mesh=mesh, mask=none)
    assert int(tmap["count"].sum()) == 0 and tmap.attrs["n_samples"] == 0
    assert np.isnan(tmap["fraction"]).all() and np.isnan(tmap["density"]).all()
    assert "no valid samples" in tmap.attrs["empty_reason"]
    assert np.isnan(sphere.visited_fraction(tmap, mesh))
    full = sphere.tilt_map(g, mesh=mesh)
    assert full["fraction"].sum() == pytest.approx(1.0)


# ------------------------------------------------------------------ figures


def _texts(ax):
    return [t.get_text() for t in ax.texts]


@pytest.mark.parametrize(
    "labels, plus_x, plus_y",
    [
        (RAT, "+x (nose)", "+y (left)"),
        (["right", "top", "out of screen"], "+x (right)", "+y (top)"),
        (None, "+x", "+y"),
    ],
)
def test_map_labels_follow_the_data(labels, plus_x, plus_y):
    from tiltlab import plot

    rec, _ = _with_mag()
    if labels is None:
        rec.attrs.pop("axis_labels")
    else:
        rec.attrs["axis_labels"] = labels
    g = F.gravity(F.estimate(rec, "lowpass"))
    assert g.attrs.get("axis_labels") == labels
    mesh = sphere.sphere_mesh(200)
    ax = plot.tilt_heatmap(g, mesh=mesh)
    texts = _texts(ax)
    assert plus_x in texts and plus_y in texts
    assert ("+x (nose)" in texts) == (labels == RAT)
    fig = plot.plot_recording(rec, ["acc"])
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert legend[0] == ("x" if labels is None else f"x ({labels[0]})")
    tr = plot.tilt_trace(g)
    assert ("nose" in tr.get_ylabel()) == (labels == RAT)
    plt.close("all")


def test_axis_names_of_plain_data_and_of_labelled_data():
    from tiltlab import plot

    assert plot.axis_names(None) == ["x", "y", "z"]
    assert plot.axis_names(np.zeros((3, 3))) == ["x", "y", "z"]
    da = xr.DataArray(np.zeros((2, 3)), dims=("time", "axis"))
    assert plot.axis_names(da) == ["x", "y", "z"]
    da.attrs["axis_labels"] = RAT
    assert plot.axis_names(da) == ["nose", "left", "dorsal"]
    assert plot.axis_texts(da)["-y"] == "−y"


@pytest.mark.parametrize("drop", [(), ("gyr",)])
def test_features_leave_out_gaps_and_say_so(drop):
    """A session with a gap (NaN samples, as read with gaps="nan") gives the features of
    its samples outside the gap: activity unchanged far from it, the gap counted in
    attrs, n_samples the samples used; a gap-free session has no 'gaps' attribute."""
    rec = _session(60.0).drop_vars(list(drop))
    full = cohort.session_features(rec, CONFIG)
    assert "gaps" not in full.attrs
    gappy = rec.copy(deep=True)
    for v in ("acc", "gyr"):
        if v in gappy:
            gappy[v][3000:3050] = np.nan
    before = gappy.copy(deep=True)
    cut = cohort.session_features(gappy, CONFIG)
    assert gappy.identical(before)  # the input is not modified
    assert cut.attrs["gaps"].startswith("50 of 6000 samples")
    assert int(cut["n_samples"]) == 5950
    assert float(cut["duration_s"]) == float(full["duration_s"])
    for k in ("immobile_fraction", "visited_fraction", "dba_mean", "tilt_immobile_z"):
        assert np.isfinite(cut[k].values), k
    assert float(cut["dba_mean"]) == pytest.approx(float(full["dba_mean"]), rel=0.02)
    assert abs(float(cut["immobile_fraction"] - full["immobile_fraction"])) < 0.02


def test_cohort_table_says_why_features_are_nan(tmp_path):
    """An accelerometer-only session runs in a cohort: status ok, its NaN features
    explained in the table's ``notes`` and in the summary, grouped by reason."""
    import pandas as pd

    from tiltlab import io

    rows = []
    for i, drop in enumerate([[], ["gyr"]]):
        path = io.save_netcdf(
            _session(30.0, seed=i).drop_vars(drop), tmp_path / f"s{i}.nc"
        )
        rows.append(
            dict(
                session=f"s{i}",
                subject=f"a{i}",
                group=f"g{i}",
                timepoint="t0",
                file=str(path),
                reader="netcdf",
                reader_options="{}",
            )
        )
    pd.DataFrame(rows).to_csv(tmp_path / "manifest.csv", index=False)
    manifest = cohort.read_manifest(tmp_path / "manifest.csv")
    table = cohort.run_cohort(manifest, CONFIG, progress=False)
    assert list(table["status"].values) == ["ok", "ok"]
    notes = table["notes"].values
    assert notes[0] == ""
    assert "circling_index" in notes[1] and "gyroscope" in notes[1]
    assert notes[1].count("needs a gyroscope") <= 2  # grouped by reason
    text = str(cohort.summary(table))
    assert "NaN features in session s1:" in text and "s0" not in text.split("NaN")[1]


def test_realism_table_compares_like_with_like_without_a_gyroscope():
    """With one recording lacking a gyroscope, every column uses the accelerometer
    rule (no gyroscope rows); with both complete, the gyroscope rule; acceleration
    percentiles skip gaps and equal the all-finite ones elsewhere."""
    rec = _session(60.0)
    both = B.realism_table({"a": rec, "b": _session(60.0, seed=4)})
    assert both.attrs["rule"] == "gyroscope"
    assert "gyro spectral peak (Hz)" in both.index
    mixed = B.realism_table({"a": rec, "tag": _acc_only(rec)})
    assert mixed.attrs["rule"] == "accelerometer"
    assert not any("gyro" in row or "deg/s" in row for row in mixed.index)
    np.testing.assert_allclose(mixed["a"].values, mixed["tag"].values)
    imm = B.immobility(rec, rule="accelerometer")
    row = "immobile fraction (VeDBA rule)"
    assert mixed.loc[row, "a"] == pytest.approx(float(imm.mean()))
    gappy = _acc_only(rec).copy(deep=True)
    gappy["acc"][100:110] = np.nan
    with_gap = B.realism_table({"tag": gappy})
    assert np.isfinite(with_gap["tag"].values).all()
    with pytest.raises(RecordingError, match="gyroscope"):
        B.realism_table({"tag": _acc_only(rec)}, rule="gyroscope")


def test_tumble_calibration_of_an_accelerometer_only_recording():
    """Without a gyroscope the accelerometer calibration is the same as with one (same
    still periods), no gyroscope offset is made up, gaps outside the periods are
    accepted, a gap inside one is named, and missing periods say how to give them."""
    from tiltlab import calibration as C
    from tiltlab.simulate import tumble_test

    rec = tumble_test(12, fs=100.0, seed=7, hold_s=4.0, move_s=1.0)
    full = C.tumble_calibration(rec, trigger=rec["trigger"])
    acc = rec.drop_vars("gyr")
    alone = C.tumble_calibration(acc, trigger=rec["trigger"])
    np.testing.assert_array_equal(alone.intervals, full.intervals)
    np.testing.assert_allclose(alone.fit.offset, full.fit.offset, rtol=0, atol=0)
    assert alone.calibration.gyr_offset is None and alone.gyr_stderr is None
    assert "gyr_offset_stderr" not in alone.calibration.info
    gappy = acc.copy(deep=True)
    first_start = int(full.intervals[0, 0])
    gappy["acc"][first_start - 5 : first_start - 1] = np.nan  # before the first period
    same = C.tumble_calibration(gappy, intervals=full.intervals)
    np.testing.assert_allclose(same.fit.offset, full.fit.offset, rtol=0, atol=0)
    gappy["acc"][first_start + 1] = np.nan  # inside it
    with pytest.raises(ValueError, match="still period 0 .*non-finite"):
        C.tumble_calibration(gappy, intervals=full.intervals)
    with pytest.raises(C.CalibrationError, match="no gyroscope.*intervals"):
        C.tumble_calibration(acc)
