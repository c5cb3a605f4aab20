"""Tests of tiltlab.cohort: manifests, the per-session pipeline and cohort runs.

The simulated cohort (3 groups × 4 animals × 3 time points, 90 s at 100 Hz, one tumble
test per animal) is made once per test session; its ``truth.csv`` holds the same feature
definitions applied to the true motion (see ``tiltlab.simulate.cohort._true_features``).
"""

import hashlib
import json
import math
import shutil

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from tiltlab import cohort, datasets, sphere
from tiltlab.cohort import FeatureConfig, ManifestError
from tiltlab.cohort import run as cohort_run
from tiltlab.simulate import CohortDesign, simulate_cohort, simulate_session

GROUPS = {"Healthy": 4, "Kainate": 4, "Arsanilate": 4}
TIME_POINTS = ("baseline", "1d", "7d")


@pytest.fixture(scope="session")
def sim(tmp_path_factory):
    design = CohortDesign().select(groups=GROUPS, time_points=TIME_POINTS)
    return simulate_cohort(
        tmp_path_factory.mktemp("cohort") / "sim",
        design=design,
        duration_s=90.0,
        fs=100.0,
        seed=2021,
        workers=2,
        progress=False,
    )


@pytest.fixture(scope="session")
def serial(sim, tmp_path_factory):
    """The simulated cohort run serially: (features, cache folder)."""
    cache = tmp_path_factory.mktemp("cache_serial")
    ds = cohort.run_cohort(
        sim / "manifest.csv", scheduler=None, workers=1, cache_dir=cache, progress=False
    )
    return ds, cache


def _features(ds):
    return list(
        cohort.feature_specs(FeatureConfig.from_json(ds.attrs["feature_config"]))
    )


def _values(ds):
    """Feature variables, status and error without the dataset attrs or the file
    coordinate (which differ between runs of the same sessions)."""
    keep = _features(ds) + ["status", "error"]
    return ds[keep].drop_attrs(deep=False).reset_coords(drop=True)


def _subset(manifest, n):
    return cohort.Manifest(
        table=manifest.table.iloc[:n].reset_index(drop=True),
        root=manifest.root,
        path=manifest.path,
    )


# ------------------------------------------------------------------ simulated cohort


def test_simulator_writes_a_valid_manifest(sim):
    m = cohort.read_manifest(sim / "manifest.csv", groups=list(GROUPS))
    assert len(m) == 12 * 3
    assert m.covariates == ["hours"]
    assert set(m.table["timepoint"]) == set(TIME_POINTS)
    assert (m.table["reader"] == "netcdf").all()
    assert all((sim / c).is_file() for c in m.table["calibration"])
    assert (sim / "sessions.csv").is_file() and (sim / "truth.csv").is_file()
    truth = pd.read_csv(sim / "truth.csv")
    assert set(truth["session"]) == set(m.sessions)


def test_features_recover_the_planted_truth(sim, serial):
    ds, _ = serial
    assert (ds["status"] == "ok").all(), cohort.summary(ds)
    truth = pd.read_csv(sim / "truth.csv").set_index("session").loc[ds["session"]]
    d_imm = np.abs(ds["immobile_fraction"].values - truth["immobile_fraction_true"])
    assert d_imm.max() <= 0.02, d_imm.max()
    mu = np.stack([ds[f"tilt_immobile_{a}"].values for a in "xyz"], axis=1)
    mu_true = truth[[f"tilt_immobile_{a}_true" for a in "xyz"]].to_numpy()
    angle = np.degrees(sphere.angle(mu, mu_true))
    assert angle.max() <= 3.0, angle.max()
    sag = ds["tilt_immobile_sagittal_deg"].values - truth["tilt_sagittal_deg_true"]
    assert np.abs(sag).max() <= 3.0
    # the lesion tilts the head toward the lesion side: arsanilate at 7 d
    ars7 = (ds["group"] == "Arsanilate") & (ds["timepoint"] == "7d")
    healthy = ds["group"] == "Healthy"
    assert (
        ds["tilt_immobile_sagittal_deg"][ars7].mean()
        > ds["tilt_immobile_sagittal_deg"][healthy].mean() + 15
    )
    # metadata: every variable documented, the configuration recorded exactly
    for v in _features(ds):
        assert ds[v].attrs["units"] and ds[v].attrs["long_name"]
    assert FeatureConfig.from_json(ds.attrs["feature_config"]) == FeatureConfig()
    assert ds.attrs["config_hash"] == FeatureConfig().hash()
    assert ds.attrs["n_computed"] == 36 and ds.attrs["n_cached"] == 0
    assert list(ds["hours"].values[:3]) == [-1.0, 24.0, 168.0]


def test_cli_run_writes_a_features_file_that_recovers_the_truth(sim, serial, tmp_path):
    """``tiltlab cohort run`` on the simulated cohort (recomputed: fresh cache) writes a
    feature file with the same features as the API run, within the recovery bounds."""
    from tiltlab import cli

    out = tmp_path / "features.nc"
    code = cli.main(
        [
            "cohort",
            "run",
            str(sim / "manifest.csv"),
            "--out",
            str(out),
            "--cache-dir",
            str(tmp_path / "cache"),
            "--no-progress",
        ]
    )
    assert code == 0
    ds = cohort.load_features(out)
    assert ds.attrs["n_computed"] == 36
    truth = pd.read_csv(sim / "truth.csv").set_index("session").loc[ds["session"]]
    d_imm = np.abs(ds["immobile_fraction"].values - truth["immobile_fraction_true"])
    assert d_imm.max() <= 0.02, d_imm.max()
    mu = np.stack([ds[f"tilt_immobile_{a}"].values for a in "xyz"], axis=1)
    mu_true = truth[[f"tilt_immobile_{a}_true" for a in "xyz"]].to_numpy()
    assert np.degrees(sphere.angle(mu, mu_true)).max() <= 3.0
    xr.testing.assert_allclose(
        _values(ds)[_features(ds)], _values(serial[0])[_features(ds)]
    )


def test_dask_local_cluster_gives_identical_features(sim, serial, tmp_path):
    ds, _ = serial
    dd = cohort.run_cohort(
        sim / "manifest.csv",
        scheduler="dask",
        workers=2,
        cache_dir=tmp_path / "cache",
        progress=False,
    )
    assert dd.attrs["n_computed"] == 36
    xr.testing.assert_identical(_values(dd), _values(ds))


def test_process_pool_gives_identical_features(sim, serial, tmp_path):
    ds, _ = serial
    m = _subset(cohort.read_manifest(sim / "manifest.csv"), 6)
    dp = cohort.run_cohort(
        m, scheduler="processes", workers=2, cache_dir=tmp_path, progress=False
    )
    assert dp.attrs["n_computed"] == 6
    xr.testing.assert_identical(_values(dp), _values(ds.isel(session=slice(0, 6))))


def test_faults_are_recorded_and_a_rerun_recomputes_only_them(sim, serial, tmp_path):
    ds, serial_cache = serial
    cache = tmp_path / "cache"
    shutil.copytree(serial_cache, cache)
    table = pd.read_csv(sim / "manifest.csv", dtype=str, keep_default_na=False)
    for c in ("file", "calibration"):
        table[c] = [str(sim / f) for f in table[c]]
    broken = {table.loc[3, "session"]: "truncated", table.loc[7, "session"]: "missing"}
    originals = {}
    for i in (3, 7):
        originals[i] = table.loc[i, "file"]
        table.loc[i, "file"] = f"broken/{table.loc[i, 'session']}.nc"
    (tmp_path / "broken").mkdir()
    data = open(originals[3], "rb").read()
    (tmp_path / table.loc[3, "file"]).write_bytes(data[: len(data) // 2])
    table.to_csv(tmp_path / "manifest.csv", index=False)
    # the two sessions were never computed intact: no cache entries for them
    original = cohort.read_manifest(sim / "manifest.csv")
    cfg = FeatureConfig()

    def entry(i):
        row = original.row(table.loc[i, "session"])
        return cache / f"{cohort.cache_key(row, original.root, cfg)}.json"

    for i in (3, 7):
        entry(i).unlink()
    # an unreadable cache entry (e.g. left by an old, non-atomic writer) is a miss
    entry(0).write_text(entry(0).read_text()[:20])

    run1 = cohort.run_cohort(tmp_path / "manifest.csv", cache_dir=cache, progress=False)
    s = cohort.summary(run1)
    assert (s.n_sessions, s.n_ok, s.n_failed) == (36, 34, 2)
    assert set(s.failures) == set(broken)
    for sid in broken:
        assert "ReadError" in s.failures[sid]
        assert np.isnan(run1["immobile_fraction"].sel(session=sid))
    assert "truncated or corrupt" in s.failures[table.loc[3, "session"]]
    assert "no such file" in s.failures[table.loc[7, "session"]]
    assert run1.attrs["n_computed"] == 3 and run1.attrs["n_cached"] == 33
    assert "2 failed" in str(s) and table.loc[7, "session"] in str(s)
    ok = run1["status"] == "ok"
    xr.testing.assert_identical(
        _values(run1).isel(session=ok.values), _values(ds).isel(session=ok.values)
    )

    for i in (3, 7):
        shutil.copyfile(originals[i], tmp_path / table.loc[i, "file"])
    run2 = cohort.run_cohort(tmp_path / "manifest.csv", cache_dir=cache, progress=False)
    assert run2.attrs["n_computed"] == 2 and run2.attrs["n_cached"] == 34
    assert cohort.summary(run2).n_failed == 0
    xr.testing.assert_identical(_values(run2), _values(ds))
    assert not list(cache.glob(".*.tmp")) and not list(cache.glob("*.tmp"))


def test_a_killed_run_resumes_from_the_cache(sim, serial, tmp_path, monkeypatch):
    ds, _ = serial
    m = _subset(cohort.read_manifest(sim / "manifest.csv"), 5)
    real = cohort_run.compute_session
    calls = []

    def dies_on_the_third(*args):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*args)

    monkeypatch.setattr(cohort_run, "compute_session", dies_on_the_third)
    with pytest.raises(KeyboardInterrupt):
        cohort.run_cohort(m, cache_dir=tmp_path, progress=False)
    monkeypatch.setattr(cohort_run, "compute_session", real)
    assert len(list(tmp_path.glob("*.json"))) == 2
    out = tmp_path / "features.nc"
    again = cohort.run_cohort(m, cache_dir=tmp_path, progress=False, out=out)
    assert again.attrs["n_cached"] == 2 and again.attrs["n_computed"] == 3
    xr.testing.assert_identical(_values(again), _values(ds.isel(session=slice(0, 5))))
    xr.testing.assert_identical(cohort.load_features(out), again)


def test_a_new_configuration_recomputes_everything(sim, serial, tmp_path):
    _, cache = serial
    m = _subset(cohort.read_manifest(sim / "manifest.csv"), 2)
    shutil.copytree(cache, tmp_path / "c")
    cfg = FeatureConfig(method="lowpass", method_params={"cutoff_hz": 2.0})
    ds = cohort.run_cohort(m, cfg, cache_dir=tmp_path / "c", progress=False)
    assert ds.attrs["n_computed"] == 2 and ds.attrs["config_hash"] == cfg.hash()


# ------------------------------------------------------------------ one session


def test_session_features_do_not_mutate_and_label_everything():
    rec = simulate_session(60.0, 100.0, seed=4, keep_true=False)
    before = rec.copy(deep=True)
    cfg = FeatureConfig(tilt_thresholds_deg=(22.5, 10), speed_quantiles=(0.9, 0.5))
    f = cohort.session_features(rec, cfg)
    xr.testing.assert_identical(rec, before)
    assert list(f.data_vars) == list(cohort.feature_specs(cfg))
    assert "tilted_fraction_22p5deg" in f and "angular_speed_moving_q90" in f
    assert f["tilted_fraction_10deg"] >= f["tilted_fraction_22p5deg"]
    for v in f.data_vars.values():
        assert v.ndim == 0 and v.attrs["units"] and v.attrs["long_name"]
    assert 0 < float(f["immobile_fraction"]) < 1
    assert f.attrs["config_hash"] == cfg.hash()
    # the same session in rad/s gives the same features
    rad = rec.assign(gyr=np.radians(rec["gyr"]).assign_attrs(units="rad/s"))
    f2 = cohort.session_features(rad, cfg)
    for v in ("immobile_fraction", "circling_index", "tilt_immobile_y"):
        assert float(f2[v]) == pytest.approx(float(f[v]), rel=1e-9, abs=1e-12)


def test_session_features_refuse_bad_recordings():
    rec = simulate_session(10.0, 100.0, seed=1, keep_true=False)
    bad = rec.copy(deep=True)
    bad["acc"][5, 0] = np.inf  # NaN marks a gap (left out); infinity is an error
    with pytest.raises(ValueError, match="acc"):
        cohort.session_features(bad)
    with pytest.raises(ValueError, match="too short"):
        cohort.session_features(rec.isel(time=slice(0, 150)))


# ------------------------------------------------------------------ configuration


def test_feature_config_round_trips_and_hashes_stably():
    c = FeatureConfig(method="lowpass", method_params={"cutoff_hz": 2.0})
    d = c.to_dict()
    assert d["method_params"] == {"cutoff_hz": 2.0, "order": 2}  # defaults named
    assert FeatureConfig.from_dict(d) == c
    assert FeatureConfig.from_json(c.to_json()) == c
    assert c.hash() == hashlib.sha256(c.to_json().encode()).hexdigest()
    assert (
        c.hash()
        == FeatureConfig(
            method="lowpass", method_params={"order": 2, "cutoff_hz": 2}
        ).hash()
    )
    assert c.hash() != FeatureConfig(method="lowpass").hash()
    assert len({c, FeatureConfig.from_dict(d)}) == 1
    json.loads(c.to_json())
    with pytest.raises(AttributeError):
        c.method = "madgwick"


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"method": "nope"}, "method"),
        ({"method_params": {"beta": 0.1}}, "method_params"),
        ({"threshold_deg_s": -1}, "threshold_deg_s"),
        ({"merge_gap_s": "x"}, "merge_gap_s"),
        ({"mesh_n": 2.5}, "mesh_n"),
        ({"tilt_thresholds_deg": (20, 200)}, "tilt_thresholds_deg"),
        ({"speed_quantiles": (0.5, 1.5)}, "speed_quantiles"),
        ({"dba_window_s": 0}, "dba_window_s"),
        ({"lesion_side": "up"}, "lesion_side"),
        ({"gyr_offset": "tumble"}, "gyr_offset"),
        ({"calibration_model": "sphere"}, "calibration_model"),
        ({"use_mag": True}, "use_mag"),
        ({"auto_threshold": "yes"}, "auto_threshold"),
    ],
)
def test_feature_config_rejects_bad_values(kwargs, field):
    with pytest.raises(ValueError, match=f"FeatureConfig.{field}"):
        FeatureConfig(**kwargs)


def test_feature_config_from_dict_rejects_unknown_fields():
    with pytest.raises(ValueError, match="cutoff"):
        FeatureConfig.from_dict({"cutoff": 2.0})


# ------------------------------------------------------------------ manifests

_HEADER = "session,subject,group,timepoint,file,reader,reader_options,weight_g\n"
_ROWS = [
    "A01_d0,A01,sham,0,a01_d0.nc,netcdf,,310\n",
    "A01_d7,A01,sham,7,a01_d7.nc,netcdf,,305\n",
    'B01_d0,B01,lesion,0,b01_d0.csv,csv,"{""columns"": {""acc"": [""ax"", ""ay"", ""az""], ""gyr"": [""gx"", ""gy"", ""gz""]}, ""units"": {""acc"": ""g"", ""gyr"": ""deg/s""}, ""fs"": 100}",298\n',
]


def _manifest(tmp_path, rows=None, header=_HEADER):
    p = tmp_path / "manifest.csv"
    p.write_text(header + "".join(_ROWS if rows is None else rows))
    return p


def test_read_manifest_parses_types_and_covariates(tmp_path):
    m = cohort.read_manifest(_manifest(tmp_path), groups=["sham", "lesion"])
    assert m.sessions == ["A01_d0", "A01_d7", "B01_d0"]
    assert m.covariates == ["weight_g"]
    assert m.table["timepoint"].tolist() == [0, 7, 0]
    assert (
        m.root == tmp_path.resolve() and m.path == (tmp_path / "manifest.csv").resolve()
    )
    assert json.loads(m.row("B01_d0")["reader_options"])["fs"] == 100
    assert m.row("A01_d0")["calibration"] == ""


@pytest.mark.parametrize(
    "row, message",
    [
        ("A01_d14,A01,sham,14,a01_d7.nc,netcdf,,300\n", "already named on line 3"),
        ("A01_d14,A01,sham,14,a01_d14.nc,matlab,,300\n", "unknown reader 'matlab'"),
        ('A01_d14,A01,sham,14,a01_d14.csv,csv,"{""fs"": 100",300\n', "not valid JSON"),
        ("A01_d14,A01,sham,14,a01_d14.nc,broad,[1],300\n", "must be a JSON object"),
        (
            'A01_d14,A01,sham,14,a01_d14.csv,csv,"{""fs"": 100}",300\n',
            "needs reader_options",
        ),
        (
            'A01_d14,A01,sham,14,a01_d14.nc,netcdf,"{""foo"": 1}",300\n',
            "does not accept",
        ),
        ("A01_d0,A01,sham,14,a01_d14.nc,netcdf,,300\n", "already used on line 2"),
        ("A01_d14,A01,,14,a01_d14.nc,netcdf,,300\n", "empty 'group'"),
    ],
)
def test_read_manifest_rejects_bad_rows_naming_them(tmp_path, row, message):
    path = _manifest(tmp_path, _ROWS + [row])
    with pytest.raises(ManifestError) as err:
        cohort.read_manifest(path)
    text = str(err.value)
    assert message in text and "manifest.csv, line 5" in text
    assert "(session 'A01_d" in text


def test_read_manifest_rejects_an_unknown_group_naming_the_row(tmp_path):
    with pytest.raises(
        ManifestError, match=r"line 4 \(session 'B01_d0'\): unknown group 'lesion'"
    ):
        cohort.read_manifest(_manifest(tmp_path), groups=["sham", "kainate"])


def test_read_manifest_rejects_a_missing_column(tmp_path):
    header = _HEADER.replace("reader,", "")
    rows = [",".join(r.split(",")[:5] + r.split(",")[6:]) for r in _ROWS[:2]]
    with pytest.raises(
        ManifestError,
        match=r"line 1 \(header\): missing required column\(s\) \['reader'\]",
    ):
        cohort.read_manifest(_manifest(tmp_path, rows, header))


def test_read_manifest_rejects_before_any_work(tmp_path, monkeypatch):
    monkeypatch.setattr(cohort_run, "compute_session", pytest.fail)
    path = _manifest(tmp_path, _ROWS + ["C01_d0,C01,sham,0,a01_d0.nc,netcdf,,1\n"])
    with pytest.raises(ManifestError, match="line 5"):
        cohort.run_cohort(path, progress=False, cache_dir=tmp_path)


def test_init_manifest_parses_fields_from_paths(sim, tmp_path):
    src = sorted((sim / "sessions").glob("*.nc"))
    for f in src[:4]:
        subject, tp = f.stem.split("_")
        group = subject.rstrip("0123456789")
        dest = tmp_path / "data" / group / f"{subject}_{tp}.nc"
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(f, dest)
    (tmp_path / "data" / "notes.txt").write_text("not a session")
    out = tmp_path / "study" / "manifest.csv"
    out.parent.mkdir()
    m = cohort.init_manifest(
        tmp_path / "data", "{group}/{subject}_{timepoint}.nc", out=out
    )
    assert len(m) == 4 and m.path == out.resolve()
    first = m.table.iloc[0]
    assert first["session"] == f"{first['subject']}_{first['timepoint']}"
    assert first["file"].startswith("../data/")
    back = cohort.read_manifest(out)
    pd.testing.assert_frame_equal(back.table, m.table)
    rec = cohort.load_session(back.row(first["session"]), back.root)
    assert rec.attrs["subject"] == first["subject"]
    # group from a mapping, a covariate from an extra field, {session} kept as given
    m2 = cohort.init_manifest(
        tmp_path / "data",
        "{batch}/{session}.nc",
        group={s: "all" for s in m.sessions},
        reader_options={},
    )
    assert m2.covariates == ["batch"] and set(m2.table["group"]) == {"all"}
    assert set(m2.sessions) == set(m.sessions)
    with pytest.raises(ValueError, match="group="):
        cohort.init_manifest(tmp_path / "data", "{batch}/{subject}_{timepoint}.nc")
    with pytest.raises(ValueError, match="no file"):
        cohort.init_manifest(tmp_path / "data", "{group}/{subject}.h5", group="x")


# ------------------------------------------------------------------ real data


@pytest.mark.realdata
def test_fayat_rat_as_a_one_session_cohort(data_mirror, tmp_path):
    path = datasets.fetch("fayat2021/example_imu.csv")
    pd.DataFrame(
        [
            {
                "session": "rat_example",
                "subject": "rat",
                "group": "healthy",
                "timepoint": "",
                "file": str(path),
                "reader": "fayat_csv",
                "reader_options": "",
            }
        ]
    ).to_csv(tmp_path / "manifest.csv", index=False)
    ds = cohort.run_cohort(tmp_path / "manifest.csv", progress=False)
    assert ds.sizes["session"] == 1 and (ds["status"] == "ok").all()
    direct = cohort.session_features(datasets.load_fayat_example())
    for v in direct.data_vars:
        assert float(ds[v][0]) == pytest.approx(float(direct[v]), nan_ok=True)
    # Fayat's rat: immobile a third of the time, the valley threshold near 12 °/s
    assert 0.2 < float(ds["immobile_fraction"][0]) < 0.6
    assert 8.0 < float(ds["immobility_threshold_auto"][0]) < 20.0
    assert (
        abs(float(ds["immobile_fraction_auto"][0]) - float(ds["immobile_fraction"][0]))
        < 0.05
    )
    assert (tmp_path / ".tiltlab-cache").is_dir()


@pytest.mark.realdata
def test_broad_trials_as_a_cohort_grouped_by_trial_type(data_mirror, tmp_path):
    trials, groups = datasets.broad_trials(), datasets.broad_trial_groups()
    pick = [2, 3, 10, 11]
    rows = []
    for k in pick:
        kind = next(g for g in ("rotation", "translation") if g in groups[k])
        rows.append(
            {
                "session": f"broad{k:02d}",
                # one subject per trial: a subject in two groups is refused
                "subject": f"trial{k:02d}",
                "group": kind,
                "timepoint": k,
                "file": str(datasets.fetch(trials[k])),
                "reader": "broad",
                "reader_options": "",
                "speed": "fast" if "fast" in groups[k] else "slow",
            }
        )
    pd.DataFrame(rows).to_csv(tmp_path / "manifest.csv", index=False)
    m = cohort.read_manifest(
        tmp_path / "manifest.csv", groups=["rotation", "translation"]
    )
    ds = cohort.run_cohort(m, cache_dir=tmp_path / "cache", progress=False)
    assert cohort.summary(ds).n_ok == 4
    assert ds["group"].values.tolist() == [
        "rotation",
        "rotation",
        "translation",
        "translation",
    ]
    assert ds["speed"].values.tolist() == ["slow"] * 4
    # rotation trials sweep the sensor's tilt over far more of the sphere
    vf = ds["visited_fraction"].groupby("group").mean()
    assert float(vf.sel(group="rotation")) > 5 * float(vf.sel(group="translation"))
    # BROAD's gyroscope is in rad/s: the offsets removed are small, in °/s
    assert (
        np.abs(ds[["gyr_offset_x", "gyr_offset_y", "gyr_offset_z"]].to_array()).max()
        < 2.0
    )
    assert math.isfinite(float(ds["tilt_immobile_sagittal_deg"].mean()))


def test_session_tilt_is_the_pipelines_tilt():
    """session_tilt returns the corrected Recording and the tilt that session_features
    summarises: the immobile mean tilt recomputed from it equals the feature."""
    from tiltlab import behavior, simulate

    rec = simulate.simulate_session(60.0, 100.0, seed=3)
    config = cohort.FeatureConfig()
    feats = cohort.session_features(rec, config)
    corrected, g = cohort.session_tilt(rec, config)
    assert g.dims == ("time", "axis") and g.attrs["fs"] == 100.0
    assert corrected["gyr"].attrs["units"] == rec["gyr"].attrs["units"]
    imm = behavior.detect_immobility(
        behavior.angular_speed(corrected), threshold_deg_s=config.threshold_deg_s
    )
    mu = g[imm].sum("time")
    mu = mu / np.linalg.norm(mu)
    np.testing.assert_allclose(
        mu, [float(feats[f"tilt_immobile_{a}"]) for a in "xyz"], atol=1e-9
    )


def test_each_session_is_validated_once(sim, serial, tmp_path, monkeypatch):
    """The reader validates every session; the feature step does not again."""
    import sys

    import tiltlab.schema as schema

    real = schema.validate
    callers = []

    def spy(rec, *args, **kw):
        callers.append(sys._getframe(1).f_code.co_filename)
        return real(rec, *args, **kw)

    monkeypatch.setattr(schema, "validate", spy)
    manifest = _subset(cohort.read_manifest(sim / "manifest.csv"), 2)
    ds = cohort.run_cohort(
        manifest, scheduler=None, workers=1, cache_dir=tmp_path, progress=False
    )
    assert list(ds["status"].values) == ["ok", "ok"]
    in_features = [f for f in callers if f.endswith("features.py")]
    assert callers and not in_features
    # the same features as the full serial run
    expected = serial[0].isel(session=slice(0, 2))
    xr.testing.assert_identical(_values(ds), _values(expected))
    # a Recording handed over directly is still validated
    rec = cohort.load_session(manifest.table.iloc[0].to_dict(), manifest.root)
    callers.clear()
    cohort.session_features(rec)
    assert any(f.endswith("features.py") for f in callers)
