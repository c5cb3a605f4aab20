"""One SHA256SUMS parser and writer: round trip, the sha256sum format, refusals."""

import hashlib

import pytest

from tiltlab import io
from tiltlab.io import IntegrityError


def test_round_trip_matches_sha256sum_and_hashlib(tmp_path):
    for name, text in (("b.json", "{}"), ("a.txt", "tilt")):
        (tmp_path / name).write_text(text)
    digests = {n: io.file_sha256(tmp_path / n) for n in ("b.json", "a.txt")}
    assert digests["a.txt"] == hashlib.sha256(b"tilt").hexdigest()
    io.write_sums(tmp_path, digests)
    text = (tmp_path / io.SUMS_FILE).read_text()
    assert text == f"{digests['a.txt']}  a.txt\n{digests['b.json']}  b.json\n"
    assert io.read_sums(tmp_path / io.SUMS_FILE) == digests
    assert io.check_sums(tmp_path) == digests


def test_changed_missing_and_unlisted_cases_are_refused_by_name(tmp_path):
    (tmp_path / "a.txt").write_text("tilt")
    io.write_sums(tmp_path, {"a.txt": io.file_sha256(tmp_path / "a.txt")})
    (tmp_path / "a.txt").write_text("tilT")
    with pytest.raises(IntegrityError, match="a.txt: sha256"):
        io.check_sums(tmp_path)
    (tmp_path / "a.txt").unlink()
    with pytest.raises(IntegrityError, match="a.txt is listed"):
        io.check_sums(tmp_path)
    with pytest.raises(IntegrityError, match="no SHA256SUMS"):
        io.check_sums(tmp_path / "elsewhere")
    (tmp_path / io.SUMS_FILE).write_text(f"{'0' * 64}  ../outside\n")
    with pytest.raises(IntegrityError, match="not a file name inside"):
        io.read_sums(tmp_path / io.SUMS_FILE)
