"""The Kalman family's tuning records and the renamed keywords of the filters."""

from __future__ import annotations

import inspect
import warnings

import numpy as np
import pytest

import tiltlab.filters as F
from tiltlab import schema


def _data(n=400, fs=100.0):
    rng = np.random.default_rng(3)
    t = np.arange(n) / fs
    gyr = np.stack([0.3 * np.sin(t), 0.2 * np.cos(0.5 * t), 0.1 * t / t[-1]], 1)
    gyr += 0.01 + 0.002 * rng.standard_normal((n, 3))
    acc = np.tile([0.3, -0.2, 9.8], (n, 1)) + 0.05 * rng.standard_normal((n, 3))
    mag = np.tile([0.0, 20.0, -40.0], (n, 1)) + 0.1 * rng.standard_normal((n, 3))
    return acc, gyr, mag, fs


@pytest.mark.parametrize(
    "func, record",
    [(F.ekf, F.EkfTuning), (F.eskf, F.EskfTuning), (F.rts_smoother, F.RtsTuning)],
)
def test_signature_lists_the_tuning_fields_with_the_record_defaults(func, record):
    sig = inspect.signature(func).parameters
    assert "tuning" not in sig
    for name, default in record._field_defaults.items():
        assert sig[name].kind is inspect.Parameter.KEYWORD_ONLY
        assert sig[name].default == default
    assert func.tuning is record
    method = {"ekf": "ekf", "eskf": "eskf", "rts_smoother": "rts_smoother"}[
        func.__name__
    ]
    assert {k: F.defaults(method)[k] for k in record._fields} == record._field_defaults


def test_tuning_keywords_reach_the_kernel_and_unknown_ones_are_refused():
    acc, gyr, mag, fs = _data()
    a = F.eskf(acc, gyr, fs, mag=mag, acc_noise=0.05)
    b = F.eskf(acc, gyr, fs, mag=mag)
    assert not np.array_equal(a, b)
    assert np.array_equal(b, F.eskf(acc, gyr, fs, mag=mag, **F.EskfTuning()._asdict()))
    with pytest.raises(TypeError, match="tuning"):
        F.ekf(acc, gyr, fs, tuning=F.EkfTuning())
    with pytest.raises(TypeError, match="acc_nois"):
        F.eskf(acc, gyr, fs, acc_nois=0.1)
    with pytest.raises(ValueError, match="var_acc"):
        F.ekf(acc, gyr, fs, var_acc=0.0)
    with pytest.raises(ValueError, match="vel_std"):
        F.rts_smoother(acc, gyr, fs, vel_std=-1.0)


@pytest.mark.parametrize(
    "func, old",
    [
        (F.mahony, "b0"),
        (F.eskf, "b0"),
        (F.rts_smoother, "bias"),
        (F.smoother, "bias"),
    ],
)
def test_old_gyro_offset_keywords_still_work_with_a_warning(func, old):
    acc, gyr, _, fs = _data()
    offset = np.array([0.01, 0.01, 0.01])
    new = func(acc, gyr, fs, gyr_offset=offset)
    with pytest.warns(FutureWarning, match=f"'{old}' was renamed 'gyr_offset'"):
        former = func(acc, gyr, fs, **{old: offset})
    assert np.array_equal(new, former)
    assert not np.array_equal(new, func(acc, gyr, fs))
    with pytest.raises(TypeError, match="gyr_offset"):
        func(acc, gyr, fs, gyr_offset=offset, **{old: offset})


def test_estimate_accepts_the_former_offset_name_and_run_is_an_alias():
    acc, gyr, _, fs = _data()
    rec = schema.make_recording(
        acc, gyr=gyr, fs=fs, acc_units="m/s^2", gyr_units="rad/s"
    )
    offset = [0.01, 0.0, 0.0]
    q = F.estimate(rec, "eskf", gyr_offset=offset)
    with pytest.warns(FutureWarning, match="'b0' was renamed 'gyr_offset'"):
        q_old = F.estimate(rec, "eskf", b0=offset)
    assert np.array_equal(q.values, q_old.values)
    inputs = F.prepare(rec)
    expected = F.run_method("eskf", inputs, gyr_offset=offset)
    assert np.array_equal(expected, q.values)
    with pytest.warns(FutureWarning, match="run was renamed run_method"):
        assert np.array_equal(F.run("eskf", inputs, gyr_offset=offset), expected)
    assert F.ESTIMATE_GAP_POLICIES == ("raise", "segments")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        F.run_method("mahony", inputs)


def test_the_recording_argument_is_rec_and_its_old_name_still_works():
    acc, gyr, _, fs = _data()
    rec = schema.make_recording(
        acc, gyr=gyr, fs=fs, acc_units="m/s^2", gyr_units="rad/s"
    )
    q = F.estimate(rec=rec, method="mahony")
    with pytest.warns(FutureWarning, match="'recording' was renamed 'rec'"):
        q_old = F.estimate(recording=rec, method="mahony")
    assert np.array_equal(q.values, q_old.values)
    with pytest.warns(FutureWarning, match="'recording' was renamed 'rec'"):
        inputs = F.prepare(recording=rec)
    assert np.array_equal(inputs.acc, F.prepare(rec).acc)


def test_madgwick_refuses_a_gradient_step_that_can_cancel_the_quaternion():
    acc, gyr, _, fs = _data()
    with pytest.raises(ValueError, match="beta.*too large"):
        F.madgwick(acc, gyr, 1.0, beta=0.6)
    with pytest.raises(ValueError, match=r"betas\[1\].*too large"):
        F.madgwick_batch(acc, gyr, 1.0, betas=[0.1, 0.6])
    q = F.madgwick(acc, gyr, 1.0, beta=0.5)
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0)
