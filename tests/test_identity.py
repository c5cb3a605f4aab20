"""Identity of sessions, subjects and recordings in a cohort: a catalogue of bad inputs.

One test per case, each asserting that the error names the problem (the rows, the
files, the declared names): the manifest pattern grammar and its regex alternative,
ids kept as text end to end, a subject in two groups, one recording listed twice, two
sessions of one subject at one time point, typos against declared groups and time
points, pseudo-replication in the statistics, failed sessions counted, and the cohort
command line (reader chosen from the content, --workers, portable paths, a closed pipe,
the summary printed once).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from tiltlab import cli, cohort
from tiltlab import stats as S
from tiltlab.cohort import ManifestError
from tiltlab.cohort import manifest as manifest_mod
from tiltlab.stats.design import study_design

HEADER = "session,subject,group,timepoint,file,reader\n"


def _manifest(tmp: Path, rows: list[str], header: str = HEADER) -> Path:
    path = tmp / "manifest.csv"
    path.write_text(header + "".join(rows))
    return path


def _files(root: Path, names: list[str], size: int | None = None) -> None:
    """Small files of distinct content (their names), or of one ``size``."""
    for name in names:
        p = root / name
        p.parent.mkdir(parents=True, exist_ok=True)
        text = name.encode()
        p.write_bytes(text if size is None else text.ljust(size, b"."))


# ------------------------------------------------------------------ pattern grammar


def test_pattern_splits_at_the_last_separator(tmp_path):
    _files(tmp_path / "data", ["A/rat_01_d0.nc", "A/rat_01_d7.nc", "B/rat_02_d0.nc"])
    m = cohort.init_manifest(
        tmp_path / "data", "{group}/{subject}_{timepoint}.nc", reader="netcdf"
    )
    t = m.table
    assert t["subject"].tolist() == ["rat_01", "rat_01", "rat_02"]
    assert t["timepoint"].tolist() == ["d0", "d7", "d0"]
    assert t["session"].tolist() == ["rat_01_d0", "rat_01_d7", "rat_02_d0"]


def test_pattern_with_touching_fields_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"fields \{subject\} and \{timepoint\} touch"):
        cohort.init_manifest(tmp_path, "{subject}{timepoint}.nc", group="A")


def test_pattern_with_a_brace_that_is_no_field_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"brace that is not a field"):
        cohort.init_manifest(tmp_path, "{group}/{subject-id}.nc")


def test_absolute_pattern_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"starts with '/'.*relative"):
        cohort.init_manifest(tmp_path, "/data/{subject}.nc", group="A")


def test_regex_with_named_groups_reads_what_a_pattern_cannot(tmp_path):
    _files(tmp_path, ["A/rat_01_day_7.nc", "A/rat_01_day_14.nc"])
    m = cohort.init_manifest(
        tmp_path,
        regex=r"(?P<group>[^/]+)/(?P<subject>[^/]+)_(?P<timepoint>day_\d+)\.nc",
        reader="netcdf",
    )
    assert m.table["subject"].tolist() == ["rat_01", "rat_01"]
    assert sorted(m.table["timepoint"]) == ["day_14", "day_7"]


def test_regex_without_named_groups_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"has no named group"):
        cohort.init_manifest(tmp_path, regex=r"[^/]+\.nc", group="A")


def test_invalid_regex_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"not a valid regular expression"):
        cohort.init_manifest(tmp_path, regex=r"(?P<subject>[", group="A")


def test_pattern_and_regex_together_are_refused(tmp_path):
    with pytest.raises(ValueError, match=r"not both"):
        cohort.init_manifest(tmp_path, "{subject}.nc", regex=r"(?P<subject>.+)")


# ------------------------------------------------------------------ ids are text


def test_ids_stay_text_when_reading_a_manifest(tmp_path):
    _files(tmp_path, ["a.nc", "b.nc"])
    path = _manifest(
        tmp_path,
        ["007,007,01,007,a.nc,netcdf\n", "010,010,01,7,b.nc,netcdf\n"],
    )
    t = cohort.read_manifest(path).table
    assert t["session"].tolist() == ["007", "010"]
    assert t["subject"].tolist() == ["007", "010"]
    assert t["group"].tolist() == ["01", "01"]
    assert t["timepoint"].tolist() == ["007", "7"]  # a leading zero keeps it text


def test_numbers_without_leading_zeros_are_numbers(tmp_path):
    _files(tmp_path, ["a.nc", "b.nc"])
    path = _manifest(tmp_path, ["s1,r1,A,0,a.nc,netcdf\n", "s2,r1,A,7,b.nc,netcdf\n"])
    assert cohort.read_manifest(path).table["timepoint"].tolist() == [0, 7]


def test_ids_stay_text_through_init(tmp_path):
    _files(tmp_path / "data", ["A/007_d0.nc", "A/010_d0.nc"])
    out = tmp_path / "manifest.csv"
    cohort.init_manifest(
        tmp_path / "data", "{group}/{subject}_{timepoint}.nc", reader="netcdf", out=out
    )
    back = cohort.read_manifest(out).table
    assert back["subject"].tolist() == ["007", "010"]
    assert back["session"].tolist() == ["007_d0", "010_d0"]


def test_ids_stay_text_through_a_run_and_its_files(tmp_path):
    # missing files fail at once: enough to follow the ids to the feature table
    path = _manifest(
        tmp_path, ["007_d0,007,01,007,x.nc,netcdf\n", "010_d0,010,01,007,y.nc,netcdf\n"]
    )
    ds = cohort.run_cohort(path, progress=False, cache_dir=tmp_path / "cache")
    assert ds["subject"].values.tolist() == ["007", "010"]
    assert ds["timepoint"].values.tolist() == ["007", "007"]
    back = cohort.load_features(cohort.save_features(ds, tmp_path / "f.nc"))
    assert back["subject"].values.tolist() == ["007", "010"]
    table = cohort.load_table(cohort.save_table(back, tmp_path / "f.csv"))
    assert table["subject"].tolist() == ["007", "010"]
    assert table["group"].tolist() == ["01", "01"]


# ------------------------------------------------------------------ one subject, one group


def test_subject_in_two_groups_is_refused_naming_both_rows(tmp_path):
    _files(tmp_path, ["a.nc", "b.nc"])
    path = _manifest(tmp_path, ["s1,r1,A,d0,a.nc,netcdf\n", "s2,r1,B,d7,b.nc,netcdf\n"])
    with pytest.raises(ManifestError) as err:
        cohort.read_manifest(path)
    msg = str(err.value)
    assert "manifest.csv, line 3 (session 's2')" in msg
    assert "subject 'r1' is in group 'B' here and in group 'A' on line 2" in msg
    assert "prefix them with the group ('B-r1')" in msg


def test_ids_restarting_in_each_group_are_refused_naming_files_not_lines(tmp_path):
    _files(tmp_path / "data", ["A/rat1_d0.nc", "B/rat1_d0.nc"])
    out = tmp_path / "manifest.csv"
    with pytest.raises(ManifestError) as err:
        cohort.init_manifest(
            tmp_path / "data",
            "{group}/{subject}_{timepoint}.nc",
            reader="netcdf",
            out=out,
        )
    msg = str(err.value)
    assert msg.startswith("file 'B/rat1_d0.nc' (session 'rat1_d0'): subject 'rat1'")
    assert "in file 'A/rat1_d0.nc'" in msg and "nested_subjects=True" in msg
    assert "--nested-subjects" in msg and "line" not in msg
    assert not out.exists()


def test_nested_subjects_prefix_the_group(tmp_path):
    _files(tmp_path / "data", ["A/rat1_d0.nc", "B/rat1_d0.nc"])
    m = cohort.init_manifest(
        tmp_path / "data",
        "{group}/{subject}_{timepoint}.nc",
        reader="netcdf",
        nested_subjects=True,
    )
    assert m.table["subject"].tolist() == ["A-rat1", "B-rat1"]
    assert m.table["session"].tolist() == ["A-rat1_d0", "B-rat1_d0"]


# ------------------------------------------------------------------ one recording, one row


def test_same_path_twice_is_refused(tmp_path):
    _files(tmp_path, ["a.nc"])
    path = _manifest(tmp_path, ["s1,r1,A,d0,a.nc,netcdf\n", "s2,r2,A,d0,a.nc,netcdf\n"])
    with pytest.raises(
        ManifestError, match=r"line 3 .*'a.nc' is already named on line 2"
    ):
        cohort.read_manifest(path)


def test_same_file_through_a_link_is_refused(tmp_path):
    _files(tmp_path, ["a.nc"])
    os.symlink(tmp_path / "a.nc", tmp_path / "b.nc")
    path = _manifest(tmp_path, ["s1,r1,A,d0,a.nc,netcdf\n", "s2,r2,A,d0,b.nc,netcdf\n"])
    with pytest.raises(ManifestError) as err:
        cohort.read_manifest(path)
    msg = str(err.value)
    assert "line 3 (session 's2'): file 'b.nc' is the same file as 'a.nc'" in msg
    assert "through a link" in msg and "one recording listed twice" in msg


def test_same_content_twice_is_refused(tmp_path):
    (tmp_path / "a.nc").write_bytes(b"x" * 200_000)
    (tmp_path / "copy.nc").write_bytes(b"x" * 200_000)
    path = _manifest(
        tmp_path, ["s1,r1,A,d0,a.nc,netcdf\n", "s2,r2,A,d0,copy.nc,netcdf\n"]
    )
    with pytest.raises(ManifestError) as err:
        cohort.read_manifest(path)
    msg = str(err.value)
    assert "line 3 (session 's2'): file 'copy.nc' has the same content as 'a.nc'" in msg
    assert "on line 2 (session 's1')" in msg


def test_only_files_of_equal_size_are_read(tmp_path, monkeypatch):
    calls = {"fingerprint": 0, "sha256": 0}
    fingerprint, sha256 = manifest_mod._fingerprint, manifest_mod._sha256

    def count(name, func):
        def wrapped(*args):
            calls[name] += 1
            return func(*args)

        return wrapped

    monkeypatch.setattr(manifest_mod, "_fingerprint", count("fingerprint", fingerprint))
    monkeypatch.setattr(manifest_mod, "_sha256", count("sha256", sha256))
    _files(tmp_path, ["a.nc", "bb.nc"])  # sizes differ: nothing read
    rows = ["s1,r1,A,d0,a.nc,netcdf\n", "s2,r2,A,d0,bb.nc,netcdf\n"]
    cohort.read_manifest(_manifest(tmp_path, rows))
    assert calls == {"fingerprint": 0, "sha256": 0}
    _files(tmp_path, ["a.nc", "bb.nc"], size=300_000)  # equal size, blocks differ
    cohort.read_manifest(_manifest(tmp_path, rows))
    assert calls == {"fingerprint": 2, "sha256": 0}


def test_two_sessions_of_a_subject_at_one_time_point_are_refused(tmp_path):
    _files(tmp_path, ["a.nc", "b.nc"])
    path = _manifest(
        tmp_path, ["r1_d7,r1,A,d7,a.nc,netcdf\n", "r1_d7b,r1,A,d7,b.nc,netcdf\n"]
    )
    with pytest.raises(ManifestError) as err:
        cohort.read_manifest(path)
    msg = str(err.value)
    assert "line 3 (session 'r1_d7b'): subject 'r1' already has a session at " in msg
    assert "time point 'd7' (session 'r1_d7' on line 2)" in msg
    assert "count one animal twice" in msg


# ------------------------------------------------------------------ declared names


def test_undeclared_group_is_refused_naming_the_row_and_the_declared(tmp_path):
    _files(tmp_path, ["a.nc", "b.nc"])
    path = _manifest(
        tmp_path,
        ["s1,r1,rotation,0,a.nc,netcdf\n", "s2,r2,translaton,0,b.nc,netcdf\n"],
    )
    with pytest.raises(ManifestError) as err:
        cohort.read_manifest(path, groups=["rotation", "translation"])
    msg = str(err.value)
    assert "line 3 (session 's2'): unknown group 'translaton'" in msg
    assert "declares the groups 'rotation', 'translation'" in msg
    assert "did you mean 'translation'?" in msg


def test_undeclared_time_point_is_refused(tmp_path):
    _files(tmp_path, ["a.nc", "b.nc"])
    path = _manifest(
        tmp_path, ["s1,r1,A,d0,a.nc,netcdf\n", "s2,r1,A,d07,b.nc,netcdf\n"]
    )
    with pytest.raises(ManifestError) as err:
        cohort.read_manifest(path, timepoints="d0,d7")
    msg = str(err.value)
    assert "line 3 (session 's2'): unknown time point 'd07'" in msg
    assert "declares the time points 'd0', 'd7'" in msg


def test_init_refuses_an_undeclared_group_naming_the_file(tmp_path):
    _files(tmp_path, ["sham/r1_d0.nc", "shma/r2_d0.nc"])
    with pytest.raises(ManifestError) as err:
        cohort.init_manifest(
            tmp_path,
            "{group}/{subject}_{timepoint}.nc",
            reader="netcdf",
            declared=cohort.StudyLabels(groups=["sham", "lesion"]),
        )
    msg = str(err.value)
    assert msg.startswith(
        "file 'shma/r2_d0.nc' (session 'r2_d0'): unknown group 'shma'"
    )
    assert "did you mean 'sham'?" in msg


# ------------------------------------------------------------------ statistics


def _table(duplicate=False, failed=()):
    rows = []
    for g in ("A", "B"):
        for i in range(4):
            for t, shift in (("baseline", 0.0), ("7d", 1.0 if g == "A" else 0.0)):
                rows.append(
                    {
                        "session": f"{g}{i}_{t}",
                        "subject": f"{g}{i}",
                        "group": g,
                        "timepoint": t,
                        "x": i + shift,
                        "status": "ok",
                    }
                )
    df = pd.DataFrame(rows)
    if duplicate:
        extra = df[df["session"] == "A0_7d"].assign(session="A0_7d_again")
        df = pd.concat([df, extra], ignore_index=True)
    for s in failed:
        df.loc[df["session"] == s, ["status", "x"]] = ["failed", np.nan]
    return df


def test_between_groups_refuses_two_sessions_in_a_cell():
    with pytest.raises(ValueError) as err:
        S.between_groups(_table(duplicate=True), "x", [("A", "B", "greater")])
    msg = str(err.value)
    assert "subject 'A0' at '7d' (sessions 'A0_7d', 'A0_7d_again')" in msg
    assert "pseudo-replication" in msg


def test_against_baseline_refuses_the_same_table_alike():
    with pytest.raises(ValueError) as err:
        S.against_baseline(_table(duplicate=True), "x", alternative="greater")
    assert "subject 'A0' at '7d' (sessions 'A0_7d', 'A0_7d_again')" in str(err.value)


def test_study_design_refuses_the_same_table():
    with pytest.raises(ValueError, match=r"subject 'A0' at '7d'.*pseudo-replication"):
        study_design(_table(duplicate=True))


def test_duplicates_in_a_dataset_are_named_by_session():
    df = _table(duplicate=True)
    ds = xr.Dataset(
        {"x": ("session", df["x"].to_numpy())},
        coords={
            c: ("session", df[c].to_numpy())
            for c in ("session", "subject", "group", "timepoint")
        },
    )
    with pytest.raises(ValueError, match=r"sessions 'A0_7d', 'A0_7d_again'"):
        S.between_groups(ds, "x", [("A", "B", "greater")])


def test_failed_sessions_are_counted_in_n_failed():
    df = _table(failed=["A1_7d", "B2_7d"])
    df.loc[df["session"] == "A3_7d", "x"] = np.nan  # ran, no value
    tidy = S.between_groups(df, "x", [("A", "B", "greater")])
    row = tidy.iloc[0]
    assert list(tidy.columns[8:10]) == ["n_missing", "n_failed"]
    assert (row.n1, row.n2, row.n_missing, row.n_failed) == (2, 3, 1, 2)
    within = S.against_baseline(df, "x", ["A"], alternative="greater")
    row = within.iloc[0]
    assert (row.n1, row.n_missing, row.n_failed) == (2, 1, 1)


def test_long_table_keeps_failed_sessions_on_request():
    df = _table(failed=["A1_7d"])
    assert len(S.long_table(df, "x")) == 15
    full = S.long_table(df, "x", include_failed=True)
    assert len(full) == 16 and (full["status"] == "failed").sum() == 1


# ------------------------------------------------------------------ the command line


def _broad_like(path: Path, keys=None, fill: float = 0.0) -> None:
    """An HDF5 file with BROAD's variable names (or ``keys``): what
    :func:`tiltlab.io.detect` recognises, not a readable trial."""
    import h5py

    from tiltlab.io.broad import _BROAD_VARS

    path.parent.mkdir(parents=True, exist_ok=True)
    with h5py.File(path, "w") as f:
        for k in keys or _BROAD_VARS:
            f[k] = np.full((3, 3), fill)


def test_init_chooses_the_reader_from_the_content(tmp_path):
    _broad_like(tmp_path / "rot/t01_s1.hdf5", fill=1.0)
    _broad_like(tmp_path / "rot/t02_s1.hdf5", fill=2.0)
    m = cohort.init_manifest(tmp_path, "{group}/{subject}_{timepoint}.hdf5")
    assert m.table["reader"].tolist() == ["broad", "broad"]


def test_init_refuses_a_file_it_cannot_choose_a_reader_for(tmp_path):
    _broad_like(tmp_path / "A/r1_d0.hdf5", keys=["something", "else"])
    with pytest.raises(ValueError) as err:
        cohort.init_manifest(tmp_path, "{group}/{subject}_{timepoint}.hdf5")
    msg = str(err.value)
    assert msg.startswith("file 'A/r1_d0.hdf5' looks like a ")
    assert "something(3, 3)" in msg  # what it looks like
    assert "give reader= (--reader): one of netcdf, fayat_csv" in msg


def test_cli_readers_are_the_manifest_readers():
    from tiltlab.cli.cohort import _READER_NAMES

    assert _READER_NAMES == tuple(cohort.READERS)


def test_paths_are_relative_to_the_manifest_folder(tmp_path):
    _files(tmp_path / "data", ["A/r1_d0.nc"])
    out = tmp_path / "study" / "manifest.csv"
    m = cohort.init_manifest(
        tmp_path / "data", "{group}/{subject}_{timepoint}.nc", reader="netcdf", out=out
    )
    assert m.table["file"].tolist() == ["../data/A/r1_d0.nc"]
    # written elsewhere, the manifest still names the same file
    moved = cohort.read_manifest(out).to_csv(tmp_path / "elsewhere" / "m.csv")
    again = cohort.read_manifest(moved)
    assert again.table["file"].tolist() == ["../data/A/r1_d0.nc"]
    assert cohort.session_path(again.table["file"][0], again.root).is_file()


def _features_file(path: Path, n: int = 400) -> Path:
    sessions = [f"s{i:03d}" for i in range(n)]
    ds = xr.Dataset(
        {
            "immobile_fraction": (
                "session",
                np.linspace(0, 1, n),
                {"units": "1", "long_name": "x"},
            ),
            "status": ("session", np.array(["ok"] * n)),
            "error": ("session", np.array([""] * n)),
        },
        coords={
            "session": sessions,
            "subject": ("session", [f"r{i:03d}" for i in range(n)]),
            "group": ("session", ["A"] * n),
            "timepoint": ("session", ["d0"] * n),
        },
    )
    return cohort.save_features(ds, path)


def test_show_into_a_closed_pipe_is_quiet_and_still_exports(tmp_path):
    features = _features_file(tmp_path / "f.nc")
    export = tmp_path / "t.csv"
    code = (
        "import os, sys\n"
        "r, w = os.pipe(); os.close(r); os.dup2(w, 1)  # nobody reads stdout\n"
        "from tiltlab.cli import main\n"
        f"sys.exit(main(['cohort', 'show', {str(features)!r}, '--export', "
        f"{str(export)!r}]))\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert "Traceback" not in run.stderr and "BrokenPipe" not in run.stderr, run.stderr
    assert run.returncode == 0 and export.is_file()


def test_run_prints_its_summary_once(tmp_path, capsys):
    path = _manifest(tmp_path, ["s1,r1,A,d0,missing.nc,netcdf\n"])
    status = cli.main(["cohort", "run", str(path), "--out", str(tmp_path / "f.nc")])
    captured = capsys.readouterr()
    assert status == 1
    both = captured.out + captured.err
    assert len(re.findall(r"1 sessions: 0 ok, 1 failed", both)) == 1, both
    assert "1 sessions: 0 ok, 1 failed" in captured.out


# -- options of the cohort parser (cli.cohort._add_cohort)


def test_cli_init_regex_and_nested_subjects(tmp_path, capsys):
    _files(tmp_path / "data", ["A/rat1_day_0.nc", "B/rat1_day_0.nc"])
    argv = ["cohort", "init", str(tmp_path / "data"), "--reader", "netcdf"]
    regex = r"(?P<group>[^/]+)/(?P<subject>[^/]+)_(?P<timepoint>day_\d+)\.nc"
    out = tmp_path / "m.csv"
    assert cli.main([*argv, "--regex", regex, "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "subject 'rat1' is in group 'B'" in err and "--nested-subjects" in err
    assert (
        cli.main([*argv, "--regex", regex, "--nested-subjects", "--out", str(out)]) == 0
    )
    printed = capsys.readouterr().out
    assert "2 session(s) of 2 subject(s)" in printed and "day_0 (2)" in printed
    assert pd.read_csv(out, dtype=str)["subject"].tolist() == ["A-rat1", "B-rat1"]


def test_cli_declared_groups_and_time_points(tmp_path, capsys):
    _files(tmp_path / "data", ["A/r1_d0.nc", "B/r2_d7.nc"])
    out = tmp_path / "m.csv"
    base = ["cohort", "init", str(tmp_path / "data"), "--reader", "netcdf"]
    pattern = ["--pattern", "{group}/{subject}_{timepoint}.nc", "--out", str(out)]
    assert cli.main([*base, *pattern, "--timepoints", "d0,d14"]) == 1
    err = capsys.readouterr().err
    assert (
        "unknown time point 'd7'; the study declares the time points 'd0', 'd14'"
        in (err)
    )
    assert cli.main([*base, *pattern, "--groups", "A,B"]) == 0
    capsys.readouterr()
    run = ["cohort", "run", str(out), "--out", str(tmp_path / "f.nc"), "--no-progress"]
    assert cli.main([*run, "--groups", "A,C"]) == 2
    err = capsys.readouterr().err
    assert "m.csv, line 3 (session 'r2_d7'): unknown group 'B'" in err


def test_cli_init_without_reader_on_unknown_hdf5_lists_the_choices(tmp_path, capsys):
    _broad_like(tmp_path / "A/r1_d0.hdf5", keys=["something"])
    argv = [
        "cohort",
        "init",
        str(tmp_path),
        "--pattern",
        "{group}/{subject}_{timepoint}.hdf5",
    ]
    assert cli.main([*argv, "--out", str(tmp_path / "m.csv")]) == 1
    err = capsys.readouterr().err
    assert "give reader= (--reader): one of netcdf, fayat_csv" in err
    assert not (tmp_path / "m.csv").exists()


def test_cli_workers_help_says_what_runs(capsys):
    assert cli.main(["cohort", "run", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "automatic" not in text
    assert "1 (the default) runs the sessions one after the other" in text
    from tiltlab.cohort.schedulers import backend

    assert backend(None, None).name == "serial"
    assert backend(None, 1).name == "serial"


def test_a_group_label_one_letter_off_is_warned(tmp_path):
    """Undeclared groups 'translation' and 'translaton' (a typo) are read with a
    warning naming both and how to make it an error; short labels (d1, d7) are not."""
    import warnings as _w

    import pandas as pd

    from tiltlab import cohort

    rows = []
    for k, g in enumerate(["translation"] * 3 + ["translaton"] + ["rotation"] * 3):
        f = tmp_path / f"s{k}.nc"
        f.write_bytes(bytes([k]) * (k + 1))  # distinct content
        rows.append(
            {
                "session": f"s{k}",
                "subject": f"a{k}",
                "group": g,
                "timepoint": "d1",
                "file": f.name,
                "reader": "netcdf",
            }
        )
    pd.DataFrame(rows).to_csv(tmp_path / "m.csv", index=False)
    with pytest.warns(
        cohort.ManifestWarning,
        match=r"'translation' \(3 sessions\).*'translaton' \(1 sessions\).*groups=",
    ):
        cohort.read_manifest(tmp_path / "m.csv")
    with _w.catch_warnings():
        _w.simplefilter("error", cohort.ManifestWarning)
        with pytest.raises(cohort.ManifestError, match="translaton"):
            cohort.read_manifest(tmp_path / "m.csv", groups=["translation", "rotation"])
