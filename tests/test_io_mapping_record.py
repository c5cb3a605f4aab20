"""The checked mapping record (:class:`tiltlab.io.CsvMapping`) and read_csv's call forms."""

from __future__ import annotations

import dataclasses
import inspect
import json

import numpy as np
import pytest

from tiltlab import io

MAPPING = {
    "columns": {"acc": ["ax", "ay", "az"], "gyr": ["gx", "gy", "gz"]},
    "units": {"acc": "g", "gyr": "deg/s"},
    "time_column": "t_ms",
    "time_units": "ms",
    "sep": ";",
    "attrs": {"subject": "rat 3"},
}


def _csv(path, n=120, fs=100.0):
    rng = np.random.default_rng(0)
    acc = np.round(rng.normal(0, 0.01, (n, 3)) + [0, 0, 1], 6)
    gyr = np.round(rng.normal(0, 1, (n, 3)), 6)
    t_ms = np.arange(n) * 1e3 / fs
    rows = ["t_ms;ax;ay;az;gx;gy;gz"] + [
        ";".join(f"{v:.6f}" for v in (t, *a, *g))
        for t, a, g in zip(t_ms, acc, gyr, strict=True)
    ]
    path.write_text("\n".join(rows) + "\n")
    return acc, gyr


def test_check_gives_a_frozen_record_with_defaults():
    m = io.read_csv_mapping(MAPPING)
    assert isinstance(m, io.CsvMapping)
    assert m.columns["gyr"] == ["gx", "gy", "gz"] and m.units["gyr"] == "deg/s"
    assert (m.time_scale, m.time_units) == (1e-3, "ms")
    assert (m.clock, m.gaps, m.max_gap, m.fs) == ("grid", "raise", 5.0, None)
    assert m.fs_range == io.FS_RANGE and m.read_csv == {"sep": ";"}
    assert m.attrs == {"subject": "rat 3"} and m.check_units is True
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.fs = 10.0  # type: ignore[misc]
    # the dict the function returned before: subscripting reads the fields
    assert m["time_scale"] == 1e-3 and m["columns"] is m.columns
    with pytest.raises(KeyError):
        m["nope"]


def test_record_round_trips_through_dict_and_json(tmp_path):
    m = io.CsvMapping.from_dict(
        {**MAPPING, "range": {"acc": 16}, "scale": {"gyr": 2.0}, "fs_range": None}
    )
    raw = m.to_dict()
    assert io.CsvMapping.from_dict(raw) == m
    p = tmp_path / "m.json"
    p.write_text(json.dumps(raw))
    assert io.CsvMapping.load(p) == m == io.CsvMapping.load(m)
    dt = io.CsvMapping.from_dict({**MAPPING, "time_units": "datetime"})
    assert dt.time_scale is None and io.CsvMapping.from_dict(dt.to_dict()) == dt
    no_time = io.CsvMapping.from_dict(
        {"columns": {"acc": ["a", "b", "c"]}, "units": {"acc": "g"}, "fs": 50}
    )
    assert "time_scale" not in no_time.to_dict()
    assert io.CsvMapping.from_dict(no_time.to_dict()) == no_time


def test_record_is_checked_like_a_dict():
    with pytest.raises(ValueError, match=r"gaps must be one of 'raise', 'nan'"):
        io.CsvMapping.from_dict({**MAPPING, "gaps": "drop"})
    with pytest.raises(ValueError, match=r"my file: units must give the unit of 'gyr'"):
        io.CsvMapping.from_dict({**MAPPING, "units": {"acc": "g"}}, "my file: ")


def test_read_csv_takes_the_record_a_dict_or_a_path(tmp_path):
    p = tmp_path / "s.csv"
    acc, gyr = _csv(p)
    m = io.read_csv_mapping(MAPPING)
    mp = tmp_path / "m.json"
    mp.write_text(json.dumps(MAPPING))
    recs = [
        io.read_csv(p, mapping=m),
        io.read_csv(p, mapping=MAPPING),
        io.read_csv(p, mapping=mp),
        io.read_csv(p, m),
        io.read(p, mapping=m),
    ]
    for rec in recs:
        np.testing.assert_array_equal(rec.acc.values, acc)
        np.testing.assert_array_equal(rec.gyr.values, gyr)
        assert rec.attrs["fs"] == 100.0 and rec.attrs["subject"] == "rat 3"
        np.testing.assert_array_equal(rec.time.values, recs[0].time.values)


def test_read_csv_keyword_options_override_the_record(tmp_path):
    p = tmp_path / "s.csv"
    acc, gyr = _csv(p)
    m = io.read_csv_mapping(MAPPING)
    # the time unit given as a keyword replaces the mapping's
    rec = io.read_csv(p, mapping=m, time_scale=1e-3, fs=100.0)
    assert rec.attrs["fs"] == 100.0
    with pytest.raises(ValueError, match="outside the plausible range"):
        io.read_csv(p, mapping=m, time_units="s")
    # fs_range=None disables the plausibility check
    rec = io.read_csv(p, mapping=m, time_units="s", fs_range=None)
    assert rec.attrs["fs"] == pytest.approx(0.1)
    rec = io.read_csv(
        p, mapping=m, range={"acc": 2}, scale={"gyr": 2.0}, attrs={"x": 1}
    )
    np.testing.assert_allclose(rec.gyr.values, 2.0 * gyr)
    assert rec.attrs["csv_scale"] == {"gyr": 2.0} and rec.attrs["x"] == 1
    assert rec.attrs["subject"] == "rat 3"  # attrs are merged
    with pytest.raises(ValueError, match=r"max_gap is in sample periods"):
        io.read_csv(p, mapping=m, clock="resample", max_gap=1.0)


def test_read_csv_takes_at_most_ten_arguments():
    params = inspect.signature(io.read_csv).parameters.values()
    named = [p for p in params if p.kind is not p.VAR_KEYWORD]
    assert len(named) <= 10


def test_read_gap_policies_and_the_old_name():
    assert io.READ_GAP_POLICIES == ("raise", "nan")
    with pytest.warns(FutureWarning, match="READ_GAP_POLICIES"):
        assert io.GAP_POLICIES == io.READ_GAP_POLICIES
    with pytest.raises(AttributeError):
        io.NO_SUCH_NAME  # noqa: B018
