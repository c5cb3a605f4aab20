"""Integrity: checksums of saved Recordings (tiltlab.io.save_netcdf / load_netcdf,
``tiltlab validate``), of model weights (tiltlab.learn.save / load) and the strict
parsing of ``SHA256SUMS`` files."""

import pickle
import shutil
import struct
import types
import zipfile
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr

from tiltlab import cli, io, schema
from tiltlab.io import IntegrityError, ReadError
from tiltlab.io.netcdf import CHECKSUM_ATTR

COMMITTED = Path(__file__).resolve().parents[1] / "data" / "learn"
MARK = -0.6960123456789  # a value found once in the file's bytes


def _recording(n=400, **extra):
    rng = np.random.default_rng(3)
    acc = rng.normal(0, 0.01, (n, 3)) + [0, 0, 1.0]
    acc[57, 0] = MARK
    return schema.make_recording(
        acc,
        rng.normal(0, 0.5, (n, 3)),
        100.0,
        acc_units="g",
        gyr_units="deg/s",
        attrs={"session": "s1", "flag": True, "nested": {"a": [1, 2]}},
        **extra,
    )


def _flip_mark(src: Path, dst: Path) -> None:
    """Copy ``src`` with one bit flipped in the bytes of ``MARK``: exponent bit 4,
    so −0.696 g reads −1.06e-05 g (a plausible value that passes validation)."""
    data = bytearray(src.read_bytes())
    pattern = np.float64(MARK).tobytes()
    assert data.count(pattern) == 1
    data[data.find(pattern) + 7] ^= 0x01
    dst.write_bytes(bytes(data))


def _strip_checksums(path: Path) -> None:
    """Make a file as save_netcdf wrote it before checksums were stored."""
    with h5py.File(path, "r+") as f:
        del f.attrs[CHECKSUM_ATTR]


# ------------------------------------------------------------------ NetCDF Recordings


def test_round_trip_is_exact_and_checksums_are_stored(tmp_path):
    rec = _recording()
    path = io.save_netcdf(rec, tmp_path / "r.nc")
    back = io.load_netcdf(path, validate=True)
    xr.testing.assert_identical(back, rec)
    assert CHECKSUM_ATTR not in back.attrs
    sums = io.netcdf_checksums(path)
    assert sums["algorithm"] == "sha256"
    assert set(sums["variables"]) == {str(v) for v in rec.variables}
    assert all(len(h) == 64 for h in sums["variables"].values())


def test_one_flipped_bit_is_refused_naming_the_file_and_variable(tmp_path):
    path = io.save_netcdf(_recording(), tmp_path / "r.nc")
    bad = tmp_path / "flipped.nc"
    _flip_mark(path, bad)
    with pytest.raises(IntegrityError, match=r"flipped\.nc.*variable 'acc'") as info:
        io.load_netcdf(bad, validate=True)
    assert info.value.variable == "acc" and info.value.path == bad
    assert isinstance(info.value, ReadError) and isinstance(info.value, ValueError)
    # the documented escape: salvage the data as read
    salvaged = io.load_netcdf(bad, verify=False)
    assert salvaged.acc.values[57, 0] == pytest.approx(MARK / 2**16)
    assert np.array_equal(salvaged.gyr.values, _recording().gyr.values)


def test_a_value_rewritten_with_h5py_is_refused(tmp_path):
    path = io.save_netcdf(_recording(), tmp_path / "r.nc")
    with h5py.File(path, "r+") as f:
        f["gyr"][10, 1] = 12.5  # attributes untouched
    with pytest.raises(IntegrityError, match="variable 'gyr'"):
        io.load_netcdf(path)


def test_changed_time_coordinate_and_attributes_are_refused(tmp_path):
    path = io.save_netcdf(_recording(), tmp_path / "r.nc")
    with h5py.File(path, "r+") as f:
        f["time"][3] = 0.5
    with pytest.raises(IntegrityError, match="variable 'time'"):
        io.load_netcdf(path)
    path = io.save_netcdf(_recording(), tmp_path / "a.nc")
    with h5py.File(path, "r+") as f:
        blob = f.attrs["_tiltlab_attrs_json"]
        f.attrs["_tiltlab_attrs_json"] = blob.replace('"fs": 100.0', '"fs": 101.0')
    with pytest.raises(IntegrityError, match="attributes"):
        io.load_netcdf(path)
    assert io.load_netcdf(path, verify=False).attrs["fs"] == 101.0


def test_damaged_checksum_record_is_refused(tmp_path):
    path = io.save_netcdf(_recording(), tmp_path / "r.nc")
    with h5py.File(path, "r+") as f:
        f.attrs[CHECKSUM_ATTR] = '{"algorithm": "sha256", "variab'
    with pytest.raises(IntegrityError, match=CHECKSUM_ATTR):
        io.load_netcdf(path)
    with pytest.raises(IntegrityError, match=CHECKSUM_ATTR):
        io.netcdf_checksums(path)
    xr.testing.assert_identical(io.load_netcdf(path, verify=False), _recording())


def test_old_file_without_checksums_loads_unchecked(tmp_path, recwarn):
    rec = _recording()
    path = io.save_netcdf(rec, tmp_path / "old.nc")
    _strip_checksums(path)
    assert io.netcdf_checksums(path) is None
    xr.testing.assert_identical(io.load_netcdf(path, validate=True), rec)
    assert not recwarn.list  # documented: silently, as before


def test_lossy_encodings_are_not_applied_and_the_input_is_untouched(tmp_path):
    rec = _recording()
    rec["acc"].encoding = {"dtype": "int16", "scale_factor": 0.001, "_FillValue": 0}
    rec["gyr"].values[5, 2] = np.nan
    path = io.save_netcdf(rec, tmp_path / "r.nc")
    assert rec["acc"].encoding["dtype"] == "int16"
    back = io.load_netcdf(path, allow_nan=True)  # checksums verified
    xr.testing.assert_identical(back, rec)


def test_nan_payload_does_not_count(tmp_path):
    rec = _recording()
    gyr = rec["gyr"].values.copy()
    gyr.view(np.uint64)[7, 0] = 0xFFF8000000000001  # a NaN with a payload
    rec["gyr"].values = gyr
    back = io.load_netcdf(io.save_netcdf(rec, tmp_path / "r.nc"))
    assert np.isnan(back.gyr.values[7, 0])


def test_integrity_error_pickles():
    err = IntegrityError("f.nc: bad", path="f.nc", variable="acc")
    back = pickle.loads(pickle.dumps(err))
    assert str(back) == "f.nc: bad" and back.variable == "acc"
    assert back.path == Path("f.nc")


def test_hashing_a_one_hour_recording_is_cheap():
    import time

    from tiltlab.io.netcdf import _checksum_record

    n = 300 * 3600
    acc = np.zeros((n, 3))
    acc[:, 2] = 1.0
    rec = schema.make_recording(
        acc, np.zeros((n, 3)), 300.0, acc_units="g", gyr_units="deg/s"
    )
    t0 = time.perf_counter()
    _checksum_record(rec, "{}")
    assert time.perf_counter() - t0 < 2.0  # ~50 MB of values, sha256 once


# ------------------------------------------------------------------ tiltlab validate


def test_validate_refuses_a_flipped_bit_naming_the_variable(tmp_path, capsys):
    path = io.save_netcdf(_recording(), tmp_path / "r.nc")
    assert cli.main(["validate", str(path)]) == 0
    out = capsys.readouterr().out
    assert out.strip() == f"{path}: valid Recording"
    bad = tmp_path / "flipped.nc"
    _flip_mark(path, bad)
    assert cli.main(["validate", str(bad)]) == 1
    err = capsys.readouterr().err
    assert "flipped.nc" in err and "'acc'" in err and "checksum mismatch" in err
    assert err.count("\n") == 1  # one line, no traceback
    assert cli.main(["info", str(bad)]) == 1
    assert "'acc'" in capsys.readouterr().err


def test_validate_reports_no_checksum_stored(tmp_path, capsys):
    path = io.save_netcdf(_recording(), tmp_path / "old.nc")
    _strip_checksums(path)
    assert cli.main(["validate", str(path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert "no checksum stored" in lines[0] and lines[0].startswith("warning: ")
    assert lines[-1] == f"{path}: valid Recording (1 warning)"
    assert cli.main(["info", str(path)]) == 0
    assert "checksums: none stored" in capsys.readouterr().out


def test_info_says_checksums_verified(tmp_path, capsys):
    path = io.save_netcdf(_recording(), tmp_path / "r.nc")
    assert cli.main(["info", str(path)]) == 0
    assert "checksums: verified (sha256 of 4 variables" in capsys.readouterr().out


# ------------------------------------------------------------------ model weights


@pytest.fixture(scope="module")
def learn():
    pytest.importorskip("torch")
    return pytest.importorskip("tiltlab.learn")


def _flip_tensor_bit(src: Path, dst: Path) -> None:
    """Copy a .pt file with one bit flipped in its first tensor's bytes."""
    data = bytearray(src.read_bytes())
    with zipfile.ZipFile(src) as z:
        info = next(i for i in z.infolist() if "/data/" in i.filename)
    h = info.header_offset
    name_len, extra_len = struct.unpack("<HH", data[h + 26 : h + 30])
    data[h + 30 + name_len + extra_len + 5] ^= 0x10
    dst.write_bytes(bytes(data))


def test_tampered_committed_weights_are_refused(learn, tmp_path):
    folder = shutil.copytree(COMMITTED, tmp_path / "learn")
    _flip_tensor_bit(COMMITTED / "gain_fold0.pt", folder / "gain_fold0.pt")
    with pytest.raises(IntegrityError, match=r"gain_fold0\.pt.*SHA256SUMS"):
        learn.load_model(folder / "gain_fold0.pt")
    with pytest.raises(ValueError, match=r"gain_fold0\.pt"):
        learn.check_files(folder)
    with pytest.raises(IntegrityError, match=r"gain_fold0\.pt"):
        learn.learned_estimate(None, folder / "gain_fold0.pt")  # before any data
    model, cfg, fs = learn.load_model(folder / "gain_fold0.pt", verify=False)
    assert cfg.variant == "gain"
    # the intact committed file loads, checked against its entry
    learn.load_model(COMMITTED / "gain_fold0.pt")


def test_saved_weights_carry_their_digest(learn, tmp_path, recwarn):
    cfg = learn.TrainConfig(variant="gain")
    model = learn.build_model(cfg, 285.0)
    digest = learn.save(model, cfg, 285.0, tmp_path / "m.pt")
    loaded, cfg2, fs = learn.load_model(tmp_path / "m.pt")  # no SHA256SUMS: the digest
    assert cfg2 == cfg and fs == 285.0 and not recwarn.list
    learn.load_model(tmp_path / "m.pt", sha256=digest)
    _flip_tensor_bit(tmp_path / "m.pt", tmp_path / "bad.pt")
    with pytest.raises(IntegrityError, match=r"bad\.pt.*saved with them"):
        learn.load_model(tmp_path / "bad.pt")
    with pytest.raises(IntegrityError, match=r"bad\.pt.*expected sha256"):
        learn.load_model(tmp_path / "bad.pt", sha256=digest)
    learn.load_model(tmp_path / "bad.pt", verify=False)


def test_weights_with_no_record_load_with_a_warning(learn, tmp_path):
    """A file saved before weights carried their digest, alone (no SHA256SUMS)."""
    import torch

    blob = torch.load(
        COMMITTED / "gain_fold0.pt", map_location="cpu", weights_only=True
    )
    blob.pop("sha256", None)
    torch.save(blob, tmp_path / "alone.pt")
    with pytest.warns(UserWarning, match=r"alone\.pt: no recorded sha256"):
        learn.load_model(tmp_path / "alone.pt")


def test_a_stale_sums_entry_refuses_replaced_weights(learn, tmp_path):
    shutil.copy(COMMITTED / "gain_fold0.pt", tmp_path / "quaternion_fold0.pt")
    shutil.copy(COMMITTED / "SHA256SUMS", tmp_path)
    with pytest.raises(IntegrityError, match="quaternion_fold0.pt"):
        learn.load_model(tmp_path / "quaternion_fold0.pt")


# ------------------------------------------------------------------ SHA256SUMS

_A = "a" * 64


def _sums(tmp_path, text, files=("x.json",)):
    for name in files:
        (tmp_path / name).write_text("{}")
    (tmp_path / "SHA256SUMS").write_text(text)
    return tmp_path / "SHA256SUMS"


@pytest.mark.parametrize(
    "text, match",
    [
        ("", "empty checksum file"),
        ("\n\n  \n", "empty checksum file"),
        (f"{_A} x.json\n", "line 1: malformed"),  # one space only
        (f"{_A}\n", "line 1: malformed"),  # no name
        (f"{_A}  \n", "line 1: malformed"),  # blank name
        (f"{_A[:-1]}  x.json\n", "line 1: malformed"),  # 63 digits
        (f"{'g' * 64}  x.json\n", "line 1: malformed"),  # not hex
        (f"\n{_A}  x.json\n{_A}\tx.json\n", "line 3: malformed"),  # tab
        ("# comment\n", "line 1: malformed"),
        ("SHA256 (x.json) = " + _A + "\n", "line 1: malformed"),  # BSD style
        (f"{_A}  x.json\n{_A} *x.json\n", "line 2: 'x.json' is listed twice"),
        (f"{_A}  /etc/passwd\n", "line 1: '/etc/passwd' is not a file name"),
        (f"{_A}  ../x.json\n", "line 1: '../x.json' is not a file name"),
    ],
)
def test_malformed_sums_are_refused_naming_the_line(learn, tmp_path, text, match):
    path = _sums(tmp_path, text)
    with pytest.raises(IntegrityError, match=match) as info:
        learn.read_sums(path)
    assert "SHA256SUMS" in str(info.value)
    with pytest.raises(ValueError, match=match):
        learn.check_files(tmp_path)
    from tiltlab.learn.__main__ import main as learn_main

    assert learn_main(["check", str(tmp_path)]) == 1


def test_sums_blank_lines_binary_marker_and_crlf(learn, tmp_path):
    files = ("a.json", "b c.pt", "d.json")
    for name in files:
        (tmp_path / name).write_text(name)
    lines = [
        "",
        f"{learn.sha256(tmp_path / 'a.json')}  a.json",
        "   ",
        f"{learn.sha256(tmp_path / 'b c.pt')} *b c.pt",
        f"{learn.sha256(tmp_path / 'd.json').upper()}  d.json",
        "",
    ]
    (tmp_path / "SHA256SUMS").write_bytes("\r\n".join(lines).encode())
    sums = learn.read_sums(tmp_path / "SHA256SUMS")
    assert list(sums) == list(files)
    assert sums["d.json"] == learn.sha256(tmp_path / "d.json")  # lower case
    assert learn.check_files(tmp_path) == sums


def test_sums_missing_and_changed_files(learn, tmp_path):
    _sums(tmp_path, f"{_A}  gone.json\n", files=())
    with pytest.raises(ValueError, match="gone.json is listed in .*but missing"):
        learn.check_files(tmp_path)
    _sums(tmp_path, f"{_A}  x.json\n")
    with pytest.raises(ValueError, match=r"x\.json: sha256 .* differs"):
        learn.check_files(tmp_path)


def test_committed_sums_parse(learn):
    sums = learn.read_sums(COMMITTED / "SHA256SUMS")
    assert "run.json" in sums and any(n.endswith(".pt") for n in sums)
    assert learn.check_files(COMMITTED) == sums


# ------------------------------------------------------------------ data registry


@pytest.mark.parametrize(
    "text, match",
    [
        ("", "has no entries"),
        ("# only a comment\n\n", "has no entries"),
        (f"a.csv sha256:{_A}\n", "line 1: malformed entry"),
        (f"\na.csv md5:{_A} https://x/a.csv\n", "line 2: entry a.csv: unsupported"),
        ("a.csv sha256:abc https://x/a.csv\n", "line 1: entry a.csv: 'abc' is not"),
        (
            f"a.csv sha256:{_A} https://x/a.csv\na.csv sha256:{_A} https://x/a.csv\n",
            "line 2: a.csv is listed twice",
        ),
    ],
)
def test_registry_is_parsed_strictly(tmp_path, monkeypatch, text, match):
    from tiltlab import datasets

    reg = tmp_path / "tiltlab" / "_registry"
    reg.mkdir(parents=True)
    (reg / "datasets.json").write_text('{"files": {}, "datasets": {}}')
    (reg / "registry.txt").write_text(text)
    fake = types.SimpleNamespace(files=lambda _: tmp_path / "tiltlab")
    monkeypatch.setattr(datasets, "resources", fake)
    with pytest.raises(datasets.DataError, match=match):
        datasets.registry.__wrapped__()
