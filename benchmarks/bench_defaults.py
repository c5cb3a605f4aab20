"""Do the registry's default parameters hold on data they were not chosen on?

Every method with registry defaults runs with those defaults (6D, no magnetometer) on

* BROAD trials with their optical reference (``q_ref``): inclination RMSE during
  movement, BROAD's definition, mean over the trials;
* simulated rat sessions with ground truth (``tiltlab.simulate``): tilt RMSE against the
  truth, once with the gyroscope offsets removed by a simulated tumble-test calibration
  (the book's pipeline) and once uncalibrated (raw offsets of several °/s);
* recordings with no reference: Fayat et al.'s rat example, and two recordings from
  other projects (a hand-held breadboard, a foot-mounted IMU while walking): the tilt
  disagreement with the offline ``rts_smoother`` (median and 95th percentile, degrees).

Then Mahony's integral gain ``ki`` is swept on the same data, the parameter that the
no-reference recordings single out. The criterion for a default is that it is never far
from the other methods on any of these data sets, not that it is best on one of them.

Last, a scaling section: each of these methods with its defaults on one simulated rat
session cut to 12 s, 2 min and 20 min at 300 Hz (×1, ×10, ×100: 3,600 to 360,000
samples; ``--scaling-max`` sets the largest duration), best of 3 calls (1 for
``rts_smoother``, the slowest), one line per method with its throughput at each size
and the fitted exponent of time ~ n^b (1: linear).

Run: ``python benchmarks/bench_defaults.py [--n-sim 3]`` (about 20 s on 2 cores, plus
about 30 s of scaling). Needs the
BROAD trials and the Fayat example (``TILTLAB_DATA_DIR``); the foreign recordings are
read from ``$TILTLAB_DATA_DIR/foreign`` and skipped with a note when absent.
"""

from __future__ import annotations

import argparse
import datetime
import os
import time
import warnings
from pathlib import Path

import numpy as np

from tiltlab import calibration, datasets, simulate
from tiltlab import evaluate as E
from tiltlab import filters as F
from tiltlab.schema import make_recording

from _scaling_extra import RTS_STEP, note_far, scaling_section

#: methods with tunable registry defaults (the slow pure-Python ``ahrs`` adapters are
#: left out: they mirror that package's own defaults)
TUNED = [
    "lowpass",
    "complementary",
    "madgwick",
    "mahony",
    "ekf",
    "eskf",
    "smoother",
    "rts_smoother",
    "imufusion",
]
#: methods without tiltlab defaults, shown for comparison
OTHERS = ["vqf", "offline_vqf"]
#: the offline reference for recordings without a ground truth
REFERENCE = "rts_smoother"
#: BROAD trials, in three columns: rotation and slow translation; fast translation and
#: combined motion (sustained body accelerations); tapping and vibration (the
#: disturbances that reach a 6D filter)
BROAD_TRIALS = {
    "BROAD rot./slow": [2, 6, 9, 11],
    "BROAD fast trans.": [16, 21],
    "BROAD tap/vibr.": [24, 26],
}
KI_GRID = [0.0, 0.01, 0.03, 0.1, 0.3]
FS_BOARD = 100.0


# ---------------------------------------------------------------- foreign recordings


def _board_arrays(folder: Path) -> tuple[np.ndarray, np.ndarray]:
    """Accelerometer (g, as stored) and gyroscope (deg/s, as stored) of the breadboard
    on a uniform 100 Hz grid, each interpolated linearly on its own timestamps."""
    import h5py

    def read(name: str, var: str) -> np.ndarray:
        with h5py.File(folder / name, "r") as h:
            return np.asarray(h[var][()], float)  # (4, N): t, x, y, z

    a = read("mpu6050_accelerometer.mat", "accelBuffer")
    g = read("mpu6050_gyroscope.mat", "gyroBuffer")
    t0, t1 = max(a[0, 0], g[0, 0]), min(a[0, -1], g[0, -1])
    t = np.arange(t0, t1, 1.0 / FS_BOARD)
    acc = np.column_stack([np.interp(t, a[0], a[i]) for i in (1, 2, 3)])
    gyr = np.column_stack([np.interp(t, g[0], g[i]) for i in (1, 2, 3)])
    return acc, gyr


def gyro_axis_scales(acc, gyr_rad, fs: float, cutoff_hz: float = 2.0) -> np.ndarray:
    r"""Least-squares scale of each gyroscope axis in :math:`\dot g = g \times \omega`
    (:math:`g` the unit specific force, low-passed): +1 for an axis whose sign agrees
    with the accelerometer in a right-handed frame, -1 for a flipped one."""
    from tiltlab import dsp

    a = dsp.lowpass(acc, fs, cutoff_hz)
    g = a / np.linalg.norm(a, axis=1, keepdims=True)
    w = dsp.lowpass(gyr_rad - np.median(gyr_rad, axis=0), fs, cutoff_hz)
    dg = np.gradient(g, 1.0 / fs, axis=0)
    cols = [np.cross(g, np.eye(3)[i] * w[:, i : i + 1]).ravel() for i in range(3)]
    k, *_ = np.linalg.lstsq(np.column_stack(cols), dg.ravel(), rcond=None)
    return k


def load_board(root: Path):
    """The breadboard's two recordings as Recordings (acc sign reversed; gyroscope axes
    whose sign disagrees with the accelerometer flipped, from the moved recording)."""
    folders = {
        "board, moved": root / "roll-and-tilt-at-45-90",
        "board, still": root / "unmoved-with-x-pointing-forward",
    }
    raw = {k: _board_arrays(f) for k, f in folders.items()}
    # the accelerometer reports gravity (-1 g on z when z is up): specific force is -acc
    acc_m, gyr_m = raw["board, moved"]
    k = gyro_axis_scales(-acc_m, np.radians(gyr_m), FS_BOARD)
    sign = np.where(k < 0, -1.0, 1.0)
    print(
        "board gyroscope, per-axis scale against the accelerometer: "
        + ", ".join(f"{a} {v:+.2f}" for a, v in zip("xyz", k))
        + f" -> signs applied {sign.astype(int).tolist()}"
    )
    return {
        name: make_recording(
            -acc, gyr * sign, FS_BOARD, acc_units="g", gyr_units="deg/s"
        )
        for name, (acc, gyr) in raw.items()
    }


def load_foot(root: Path):
    """gaitmap's left foot IMU (204.8 Hz, m/s² and deg/s, gaitmap's foot frame)."""
    import pandas as pd

    df = pd.read_csv(root / "imu_sample.csv", header=[0, 1], index_col=0)
    left = df["left_sensor"]
    acc = left[["acc_x", "acc_y", "acc_z"]].to_numpy(float)
    gyr = left[["gyr_x", "gyr_y", "gyr_z"]].to_numpy(float)
    return make_recording(acc, gyr, 204.8, acc_units="m/s^2", gyr_units="deg/s")


# ---------------------------------------------------------------- simulated rats


def simulated(n: int, duration_s: float, seed: int = 2021):
    """``n`` sessions: (calibrated, raw) pairs with ground truth ``q_ref``."""
    cal_recs, raw_recs = [], []
    for i in range(n):
        rng = np.random.default_rng([seed, i])
        sensor = simulate.draw_sensor(None, rng)
        tumble = simulate.tumble_test(50, 300.0, seed=[seed, i, 1], sensor=sensor)
        cal = calibration.tumble_calibration(tumble).calibration
        rec = simulate.simulate_session(
            duration_s, 300.0, seed=[seed, i, 2], sensor=sensor
        )
        raw_recs.append(rec)
        cal_recs.append(calibration.calibrate(rec, cal))
    return cal_recs, raw_recs


# ---------------------------------------------------------------- scores


def rms(x) -> float:
    x = np.asarray(x, float)
    return float(np.sqrt(np.nanmean(x * x)))


def run(rec, method: str, **params) -> np.ndarray:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        q = F.estimate(rec, method, **params)
    return q.transpose("time", "quat").values


def score_reference(recs, method, kind: str, **params) -> float:
    """Mean over recordings of the tilt RMSE against ``q_ref`` (deg)."""
    out = []
    for rec in recs:
        q = run(rec, method, **params)
        if kind == "broad":
            out.append(E.broad_errors(q, rec)["inclination"])
        else:
            out.append(rms(E.tilt_errors(q, rec["q_ref"].values)))
    return float(np.mean(out))


def score_offline(rec, q_ref, method, **params) -> tuple[float, float]:
    """Median and 95th percentile of the tilt angle to the offline reference (deg)."""
    e = E.tilt_errors(run(rec, method, **params), q_ref)
    return float(np.nanmedian(e)), float(np.nanpercentile(e, 95))


def fmt_params(p: dict) -> str:
    keep = {k: v for k, v in p.items() if k not in ("init_window_s", "max_memory_gb")}
    return ", ".join(
        f"{k}={v:.3g}" if isinstance(v, float) else f"{k}={v}" for k, v in keep.items()
    )


def print_default_scaling(longest_s: float, fs: float = 300.0) -> None:
    """Scaling of each method with its defaults on one simulated session cut to
    ``longest_s`` / 100, / 10 and whole (at ``fs``)."""
    n = int(longest_s * fs)
    sizes = [n // 100, n // 10, n]
    rec = simulate.simulate_session(n / fs, fs, seed=[2021, 99])
    recs = {k: rec.isel(time=slice(0, k)) for k in sizes}
    cases = [
        (m, lambda k, m=m: run(recs[k], m), 1 if m == REFERENCE else 3)
        for m in TUNED + OTHERS
    ]
    exps = scaling_section(
        f"registry defaults, 6D, simulated session at {fs:g} Hz "
        f"({', '.join(f'{k / fs:g} s' for k in sizes)})",
        sizes,
        cases,
    )
    note_far(
        exps,
        f"per-call costs that do not grow with n weigh at {sizes[0]:,} samples "
        "(validating the Recording, the initial orientation from the first "
        "init_window_s, building the output DataArray)",
        high_known={"rts_smoother": RTS_STEP},
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-sim", type=int, default=3)
    ap.add_argument("--sim-duration", type=float, default=120.0)
    ap.add_argument(
        "--scaling-max",
        type=float,
        default=1200.0,
        help="longest recording of the scaling section (s); also /10 and /100",
    )
    args = ap.parse_args()
    t_start = time.perf_counter()
    print(
        f"bench_defaults {datetime.date.today().isoformat()}: tiltlab registry defaults, "
        f"6D, {os.cpu_count()} CPU cores"
    )

    with_ref = {
        f"{name} ({len(ks)})": ([datasets.load(f"broad:{k}") for k in ks], "broad")
        for name, ks in BROAD_TRIALS.items()
    }
    sim_cal, sim_raw = simulated(args.n_sim, args.sim_duration)
    with_ref[f"sim rat cal. ({args.n_sim})"] = (sim_cal, "truth")
    with_ref[f"sim rat raw ({args.n_sim})"] = (sim_raw, "truth")

    no_ref = {"rat (Fayat)": datasets.load("fayat:example")}
    root = datasets.data_dir()
    foreign = None if root is None else Path(root) / "foreign"
    if foreign is not None and (foreign / "board_sunsided").is_dir():
        no_ref.update(load_board(foreign / "board_sunsided"))
    else:
        print("foreign/board_sunsided not found: skipped")
    if foreign is not None and (foreign / "foot_gaitmap").is_dir():
        no_ref["foot (gaitmap)"] = load_foot(foreign / "foot_gaitmap")
    else:
        print("foreign/foot_gaitmap not found: skipped")
    refs = {name: run(rec, REFERENCE) for name, rec in no_ref.items()}

    methods = TUNED + OTHERS
    table: dict[str, dict[str, object]] = {}
    for m in methods:
        row: dict[str, object] = {}
        for name, (recs, kind) in with_ref.items():
            row[name] = score_reference(recs, m, kind)
        for name, rec in no_ref.items():
            row[name] = score_offline(rec, refs[name], m) if m != REFERENCE else None
        table[m] = row

    cols = list(with_ref) + list(no_ref)
    print(
        "\nTilt error with the registry defaults (deg). Columns with a reference: RMSE "
        f"(mean over recordings); without: median / 95th percentile of the angle to "
        f"{REFERENCE}. [ratio] = value / median of the column over the methods shown."
    )
    med = {}
    for c in cols:
        vals = [
            (v if not isinstance(v, tuple) else v[0])
            for v in (table[m][c] for m in methods)
            if v is not None
        ]
        med[c] = float(np.median(vals))
    width = 20
    print(f"{'method':<14}" + "".join(f"{c:>{width}}" for c in cols))
    for m in methods:
        cells = []
        for c in cols:
            v = table[m][c]
            if v is None:
                cells.append(f"{'(reference)':>{width}}")
            elif isinstance(v, tuple):
                cells.append(
                    f"{f'{v[0]:.2f}/{v[1]:.1f} [{v[0] / med[c]:.1f}]':>{width}}"
                )
            else:
                cells.append(f"{f'{v:.2f} [{v / med[c]:.1f}]':>{width}}")
        print(f"{m:<14}" + "".join(cells))
    print("\ndefaults:")
    for m in TUNED:
        print(f"  {m:<14} {fmt_params(F.defaults(m))}")

    kp = F.defaults("mahony")["kp"]
    print(f"\nmahony, kp = {kp:g}, integral gain ki swept (same columns):")
    print(f"{'ki':<14}" + "".join(f"{c:>{width}}" for c in cols))
    for ki in KI_GRID:
        cells = []
        for name, (recs, kind) in with_ref.items():
            cells.append(f"{score_reference(recs, 'mahony', kind, ki=ki):>{width}.2f}")
        for name, rec in no_ref.items():
            a, b = score_offline(rec, refs[name], "mahony", ki=ki)
            cells.append(f"{f'{a:.2f}/{b:.1f}':>{width}}")
        print(f"{ki:<14g}" + "".join(cells))
    t_scaling = time.perf_counter()
    print_default_scaling(args.scaling_max)
    print(
        f"\ntotal {time.perf_counter() - t_start:.0f} s "
        f"(scaling {time.perf_counter() - t_scaling:.0f} s)"
    )


if __name__ == "__main__":
    main()
