"""Tests of the RIANN adapter (tiltlab.filters.adapters.run_riann, method "riann"):
convention, output form, static convergence, 6D-only inputs, the registry, and its
accuracy on BROAD trial 2."""

import numpy as np
import pytest

pytest.importorskip("riann")

from tiltlab import evaluate as E  # noqa: E402
from tiltlab import filters as F  # noqa: E402
from tiltlab import quaternion as Q  # noqa: E402
from tiltlab.filters import adapters  # noqa: E402
from tiltlab.filters.adapters import run_riann  # noqa: E402
from tiltlab.schema import make_recording  # noqa: E402

FS = 100.0


def _static(tilt_deg=30.0, seconds=10.0, fs=FS):
    """A sensor at rest tilted by ``tilt_deg`` about x: constant acc, zero gyro."""
    n = int(round(seconds * fs))
    q_true = Q.from_rotvec([np.radians(tilt_deg), 0.0, 0.0])  # sensor → world
    a = 9.81 * Q.gravity(q_true)  # at rest the specific force points up
    return np.tile(a, (n, 1)), np.zeros((n, 3)), a


def test_output_is_float64_unit_quaternions():
    acc, gyr, _ = _static(seconds=2.0)
    q = run_riann(acc, gyr, FS)
    assert q.shape == (acc.shape[0], 4) and q.dtype == np.float64
    assert np.all(np.isfinite(q))
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)


def test_static_tilt_converges_to_the_accelerometer_direction():
    acc, gyr, a = _static(tilt_deg=30.0, seconds=10.0)
    assert np.degrees(Q.angle_between(a, [0.0, 0.0, 1.0])) == pytest.approx(30.0)
    q = run_riann(acc, gyr, FS)
    err = np.degrees(Q.angle_between(Q.gravity(q[-1]), a / np.linalg.norm(a)))
    assert err < 1.0


def test_threads_change_the_speed_not_the_numbers():
    acc, gyr, _ = _static(seconds=3.0)
    acc = acc + np.random.default_rng(1).normal(0.0, 0.2, acc.shape)
    assert np.array_equal(run_riann(acc, gyr, FS, threads=1), run_riann(acc, gyr, FS))
    with pytest.raises(ValueError, match="threads"):
        run_riann(acc, gyr, FS, threads=0)


def test_mag_is_refused_6d_only():
    acc, gyr, _ = _static(seconds=1.0)
    with pytest.raises(ValueError, match="mag"):
        run_riann(acc, gyr, FS, mag=np.ones_like(acc))
    assert not F.METHODS["riann"].supports_mag


def test_estimate_without_mag_and_use_mag_refused():
    acc, gyr, _ = _static(seconds=2.0)
    rec = make_recording(
        acc,
        gyr,
        FS,
        acc_units="m/s^2",
        gyr_units="rad/s",
        mag=np.ones_like(acc),
        mag_units="uT",
    )
    q = F.estimate(rec, "riann")  # the Recording's mag is not passed
    assert q.dims == ("time", "quat") and q.attrs["use_mag"] == 0
    assert np.array_equal(q.values, run_riann(acc, gyr, FS))
    with pytest.raises(ValueError, match="magnetometer"):
        F.estimate(rec, "riann", use_mag=True)


def test_bad_fs_is_named():
    acc, gyr, _ = _static(seconds=1.0)
    for fs in (0, -1.0, None, float("nan")):
        with pytest.raises(ValueError, match="fs"):
            run_riann(acc, gyr, fs)


def test_registry_lists_riann_as_an_adapter():
    assert "riann" in F.methods() and "riann" in F.methods("adapter")
    m = F.get_method("riann")
    assert m.kind == "adapter" and m.function is run_riann
    assert m.defaults == {"threads": None} and m.uses_gyr  # threads: speed only


@pytest.fixture(scope="module")
def broad2(data_mirror):
    from tiltlab.datasets import load

    return load("broad:2")


@pytest.mark.realdata
def test_broad_trial_2_inclination(broad2):
    # BROAD trial 2 has a magnetometer; estimate() leaves it out (RIANN is 6D)
    q = F.estimate(broad2, "riann")
    assert q.attrs["method"] == "riann" and q.attrs["use_mag"] == 0
    e = E.broad_errors(q, broad2)
    # observed: 0.63° RMSE (Madgwick β=0.02 about 0.6°, VQF 0.43°)
    assert np.isfinite(e["inclination"]) and e["inclination"] < 2.0
    assert e["n"] > 0


def test_chunked_run_equals_one_call(monkeypatch):
    """Feeding the network in chunks with the state carried over gives exactly the
    numbers of one call over the whole sequence (memory bounded for long recordings)."""
    rng = np.random.default_rng(5)
    n = 2500
    acc = np.tile([0.0, 3.0, 9.3], (n, 1)) + 0.2 * rng.normal(size=(n, 3))
    gyr = 0.3 * rng.normal(size=(n, 3))
    whole = adapters.run_riann(acc, gyr, 200.0)
    monkeypatch.setattr(adapters, "RIANN_CHUNK", 700)
    chunked = adapters.run_riann(acc, gyr, 200.0)
    assert np.array_equal(whole, chunked)
