"""Time gaps and dropouts in the orientation filters: ``_validate.segments`` /
``describe_gaps``, ``filters.estimate(..., gaps=)`` for every registered method, and the
inputs every method refuses (empty, non-finite, all-zero accelerometer)."""

import warnings

import numpy as np
import pytest

from tiltlab import _validate as V
from tiltlab import filters as F
from tiltlab import quaternion as Q
from tiltlab._validate import RecordingError
from tiltlab.filters.registry import get_method
from tiltlab.schema import make_recording

FS = 100.0
#: optional package each adapter needs
NEEDS = {
    "vqf": ("vqf",),
    "offline_vqf": ("vqf",),
    "imufusion": ("imufusion",),
    "riann": ("riann", "onnxruntime"),
    "ahrs_madgwick": ("ahrs",),
    "ahrs_mahony": ("ahrs",),
    "ahrs_ekf": ("ahrs",),
}
MAG_METHODS = [
    n
    for n in F.methods()
    if get_method(n).supports_mag and not get_method(n).requires_mag
]


def _need(method):
    for module in NEEDS.get(method, ()):
        pytest.importorskip(module)


def _segment_s(method):
    """Length of each segment: short for the slow pure-Python ``ahrs`` adapters."""
    return 1.0 if method.startswith("ahrs_") else 2.0


def _motion(n, fs=FS, rate_dps=5.0):
    """A tilted sensor turning slowly about its x axis: acc (g), gyr (°/s), mag (µT)."""
    t = np.arange(n) / fs
    q0 = Q.from_rotvec([0.3, -0.2, 0.0])
    w = np.radians(rate_dps)
    q = Q.mul(q0, Q.from_rotvec(np.stack([w * t, 0 * t, 0 * t], axis=1)))
    acc = Q.gravity(q)
    gyr = np.tile([rate_dps, 0.0, 0.0], (n, 1))
    mag = Q.rotate_inverse(q, np.tile([0.0, 20.0, -40.0], (n, 1)))
    return t, acc, gyr, mag


def _recording(acc, gyr, time, mag=None):
    return make_recording(
        acc,
        gyr,
        FS,
        mag=mag,
        time=time,
        max_jitter=np.inf,
        allow_nan=True,
        acc_units="g",
        gyr_units="deg/s",
        mag_units="uT",
    )


def _gapped(method, mag=False):
    """Two segments with 1 s (100 samples) dropped from the time axis between them."""
    m = int(round(_segment_s(method) * FS))
    t, acc, gyr, mg = _motion(2 * m + 100)
    keep = np.r_[0:m, m + 100 : 2 * m + 100]
    mag = mag or get_method(method).requires_mag
    rec = _recording(acc[keep], gyr[keep], t[keep], mg[keep] if mag else None)
    return rec, [(0, m), (m, 2 * m)]


def _with_nan(method, var="acc", mag=False):
    """A regular time axis with 100 rows of ``var`` (1 s) set to NaN."""
    m = int(round(_segment_s(method) * FS))
    t, acc, gyr, mg = _motion(2 * m + 100)
    data = {"acc": acc, "gyr": gyr, "mag": mg}
    data[var] = data[var].copy()
    data[var][m : m + 100, 1] = np.nan
    mag = mag or get_method(method).requires_mag
    rec = _recording(data["acc"], data["gyr"], t, data["mag"] if mag else None)
    return rec, [(0, m), (m + 100, 2 * m + 100)]


def _estimate_quietly(*args, **kw):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        q = F.estimate(*args, **kw)
    mine = [w for w in caught if "left NaN" in str(w.message)]
    return q, mine


def _check_segments(rec, segs, method, *, use_mag=False):
    """gaps='segments': NaN outside ``segs``, unit quaternions inside, attrs, and each
    segment equal to estimating it as a Recording of its own."""
    n = rec.sizes["time"]
    q, warned = _estimate_quietly(
        rec, method, use_mag=use_mag, gaps="segments", min_segment_s=0.5
    )
    inside = np.zeros(n, dtype=bool)
    for a, b in segs:
        inside[a:b] = True
    assert q.dims == ("time", "quat") and q.shape == (n, 4)
    assert np.array_equal(q.time.values, rec.time.values)
    assert np.all(np.isnan(q.values[~inside]))
    assert np.all(np.isfinite(q.values[inside]))
    assert np.allclose(Q.norm(q.values[inside]), 1.0, atol=1e-6)
    assert q.attrs["n_segments"] == 2 and q.attrs["gaps"] == "segments"
    t = rec.time.values
    expected = [t[i] for a, b in segs for i in (a, b - 1)]
    assert np.allclose(q.attrs["segments"], expected)
    for a, b in segs:
        alone = F.estimate(rec.isel(time=slice(a, b)), method, use_mag=use_mag)
        assert np.allclose(q.values[a:b], alone.values, atol=1e-9)
    return q, warned


# ----------------------------------------------------------------- _validate helpers


def test_segments_split_at_time_jumps_and_non_finite_rows():
    t = np.arange(1000) / FS
    assert V.segments(t, FS) == [(0, 1000)]
    assert V.describe_gaps(t, FS, [(0, 1000)]) == "no gaps"
    dropped = np.delete(t, np.arange(500, 600))
    segs = V.segments(dropped, FS)
    assert segs == [(0, 500), (500, 900)]
    text = V.describe_gaps(dropped, FS, segs)
    assert text.startswith("1 gap: 1.00 s at t = 5.00 s") and "time jump" in text
    x = np.zeros((1000, 9))
    x[:3, 0] = np.nan
    x[500:600, 4] = np.nan
    x[-1, 8] = np.inf
    segs = V.segments(t, FS, values=x)
    assert segs == [(3, 500), (600, 999)]
    text = V.describe_gaps(t, FS, segs)
    assert text.startswith("3 gaps:") and "100 non-finite samples" in text
    assert V.segments(t[:0], FS) == []
    assert "no valid samples" in V.describe_gaps(t, FS, [])


def test_segments_tolerance_and_bad_arguments():
    t = np.array([0.0, 0.01, 0.02, 0.04, 0.05])  # one dropped sample
    assert V.segments(t, FS) == [(0, 3), (3, 5)]
    assert V.segments(t, FS, tolerance=1.5) == [(0, 5)]
    # a short step (jitter, down-sampling residue) is no gap
    assert V.segments([0.0, 0.01, 0.0167, 0.0267], FS) == [(0, 4)]
    with pytest.raises(ValueError, match="fs"):
        V.segments(t, None)
    with pytest.raises(ValueError, match="tolerance"):
        V.segments(t, FS, tolerance=-1)
    with pytest.raises(ValueError, match="values"):
        V.segments(t, FS, values=np.zeros((4, 3)))
    with pytest.raises(RecordingError, match="increasing"):
        V.segments([0.0, 0.02, 0.01], FS)


def test_describe_gaps_lists_a_few_and_counts_the_rest():
    t = np.delete(np.arange(2000) / FS, np.arange(10, 2000, 100))
    segs = V.segments(t, FS)
    text = V.describe_gaps(t, FS, segs, max_items=3)
    assert text.startswith(f"{len(segs) - 1} gaps:")
    assert text.endswith(f"and {len(segs) - 4} more")


# ----------------------------------------------------------------- every method


@pytest.mark.parametrize("method", F.methods())
def test_time_gap_raises_by_default(method):
    _need(method)
    rec, _ = _gapped(method)
    with pytest.raises(RecordingError, match="gap") as err:
        F.estimate(rec, method)
    assert "1.00 s at t = " in str(err.value) and 'gaps="segments"' in str(err.value)


@pytest.mark.parametrize("method", F.methods())
def test_time_gap_segments(method):
    _need(method)
    rec, segs = _gapped(method)
    _, warned = _check_segments(rec, segs, method)
    assert not warned  # a time jump leaves no sample NaN


@pytest.mark.parametrize("method", F.methods())
def test_nan_run_in_acc(method):
    _need(method)
    rec, segs = _with_nan(method, "acc")
    with pytest.raises(RecordingError, match="gap") as err:
        F.estimate(rec, method)
    assert "100 non-finite samples" in str(err.value)
    _, warned = _check_segments(rec, segs, method)
    assert len(warned) == 1 and "100 of" in str(warned[0].message)
    assert issubclass(warned[0].category, RuntimeWarning)


@pytest.mark.parametrize("method", F.methods())
def test_empty_and_all_zero_acc_are_refused_naming_acc(method):
    _need(method)
    m = get_method(method)
    n = int(round(_segment_s(method) * FS))
    gyr = np.zeros((n, 3))
    with pytest.raises(ValueError, match="acc"):
        m(np.zeros((0, 3)), np.zeros((0, 3)), FS)
    with pytest.raises(ValueError, match="acc"):
        m(np.zeros((n, 3)), gyr, FS)
    with pytest.raises(ValueError, match="acc"):
        m(np.full((n, 3), np.nan), gyr, FS)
    rec = make_recording(
        np.zeros((n, 3)),
        gyr,
        FS,
        validate_result=False,
        acc_units="g",
        gyr_units="deg/s",
    )
    with pytest.raises(ValueError, match="acc"):
        F.estimate(rec, method)
    with pytest.raises(ValueError, match="acc"):
        F.estimate(rec, method, gaps="segments")
    empty = make_recording(
        np.zeros((0, 3)),
        np.zeros((0, 3)),
        FS,
        validate_result=False,
        acc_units="g",
        gyr_units="deg/s",
    )
    for gaps in ("raise", "segments"):
        with pytest.raises(ValueError, match="acc"):
            F.estimate(empty, method, gaps=gaps)


@pytest.mark.parametrize("method", F.methods())
def test_bad_gaps_value_is_named(method):
    _need(method)
    rec, _ = _gapped(method)
    for bad in ("skip", None, True):
        with pytest.raises(ValueError, match="gaps"):
            F.estimate(rec, method, gaps=bad)
    with pytest.raises(ValueError, match="min_segment_s"):
        F.estimate(rec, method, gaps="segments", min_segment_s=-1.0)


# ----------------------------------------------------------------- details


@pytest.mark.parametrize("method", MAG_METHODS)
def test_nan_in_mag_matters_only_with_use_mag(method):
    _need(method)
    rec, segs = _with_nan(method, "mag", mag=True)
    F.estimate(rec, method)  # 6D: the magnetometer is not read
    with pytest.raises(RecordingError, match="mag"):
        F.estimate(rec, method, use_mag=True)
    _check_segments(rec, segs, method, use_mag=True)


def test_nan_in_gyr_and_a_short_segment():
    t, acc, gyr, _ = _motion(500)
    gyr = gyr.copy()
    gyr[100:110] = np.nan  # segment [0, 100) is 1 s
    gyr[140:150] = np.nan  # segment [110, 140) is 0.3 s: too short
    rec = _recording(acc, gyr, t)
    with pytest.warns(RuntimeWarning, match=r"50 of 500 samples left NaN") as w:
        q = F.estimate(rec, "madgwick", gaps="segments", beta=0.1)
    assert "1 segment shorter than min_segment_s = 1 s" in str(w[0].message)
    nan = np.isnan(q.values[:, 0])
    assert np.array_equal(np.flatnonzero(nan), np.r_[100:150])
    assert q.attrs["n_segments"] == 2 and q.attrs["param_beta"] == 0.1
    assert np.allclose(q.attrs["segments"], [t[0], t[99], t[150], t[499]])
    alone = F.estimate(rec.isel(time=slice(150, 500)), "madgwick", beta=0.1)
    assert np.allclose(q.values[150:], alone.values)


def test_gap_free_recording_is_unchanged():
    t, acc, gyr, _ = _motion(300)
    rec = _recording(acc, gyr, t)
    q = F.estimate(rec, "mahony")
    assert "n_segments" not in q.attrs and "segments" not in q.attrs
    assert np.array_equal(q.values, F.run_method("mahony", F.prepare(rec)))
    qs, warned = _estimate_quietly(rec, "mahony", gaps="segments")
    assert not warned and qs.attrs["n_segments"] == 1
    assert np.array_equal(qs.values, q.values)


def test_prepare_refuses_nan_unless_allowed():
    rec, _ = _with_nan("madgwick", "acc")
    with pytest.raises(ValueError, match="acc"):
        F.prepare(rec)
    assert np.isnan(F.prepare(rec, allow_nan=True).acc).any()


def test_fs_contradicting_the_time_axis_is_still_refused():
    rec, _ = _gapped("madgwick")
    with pytest.raises(RecordingError, match="fs"):
        F.estimate(rec.assign_attrs(fs=2 * FS), "madgwick", gaps="segments")
