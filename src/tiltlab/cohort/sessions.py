r"""Reading one session of a cohort manifest: the reader registry and the loaders.

:data:`READERS` maps a manifest's ``reader`` column to the function that reads the
session's recording; :func:`load_session` reads a row's recording with it (with the
row's ``reader_options``, checked as :func:`~tiltlab.cohort.read_manifest` checks
them), and :func:`load_calibration` the row's tumble test. :func:`session_path`
resolves a row's relative ``file`` against the manifest's folder. A malformed row is
a :class:`ManifestError`. The package :mod:`tiltlab.cohort` gives the reference of
the study design (Fayat et al. 2021).
"""

from __future__ import annotations

import inspect
import json
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import xarray as xr

from .. import io as _io
from ..quality import UnitCheckError

__all__ = [
    "READERS",
    "ManifestError",
    "load_session",
    "load_calibration",
    "session_path",
]


def _read_netcdf(
    path,
    *,
    allow_nan: bool | None = None,
    max_jitter: float = 0.35,
    quat_atol: float = 1e-6,
    check_units: bool = True,
) -> xr.Dataset:
    """Read a NetCDF Recording (:func:`tiltlab.io.load_netcdf`) and validate it.

    A NetCDF Recording (:func:`tiltlab.io.load_netcdf`), validated with these
    options of :func:`tiltlab.schema.validate`.
    """
    kw = {"max_jitter": max_jitter, "quat_atol": quat_atol, "check_units": check_units}
    if allow_nan is not None:
        kw["allow_nan"] = allow_nan
    return _io.load_netcdf(path, validate=True, **kw)


#: reader name → function ``reader(path, **reader_options)`` returning a Recording
READERS: dict[str, Callable[..., xr.Dataset]] = {
    "netcdf": _read_netcdf,
    "fayat_csv": _io.read_fayat_imu,
    "fayat_tumble": _io.read_fayat_tumble,
    "broad": _io.read_broad,
    "csv": _io.read_csv,
    "tagtools": _io.read_tagtools,
    "auto": _io.read,
}
#: calibration file suffix → reader
_CALIBRATION_READERS = {".nc": "netcdf", ".netcdf": "netcdf", ".csv": "fayat_tumble"}


class ManifestError(ValueError):
    """Signal a malformed manifest.

    A manifest is malformed; the message names the line (or, for
    :func:`~tiltlab.cohort.init_manifest`, the file) and the session.
    """


def _options(text: str, reader: str, where: str) -> dict[str, Any]:
    text = "" if text is None else str(text).strip()
    if not text:
        opts: Any = {}
    else:
        try:
            opts = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ManifestError(
                f"{where}: reader_options is not valid JSON ({exc.msg} at character "
                f"{exc.pos}): {text!r}"
            ) from None
    if not isinstance(opts, dict):
        raise ManifestError(
            f"{where}: reader_options must be a JSON object, got {type(opts).__name__}"
        )
    if reader == "csv":
        missing = [k for k in ("columns", "units") if k not in opts]
        if missing:
            raise ManifestError(
                f"{where}: the csv reader needs reader_options {missing} (a column and "
                "unit mapping, and fs or time_column)"
            )
        if "fs" not in opts and "time_column" not in opts:
            raise ManifestError(
                f"{where}: the csv reader needs 'fs' or 'time_column' in "
                "reader_options: tiltlab never assumes a sampling rate"
            )
    else:
        params = inspect.signature(READERS[reader]).parameters
        if not any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values()):
            unknown = [k for k in opts if k not in params or k == "path"]
            if unknown:
                raise ManifestError(
                    f"{where}: reader {reader!r} does not accept option(s) {unknown}"
                )
    return opts


def session_path(file, root) -> Path:
    """``file`` if absolute, else ``root / file``.

    Parameters
    ----------
    file : str or os.PathLike
        File path from a manifest (``~`` expanded).
    root : str or os.PathLike
        Directory that relative paths are resolved against.

    Returns
    -------
    pathlib.Path
        The resolved path.
    """
    p = Path(str(file)).expanduser()
    return p if p.is_absolute() else Path(root) / p


def _takes(func: Callable[..., Any], name: str) -> bool:
    """Tell whether ``func`` accepts the keyword ``name`` (itself or by ``**``)."""
    try:
        params = inspect.signature(func).parameters
    except (TypeError, ValueError):
        return False
    if name in params:
        return True
    # **attrs of a reader are dataset attributes, not options: only io.read forwards
    return func is _io.read


def load_session(row: Mapping[str, Any], root) -> xr.Dataset:
    """Read one session's Recording with the reader its manifest row names.

    Parameters
    ----------
    row : mapping
        A manifest row (a dict from :meth:`~tiltlab.cohort.Manifest.rows` or a pandas Series) with
        ``file``, ``reader`` and optionally ``reader_options`` (JSON text or a dict).
    root : path-like
        Folder of the manifest (:attr:`~tiltlab.cohort.Manifest.root`).

    Returns
    -------
    xarray.Dataset
        The Recording, validated by its reader (:func:`tiltlab.schema.validate`), with
        the manifest's ``session``, ``subject`` and ``group`` added to its attrs as
        ``cohort_session``, ``cohort_subject`` and ``cohort_group``.

    Raises
    ------
    tiltlab.io.ReadError
        A missing, truncated or unreadable file.
    tiltlab._validate.RecordingError
        A recording that breaks the Recording contract.
    """
    reader = str(row["reader"])
    if reader not in READERS:
        raise ManifestError(f"unknown reader {reader!r}; known: {sorted(READERS)}")
    opts = row.get("reader_options", "")
    if not isinstance(opts, Mapping):
        opts = _options(opts, reader, f"session {row.get('session')!r}")
    opts = dict(opts)
    func = READERS[reader]
    try:
        rec = func(session_path(row["file"], root), **opts)
    except UnitCheckError as err:
        # name the switch as a manifest gives it
        raise err.for_switch("manifest") from None
    extra = {
        f"cohort_{k}": str(row[k]) for k in ("session", "subject", "group") if k in row
    }
    return rec.assign_attrs(extra) if extra else rec


def load_calibration(row: Mapping[str, Any], root) -> xr.Dataset | None:
    """Load the tumble test named in a manifest row's ``calibration``, or None.

    ``.nc`` files are read with :func:`tiltlab.io.load_netcdf` (validated), ``.csv``
    files with :func:`tiltlab.io.read_fayat_tumble`.

    Parameters
    ----------
    row : Mapping
        Manifest row; its ``calibration`` entry names the file (empty or ``"nan"``: no
        calibration) and its ``reader_options`` (a Mapping or a JSON string) may set
        ``check_units`` to False.
    root : str or os.PathLike
        Directory that a relative ``calibration`` path is resolved against.

    Returns
    -------
    xarray.Dataset or None
        The tumble-test Recording, or None when the row names no calibration.

    Raises
    ------
    ManifestError
        If the calibration file is neither ``.nc`` nor ``.csv``.
    """
    cal = str(row.get("calibration", "") or "").strip()
    if not cal or cal == "nan":
        return None
    reader = _CALIBRATION_READERS.get(Path(cal).suffix.lower())
    if reader is None:
        raise ManifestError(f"calibration file {cal!r} must be .nc or .csv")
    opts = row.get("reader_options", "")
    if not isinstance(opts, Mapping):
        try:
            opts = json.loads(str(opts)) if str(opts or "").strip() else {}
        except json.JSONDecodeError:
            opts = {}
    kw = {}
    if isinstance(opts, Mapping) and opts.get("check_units") is False:
        if _takes(READERS[reader], "check_units"):
            kw["check_units"] = False
    try:
        return READERS[reader](session_path(cal, root), **kw)
    except UnitCheckError as err:
        raise err.for_switch("manifest") from None
