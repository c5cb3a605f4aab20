"""The cohort feature table as CSV and Parquet (tiltlab.cohort.tables).

A small cohort (four 12 s simulated sessions, one of them a damaged file) is run once per
module; subject ids such as ``"007"`` and ``"rat_01"`` and numeric time points check that
ids always come back as strings.
"""

import json
import subprocess
import sys
import textwrap

import numpy as np
import pandas as pd
import pytest

from tiltlab import cli, cohort, io
from tiltlab.cohort import tables

# (session, subject, group, timepoint, hours, litter, sex); "010_7" is damaged
SESSIONS = [
    ("007_1", "007", "sham", "1", 24.0, 3, "F"),
    ("rat_01_1", "rat_01", "sham", "1", 24.5, 3, "M"),
    ("010_7", "010", "lesion", "7", 168.0, 4, "F"),
    ("rat_02_7", "rat_02", "lesion", "7", 167.5, 4, "M"),
]
FAILED = "010_7"


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """Session files, a manifest and a cache folder shared by the module's runs."""
    from tiltlab import simulate

    root = tmp_path_factory.mktemp("tables")
    rows = []
    for i, (session, subject, group, tp, hours, litter, sex) in enumerate(SESSIONS):
        file = f"data/{session}.nc"
        rec = simulate.simulate_session(12.0, 100.0, seed=i, keep_true=False)
        io.save_netcdf(rec, root / file)
        rows.append(
            {
                "session": session,
                "subject": subject,
                "group": group,
                "timepoint": tp,
                "file": file,
                "reader": "netcdf",
                "hours": hours,
                "litter": litter,
                "sex": sex,
            }
        )
    (root / "data" / f"{FAILED}.nc").write_bytes(b"not a netcdf file")
    pd.DataFrame(rows).to_csv(root / "manifest.csv", index=False)
    return root


@pytest.fixture(scope="module")
def features(study):
    """The cohort's features, saved as NetCDF and loaded back (NetCDF → table)."""
    ds = cohort.run_cohort(
        study / "manifest.csv", cache_dir=study / "cache", progress=False
    )
    path = cohort.save_features(ds, study / "features.nc")
    return cohort.load_features(path)


def _feature_names(ds):
    return [v for v in ds.data_vars if v not in ("status", "error", "notes")]


# ------------------------------------------------------------------ to_table


def test_to_table_is_tidy_with_ids_as_strings(features):
    df = cohort.to_table(features)
    feats = _feature_names(features)
    assert list(df.columns) == (
        ["session", "subject", "group", "timepoint", "status", "error", "notes"]
        + feats
        + ["file", "reader", "hours", "litter", "sex"]
    )
    assert len(df) == len(SESSIONS) and isinstance(df.index, pd.RangeIndex)
    assert df["session"].tolist() == [s[0] for s in SESSIONS]
    assert df["subject"].tolist() == ["007", "rat_01", "010", "rat_02"]
    # numeric time points (numbers in the Dataset) are strings in the table
    assert features["timepoint"].dtype.kind in "iu"
    assert df["timepoint"].tolist() == ["1", "1", "7", "7"]
    for c in ("session", "subject", "group", "timepoint", "status", "error", "notes"):
        assert pd.api.types.is_string_dtype(df[c].dtype), c
        assert all(isinstance(v, str) for v in df[c]), c
    for v in feats:
        assert df[v].dtype == np.float64
        np.testing.assert_array_equal(df[v].to_numpy(), features[v].values)
    assert df["hours"].dtype == np.float64 and df["litter"].dtype == np.int64
    assert df["sex"].tolist() == ["F", "M", "F", "M"]
    # the failed session is a row: its error, NaN features
    failed = df.set_index("session").loc[FAILED]
    assert failed["status"] == "failed" and failed["error"].startswith("ReadError:")
    assert failed[feats].isna().all()
    ok = df[df["session"] != FAILED]
    assert (ok["status"] == "ok").all() and (ok["error"] == "").all()
    # units, long names and roles per column; the Dataset's attributes
    units, long_name = df.attrs["units"], df.attrs["long_name"]
    assert set(units) == set(long_name) == set(df.columns)
    assert units["tilt_immobile_sagittal_deg"] == "deg" and units["dba_mean"] == "g"
    for v in feats:
        assert units[v] == features[v].attrs["units"]
        assert long_name[v] == features[v].attrs["long_name"] != ""
    assert long_name["subject"] and long_name["status"] == "ok or failed"
    assert df.attrs["role"]["subject"] == "id" and df.attrs["role"]["dba_mean"] == (
        "feature"
    )
    assert df.attrs["role"]["hours"] == "covariate"
    assert df.attrs["dataset"]["feature_config"] == features.attrs["feature_config"]
    assert df.attrs["dataset"]["n_failed"] == 1
    json.dumps(df.attrs)  # plain Python values


# ------------------------------------------------------------------ round trips


def _assert_same_table(back, df):
    pd.testing.assert_frame_equal(back, df, check_exact=True)
    for c in df.columns:
        if df[c].dtype == np.float64:  # bit for bit, NaN where NaN
            a, b = df[c].to_numpy(), back[c].to_numpy()
            assert np.array_equal(np.isnan(a), np.isnan(b)), c
            assert np.array_equal(
                a[~np.isnan(a)].view(np.uint64), b[~np.isnan(b)].view(np.uint64)
            ), c
    for key in ("units", "long_name", "role"):
        assert back.attrs[key] == df.attrs[key], key


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_round_trip_netcdf_to_table_file(features, tmp_path, suffix):
    path = cohort.save_table(features, tmp_path / f"features{suffix}")
    assert path == tmp_path / f"features{suffix}" and path.is_file()
    back = cohort.load_table(path)
    df = cohort.to_table(features)
    _assert_same_table(back, df)
    assert back["subject"].tolist() == ["007", "rat_01", "010", "rat_02"]
    assert back.loc[back["session"] == FAILED, "error"].item().startswith("ReadError")
    assert back.loc[back["session"] != FAILED, "error"].tolist() == ["", "", ""]
    if suffix == ".parquet":
        assert back.attrs["dataset"] == df.attrs["dataset"]
        assert isinstance(back.attrs["dataset"]["n_sessions"], int)
    else:
        assert (tmp_path / "features.columns.csv").is_file()
    # written atomically: no temporary file left beside it
    assert not [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_floats_are_exact_and_nan_kept(features, tmp_path, suffix):
    ds = features.copy(deep=True)
    tricky = np.array([1 / 3, 5e-324, -0.0, np.nan])
    ds["dba_mean"].values[:] = tricky
    ds["odba_mean"].values[:] = [0.1 + 0.2, 1.7976931348623157e308, np.inf, -np.inf]
    back = cohort.load_table(cohort.save_table(ds, tmp_path / f"t{suffix}"))
    _assert_same_table(back, cohort.to_table(ds))
    assert np.signbit(back["dba_mean"][2]) and np.isnan(back["dba_mean"][3])


def test_a_table_saves_again(features, tmp_path):
    """load_table's DataFrame (a CSV's) saves as Parquet with the same units."""
    df = cohort.load_table(cohort.save_table(features, tmp_path / "a.csv"))
    back = cohort.load_table(cohort.save_table(df, tmp_path / "a.parquet"))
    _assert_same_table(back, df)


def test_files_read_without_tiltlab_or_xarray(features, tmp_path):
    """pandas alone reads the CSV (and its data dictionary); pyarrow the units."""
    cohort.save_table(features, tmp_path / "features.csv")
    cohort.save_table(features, tmp_path / "features.parquet")
    script = textwrap.dedent(
        """
        import json, sys
        sys.modules["xarray"] = None  # importing it (or tiltlab) would fail
        sys.modules["tiltlab"] = None
        import pandas as pd
        import pyarrow.parquet as pq
        folder = sys.argv[1]
        ids = {"session": str, "subject": str, "group": str, "timepoint": str}
        df = pd.read_csv(f"{folder}/features.csv", dtype=ids)
        units = pd.read_csv(f"{folder}/features.columns.csv", keep_default_na=False)
        pq_df = pd.read_parquet(f"{folder}/features.parquet")
        schema = pq.read_schema(f"{folder}/features.parquet")
        print(json.dumps({
            "subject": df["subject"].tolist(),
            "timepoint": df["timepoint"].tolist(),
            "dba_mean": [repr(v) for v in df["dba_mean"]],
            "status": df["status"].tolist(),
            "units": dict(zip(units["column"], units["units"])),
            "pq_subject": pq_df["subject"].tolist(),
            "pq_units": schema.field("dba_mean").metadata[b"units"].decode(),
            "pq_config": schema.metadata[b"feature_config"].decode(),
        }))
        """
    )
    proc = subprocess.run(
        [sys.executable, "-c", script, str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    got = json.loads(proc.stdout)
    df = cohort.to_table(features)
    assert got["subject"] == got["pq_subject"] == df["subject"].tolist()
    assert got["timepoint"] == ["1", "1", "7", "7"]
    assert got["dba_mean"] == [repr(float(v)) for v in df["dba_mean"]]  # exact
    assert got["status"] == df["status"].tolist()
    assert got["units"] == df.attrs["units"]
    assert got["pq_units"] == "g"
    assert got["pq_config"] == features.attrs["feature_config"]


def test_csv_layout(features, tmp_path):
    path = cohort.save_table(features, tmp_path / "features.csv")
    raw = path.read_bytes()
    assert not raw.startswith(b"\xef\xbb\xbf") and b"\r\n" not in raw
    lines = raw.decode("utf-8").splitlines()
    assert lines[0].startswith("session,subject,group,timepoint,status,error,notes,")
    assert lines[1].startswith("007_1,007,sham,1,ok,")
    side = pd.read_csv(tables.sidecar_path(path), keep_default_na=False, dtype=str)
    assert list(side.columns) == list(cohort.tables.SIDECAR_COLUMNS)
    assert side["column"].tolist() == list(cohort.to_table(features).columns)
    row = side.set_index("column").loc["tilt_immobile_sagittal_deg"]
    assert (row["units"], row["dtype"], row["role"]) == ("deg", "float64", "feature")
    assert side.set_index("column").loc["subject", "dtype"] == "string"


def test_csv_without_its_sidecar_warns_and_guesses(features, tmp_path):
    path = cohort.save_table(features, tmp_path / "features.csv")
    tables.sidecar_path(path).unlink()
    with pytest.warns(UserWarning, match="no data dictionary features.columns.csv"):
        back = cohort.load_table(path)
    df = cohort.to_table(features)
    assert back["subject"].tolist() == df["subject"].tolist()
    assert back["timepoint"].tolist() == ["1", "1", "7", "7"]
    assert back["error"].tolist() == df["error"].tolist()
    np.testing.assert_array_equal(back["dba_mean"], df["dba_mean"])
    assert back["litter"].dtype == np.int64 and back.attrs["units"]["dba_mean"] == ""


def test_a_failed_write_keeps_the_old_file(features, tmp_path, monkeypatch):
    path = cohort.save_table(features, tmp_path / "features.csv")
    before = path.read_bytes()

    def boom(df, tmp):
        tmp.write_text("half a file")
        raise OSError("disk full")

    monkeypatch.setattr(tables, "_write_csv", boom)
    with pytest.raises(OSError, match="disk full"):
        cohort.save_table(features, path)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "features.columns.csv",
        "features.csv",
    ]


# ------------------------------------------------------------------ bad input


def test_to_table_refuses_what_is_not_a_cohort_table(features):
    from tiltlab import simulate

    rec = simulate.simulate_session(2.0, 50.0, seed=0, keep_true=False)
    with pytest.raises(ValueError, match="no 'session' dimension.*Recording"):
        cohort.to_table(rec)
    with pytest.raises(ValueError, match="no 'status' variable"):
        cohort.to_table(features.drop_vars("status"))
    two_d = features.assign(map=(("session", "k"), np.zeros((len(SESSIONS), 2))))
    with pytest.raises(ValueError, match=r"not a flat cohort feature table.*map"):
        cohort.to_table(two_d)
    with pytest.raises(TypeError, match="already a pandas.DataFrame"):
        cohort.to_table(cohort.to_table(features))
    with pytest.raises(TypeError, match="got dict"):
        cohort.save_table({"session": []}, "x.csv")


def test_unknown_suffixes_name_the_supported_ones(features, tmp_path):
    for name in ("features.xlsx", "features"):
        with pytest.raises(ValueError, match=r"unknown table format.*\.csv.*\.parquet"):
            cohort.save_table(features, tmp_path / name)
        with pytest.raises(ValueError, match=r"unknown table format.*\.csv.*\.parquet"):
            cohort.load_table(tmp_path / name)
    with pytest.raises(ValueError, match="read with load_features"):
        cohort.load_table(tmp_path / "features.nc")
    assert not list(tmp_path.iterdir())
    (tmp_path / "dir.csv").mkdir()
    with pytest.raises(ValueError, match="is a folder"):
        cohort.save_table(features, tmp_path / "dir.csv")


def test_load_table_refuses_bad_files(study, features, tmp_path):
    with pytest.raises(FileNotFoundError, match="no such table file"):
        cohort.load_table(tmp_path / "nothing.csv")
    # a manifest is a CSV table, not a feature table
    with pytest.raises(ValueError, match=r"not a cohort feature table \(no 'status'"):
        cohort.load_table(study / "manifest.csv")
    path = cohort.save_table(features, tmp_path / "features.csv")
    with pytest.raises(ValueError, match="column sidecar"):
        cohort.load_table(tables.sidecar_path(path))
    bad = tmp_path / "bad.parquet"
    bad.write_text("session,status\n")
    with pytest.raises(ValueError, match="not a readable Parquet file"):
        cohort.load_table(bad)
    empty = tmp_path / "empty.csv"
    empty.write_bytes(b"")
    with pytest.raises(ValueError, match="not a readable CSV table"):
        cohort.load_table(empty)
    # a value that does not fit its column's type names the line and the column
    raw = pd.read_csv(path, dtype=str, keep_default_na=False)
    raw.loc[1, "n_samples"] = "lots"
    raw.to_csv(path, index=False)
    with pytest.raises(ValueError, match=r"line 3: column 'n_samples' holds 'lots'"):
        cohort.load_table(path)


# ------------------------------------------------------------------ command line


def _run(study, out, *extra):
    return cli.main(
        [
            "cohort",
            "run",
            str(study / "manifest.csv"),
            "--out",
            str(out),
            "--cache-dir",
            str(study / "cache"),
            "--no-progress",
            *extra,
        ]
    )


def test_cli_run_writes_netcdf_csv_and_parquet(study, tmp_path, capsys):
    out = tmp_path / "results" / "features.nc"
    assert _run(study, out) == 1  # one session failed; all files still written
    printed = capsys.readouterr().out
    names = ["features.nc", "features.csv", "features.columns.csv", "features.parquet"]
    assert sorted(p.name for p in out.parent.iterdir()) == sorted(names)
    for name in names[1:]:
        assert str(out.parent / name) in printed
    df = cohort.to_table(cohort.load_features(out))
    for suffix in (".csv", ".parquet"):
        back = cohort.load_table(out.with_suffix(suffix))
        _assert_same_table(back, df)
        assert back.loc[back["session"] == FAILED, "status"].item() == "failed"


def test_cli_show_export(study, features, tmp_path, capsys):
    nc = study / "features.nc"
    for name in ("t.csv", "t.parquet"):
        assert (
            cli.main(["cohort", "show", str(nc), "--export", str(tmp_path / name)]) == 0
        )
        printed = capsys.readouterr().out
        assert f"wrote {tmp_path / name}: 4 session(s) x " in printed
        _assert_same_table(
            cohort.load_table(tmp_path / name), cohort.to_table(features)
        )
    assert "t.columns.csv" in {p.name for p in tmp_path.iterdir()}


def test_cli_refuses_bad_table_names(study, tmp_path, capsys):
    nc = study / "features.nc"
    assert (
        cli.main(["cohort", "show", str(nc), "--export", str(tmp_path / "t.xlsx")]) == 2
    )
    err = capsys.readouterr().err
    assert err.startswith("tiltlab: ") and err.count("\n") == 1
    assert "unknown table format '.xlsx'" in err and ".csv" in err and ".parquet" in err
    # --out is the NetCDF file: a table name there is refused before any work
    assert _run(study, tmp_path / "features.csv") == 2
    assert "names the NetCDF feature file" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_cli_help_names_the_tables(capsys):
    assert cli.main(["cohort", "run", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "FEATURES.csv" in text and "FEATURES.parquet" in text
    assert "FEATURES.columns.csv" in text
    assert cli.main(["cohort", "show", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "--export TABLE.csv|TABLE.parquet" in text
