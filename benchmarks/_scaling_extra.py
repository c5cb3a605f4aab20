"""Scaling helpers on top of ``_timing`` for the benchmark scripts.

``_timing.scaling`` times one function at each size; the scripts here also need the
fitted exponent of times measured elsewhere (``fit_exponent``: bench_scale may take
its largest point from its main table), a header and one line per operation
(``scaling_section``, ``print_line``), and a note when an exponent is far from 1
(``note_far``).
"""

from __future__ import annotations

import numpy as np

from _timing import print_scaling, scaling

#: exponents outside this band get a note (fixed costs, or work per sample growing)
LOW, HIGH = 0.9, 1.1

#: why rts_smoother's exponent can exceed 1 (a step, not a growth)
RTS_STEP = (
    "a step, not a growth: recordings of more than 2**14 + 1 samples are smoothed in "
    "checkpointed blocks, whose backward pass reruns the forward filter over each "
    "block (one more forward pass: about 1.5 x the time of a single block); the time per "
    "sample is flat above that length"
)


def ladder(n: int) -> list[int]:
    """Three sizes in ratio ×1, ×10, ×100, the largest at most ``n`` ≥ 100 (n/100, n/10
    and n when 100 divides ``n``)."""
    first = max(1, n // 100)
    return [first, 10 * first, 100 * first]


def fit_exponent(sizes, times) -> float:
    """Fit the exponent ``b`` of ``time ~ n**b`` by least squares on logs (as
    ``_timing.scaling`` does)."""
    return float(np.polyfit(np.log(sizes), np.log(times), 1)[0])


def scaling_section(title: str, sizes, cases, repeat: int = 3) -> dict[str, float]:
    """Print a header, then time each ``(name, fn)`` or ``(name, fn, repeat)`` of
    ``cases`` (``repeat`` for that case only: slow ones) with ``fn(n)`` at each size
    (``_timing.scaling``) and print its line (``print_line``); returns the exponents
    by name."""
    print(f"\nscaling, {title} (sizes: {', '.join(f'{s:,}' for s in sizes)}):")
    out = {}
    for name, fn, *rep in cases:
        times, b = scaling(fn, sizes, rep[0] if rep else repeat)
        print_line(name, sizes, times, b)
        out[name] = b
    return out


def print_line(name: str, sizes, times, exponent: float) -> None:
    """Print ``_timing.print_scaling``'s line (rates to three significant figures)."""
    print_scaling(name, sizes, times, exponent)


def note_far(
    exponents: dict[str, float],
    low_why: str,
    high_why: str = "",
    high_known: dict[str, str] | None = None,
) -> None:
    """Print a note naming the exponents outside [LOW, HIGH] and the reason given;
    ``high_known`` maps a name prefix to its own reason for an exponent above HIGH."""
    shown = {k: round(b, 2) for k, b in exponents.items()}  # as printed
    known = {
        k: next(w for p, w in (high_known or {}).items() if k.startswith(p))
        for k, b in shown.items()
        if b > HIGH and any(k.startswith(p) for p in high_known or {})
    }
    low = [f"{k} ({b:.2f})" for k, b in shown.items() if b < LOW]
    high = [f"{k} ({b:.2f})" for k, b in shown.items() if b > HIGH and k not in known]
    if low:
        print(f"note: exponent below {LOW:g} for {', '.join(low)}: {low_why}")
    if high:
        why = high_why or (
            "either the work per sample grows with n or the largest size left the "
            "CPU caches; on a shared machine, check that it repeats"
        )
        print(f"note: exponent above {HIGH:g} for {', '.join(high)}: {why}")
    for k, why in known.items():
        print(f"note: exponent above {HIGH:g} for {k} ({shown[k]:.2f}): {why}")
