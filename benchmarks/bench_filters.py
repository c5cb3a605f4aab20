"""Throughput of tiltlab.filters against the ahrs package, measured in the same run.

Targets: Madgwick (6D and 9D) >= 1000x ahrs on a 1-minute and a 1-hour input (300 Hz);
Madgwick 6D >= 10 M samples/s on one core; EKF >= 1 M samples/s; a 30-value gain grid
over 1 M samples < 5 s on 2 cores; the chosen offline smoother (``filters.smoother``)
>= 1 M samples/s and at least offlineVQF's throughput on the same input. The scaling
section prints each filter's throughput at n/100, n/10 and n samples with the fitted
exponent of time ~ n^b (b = 1: flat throughput).

Run: ``python benchmarks/bench_filters.py [--n 1080000] [--n-ref 20000] [--scaling-max 10000000]``.
"""

from __future__ import annotations

import argparse
import os
import time
import warnings

import numpy as np

from tiltlab import evaluate as E
from tiltlab import filters as F
from tiltlab import quaternion as Q
from tiltlab.schema import make_recording
from _timing import best_of, print_scaling, scaling


def synthetic(n: int, fs: float = 300.0, seed: int = 0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    omega = np.column_stack(
        [1.5 * np.sin(0.7 * t), np.cos(0.4 * t + 1.0), 0.8 * np.sin(0.9 * t + 2.0)]
    )
    q = Q.integrate_gyro(np.vstack([omega[1:], omega[-1:]]), fs, Q.identity())
    acc = 9.81 * Q.gravity(q) + 0.3 * rng.standard_normal((n, 3))
    mag = Q.rotate_inverse(q, [0.0, 20.0, -40.0]) + 0.5 * rng.standard_normal((n, 3))
    gyr = omega + 0.02 * rng.standard_normal((n, 3)) + np.array([0.01, -0.02, 0.005])
    return acc, gyr, mag, q, fs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--n",
        type=int,
        default=1_080_000,
        help="samples for tiltlab kernels (default 1 h at 300 Hz)",
    )
    ap.add_argument(
        "--n-ref",
        type=int,
        default=20_000,
        help="samples for the (slow) ahrs reference",
    )
    ap.add_argument(
        "--grid", type=int, default=30, help="number of gain values in the grid"
    )
    ap.add_argument(
        "--n-offline",
        type=int,
        default=100_000,
        help="samples for the (slow) error-state RTS smoother",
    )
    ap.add_argument(
        "--scaling-max",
        type=int,
        default=0,
        help="also print the native filters' scaling up to this many samples "
        "(e.g. 10000000: 100 k, 1 M and 10 M; about 1 GB of memory)",
    )
    args = ap.parse_args()
    n, n_ref = args.n, args.n_ref

    acc, gyr, mag, q_true, fs = synthetic(n)
    a_r, g_r, m_r = acc[:n_ref], gyr[:n_ref], mag[:n_ref]
    q0 = q_true[0]
    print(
        f"tiltlab.filters benchmark: N = {n:,} samples (ahrs: {n_ref:,}), {os.cpu_count()} CPU cores"
    )

    # warm-up (numba compile / cache load)
    for fn in (F.madgwick, F.mahony, F.ekf, F.complementary):
        fn(acc[:100], gyr[:100], fs, q0=q0)
        fn(acc[:100], gyr[:100], fs, q0=q0, mag=mag[:100])

    try:
        import ahrs.filters as ahrs_filters
    except ImportError:  # pragma: no cover
        ahrs_filters = None

    rows = []
    cases = [
        (
            "madgwick 6D",
            lambda a, g, m: F.madgwick(a, g, fs, beta=0.05, q0=q0),
            lambda a, g, m: ahrs_filters.Madgwick(
                gyr=g, acc=a, frequency=fs, gain=0.05, q0=q0
            ),
        ),
        (
            "madgwick 9D",
            lambda a, g, m: F.madgwick(a, g, fs, mag=m, beta=0.05, q0=q0),
            lambda a, g, m: ahrs_filters.Madgwick(
                gyr=g, acc=a, mag=m, frequency=fs, gain=0.05
            ),
        ),
        (
            "mahony 6D",
            lambda a, g, m: F.mahony(a, g, fs, q0=q0),
            lambda a, g, m: ahrs_filters.Mahony(gyr=g, acc=a, frequency=fs, q0=q0),
        ),
        (
            "ekf 6D",
            lambda a, g, m: F.ekf(a, g, fs, q0=q0),
            lambda a, g, m: ahrs_filters.EKF(
                gyr=g, acc=a, frequency=fs, frame="NED", q0=q0
            ),
        ),
        (
            "ekf 9D",
            lambda a, g, m: F.ekf(a, g, fs, mag=m, dip=63.4, q0=q0),
            lambda a, g, m: ahrs_filters.EKF(
                gyr=g,
                acc=a,
                mag=m,
                frequency=fs,
                frame="NED",
                q0=q0,
                magnetic_ref=np.array([0.0, 0.447, -0.894]),
            ),
        ),
        ("complementary 6D", lambda a, g, m: F.complementary(a, g, fs, q0=q0), None),
    ]
    print(
        f"\n{'method':18s} {'tiltlab (M samples/s)':>22s} {'ahrs (k samples/s)':>19s} {'ratio':>8s}"
    )
    for name, ours, ref in cases:
        t_ours = best_of(lambda: ours(acc, gyr, mag))
        r_ours = n / t_ours
        if ref is not None and ahrs_filters is not None:
            nr = n_ref // 4 if name.startswith("ekf") else n_ref
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t_ref = best_of(lambda: ref(a_r[:nr], g_r[:nr], m_r[:nr]), repeat=1)
            r_ref = nr / t_ref
            print(
                f"{name:18s} {r_ours / 1e6:22.2f} {r_ref / 1e3:19.2f} {r_ours / r_ref:8.0f}x"
            )
        else:
            print(f"{name:18s} {r_ours / 1e6:22.2f} {'-':>19s} {'-':>8s}")
        rows.append((name, r_ours))

    # ---- offline methods (6D): the chosen smoother and offlineVQF on the full input;
    # the error-state RTS smoother (checkpointed backward pass, bounded memory) on at
    # most --n-offline samples to keep this benchmark short
    no = min(n, args.n_offline)
    F.rts_smoother(acc[:200], gyr[:200], fs)  # warm-up
    F.smoother(acc[:2000], gyr[:2000], fs)
    offline = [
        ("smoother 6D", n, lambda k: F.smoother(acc[:k], gyr[:k], fs)),
        ("offlineVQF 6D", n, lambda k: F.run_offline_vqf(acc[:k], gyr[:k], fs)),
        ("rts_smoother 6D", no, lambda k: F.rts_smoother(acc[:k], gyr[:k], fs)),
        (
            "rts forward only",
            no,
            lambda k: F.rts_smoother(acc[:k], gyr[:k], fs, smooth=False),
        ),
    ]
    print("\noffline methods (samples/s):")
    r_off = {}
    for name, k, fn in offline:
        r_off[name] = k / best_of(lambda fn=fn, k=k: fn(k), repeat=2)
        print(f"{name:18s} {r_off[name] / 1e6:10.3f} M/s  (N = {k:,})")
    ratio_sm = r_off["smoother 6D"] / r_off["offlineVQF 6D"]
    peak_mb = peak_allocation_mb(lambda: F.smoother(acc, gyr, fs))
    per_hour_mb = peak_mb * 3600 * fs / n
    print(
        f"smoother peak allocation: {peak_mb:.0f} MB for {n:,} samples "
        f"= {per_hour_mb:.0f} MB per hour at {fs:g} Hz (target <= 500 MB)"
    )
    print(f"smoother / offlineVQF throughput ratio: {ratio_sm:.2f}")
    print(
        "rts_smoother / offlineVQF throughput ratio: "
        f"{r_off['rts_smoother 6D'] / r_off['offlineVQF 6D']:.2f}"
    )

    # ---- gain grid: 30 values over N samples, 2 workers
    betas = np.geomspace(0.002, 0.5, args.grid)
    rec = make_recording(
        acc,
        gyr,
        fs,
        acc_units="m/s^2",
        gyr_units="rad/s",
        q_ref=q_true,
        extra={"movement": (("time",), np.ones(n, bool), {})},
    )
    E.grid_search([rec], "madgwick", {"beta": betas[:2]}, n_jobs=2)  # warm-up
    t0 = time.perf_counter()
    grid = E.grid_search([rec], "madgwick", {"beta": betas}, n_jobs=2)
    t_grid = time.perf_counter() - t0
    print(
        f"\ngrid_search: {args.grid} Madgwick gains x {n:,} samples (scored: tilt RMSE), 2 threads: {t_grid:.2f} s "
        f"(best beta {float(grid.beta[int(grid.argmin('beta').item())]):.3g}, RMSE {float(grid.min()):.3f} deg)"
    )
    F.madgwick_batch(acc[:1000], gyr[:1000], fs, betas=betas[:2], q0=q0)  # warm-up
    import numba

    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
    t0 = time.perf_counter()
    F.madgwick_batch(acc, gyr, fs, betas=betas, q0=q0)
    t_batch = time.perf_counter() - t0
    print(
        f"madgwick_batch (numba prange, 2 threads): {args.grid} gains x {n:,} samples: {t_batch:.2f} s"
    )

    print_native_scaling(acc, gyr, fs, q0, n)
    if args.scaling_max > n:
        acc_l, gyr_l, _, q_l, _ = synthetic(args.scaling_max)
        print_native_scaling(acc_l, gyr_l, fs, q_l[0], args.scaling_max)
        del acc_l, gyr_l, q_l
    print_offline_scaling(acc, gyr, fs, n, no)
    mad_ratio = print_duration_ratios(acc, gyr, mag, fs, q0, a_r, g_r, m_r)

    print("\ntargets:")
    for label, r in mad_ratio.items():
        print(f"  {label} >= 1000x ahrs: {r:.0f}x -> {'OK' if r >= 1000 else 'MISSED'}")
    sm = r_off["smoother 6D"]
    print(
        f"  smoother >= 1 M samples/s and >= offlineVQF: {sm / 1e6:.2f} M/s, "
        f"{ratio_sm:.2f}x offlineVQF -> {'OK' if sm >= 1e6 and ratio_sm >= 1 else 'MISSED'}"
    )
    mad = dict(rows)["madgwick 6D"]
    ekf = dict(rows)["ekf 6D"]
    print(
        f"  Madgwick 6D >= 10 M samples/s: {mad / 1e6:.1f} M/s -> {'OK' if mad >= 1e7 else 'MISSED'}"
    )
    print(
        f"  EKF 6D >= 1 M samples/s: {ekf / 1e6:.2f} M/s -> {'OK' if ekf >= 1e6 else 'MISSED'}"
    )
    print(
        f"  30-gain grid over 1 M samples < 5 s: {t_grid:.2f} s (grid_search), {t_batch:.2f} s (batch) -> "
        f"{'OK' if min(t_grid, t_batch) < 5 else 'MISSED'}"
    )


def print_native_scaling(acc, gyr, fs, q0, n: int) -> None:
    """Print the native filters' throughput at n/100, n/10 and n samples.

    Each line ends with the fitted exponent (flat throughput: time ~ n^1).
    """
    sizes = [max(1000, n // 100), max(10_000, n // 10), n]
    print(f"\nscaling (samples: {', '.join(f'{s:,}' for s in sizes)}):")
    for name, fn in (
        ("madgwick 6D", lambda k: F.madgwick(acc[:k], gyr[:k], fs, beta=0.05, q0=q0)),
        ("mahony 6D", lambda k: F.mahony(acc[:k], gyr[:k], fs, q0=q0)),
        ("complementary 6D", lambda k: F.complementary(acc[:k], gyr[:k], fs, q0=q0)),
        ("ekf 6D", lambda k: F.ekf(acc[:k], gyr[:k], fs, q0=q0)),
        ("eskf 6D", lambda k: F.eskf(acc[:k], gyr[:k], fs, q0=q0)),
    ):
        times, b = scaling(fn, sizes)
        print_scaling(name, sizes, times, b)


def peak_allocation_mb(fn) -> float:
    """Return the peak memory (MB) that ``fn()`` allocates through Python/NumPy."""
    import tracemalloc

    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1] / 1e6
    finally:
        tracemalloc.stop()


def print_offline_scaling(acc, gyr, fs, n: int, n_rts: int) -> None:
    """Print the offline methods' throughput at three sizes with the fitted exponent."""
    for name, top, fn in (
        ("smoother 6D", n, lambda k: F.smoother(acc[:k], gyr[:k], fs)),
        ("offlineVQF 6D", n, lambda k: F.run_offline_vqf(acc[:k], gyr[:k], fs)),
        ("rts_smoother 6D", n_rts, lambda k: F.rts_smoother(acc[:k], gyr[:k], fs)),
    ):
        sizes = [max(1000, top // 100), max(10_000, top // 10), top]
        times, b = scaling(fn, sizes, repeat=2)
        print_scaling(name, sizes, times, b)


def print_duration_ratios(acc, gyr, mag, fs, q0, a_r, g_r, m_r) -> dict[str, float]:
    """Print and return Madgwick's speed-up over ahrs on a 1-minute and a 1-hour input.

    ahrs costs the same per sample at any length (pure Python), so its rate is measured
    once on ``a_r``; ours is timed on the first minute and on the first hour (or all of
    ``acc`` when shorter), whole calls included.
    """
    out: dict[str, float] = {}
    try:
        import ahrs.filters as ahrs_filters
    except ImportError:  # pragma: no cover
        return out
    print(f"\nMadgwick against ahrs by input length (fs = {fs:g} Hz):")
    for dim, m, m_r_ in (("6D", None, None), ("9D", mag, m_r)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t_ref = best_of(
                lambda: ahrs_filters.Madgwick(
                    gyr=g_r, acc=a_r, mag=m_r_, frequency=fs, gain=0.05, q0=q0
                ),
                repeat=1,
            )
        r_ref = len(a_r) / t_ref
        for label, k in (("1 min", int(60 * fs)), ("1 h", int(3600 * fs))):
            k = min(k, len(acc))
            mk = None if m is None else m[:k]
            t = best_of(
                lambda k=k, mk=mk: F.madgwick(
                    acc[:k], gyr[:k], fs, mag=mk, beta=0.05, q0=q0
                ),
                repeat=5,
            )
            ratio = k / t / r_ref
            out[f"madgwick {dim} {label}"] = ratio
            print(
                f"  {dim} {label:5s} ({k:,} samples): {k / t / 1e6:6.2f} M/s, "
                f"ahrs {r_ref / 1e3:.1f} k/s -> {ratio:.0f}x"
            )
    return out


if __name__ == "__main__":
    main()
