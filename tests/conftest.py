"""Shared fixtures.

Real-data tests need the reference data: a local mirror named by TILTLAB_DATA_DIR, or
internet access. Without either they are skipped, unless TILTLAB_REQUIRE_DATA=1 (set by
.ci/run), in which case missing data is a failure.
"""

import os
from pathlib import Path

import pytest

import tiltlab.datasets as datasets


def _data_ready() -> tuple[bool, str]:
    mirror = datasets.data_dir()
    if mirror is None:
        return False, "TILTLAB_DATA_DIR is not set (no local data mirror)"
    if not (mirror / "MANIFEST.json").is_file():
        return False, f"{mirror} has no MANIFEST.json"
    return True, ""


@pytest.fixture(scope="session")
def data_mirror() -> Path:
    ok, why = _data_ready()
    if not ok:
        if os.environ.get("TILTLAB_REQUIRE_DATA", "") not in ("", "0"):
            pytest.fail(f"real data required but unavailable: {why}")
        pytest.skip(why)
    return datasets.data_dir()


@pytest.fixture(scope="session")
def foreign(data_mirror) -> Path:
    """The mirror's recordings from other labs (``foreign/``), in their own formats."""
    path = data_mirror / "foreign"
    if not path.is_dir():
        why = f"{path} is missing (the foreign recordings)"
        if os.environ.get("TILTLAB_REQUIRE_DATA", "") not in ("", "0"):
            pytest.fail(f"real data required but unavailable: {why}")
        pytest.skip(why)
    return path
