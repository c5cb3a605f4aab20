"""Cohort workers run one session per core: no thread pools, no malloc trimming.

Dask's Nanny sets ``MALLOC_TRIM_THRESHOLD_=65536`` in its workers (and in the process
that starts them), which doubled a worker's CPU time per session; numba's and BLAS's
own threads in two workers on two cores only compete for them. These tests check the
workers' set-up, not their speed (speed is measured in ``benchmarks/bench_cohort.py``).
"""

from __future__ import annotations

import os
import threading

import numba
import numpy as np
import pytest

from tiltlab import cohort
from tiltlab.cohort import run as cohort_run
from tiltlab.cohort.schedulers import backend, run_in_worker
from tiltlab.simulate import CohortDesign, simulate_cohort


def _worker_setup() -> tuple[str | None, int, int]:
    return os.getenv("MALLOC_TRIM_THRESHOLD_"), numba.get_num_threads(), os.getpid()


@pytest.mark.parametrize("scheduler", ["processes", "dask"])
def test_workers_run_on_one_thread_without_malloc_trimming(scheduler):
    before = dict(os.environ)
    b = backend(scheduler, 1)
    try:
        trim, threads, pid = b.submit(_worker_setup).result()
    finally:
        b.close()
    assert pid != os.getpid()
    assert trim is None
    assert threads == 1
    # the parent's environment is left as it was (the Nanny writes into it)
    assert dict(os.environ) == before


def test_run_in_worker_limits_only_the_calling_thread():
    main_threads = numba.get_num_threads()
    seen = {}

    def task():
        seen["value"] = run_in_worker(np.add, 2, 3)
        seen["threads"] = numba.get_num_threads()

    t = threading.Thread(target=task)
    t.start()
    t.join()
    assert seen == {"value": 5, "threads": 1}
    assert numba.get_num_threads() == main_threads


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    design = CohortDesign().select(
        groups={"Healthy": 1, "Kainate": 1}, time_points=("baseline", "1d")
    )
    return simulate_cohort(
        tmp_path_factory.mktemp("speed") / "sim",
        design=design,
        duration_s=30.0,
        fs=100.0,
        seed=7,
        workers=1,
        progress=False,
    )


def test_a_fully_cached_rerun_starts_no_workers(small, tmp_path, monkeypatch):
    first = cohort.run_cohort(
        small / "manifest.csv", cache_dir=tmp_path, progress=False
    )
    assert first.attrs["n_computed"] == 4

    def refuse(*args, **kwargs):
        raise AssertionError("a back end was started for cached sessions")

    monkeypatch.setattr(cohort_run, "_backend", refuse)
    again = cohort.run_cohort(
        small / "manifest.csv",
        scheduler="dask",
        workers=2,
        cache_dir=tmp_path,
        progress=False,
    )
    assert (again.attrs["n_computed"], again.attrs["n_cached"]) == (0, 4)
    for name in cohort.feature_specs(cohort.FeatureConfig()):
        np.testing.assert_array_equal(again[name].values, first[name].values)


def test_sessions_are_submitted_while_the_manifest_is_still_read(
    small, tmp_path, monkeypatch
):
    """The first task goes out before the last session's file is hashed."""
    order = []
    real_key, real_backend = cohort_run.cache_key, cohort_run._backend

    def key(row, *args, **kwargs):
        order.append(("hash", row["session"]))
        return real_key(row, *args, **kwargs)

    class Recorder:
        def __init__(self, inner):
            self.inner, self.name = inner, inner.name

        def submit(self, fn, row, *args):
            order.append(("submit", row["session"]))
            return self.inner.submit(fn, row, *args)

        def as_completed(self, futures):
            return self.inner.as_completed(futures)

        def close(self):
            self.inner.close()

    monkeypatch.setattr(cohort_run, "cache_key", key)
    monkeypatch.setattr(cohort_run, "_backend", lambda *a: Recorder(real_backend(*a)))
    ds = cohort.run_cohort(small / "manifest.csv", cache_dir=tmp_path, progress=False)
    assert int(ds.attrs["n_ok"]) == 4
    sessions = [s for what, s in order if what == "hash"]
    assert order[:2] == [("hash", sessions[0]), ("submit", sessions[0])]
    assert order.index(("submit", sessions[0])) < order.index(("hash", sessions[-1]))
