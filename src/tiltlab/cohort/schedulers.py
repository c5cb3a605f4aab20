"""Schedulers for :func:`tiltlab.cohort.run_cohort`: one interface, three back ends.

Every back end offers ``submit(fn, *args)`` → a future with ``result()``,
``as_completed(futures)`` → the futures in completion order, and ``close()``:

* serial — tasks run in this process, one by one, when collected;
* processes — a :class:`concurrent.futures.ProcessPoolExecutor` whose workers are
  started with ``spawn`` (a script that runs a cohort on processes therefore needs the
  usual ``if __name__ == "__main__":`` guard) and end with their parent, even when it
  is killed (:func:`exit_with_parent`);
* dask — a ``dask.distributed`` client: a ``LocalCluster`` started here
  (``"dask"``), an existing scheduler (an address ``"tcp://…"``) or a given
  ``distributed.Client``.

:func:`run_cohort` uses only these three calls, so a session's task is the same
whatever runs it.

A worker process runs one session at a time on one core: its numba kernels and BLAS
run on one thread (:func:`run_in_worker`), since two workers already fill two cores
and a second thread per worker only oversubscribes them (OpenBLAS and OpenMP threads
that spin while they wait took about a fifth of a worker's CPU time).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
import time
import uuid
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures import as_completed as _cf_as_completed

__all__ = ["backend"]


class _Lazy:
    """A task run when its result is first asked for (serial scheduler)."""

    def __init__(self, fn: Callable, args: tuple):
        self.fn, self.args, self._done, self._value = fn, args, False, None

    def result(self):
        if not self._done:
            self._value, self._done = self.fn(*self.args), True
        return self._value


class _Serial:
    name = "serial"

    def submit(self, fn, *args):
        return _Lazy(fn, args)

    def as_completed(self, futures: Iterable) -> Iterator:
        for f in futures:
            f.result()
            yield f

    def close(self):
        pass


def exit_with_parent(parent: int, poll_s: float = 1.0) -> None:
    """End this (worker) process when ``parent`` dies, even by SIGKILL.

    On Linux the kernel sends SIGTERM at once (``prctl(PR_SET_PDEATHSIG)``); everywhere
    a daemon thread checks every ``poll_s`` seconds that the parent is still the one
    that started it, and exits otherwise. Without it a killed ``cohort run`` leaves its
    pool workers (and so the multiprocessing resource tracker) running.

    Parameters
    ----------
    parent : int
        Process id of the parent.
    poll_s : float
        Seconds between two checks of the watching thread.
    """
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(1, signal.SIGTERM)  # 1 = PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # not Linux: the thread below does it
        pass
    if os.getppid() != parent:  # the parent died before prctl took effect
        os._exit(1)

    def watch() -> None:
        while True:
            time.sleep(poll_s)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, name="tiltlab-exit-with-parent", daemon=True).start()


#: environment of a local Dask worker: one thread per library (set before it starts)
ONE_THREAD_ENV = {
    "NUMBA_NUM_THREADS": "1",
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
}
_blas_limited = False


def _one_thread() -> None:
    """Run numba's parallel kernels (in this thread) and BLAS (in this process) on one thread."""
    global _blas_limited
    import numba

    if numba.get_num_threads() != 1:
        numba.set_num_threads(1)  # thread-local: set in the thread that runs the task
    if not _blas_limited:
        _blas_limited = True
        try:
            from threadpoolctl import threadpool_limits
        except ImportError:  # pragma: no cover - optional: BLAS keeps its threads
            return
        threadpool_limits(1)


def run_in_worker(fn: Callable, *args):
    """Call ``fn(*args)`` in a worker, its numba kernels and BLAS on one thread.

    A worker of a pool (or of a Dask cluster) shares the machine's cores with the other
    workers: a kernel's or BLAS's own threads there compete for the same cores (and
    spin while they wait) instead of adding any. The results do not depend on the
    number of threads: the parallel kernels split their work in fixed chunks.

    Parameters
    ----------
    fn : callable
        The task.
    *args
        Its arguments.

    Returns
    -------
    object
        ``fn(*args)``.
    """
    _one_thread()
    return fn(*args)


def _start_worker(parent: int) -> None:
    """Initialise a pool worker: end with ``parent``, run on one thread.

    Unpickling this function imported :mod:`tiltlab.cohort` (the whole pipeline)
    already, at the worker's start, while the parent still reads the manifest's files.
    """
    exit_with_parent(parent)
    _one_thread()


class _Processes:
    name = "processes"

    def __init__(self, workers: int):
        # spawn, not fork: numba's OpenMP threads make fork() unsafe once a kernel ran;
        # the workers end with this process, however it ends
        self.pool = ProcessPoolExecutor(
            max_workers=workers,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_start_worker,
            initargs=(os.getpid(),),
        )

    def submit(self, fn, *args) -> Future:
        return self.pool.submit(run_in_worker, fn, *args)

    def as_completed(self, futures):
        return _cf_as_completed(futures)

    def close(self):
        self.pool.shutdown(wait=True, cancel_futures=True)


def _local_cluster(workers: int):
    """Start a ``distributed.LocalCluster`` of ``workers`` one-thread processes.

    Dask's Nanny sets ``MALLOC_TRIM_THRESHOLD_=65536`` in the workers (its
    ``distributed.nanny.pre-spawn-environ``): with it glibc returns every freed large
    array to the system at once and maps the next one afresh, which doubled a worker's
    CPU time per session (1.0 s instead of 0.5 s for 20 min at 300 Hz). The workers
    start without it. The Nanny also writes its pre-spawn variables into this process's
    ``os.environ``: they are put back as they were, so that a process pool started
    later here does not inherit them either.
    """
    import dask
    from distributed import LocalCluster

    saved = dict(os.environ)
    try:
        with dask.config.set(
            {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}
        ):
            return LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",  # any free port: never clash with another
                env=dict(ONE_THREAD_ENV),  # one core per worker: no thread pools
            )
    finally:
        for k in set(os.environ) - set(saved):
            del os.environ[k]
        os.environ.update(saved)


class _Dask:
    name = "dask"

    def __init__(self, scheduler, workers: int | None):
        from distributed import Client

        self.cluster = None
        self.own_client = True
        if isinstance(scheduler, Client):
            self.client, self.own_client = scheduler, False
        elif scheduler == "dask":
            self.cluster = _local_cluster(int(workers or os.cpu_count() or 1))
            self.client = Client(self.cluster)
        else:
            self.client = Client(scheduler)

    def submit(self, fn, *args):
        return self.client.submit(
            run_in_worker,
            fn,
            *args,
            pure=False,
            key=f"tiltlab-session-{uuid.uuid4().hex}",
        )

    def as_completed(self, futures):
        from distributed import as_completed

        return as_completed(list(futures))

    def close(self):
        if self.own_client:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def backend(scheduler, workers: int | None):
    """Choose the back end for a ``scheduler`` argument of :func:`run_cohort`.

    Parameters
    ----------
    scheduler : None, str or distributed.Client
        ``None``: serial, or a process pool when ``workers > 1``; ``"processes"``: a
        process pool; ``"dask"``: a local Dask cluster (one process per worker); a
        scheduler address ``"tcp://host:port"`` or a ``distributed.Client``: that
        Dask scheduler (a given Client is not closed by the back end).
    workers : int, optional
        Number of worker processes (at least 1); default the CPU count for
        ``"processes"`` and ``"dask"``, serial for ``None``.

    Returns
    -------
    object
        Back end with ``name``, ``submit(fn, *args)``, ``as_completed(futures)`` and
        ``close()``.

    Raises
    ------
    ValueError
        If ``workers`` is not a positive integer or ``scheduler`` is not recognised.
    """
    if workers is not None and (isinstance(workers, bool) or int(workers) != workers):
        raise ValueError(f"workers must be a positive integer, got {workers!r}")
    if workers is not None and workers < 1:
        raise ValueError(f"workers must be at least 1, got {workers!r}")
    if scheduler is None:
        if workers is not None and workers > 1:
            return _Processes(int(workers))
        return _Serial()
    if scheduler == "processes":
        return _Processes(int(workers or os.cpu_count() or 1))
    if scheduler == "dask" or (isinstance(scheduler, str) and "://" in scheduler):
        return _Dask(scheduler, workers)
    try:
        from distributed import Client
    except ImportError:  # pragma: no cover - distributed is a dependency
        Client = ()
    if isinstance(scheduler, Client):
        return _Dask(scheduler, workers)
    raise ValueError(
        "scheduler must be None, 'processes', 'dask', a scheduler address "
        f"'tcp://host:port' or a distributed.Client, got {scheduler!r}"
    )
