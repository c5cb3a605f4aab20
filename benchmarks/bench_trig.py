"""Throughput of tiltlab.trig conversions and formulas vs scipy's Rotation on the same inputs
(and of tiltlab.behavior's DBA).

Run: ``python benchmarks/bench_trig.py [n]``. Prints samples/s and ratios (no assertions).
"""

from __future__ import annotations

import sys

import numpy as np
from scipy.spatial.transform import Rotation

import tiltlab.behavior as behavior
import tiltlab.trig as trig
from _timing import best_of as _best_of


def best_of(fn, repeat: int = 5) -> float:
    return _best_of(fn, repeat)


def main(n: int = 1_000_000) -> None:
    rng = np.random.default_rng(0)
    th, ph, la = (
        rng.uniform(-np.pi, np.pi, n),
        rng.uniform(-1.5, 1.5, n),
        rng.uniform(-np.pi, np.pi, n),
    )
    q = trig.angles_to_quaternion(th, ph, la)
    rot = Rotation.from_quat(q, scalar_first=True)
    f, m = trig.acc_from_angles(ph, la), trig.mag_from_angles(th, ph, la)
    eul = np.column_stack([th, -ph, la])
    rows = [
        (
            "angles -> quaternion",
            best_of(lambda: trig.angles_to_quaternion(th, ph, la)),
            best_of(lambda: Rotation.from_euler("ZYX", eul).as_quat(scalar_first=True)),
        ),
        (
            "quaternion -> angles",
            best_of(lambda: trig.angles_from_quaternion(q)),
            best_of(lambda: rot.as_euler("ZYX")),
        ),
        ("heading (Eqs. 3, 5) from acc+mag", best_of(lambda: trig.heading(f, m)), None),
        (
            "arc (Eq. 7)",
            best_of(lambda: trig.arc(th, ph, np.roll(th, 1), np.roll(ph, 1))),
            None,
        ),
        (
            "Eq. 11 + Eqs. 12-13",
            best_of(
                lambda: trig.azimuth_change(
                    ph, la, ph, la, *trig.simultaneous_rotations(ph, la, th)
                )
            ),
            None,
        ),
    ]
    print(f"n = {n:,} samples")
    for name, t, t_ref in rows:
        line = f"{name:36s} {n / t / 1e6:8.2f} M samples/s"
        if t_ref is not None:
            line += f"   scipy {n / t_ref / 1e6:8.2f} M/s   ratio tiltlab/scipy speed = {t_ref / t:5.2f}"
        print(line)
    acc = rng.normal(size=(n, 3))
    t = best_of(lambda: behavior.dba(acc, 100.0, window_s=1.0), 3)
    print(f"{'DBA (sliding 1 s window @100 Hz)':36s} {n / t / 1e6:8.2f} M samples/s")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000)
