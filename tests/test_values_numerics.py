"""Bad inputs that used to change values silently, break the numerics, repair beyond
reason or give misleading messages: each now gives a defined result or an error that
names the problem.

A. values changed on read (BROAD movement NaN, Fayat counter 1300.5, complex input);
B. numerics (exact rank tests for large n, slerp at antipodes, mean tilt point of a
   symmetric map, bootstrap from one sample);
C. extreme repairs refused (a mostly-NaN regridding, rotation taken for a gyro offset,
   a recording shorter than a learned model's window);
D. messages that name the problem (directory, ``NaN`` text, date-time and millisecond
   time axes, a transposed BROAD ``.mat``, unequal paired samples).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from tiltlab import _validate, calibration, io, quaternion, schema, sphere, stats
from tiltlab._validate import RecordingError
from tiltlab.calibration import CalibrationError
from tiltlab.io import ReadError
from tiltlab.quality import QualityWarning

FS = 100.0


# --------------------------------------------------------------------------- helpers


def _broad_arrays(n: int = 200) -> dict[str, np.ndarray]:
    q = np.zeros((n, 4))
    q[:, 0] = 1.0
    movement = np.zeros(n, bool)
    movement[50:150] = True
    return {
        "imu_acc": np.tile([0.0, 0.0, 9.81], (n, 1)),
        "imu_gyr": np.zeros((n, 3)),
        "imu_mag": np.tile([20.0, 0.0, -40.0], (n, 1)),
        "opt_quat": q,
        "opt_pos": np.zeros((n, 3)),
        "movement": movement,
    }


def _write_broad_hdf5(path: Path, data: dict[str, np.ndarray]) -> Path:
    import h5py

    with h5py.File(path, "w") as f:
        for k, v in data.items():
            f[k] = v
        f.attrs["sampling_rate"] = FS
    return path


def _write_broad_mat(path: Path, data: dict[str, np.ndarray]) -> Path:
    import scipy.io

    scipy.io.savemat(path, {**data, "sampling_rate": np.array([[FS]])})
    return path


def _fayat_csv(path: Path, counter_text: list[str]) -> Path:
    rows = ["counter,ax,ay,az,gx,gy,gz"] + [
        f"{c},0,0,1,0.1,0.2,0.3" for c in counter_text
    ]
    path.write_text("\n".join(rows) + "\n")
    return path


def _csv(path: Path, t: np.ndarray, acc_text=None) -> Path:
    rows = ["t,ax,ay,az"]
    for i, ti in enumerate(t):
        ax = "0" if acc_text is None or i not in acc_text else acc_text[i]
        rows.append(f"{float(ti)!r},{ax},0,1")
    path.write_text("\n".join(rows) + "\n")
    return path


_COLS = {"acc": ["ax", "ay", "az"]}
_UNITS = {"acc": "g"}


# --------------------------------------------------------------------------- A


def test_broad_movement_nan_is_refused_naming_the_rows(tmp_path):
    data = _broad_arrays()
    mv = data["movement"].astype(float)
    mv[[3, 7]] = np.nan
    data["movement"] = mv
    p = _write_broad_hdf5(tmp_path / "nan.hdf5", data)
    with pytest.raises(ReadError, match=r"movement.*2 NaN at rows \[3, 7\]"):
        io.read_broad(p)
    # a flag that is neither 0 nor 1 is refused too, in the .mat layout as well
    data["movement"] = np.where(np.isnan(mv), 2.0, mv).astype(np.uint8)[:, None]
    p = _write_broad_mat(tmp_path / "two.mat", data)
    with pytest.raises(ReadError, match=r"movement.*other than 0/1.*rows \[3, 7\]"):
        io.read_broad(p)


def test_broad_valid_movement_flags_read_as_before(tmp_path):
    data = _broad_arrays()
    rec = io.read_broad(_write_broad_hdf5(tmp_path / "ok.hdf5", data))
    np.testing.assert_array_equal(rec.movement.values, data["movement"])
    mat = dict(data, movement=data["movement"].astype(np.uint8)[:, None])
    back = io.read_broad(_write_broad_mat(tmp_path / "ok.mat", mat))
    assert back.movement.dtype == bool
    np.testing.assert_array_equal(back.movement.values, data["movement"])
    # float 0.0/1.0 flags are exact, hence accepted
    flt = dict(data, movement=data["movement"].astype(float))
    again = io.read_broad(_write_broad_hdf5(tmp_path / "flt.hdf5", flt))
    np.testing.assert_array_equal(again.movement.values, data["movement"])


def test_fayat_fractional_counter_is_refused_naming_the_row(tmp_path):
    counters = [str(3 * k) for k in range(10)]
    good = io.read_fayat_imu(_fayat_csv(tmp_path / "ok.csv", counters))
    assert good.counter.dtype == np.int64
    counters[4] = "1300.5"
    p = _fayat_csv(tmp_path / "bad.csv", counters)
    with pytest.raises(ReadError, match=r"counter.*1300\.5.*data row 4"):
        io.read_fayat_imu(p)


@pytest.mark.parametrize(
    "value", [np.array([[1 + 2j, 0, 0]] * 4), np.array([[1 + 0j, 0, 0]] * 4)]
)
def test_complex_input_is_refused_by_name(value):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning: a clear error instead
        with pytest.raises(ValueError, match=r"gyr holds complex numbers.*gyr\.real"):
            _validate.vectors(value, "gyr")
        with pytest.raises(ValueError, match=r"gyr holds complex numbers"):
            _validate.signal(value, "gyr", fs=FS)
        da = xr.DataArray(value, dims=("time", "axis"), attrs={"fs": FS})
        with pytest.raises(ValueError, match=r"gyr holds complex numbers"):
            _validate.signal(da, "gyr")


def test_real_input_is_unchanged_by_the_complex_check():
    a = [[1, 2, 3], [4.5, 5, 6]]
    np.testing.assert_array_equal(_validate.vectors(a, "x"), np.array(a, dtype=float))
    with pytest.raises(ValueError, match="x must be numeric"):
        _validate.vectors([[1, 2], [3]], "x", width=None, ndim=None)


# --------------------------------------------------------------------------- B


def test_wilcoxon_beyond_the_exact_range_is_asymptotic_not_nan():
    rng = np.random.default_rng(0)
    d = rng.normal(0.1, 1.0, 1100)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow warning, no NaN
        auto = stats.wilcoxon_signed_rank(d, alternative="greater", exact_max_n=5000)
    assert np.isfinite(auto.p) and auto.method == "asymptotic-cc"
    assert "EXACT_MAX_PAIRS" in auto.note and "1100" in auto.note
    with pytest.warns(RuntimeWarning, match="beyond the exact range"):
        exact = stats.wilcoxon_signed_rank(d, alternative="greater", method="exact")
    asym = stats.wilcoxon_signed_rank(d, alternative="greater", method="asymptotic")
    assert exact.p == asym.p and exact.method == asym.method
    assert asym.note == ""
    # inside the range nothing changes
    small = stats.wilcoxon_signed_rank(d[:20], alternative="greater")
    assert small.method == "exact" and small.note == ""


def test_mann_whitney_large_exact_is_finite():
    rng = np.random.default_rng(1)
    x, y = rng.normal(0.2, 1, 700), rng.normal(0, 1, 700)
    with pytest.warns(RuntimeWarning, match="beyond the exact range"):
        r = stats.mann_whitney(x, y, alternative="greater", method="exact")
    assert np.isfinite(r.p) and r.method == "asymptotic-cc"
    assert "EXACT_MAX_CELLS" in r.note
    ref = stats.mann_whitney(x, y, alternative="greater", method="asymptotic")
    assert r.p == ref.p
    # "auto" with a tiny group against a huge one stays exact (counted over the
    # smaller group), and agrees with the same test written the other way round
    big, tiny = rng.normal(0, 1, 3000), rng.normal(1.5, 1, 5)
    a = stats.mann_whitney(big, tiny, alternative="less")
    b = stats.mann_whitney(tiny, big, alternative="greater")
    assert a.method == b.method == "exact" and np.isfinite(a.p)
    assert a.p == pytest.approx(b.p, rel=1e-12)
    tied = np.round(big, 1)
    c = stats.mann_whitney(tied, np.round(tiny, 1), alternative="less")
    d = stats.mann_whitney(np.round(tiny, 1), tied, alternative="greater")
    assert c.method == d.method == "exact-conditional"
    assert c.p == pytest.approx(d.p, rel=1e-9)


def test_quaternion_slerp_shortest_path_and_antipodes():
    q0 = quaternion.random_quaternions(6, 1)
    q1 = quaternion.random_quaternions(6, 2)
    t = np.linspace(0.0, 1.0, 11)[:, None]
    path = quaternion.slerp(q0, q1, t)  # (11, 6, 4)
    assert np.isfinite(path).all()
    np.testing.assert_allclose(path[0], q0, atol=1e-12)
    # the end is the rotation of q1 (q1 or -q1)
    assert np.all(quaternion.total_error(path[-1], q1) < 1e-7)
    # q and -q are one rotation: no motion, never NaN
    same = quaternion.slerp(q0[0], -q0[0], t[:, 0])
    np.testing.assert_allclose(same, np.tile(q0[0], (11, 1)), atol=1e-12)
    # 180° apart (q0 . q1 = 0): the documented positive half-turn, continuous, unit
    a, b = np.array([1.0, 0, 0, 0]), np.array([0.0, 0, 0, 1])
    half = quaternion.slerp(a, b, t[:, 0])
    assert np.isfinite(half).all()
    np.testing.assert_allclose(np.linalg.norm(half, axis=1), 1.0)
    np.testing.assert_allclose(half[5], [np.sqrt(0.5), 0, 0, np.sqrt(0.5)])
    np.testing.assert_allclose(
        quaternion.slerp(a, -b, 0.5), [np.sqrt(0.5), 0, 0, -np.sqrt(0.5)]
    )
    # shortest path: the rotation angle to q0 grows steadily up to at most 180°
    ang = quaternion.total_error(quaternion.slerp(q0[0], q1[0], t[:, 0]), q0[0])
    assert np.all(np.diff(ang) > 0) and ang[-1] <= np.pi
    with pytest.raises(ValueError, match="q1 must hold unit quaternions"):
        quaternion.slerp(a, 2 * b, 0.5)


def test_sphere_slerp_at_antipodes_is_an_error_not_a_jump():
    with pytest.raises(ValueError, match=r"opposite directions.*not unique"):
        sphere.slerp_vectors([0.0, 0, 1], [0.0, 0, -1], np.linspace(0, 1, 5))
    same = sphere.slerp_vectors([0.0, 0, 1], [0.0, 0, 1], np.linspace(0, 1, 5))
    np.testing.assert_allclose(same, np.tile([0.0, 0, 1], (5, 1)))
    g = np.array([[0.0, 0, 1], [0.0, 0, 1], [0.0, 0, -1]])
    with pytest.raises(ValueError, match=r"samples 1 and 2 are opposite"):
        sphere.mkde(g, fs=10.0)


def test_mean_tilt_point_of_a_symmetric_map_raises_like_vmf_fit():
    mesh = sphere.sphere_mesh()
    with pytest.raises(ValueError, match=r"tmap: the map has no mean direction"):
        sphere.mean_tilt_point(np.ones(mesh.n_faces), mesh)
    with pytest.raises(ValueError, match=r"no mean direction"):
        sphere.vmf_fit([[0.0, 0, 1], [0.0, 0, -1]])
    # a Dataset from tilt_map: the same rule, its mesh rebuilt from n_vertices
    x = sphere.fibonacci_lattice(20000)
    tm = sphere.tilt_map(x, mesh=mesh)
    with pytest.raises(ValueError, match=r"no mean direction"):
        sphere.mean_tilt_point(tm)
    # a concentrated map is unaffected
    y = sphere.vmf_sample([0.0, 0.3, 1.0], 20.0, 5000, rng=2)
    fit = sphere.mean_tilt_point(sphere.tilt_map(y, mesh=mesh))
    assert fit.rbar > 0.9 and np.isfinite(fit.mu).all()


def test_vmf_bootstrap_needs_two_samples_or_two_blocks():
    with pytest.raises(
        ValueError, match=r"x has 1 sample: a bootstrap needs at least 2"
    ):
        sphere.vmf_bootstrap([[0.0, 0, 1]], n_boot=10)
    x = sphere.vmf_sample([0.0, 0, 1], 10.0, 100, rng=3)
    with pytest.raises(
        ValueError, match=r"block = 60 samples leaves fewer than 2 blocks"
    ):
        sphere.vmf_bootstrap(x, n_boot=10, block=60)
    w = np.zeros(100)
    w[7] = 5.0
    with pytest.raises(ValueError, match=r"1 direction with non-zero weight"):
        sphere.vmf_bootstrap(x, w, n_boot=10)
    cone = sphere.vmf_bootstrap(x, n_boot=50, block=50, rng=1)
    assert cone.half_angle > 0


# --------------------------------------------------------------------------- C


def test_gaps_nan_refuses_a_mostly_missing_grid_naming_the_jump(tmp_path):
    t = np.arange(1000) / FS
    t[-1] = 20009.99  # one corrupted timestamp: 2 001 000 samples at 100 Hz
    p = _csv(tmp_path / "jump.csv", t)
    with pytest.raises(
        RecordingError,
        match=r"2000000 of 2001000 samples.*99\.95 %.*50 %.*data row 998.*data row 999",
    ):
        io.read_csv(p, _COLS, _UNITS, time_column="t", fs=FS, gaps="nan")
    # the resampling clock refuses it too
    with pytest.raises(
        RecordingError, match=r"more than the 50 % allowed.*data row 998"
    ):
        io.read_csv(
            p, _COLS, _UNITS, time_column="t", fs=FS, gaps="nan", clock="resample"
        )
    # a few dropped samples are still filled with NaN rows
    t2 = np.delete(np.arange(1000) / FS, [100, 101, 500])
    rec = io.read_csv(
        _csv(tmp_path / "few.csv", t2),
        _COLS,
        _UNITS,
        time_column="t",
        fs=FS,
        gaps="nan",
    )
    assert rec.sizes["time"] == 1000 and int(np.isnan(rec.acc[:, 0]).sum()) == 3


def test_robust_gyro_offset_refuses_sustained_rotation():
    rng = np.random.default_rng(5)
    n = 6000
    circling = np.column_stack(
        [rng.normal(0, 0.2, n), rng.normal(0, 0.2, n), 90.0 + rng.normal(0, 0.2, n)]
    )
    rec = schema.make_recording(
        np.tile([0.0, 0.0, 1.0], (n, 1)), circling, FS, acc_units="g", gyr_units="deg/s"
    )
    with pytest.warns(QualityWarning, match=r"rotate steadily at 90 °/s.*sustained"):
        warned = calibration.robust_gyro_offset(rec)
    assert warned[2] == pytest.approx(90.0, abs=0.1)  # returned, but flagged
    with pytest.raises(CalibrationError, match=r"rotate steadily at 90 °/s.*sustained"):
        calibration.robust_gyro_offset(rec, on_rotation="raise")
    with pytest.raises(CalibrationError, match=r"90 °/s"):  # rad/s, converted
        calibration.robust_gyro_offset(
            np.radians(circling), FS, units="rad/s", on_rotation="raise"
        )
    with pytest.warns(QualityWarning, match="max_offset_deg_s"):
        calibration.robust_gyro_offset(circling, FS)  # plain: checked as °/s
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        off = calibration.robust_gyro_offset(circling, FS, max_offset_deg_s=None)
        assert off[2] == pytest.approx(90.0, abs=0.1)
        # a real offset of Fayat's size passes silently
        still = rng.normal(0, 0.2, (n, 3)) + [-22.6, 10.5, 4.0]
        np.testing.assert_allclose(
            calibration.robust_gyro_offset(still, FS), [-22.6, 10.5, 4.0], atol=0.05
        )
    with pytest.raises(ValueError, match="on_rotation"):
        calibration.robust_gyro_offset(still, FS, on_rotation="ignore")


def test_learned_run_refuses_a_recording_shorter_than_the_window():
    torch = pytest.importorskip("torch")
    from tiltlab import learn
    from tiltlab.learn.data import Sequence

    cfg = learn.TrainConfig(window_s=0.128)
    fs = 300.0
    model = learn.build_model(cfg, fs)
    window = cfg.window(fs)  # 38 samples

    def seq(n):
        q = np.zeros((n, 4), np.float32)
        q[:, 0] = 1
        v = np.tile(np.float32([0, 0, 1]), (n, 1))
        return Sequence(q, v, v, q, None, fs, "short")

    with pytest.raises(
        ValueError, match=rf"has {window + 1} samples.*window is {window} samples"
    ):
        learn.closed_loop_estimate(model, seq(window + 1), cfg)
    with torch.no_grad():
        out = learn.closed_loop_estimate(model, seq(window + 2), cfg)
    assert out.shape == (window + 2, 4)


# --------------------------------------------------------------------------- D


def test_a_directory_is_named_as_a_directory(tmp_path):
    d = tmp_path / "trial.hdf5"
    d.mkdir()
    with pytest.raises(ReadError, match="is a directory, not a file"):
        io.read_broad(d)
    with pytest.raises(ReadError, match="is a directory, not a file"):
        io.read_csv(d, _COLS, _UNITS, fs=FS)
    with pytest.raises(ReadError, match="is a directory, not a file"):
        io.read_fayat_imu(d)
    with pytest.raises(ReadError, match="is a directory, not a file"):
        io.read_fayat_tumble(d)
    with pytest.raises(ReadError, match="no such file"):
        io.read_broad(tmp_path / "missing.hdf5")


def test_nan_text_in_a_csv_is_named_as_a_missing_value(tmp_path):
    t = np.arange(20) / FS
    p = _csv(tmp_path / "nan.csv", t, {5: "NaN", 9: "NaN"})
    with pytest.raises(
        ReadError, match=r"missing value 'NaN' in column 'ax', data row 5 \(2 missing"
    ) as err:
        io.read_csv(p, _COLS, _UNITS, fs=FS)
    assert "truncated" not in str(err.value)
    p = _csv(tmp_path / "empty.csv", t, {5: ""})
    with pytest.raises(ReadError, match=r"empty field in column 'ax', data row 5"):
        io.read_csv(p, _COLS, _UNITS, fs=FS)
    p = _csv(tmp_path / "text.csv", t, {5: "abc"})
    with pytest.raises(ReadError, match=r"non-numeric value 'abc'"):
        io.read_csv(p, _COLS, _UNITS, fs=FS)


def _labelled_gyr(time) -> xr.DataArray:
    n = len(time)
    return xr.DataArray(
        np.zeros((n, 3)),
        dims=("time", "axis"),
        coords={"time": time},
        attrs={"fs": FS, "units": "deg/s"},
    )


def test_datetime_time_axis_is_named():
    t = np.datetime64("2024-01-01T00:00:00", "ns") + np.arange(50) * np.timedelta64(
        10, "ms"
    )
    with pytest.raises(
        RecordingError, match=r"holds date-times.*not seconds.*timedelta64"
    ):
        _validate.signal(_labelled_gyr(t), "gyr")
    with pytest.raises(RecordingError, match=r"holds durations"):
        _validate.signal(_labelled_gyr(t - t[0]), "gyr")


def test_time_in_milliseconds_is_named():
    with pytest.raises(
        RecordingError, match=r"looks like milliseconds.*divide it by 1000 "
    ):
        _validate.signal(_labelled_gyr(np.arange(50) * 10.0), "gyr")
    assert _validate.time_unit_hint(0.01, FS) == ""
    assert "microseconds" in _validate.time_unit_hint(1e4, FS)


def test_transposed_broad_mat_is_named(tmp_path):
    data = {k: (v.T if v.ndim == 2 else v[None, :]) for k, v in _broad_arrays().items()}
    data["movement"] = data["movement"].astype(np.uint8)
    p = _write_broad_mat(tmp_path / "t.mat", data)
    with pytest.raises(
        ReadError, match=r"stored transposed.*imu_acc \(3, 200\)"
    ) as err:
        io.read_broad(p)
    assert "4 samples" not in str(err.value)


def test_unequal_paired_samples_are_named():
    with pytest.raises(ValueError, match=r"x and y must be paired.*got 5 and 6"):
        stats.wilcoxon_signed_rank(
            np.arange(5.0), np.arange(6.0), alternative="greater"
        )


def test_null_distributions_beyond_the_exact_range_raise_instead_of_nan():
    with pytest.raises(ValueError, match=r"n = 1100 is beyond the exact range"):
        stats.signed_rank_null_distribution(1100)
    with pytest.raises(ValueError, match=r"n1 = 700 and n2 = 700 are beyond"):
        stats.mwu_null_distribution(700, 700)
    # lopsided groups: counted over the smaller one, same distribution both ways
    a, b = stats.mwu_null_distribution(3000, 3), stats.mwu_null_distribution(3, 3000)
    np.testing.assert_array_equal(a, b)
    assert a.sum() == pytest.approx(1.0)


def test_quaternion_functions_refuse_complex_input_by_name():
    q = np.array([1.0 + 0j, 0, 0, 0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for call, name in [
            (lambda: quaternion.mul(q, q.real), "p"),
            (lambda: quaternion.to_matrix(q), "q"),
            (lambda: quaternion.rotate(q.real, [1j, 0, 0]), "v"),
            (lambda: quaternion.slerp(q.real, q, 0.5), "q1"),
            (lambda: quaternion.tilt_error(q.real, q), "q_ref"),
        ]:
            with pytest.raises(ValueError, match=rf"{name} holds complex numbers"):
                call()


def test_multi_file_regridding_to_mostly_nan_is_refused(tmp_path):
    """One corrupted time stamp per stream (a jump of 1000 s at the end) would make the
    merged grid 99 % NaN: the multi-file reader refuses it, naming the stream."""
    import pandas as pd

    from tiltlab import io

    t = np.arange(500) / 100.0
    t[-1] = 1000.0
    rng = np.random.default_rng(0)
    for name in ("acc", "gyr"):
        base = [0.0, 0.0, 1.0] if name == "acc" else [0.0, 0.0, 0.0]
        v = np.asarray(base) + 0.01 * rng.normal(size=(500, 3))
        pd.DataFrame({"t": t, "x": v[:, 0], "y": v[:, 1], "z": v[:, 2]}).to_csv(
            tmp_path / f"{name}.csv", index=False
        )
    files = {
        v: {
            "path": f"{v}.csv",
            "columns": ["x", "y", "z"],
            "time_column": "t",
            "time_units": "s",
            "units": u,
        }
        for v, u in (("acc", "g"), ("gyr", "deg/s"))
    }
    with pytest.raises(ValueError, match=r"files\['acc'\].*missing"):
        io.read_multi({"files": files, "fs": 100, "gaps": "nan"}, base=tmp_path)


@pytest.mark.parametrize(
    "cell, message", [("NaN", "missing value 'NaN'"), ("", "empty field")]
)
def test_fixed_column_readers_name_missing_text(tmp_path, cell, message):
    """The text NaN in a published data set's CSV is named as a missing value, not as an
    empty field of a truncated file."""
    from tiltlab import io

    lines = ["counter,ax,ay,az,gx,gy,gz"] + [f"{3 * i},0,0,1,0,0,0" for i in range(5)]
    lines[3] = f"6,{cell},0,1,0,0,0"
    (tmp_path / "a.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(io.ReadError, match=f"{message} in column 'ax', data row 2"):
        io.read_fayat_imu(tmp_path / "a.csv")
