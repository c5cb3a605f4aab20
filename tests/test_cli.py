"""The command line wraps the package; errors are reported, not raised."""

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tiltlab import cli, io, schema


def test_info_and_validate_on_saved_recording(tmp_path, capsys):
    rng = np.random.default_rng(0)
    rec = schema.make_recording(
        np.tile([0, 0, 1.0], (100, 1)),
        rng.normal(0, 0.1, (100, 3)),
        50.0,
        acc_units="g",
        gyr_units="deg/s",
        attrs={"session": "s1"},
    )
    path = io.save_netcdf(rec, tmp_path / "r.nc")
    assert cli.main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "samples: 100" in out and "fs_hz: 50.0" in out
    assert cli.main(["validate", str(path)]) == 0
    bad = rec.copy()
    bad.attrs.pop("fs")
    io.save_netcdf(bad, tmp_path / "bad.nc")
    assert cli.main(["validate", str(tmp_path / "bad.nc")]) == 1
    assert "'fs'" in capsys.readouterr().err


def test_fetch_verifies_mirror(data_mirror, capsys):
    assert cli.main(["fetch", "fayat2021/example_imu.csv"]) == 0
    assert "verified" in capsys.readouterr().out
    assert cli.main(["fetch", "nope.csv"]) == 1


# --------------------------------------------------------------------------- generic CSV


def _write_lab_csv(path, n=300, fs=100.0, seed=1):
    rng = np.random.default_rng(seed)
    acc = rng.normal(0, 0.01, (n, 3)) + [0, 0, 1.0]
    gyr = rng.normal(0, 1.0, (n, 3))
    lines = ["t_ms;ax;ay;az;gx;gy;gz"] + [
        ";".join(f"{v:.10g}" for v in (1e3 * i / fs, *acc[i], *gyr[i]))
        for i in range(n)
    ]
    path.write_text("\n".join(lines) + "\n")


MAPPING = {
    "columns": {"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]},
    "units": {"acc": "g", "gyr": "deg/s"},
    "time_column": "t_ms",
    "time_units": "ms",
    "sep": ";",
}


def test_generic_csv_info_and_validate_with_mapping(tmp_path, capsys):
    csv = tmp_path / "my_session.csv"
    _write_lab_csv(csv)
    mapping = tmp_path / "mapping.json"
    mapping.write_text(json.dumps(MAPPING))
    assert cli.main(["info", str(csv), "--mapping", str(mapping)]) == 0
    out = capsys.readouterr().out
    assert "samples: 300" in out and "fs_hz: 100.0" in out
    assert "acc [g], gyr [deg/s]" in out and "'t_ms' (ms)" in out
    assert cli.main(["validate", str(csv), "--mapping", str(mapping)]) == 0
    assert "valid Recording" in capsys.readouterr().out


def test_csv_without_mapping_says_how_to_give_one(tmp_path, capsys):
    csv = tmp_path / "my_session.csv"
    _write_lab_csv(csv)
    for cmd in ("info", "validate"):
        assert cli.main([cmd, str(csv)]) == 1
        err = capsys.readouterr().err
        assert err.startswith("tiltlab: don't know how to read")
        assert "--mapping mapping.json" in err and '"columns"' in err
        assert err.count("\n") == 1 and "Traceback" not in err
    # the mapping format is documented in the command's help
    assert cli.main(["info", "--help"]) == 0
    assert '"time_units": "ms"' in capsys.readouterr().out


@pytest.mark.parametrize(
    ("mapping", "expected"),
    [
        (None, "no such mapping file"),
        ('{"columns": ', "not valid JSON (line 1"),
        (
            json.dumps({**MAPPING, "units": {"acc": "g"}}),
            "units must give the unit of 'gyr'",
        ),
        (
            json.dumps(
                {
                    **MAPPING,
                    "columns": {**MAPPING["columns"], "acc": ["ax", "ay", "AZ"]},
                }
            ),
            "missing column(s) 'AZ' (mapped to acc), did you mean 'az'?; available columns: 't_ms', 'ax'",
        ),
        (
            json.dumps({**MAPPING, "time_units": "s"}),
            'the time column looks like milliseconds: give "time_units": "ms"',
        ),
    ],
)
def test_csv_user_errors_are_one_line(tmp_path, capsys, mapping, expected):
    csv = tmp_path / "s.csv"
    _write_lab_csv(csv)
    mp = tmp_path / "mapping.json"
    if mapping is not None:
        mp.write_text(mapping)
    assert cli.main(["validate", str(csv), "--mapping", str(mp)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("tiltlab: ") and expected in err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_recording_errors_and_missing_files(tmp_path, capsys):
    assert cli.main(["info", str(tmp_path / "nothing.nc")]) == 1
    assert "no such file" in capsys.readouterr().err
    csv = tmp_path / "s.csv"
    _write_lab_csv(csv)
    # a repeated time stamp breaks the Recording contract (RecordingError)
    lines = csv.read_text().splitlines()
    csv.write_text("\n".join([*lines[:50], lines[49], *lines[50:]]) + "\n")
    mp = tmp_path / "m.json"
    mp.write_text(json.dumps(MAPPING))
    rc = cli.main(["validate", str(csv), "--mapping", str(mp)])
    err = capsys.readouterr().err
    assert rc == 1 and "not strictly increasing" in err
    assert err.startswith("tiltlab: ") and err.count("\n") == 1


# --------------------------------------------------------------------------- cohort


SESSIONS = [
    ("sham", "r1", "d0"),
    ("sham", "r1", "d7"),
    ("lesion", "r2", "d0"),
    ("lesion", "r2", "d7"),
]


@pytest.fixture(scope="module")
def cohort_sessions(tmp_path_factory):
    """Four short simulated sessions laid out as data/{group}/{subject}_{timepoint}.nc."""
    from tiltlab import simulate

    root = tmp_path_factory.mktemp("cohort")
    for i, (group, subject, tp) in enumerate(SESSIONS):
        rec = simulate.simulate_session(12.0, 100.0, seed=i, keep_true=False)
        io.save_netcdf(rec, root / "data" / group / f"{subject}_{tp}.nc")
    return root


@pytest.fixture
def study(cohort_sessions, tmp_path, capsys):
    """A fresh copy of the cohort (tests may damage files), its manifest and what
    ``cohort init`` printed."""
    shutil.copytree(cohort_sessions / "data", tmp_path / "data")
    manifest = tmp_path / "manifest.csv"
    rc = cli.main(
        [
            "cohort",
            "init",
            str(tmp_path / "data"),
            "--pattern",
            "{group}/{subject}_{timepoint}.nc",
            "--out",
            str(manifest),
        ]
    )
    assert rc == 0
    return tmp_path, manifest, capsys.readouterr().out


def _run(manifest, out, *extra):
    return cli.main(
        [
            "cohort",
            "run",
            str(manifest),
            "--out",
            str(out),
            "--cache-dir",
            str(Path(out).parent / "cache"),
            "--no-progress",
            *extra,
        ]
    )


def test_cohort_init_run_show(study, capsys):
    root, manifest, out = study
    assert "4 session(s) of 2 subject(s)" in out and "sham (2)" in out
    table = pd.read_csv(manifest)
    assert sorted(table["session"]) == ["r1_d0", "r1_d7", "r2_d0", "r2_d7"]
    assert set(table["file"]) == {
        f"data/{g}/{s}_{t}.nc" for g, s, t in SESSIONS
    }  # relative to the manifest's folder

    features = root / "features.nc"
    assert _run(manifest, features) == 0
    out = capsys.readouterr().out
    assert "4 sessions: 4 ok, 0 failed (4 computed, 0 from cache)" in out
    assert features.is_file()

    assert cli.main(["cohort", "show", str(features)]) == 0
    out = capsys.readouterr().out
    header = out.splitlines()[0].split()
    for col in ("subject", "group", "timepoint", "status", "immobile_fraction"):
        assert col in header
    rows = {line.split()[0]: line.split() for line in out.splitlines()[2:6]}
    assert rows["r2_d7"][1:5] == ["r2", "lesion", "d7", "ok"]
    assert "tilt_immobile_sagittal_deg [deg]" in out  # units of the shown features
    assert "more feature(s), shown with --all" in out
    assert "config (hash " in out and re.search(r'\n  method += "smoother"', out)
    assert cli.main(["cohort", "show", str(features), "--all"]) == 0
    assert "odba_mean" in capsys.readouterr().out.splitlines()[0]

    # a second run takes every session from the cache
    assert _run(manifest, root / "again.nc") == 0
    assert "(0 computed, 4 from cache)" in capsys.readouterr().out


def test_cohort_init_errors(study, capsys):
    root, manifest, _ = study
    capsys.readouterr()
    args = ["cohort", "init", str(root / "data"), "--pattern"]
    # an existing manifest is not replaced without --force
    assert (
        cli.main([*args, "{group}/{subject}_{timepoint}.nc", "--out", str(manifest)])
        == 1
    )
    assert "exists" in capsys.readouterr().err
    assert (
        cli.main(
            [
                *args,
                "{group}/{subject}_{timepoint}.nc",
                "--out",
                str(manifest),
                "--force",
            ]
        )
        == 0
    )
    # no {group} field and no --group; nothing matches; no such folder
    for argv, expected in (
        ([*args, "{subject}.nc", "--out", str(root / "m.csv")], "give group="),
        (
            [*args, "{group}/{subject}.csv", "--out", str(root / "m.csv")],
            "no file under",
        ),
        (
            ["cohort", "init", str(root / "nope"), "--pattern", "{subject}.nc"],
            "no such folder",
        ),
    ):
        assert cli.main(argv) == 1
        err = capsys.readouterr().err
        assert (
            err.startswith("tiltlab: ") and expected in err and "Traceback" not in err
        )
    # one group for all when the pattern has none
    assert (
        cli.main(
            [
                *args,
                "sham/{subject}_{timepoint}.nc",
                "--group",
                "sham",
                "--out",
                str(root / "m.csv"),
            ]
        )
        == 0
    )
    assert set(pd.read_csv(root / "m.csv")["group"]) == {"sham"}


def test_cohort_run_with_a_failed_session(study, capsys):
    root, manifest, _ = study
    damaged = root / "data" / "sham" / "r1_d7.nc"
    damaged.write_bytes(damaged.read_bytes()[:3000])
    capsys.readouterr()
    features = root / "features.nc"
    assert _run(manifest, features) == 1
    captured = capsys.readouterr()
    assert "4 sessions: 3 ok, 1 failed" in captured.out
    assert (
        "failed r1_d7: ReadError:" in captured.out
        and "truncated or corrupt" in captured.out
    )
    assert captured.err.startswith("tiltlab: 1 of 4 session(s) failed: r1_d7")
    assert "Traceback" not in captured.out + captured.err
    # the failed session is in the feature file, marked, with NaN features
    assert cli.main(["cohort", "show", str(features)]) == 0
    out = capsys.readouterr().out
    assert "failed" in next(
        line for line in out.splitlines() if line.startswith("r1_d7")
    )


def test_cohort_run_failed_session_in_a_subprocess(study):
    """The installed command: exit status 1, the failure reported, no traceback."""
    root, manifest, _ = study
    damaged = root / "data" / "lesion" / "r2_d0.nc"
    damaged.write_bytes(b"not a netcdf file")
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "tiltlab.cli",
            "cohort",
            "run",
            str(manifest),
            "--out",
            str(root / "f.nc"),
            "--cache-dir",
            str(root / "cache"),
            "--workers",
            "2",
            "--scheduler",
            "processes",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 1, proc.stderr
    assert "failed r2_d0: ReadError" in proc.stdout
    assert "tiltlab: 1 of 4 session(s) failed: r2_d0" in proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (lambda t: t.drop(columns="reader"), "missing required column(s) ['reader']"),
        (lambda t: t.assign(reader="nope"), "unknown reader 'nope'"),
        (
            lambda t: t.assign(session="same"),
            "session id 'same' already used on line 2",
        ),
    ],
)
def test_cohort_run_rejects_a_bad_manifest(study, capsys, edit, expected):
    root, manifest, _ = study
    bad = root / "bad.csv"
    edit(pd.read_csv(manifest)).to_csv(bad, index=False)
    capsys.readouterr()
    assert _run(bad, root / "f.nc") == 2
    err = capsys.readouterr().err
    assert err.startswith("tiltlab: bad.csv, line ") and expected in err
    assert err.count("\n") == 1 and not (root / "f.nc").exists()


@pytest.mark.parametrize(
    ("config", "expected"),
    [
        (None, "no such config file"),
        ('{"method": ', "config is not valid JSON (line 1"),
        ("[1, 2]", "a config is a JSON object"),
        ('{"mesh_n": 3}', "FeatureConfig.mesh_n must be at least 12"),
        ('{"methd": "lowpass"}', "unknown FeatureConfig field(s) ['methd']"),
        ('{"method": "nope"}', "unknown method 'nope'"),
    ],
)
def test_cohort_run_rejects_a_bad_config(study, capsys, config, expected):
    root, manifest, _ = study
    path = root / "config.json"
    if config is not None:
        path.write_text(config)
    capsys.readouterr()
    assert _run(manifest, root / "f.nc", "--config", str(path)) == 2
    err = capsys.readouterr().err
    assert err.startswith("tiltlab: ") and expected in err and err.count("\n") == 1


def test_cohort_run_with_a_config_and_missing_manifest(study, capsys):
    root, manifest, _ = study
    config = root / "config.json"
    config.write_text(
        json.dumps({"method": "lowpass", "method_params": {"cutoff_hz": 2.0}})
    )
    assert _run(manifest, root / "f.nc", "--config", str(config)) == 0
    capsys.readouterr()
    assert cli.main(["cohort", "show", str(root / "f.nc")]) == 0
    out = capsys.readouterr().out
    assert re.search(r'\n  method += "lowpass"', out) and '"cutoff_hz": 2.0' in out
    assert _run(root / "nothing.csv", root / "g.nc") == 2
    assert "no such manifest" in capsys.readouterr().err
    # options argparse refuses: usage error, exit 2
    assert _run(manifest, root / "g.nc", "--workers", "0") == 2
    assert "--workers must be at least 1" in capsys.readouterr().err
    assert _run(manifest, root / "g.nc", "--scheduler", "threads") == 2
    assert cli.main(["cohort", "show", str(root / "nothing.nc")]) == 1
    assert "no such file" in capsys.readouterr().err


def test_cohort_of_generic_csv_sessions(tmp_path, capsys):
    """A lab's own CSV files (time in ms) through init --reader csv, run and show."""
    for seed, subject in enumerate(("a1", "a2")):
        (tmp_path / "raw").mkdir(exist_ok=True)
        # two animals, two recordings: identical files would be one recording twice
        _write_lab_csv(tmp_path / "raw" / f"{subject}_base.csv", n=1500, seed=seed)
    mapping = tmp_path / "mapping.json"
    mapping.write_text(json.dumps(MAPPING))
    manifest = tmp_path / "manifest.csv"
    argv = [
        "cohort",
        "init",
        str(tmp_path / "raw"),
        "--pattern",
        "{subject}_{timepoint}.csv",
        "--reader",
        "csv",
        "--group",
        "all",
        "--out",
        str(manifest),
    ]
    assert cli.main([*argv, "--reader-options", str(mapping)]) == 0
    assert _run(manifest, tmp_path / "f.nc") == 0
    assert "2 sessions: 2 ok, 0 failed" in capsys.readouterr().out
    # the csv reader needs a mapping: init without one is rejected, naming what is missing
    assert cli.main([*argv, "--force"]) == 1
    assert "the csv reader needs reader_options" in capsys.readouterr().err
