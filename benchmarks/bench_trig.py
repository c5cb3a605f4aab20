"""Throughput of tiltlab.trig conversions and formulas vs scipy's Rotation on the same inputs
(and of tiltlab.behavior's DBA).

Then a scaling section: each tiltlab operation above at n/100, n/10 and n samples
(×1, ×10, ×100), its throughput at each size and the fitted exponent of time ~ n^b
(1: linear).

Run: ``python benchmarks/bench_trig.py [n]``. Prints samples/s and ratios (no assertions).
"""

from __future__ import annotations

import sys

import numpy as np
from scipy.spatial.transform import Rotation

import tiltlab.behavior as behavior
import tiltlab.trig as trig
from _scaling_extra import ladder, note_far, scaling_section
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
    print_trig_scaling(th, ph, la, q, f, m, acc, n)


def print_trig_scaling(th, ph, la, q, f, m, acc, n: int) -> None:
    """Scaling of the tiltlab operations on the first n/100, n/10 and n samples."""
    th1, ph1 = np.roll(th, 1), np.roll(ph, 1)

    def eqs_11_13(k):
        p, lam, t = ph[:k], la[:k], th[:k]
        return trig.azimuth_change(
            p, lam, p, lam, *trig.simultaneous_rotations(p, lam, t)
        )

    cases = [
        (
            "angles->quaternion",
            lambda k: trig.angles_to_quaternion(th[:k], ph[:k], la[:k]),
        ),
        ("quaternion->angles", lambda k: trig.angles_from_quaternion(q[:k])),
        ("heading", lambda k: trig.heading(f[:k], m[:k])),
        ("arc", lambda k: trig.arc(th[:k], ph[:k], th1[:k], ph1[:k])),
        ("Eqs. 11-13", eqs_11_13),
        ("DBA", lambda k: behavior.dba(acc[:k], 100.0, window_s=1.0)),
    ]
    exps = scaling_section("tiltlab.trig and DBA", ladder(n), cases)
    note_far(
        exps,
        "per-call costs (argument checks, allocation) still weigh at the smallest "
        "size, where a call takes tens of microseconds",
        "a step, not a growth: at the largest size the rotation matrix and the "
        "other temporaries (tens of MB) no longer fit the CPU's last-level cache and "
        "the pass is bound by "
        "memory bandwidth, which other running programs share; the work per sample "
        "does not grow (throughput is flat beyond that step)",
    )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000)
