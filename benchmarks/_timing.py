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
