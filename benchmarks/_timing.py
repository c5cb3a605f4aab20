"""Timing helper shared by the benchmark scripts (run as ``python benchmarks/bench_*.py``)."""

import time


def best_of(fn, repeat: int = 3, *, warmup: bool = False) -> float:
    """Best wall time (s) of ``repeat`` calls of ``fn()``; with ``warmup``, one untimed call first
    (numba compilation, caches)."""
    if warmup:
        fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def scaling(fn, sizes, repeat: int = 3) -> tuple[list[float], float]:
    """Time ``fn(n)`` at each size (best of ``repeat``, one untimed warm-up at the
    smallest) and fit the exponent ``b`` of ``time ~ n**b`` by least squares on logs.

    Returns the times (s) and ``b``: 1 is linear, below 1 means fixed costs still
    weigh at the small sizes, above 1 that the work per sample grows with ``n``.
    """
    import numpy as np

    fn(sizes[0])
    times = [best_of(lambda: fn(n), repeat) for n in sizes]
    b = float(np.polyfit(np.log(sizes), np.log(times), 1)[0])
    return times, b


def print_scaling(name: str, sizes, times, exponent: float) -> None:
    """Print one line: throughput at each size and the fitted exponent."""
    rates = ", ".join(
        f"{n:,}: {n / t / 1e6:.3g} M/s" for n, t in zip(sizes, times, strict=True)
    )
    print(f"{name:18s} {rates}; time ~ n^{exponent:.2f}")
