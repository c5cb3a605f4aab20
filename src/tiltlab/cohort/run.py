r"""Run a cohort: one task per session on any scheduler, a disk cache, no lost sessions.

:func:`run_cohort` submits one task per session that is not in the cache and collects
the results as they complete, through the same two calls (``submit``, then
``as_completed``) whatever runs them: this process (serial), a local process pool, or a
``dask.distributed`` cluster. A session is submitted as soon as its cache entry is
found missing (the back end starts at the first one), so the workers compute while
the parent still hashes the following files. Every result is written to the cache as
soon as it arrives, atomically (a temporary file renamed into place), so a killed run
leaves no corrupt entry and a restarted run resumes where it stopped. A session that
cannot be read or computed becomes a row with ``status = "failed"``, its ``error`` and
NaN features; the others complete.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import sys
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from .. import __version__, _deprecate
from .. import io as _io
from ..datasets import file_sha256
from ..quality import UnitCheckError
from .config import FeatureConfig
from .features import feature_specs, session_features
from .manifest import (
    Manifest,
    load_calibration,
    load_session,
    read_manifest,
    session_path,
)
from .schedulers import backend as _backend

__all__ = [
    "CohortSummary",
    "run_cohort",
    "summary",
    "save_features",
    "load_features",
    "compute_session",
    "cache_key",
]

#: bump when the feature computation changes in a way the config hash cannot see
CACHE_VERSION = 1
DEFAULT_CACHE = ".tiltlab-cache"


# ------------------------------------------------------------------ one session


@functools.lru_cache(maxsize=8)
def _calibration_file(
    path: str, size: int, mtime_ns: int, check_units: bool = True
) -> xr.Dataset | None:
    # a subject's tumble test serves all its sessions: read it once per process
    opts = {} if check_units else {"check_units": False}
    return load_calibration({"calibration": path, "reader_options": opts}, "/")


def _check_units(row: dict) -> bool:
    """Tell whether to check units (not if reader_options say so)."""
    opts = row.get("reader_options", "")
    if not isinstance(opts, dict):
        try:
            opts = json.loads(str(opts)) if str(opts or "").strip() else {}
        except json.JSONDecodeError:
            return True
    return not (isinstance(opts, dict) and opts.get("check_units") is False)


def _calibration_of(row: dict, root: str) -> xr.Dataset | None:
    cal = str(row.get("calibration", "") or "")
    if not cal:
        return None
    path = session_path(cal, root)
    if not path.is_file():
        return load_calibration(row, root)  # raises the reader's error
    st = path.stat()
    return _calibration_file(
        str(path.resolve()), st.st_size, st.st_mtime_ns, _check_units(row)
    )


def compute_session(row: dict, root: str, config: FeatureConfig) -> dict[str, Any]:
    """Load one session (and its calibration) and compute its features; never raises.

    Returns ``{"session", "status", "error", "features"}``: ``status`` is ``"ok"``
    with the feature Dataset, or ``"failed"`` with ``error`` = ``"<Type>: <message>"``
    and ``features`` None. This is the task :func:`run_cohort` submits.

    Parameters
    ----------
    row : dict
        Manifest row (``session``, ``file``, ``reader``, ``calibration``,
        ``reader_options`` ...).
    root : str
        Directory that relative file paths in ``row`` are resolved against.
    config : FeatureConfig
        Feature configuration.

    Returns
    -------
    dict
        ``session`` (str), ``status`` (``"ok"`` or ``"failed"``), ``error`` (str,
        empty when ok) and ``features`` (xarray.Dataset or None).
    """
    try:
        rec = load_session(row, root)
        cal = _calibration_of(row, root)
        # load_session validated the Recording with the row's reader options: the
        # feature step does not validate it a second time
        ds = session_features(rec, config, calibration=cal, validate=False)
    except Exception as exc:  # any failure is recorded, never propagated
        if isinstance(exc, UnitCheckError):
            exc = exc.for_switch("manifest")
        msg = " ".join(str(exc).split())
        return {
            "session": row["session"],
            "status": "failed",
            "error": f"{type(exc).__name__}: {msg}",
            "features": None,
        }
    return {"session": row["session"], "status": "ok", "error": "", "features": ds}


# ------------------------------------------------------------------ cache


def _sha256(path: Path) -> str | None:
    try:
        return file_sha256(path)
    except OSError:
        return None


def _options_of(row) -> dict:
    opts = row.get("reader_options") or {}
    return dict(opts) if isinstance(opts, dict) else json.loads(opts)


def cache_key(
    row: dict, root, config: FeatureConfig, *, digests: dict | None = None
) -> str | None:
    """Compute the cache key of a session.

    The cache key of a session: SHA-256 over its file's bytes, its calibration
    file's bytes, the reader and its options, the configuration's hash and the package
    version. None when a file cannot be read (such a session is always recomputed).
    ``digests`` (path → SHA-256) memoises file digests over one run (a subject's
    calibration file serves several sessions).

    Parameters
    ----------
    row : dict
        Manifest row (``file``, ``reader``, ``reader_options``, ``calibration``).
    root : str or os.PathLike
        Directory that relative file paths in ``row`` are resolved against.
    config : FeatureConfig
        Feature configuration (its hash enters the key).
    digests : dict, optional
        Memo of file digests, path (str) -> SHA-256 hex digest or None; updated in
        place.

    Returns
    -------
    str or None
        Hex SHA-256 key (64 characters), or None when a file cannot be read.
    """
    memo = {} if digests is None else digests

    def digest(f) -> str | None:
        p = str(session_path(f, root))
        if p not in memo:
            memo[p] = _sha256(Path(p))
        return memo[p]

    parts = {
        "file": digest(row["file"]),
        "reader": row["reader"],
        "reader_options": _options_of(row),
        "config": config.hash(),
        "version": [CACHE_VERSION, __version__],
    }
    if parts["file"] is None:
        return None
    cal = str(row.get("calibration", "") or "")
    if cal:
        parts["calibration"] = digest(cal)
        if parts["calibration"] is None:
            return None
    blob = json.dumps(parts, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(blob.encode()).hexdigest()


def _cache_get(cache: Path, key: str | None, names) -> xr.Dataset | None:
    if key is None:
        return None
    path = cache / f"{key}.json"
    try:
        entry = json.loads(path.read_text())
        ds = xr.Dataset(
            {
                k: ((), np.float64(entry["values"][k]), entry["var_attrs"][k])
                for k in names
            },
            attrs=entry["attrs"],
        )
    except (OSError, ValueError, KeyError, TypeError):
        return None  # absent or unreadable: a miss (the entry is rewritten)
    return ds


def _write_atomically(path, write: Callable[[Path], object]) -> Path:
    """Write a file atomically: through a temporary file renamed into place.

    Call ``write(tmp)`` on a temporary file beside ``path``, then rename it into
    place (:func:`os.replace`): a reader sees the old file or the new one, never half
    of one, and a failed ``write`` leaves no temporary file behind.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{uuid.uuid4().hex}.tmp")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def _atomic_write(text: str, path: Path) -> Path:
    """Write ``text`` to a temporary file beside ``path``, then rename it into place."""

    def write(tmp: Path) -> None:
        with open(tmp, "w") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())

    return _write_atomically(path, write)


def _cache_put(cache: Path, key: str, ds: xr.Dataset) -> Path:
    # scalars as JSON: exact float64 round trip (repr), much faster than NetCDF
    entry = {
        "values": {k: float(v.values) for k, v in ds.data_vars.items()},
        "var_attrs": {k: dict(v.attrs) for k, v in ds.data_vars.items()},
        "attrs": dict(ds.attrs),
    }
    return _atomic_write(json.dumps(entry, sort_keys=True), cache / f"{key}.json")


# ------------------------------------------------------------------ the run


def _assemble(
    manifest: Manifest,
    config: FeatureConfig,
    results: dict[str, dict[str, Any]],
    n_computed: int,
    n_cached: int,
) -> xr.Dataset:
    table = manifest.table
    spec = feature_specs(config)
    n = len(table)
    values = {k: np.full(n, np.nan) for k in spec}
    status = np.empty(n, dtype=object)
    error = np.empty(n, dtype=object)
    notes = np.full(n, "", dtype=object)
    for i, sid in enumerate(table["session"]):
        r = results[sid]
        status[i], error[i] = r["status"], r["error"]
        if r["features"] is not None:
            for k in spec:
                values[k][i] = float(r["features"][k].values)
            notes[i] = str(r["features"].attrs.get("notes", ""))
    data = {
        k: ("session", values[k], {"units": u, "long_name": ln})
        for k, (u, ln) in spec.items()
    }
    data["status"] = ("session", status.astype(str), {"long_name": "ok or failed"})
    data["error"] = (
        "session",
        error.astype(str),
        {"long_name": "why the session failed (empty when ok)"},
    )
    data["notes"] = (
        "session",
        notes.astype(str),
        {"long_name": "why features of a session that ran are NaN (feature: reason)"},
    )

    def coord(col):
        v = table[col]
        arr = (
            v.to_numpy()
            if pd.api.types.is_numeric_dtype(v)
            else v.astype(str).to_numpy()
        )
        return ("session", arr.astype(str) if arr.dtype == object else arr)

    coords = {"session": table["session"].astype(str).to_numpy()}
    for c in ["subject", "group", "timepoint", "file", "reader"] + manifest.covariates:
        coords[c] = coord(c)
    n_failed = int(np.sum(status == "failed"))
    attrs = {
        "title": "tiltlab cohort features",
        "feature_config": config.to_json(),
        "config_hash": config.hash(),
        "tiltlab_version": __version__,
        # the manifest's name only: the table stays valid when the study folder moves
        "manifest": manifest.path.name if manifest.path else "",
        "n_sessions": n,
        "n_ok": n - n_failed,
        "n_failed": n_failed,
        "n_computed": n_computed,
        "n_cached": n_cached,
        "references": "R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318",
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


class _Run:
    """The sessions of one :func:`run_cohort`: cache look-ups, tasks and results.

    The back end is started at the first session missing from the cache (a run that
    finds every session cached starts none); each task is one session, read by path in
    the worker, which sends back only the session's feature Dataset (a few scalars).
    """

    def __init__(
        self, cache: Path, root: str, config: FeatureConfig, scheduler, workers
    ):
        self.cache, self.root, self.config = cache, root, config
        self.scheduler, self.workers = scheduler, workers
        self.spec = feature_specs(config)
        self.backend = None
        self.futures: dict[Any, str] = {}
        self.results: dict[str, dict[str, Any]] = {}
        self.keys: dict[str, str | None] = {}
        self.digests: dict[str, str | None] = {}
        self.n_cached = 0

    @property
    def n_computed(self) -> int:
        return len(self.futures)

    def lookup_or_submit(self, row: dict, bar) -> None:
        """Take the session from the cache, or submit its task."""
        sid = row["session"]
        key = cache_key(row, self.root, self.config, digests=self.digests)
        self.keys[sid] = key
        hit = _cache_get(self.cache, key, self.spec)
        if hit is not None:
            self.results[sid] = {"status": "ok", "error": "", "features": hit}
            self.n_cached += 1
            bar.update()
            return
        if self.backend is None:
            self.backend = _backend(self.scheduler, self.workers)
        task = self.backend.submit(compute_session, row, self.root, self.config)
        self.futures[task] = sid

    def collect(self, bar) -> None:
        """Gather the results as they complete; cache each one as it arrives."""
        if not self.futures:
            return
        for fut in self.backend.as_completed(list(self.futures)):
            sid = self.futures[fut]
            try:
                res = fut.result()
            except Exception as exc:  # the worker itself died
                res = {
                    "status": "failed",
                    "error": f"{type(exc).__name__}: {exc}",
                    "features": None,
                }
            if res["status"] == "ok" and self.keys[sid] is not None:
                _cache_put(self.cache, self.keys[sid], res["features"])
            self.results[sid] = res
            bar.update()

    def close(self) -> None:
        if self.backend is not None:
            self.backend.close()


def run_cohort(
    manifest,
    config: FeatureConfig | None = None,
    *,
    scheduler=None,
    workers: int | None = None,
    cache_dir=None,
    progress: bool = True,
    out=None,
) -> xr.Dataset:
    r"""Compute every session's features and gather them in one Dataset.

    Parameters
    ----------
    manifest : Manifest or path-like
        A manifest (:func:`~tiltlab.cohort.read_manifest`) or its CSV file.
    config : FeatureConfig, optional
        Feature configuration (default :class:`FeatureConfig()`).
    scheduler : None, "processes", "dask", str or distributed.Client
        Where the sessions run: ``None`` serially in this process (a local process pool
        when ``workers > 1``), ``"processes"`` a local process pool of ``workers``,
        ``"dask"`` a ``distributed.LocalCluster(n_workers=workers,
        threads_per_worker=1)`` started and closed here, an address ``"tcp://…"`` an
        existing scheduler, or a ``distributed.Client`` (left open). The same tasks are
        submitted in every case and give identical features.
    workers : int, optional
        Number of worker processes; each runs one session at a time, its numba
        kernels and BLAS on one thread.
    cache_dir : path-like, optional
        Per-session cache (default ``.tiltlab-cache`` beside the manifest). Entries are
        keyed by :func:`cache_key`: a rerun recomputes only sessions whose file,
        calibration file, reader options or configuration changed, and sessions that
        failed.
    progress : bool
        Show a tqdm progress bar of sessions done, and print the summary at the end.
    out : path-like, optional
        Also save the Dataset there (:func:`save_features`).

    Returns
    -------
    xarray.Dataset
        Dimension ``session``; the features of :func:`~tiltlab.cohort.session_features`
        (NaN for failed sessions), ``status`` ("ok"/"failed"), ``error`` and
        ``notes`` (for a session that ran, why some of its features are NaN, e.g. no
        gyroscope or no immobile sample);
        coordinates ``subject``, ``group``, ``timepoint``, ``file``, ``reader`` and the
        covariates; attrs ``feature_config`` (JSON), ``config_hash``, ``n_sessions``,
        ``n_ok``, ``n_failed``, ``n_computed`` (sessions computed in this run,
        failed ones included) and ``n_cached`` (taken from the cache).

    Notes
    -----
    Feature definitions follow Fayat et al. §2.7–2.10 (see
    :func:`~tiltlab.cohort.session_features`). The run never raises for a bad session;
    read the outcome with :func:`summary`.

    References
    ----------
    .. [1] R. Fayat et al., Sensors 21(18):6318, 2021. doi:10.3390/s21186318
    """
    from tqdm import tqdm

    if not isinstance(manifest, Manifest):
        manifest = read_manifest(manifest)
    config = config or FeatureConfig()
    if not isinstance(config, FeatureConfig):
        raise TypeError(f"config must be a FeatureConfig, got {type(config).__name__}")
    root = str(manifest.root)
    cache = Path(cache_dir) if cache_dir is not None else manifest.root / DEFAULT_CACHE
    rows = list(manifest.rows())
    bar = tqdm(total=len(rows), desc="sessions", unit="session", disable=not progress)
    run = _Run(cache, root, config, scheduler, workers)
    try:
        # a session is submitted as soon as its cache entry is found missing: the
        # workers start, and compute, while the following files are still hashed
        for row in rows:
            run.lookup_or_submit(row, bar)
        run.collect(bar)
    finally:
        run.close()
    bar.close()
    ds = _assemble(manifest, config, run.results, run.n_computed, run.n_cached)
    if out is not None:
        save_features(ds, out)
    if progress:
        print(summary(ds), file=sys.stderr)
    return ds


# ------------------------------------------------------------------ summary, files


@dataclass(frozen=True)
class CohortSummary:
    """Summarise a cohort run.

    Outcome of a cohort run: counts, per failed session the reason, and per session
    that ran with NaN features why they are NaN.
    """

    n_sessions: int
    n_ok: int
    n_failed: int
    n_computed: int | None = None
    n_cached: int | None = None
    failures: dict[str, str] = field(default_factory=dict)
    notes: dict[str, str] = field(default_factory=dict)

    def __str__(self) -> str:
        """Describe the run in a few lines."""
        head = f"{self.n_sessions} sessions: {self.n_ok} ok, {self.n_failed} failed"
        if self.n_computed is not None:
            head += f" ({self.n_computed} computed, {self.n_cached} from cache)"
        lines = [head] + [f"  failed {s}: {e}" for s, e in self.failures.items()]
        by_note: dict[str, list[str]] = {}
        for session, note in self.notes.items():  # sessions that share a reason
            by_note.setdefault(note, []).append(session)
        for note, sessions in by_note.items():
            shown = ", ".join(sessions[:4]) + (", …" if len(sessions) > 4 else "")
            count = f"{len(sessions)} sessions" if len(sessions) > 1 else "session"
            lines.append(f"  NaN features in {count} {shown}: {note}")
        return "\n".join(lines)


def summary(features: xr.Dataset) -> CohortSummary:
    """Count ok and failed sessions of a cohort Dataset, and why each failed.

    Parameters
    ----------
    features : xarray.Dataset
        Cohort feature table along ``session`` with ``status`` and ``error`` (and
        ``notes``), as from :func:`run_cohort` or :func:`load_features`.

    Returns
    -------
    CohortSummary
        Numbers of sessions, ok, failed, computed and cached sessions, and the
        ``failures`` and ``notes`` by session.

    Raises
    ------
    ValueError
        If ``features`` has no ``status`` along a ``session`` dimension.
    """
    if "status" not in features or "session" not in features.dims:
        raise ValueError("not a cohort feature table (no 'status' along 'session')")
    status = features["status"].values.astype(str)
    err = features["error"].values.astype(str)
    sessions = features["session"].values.astype(str)
    failed = status == "failed"
    notes = (
        features["notes"].values.astype(str)
        if "notes" in features
        else np.full(status.size, "")
    )

    def attr(k):
        v = features.attrs.get(k)
        return None if v is None else int(v)

    return CohortSummary(
        n_sessions=int(status.size),
        n_ok=int(np.sum(status == "ok")),
        n_failed=int(failed.sum()),
        n_computed=attr("n_computed"),
        n_cached=attr("n_cached"),
        failures={s: e for s, e, f in zip(sessions, err, failed) if f},
        notes={s: n for s, n in zip(sessions, notes, strict=True) if n and n != "nan"},
    )


@_deprecate.renamed(ds="features")
def save_features(features: xr.Dataset, path) -> Path:
    """Save a feature table to NetCDF, atomically.

    The round trip with :func:`load_features` is exact;
    :func:`~tiltlab.cohort.save_table` writes the table as CSV or Parquet.

    Parameters
    ----------
    features : xarray.Dataset
        Feature table (of :func:`run_cohort`).
    path : str or os.PathLike
        Output NetCDF file.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    TypeError
        If ``features`` is not an xarray.Dataset.
    """
    if not isinstance(features, xr.Dataset):
        raise TypeError(f"expected an xarray.Dataset, got {type(features).__name__}")
    return _write_atomically(path, lambda tmp: _io.save_netcdf(features, tmp))


def load_features(path) -> xr.Dataset:
    """Load a feature table written by :func:`save_features` (or :func:`run_cohort`).

    Parameters
    ----------
    path : str or os.PathLike
        NetCDF file.

    Returns
    -------
    xarray.Dataset
        The feature table, along ``session``.

    Raises
    ------
    ValueError
        If the file has no ``session`` dimension.
    """
    ds = _io.load_netcdf(path)
    if "session" not in ds.dims:
        raise ValueError(f"{path}: not a cohort feature table (no 'session' dimension)")
    return ds
