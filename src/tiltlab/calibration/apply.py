r"""The :class:`Calibration` record and :func:`calibrate`, which applies it to a Recording.

A calibration maps raw readings to corrected ones, per sensor,

.. math:: x' = R\,C\,\big(x - o(T)\big),

with offsets :math:`o` (constant, or a :class:`TemperatureModel` of the sensor
temperature T), a scale/misalignment correction matrix :math:`C` (identity if absent)
and an optional frame rotation :math:`R` (e.g. IMU→head from :func:`imu_to_head_alignment`
or device→body from :func:`mounting_rotation`). Offsets are stored in g, °/s and µT;
:func:`calibrate` converts to the Recording's units. What was applied is recorded, as
JSON, in ``attrs["calibration"]``; applying the same calibration twice, or correcting an
already corrected quantity again, raises :class:`CalibrationError`.
:func:`save_calibration_file` and :func:`load_calibration_file` keep a calibration in a JSON file
(with its fingerprint, checked on loading), so that one calibration session corrects the
recordings of later ones.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import xarray as xr

from .. import _validate as _v
from .. import quaternion as _quat
from .. import units as _units
from .._validate import RecordingError
from ._util import CalibrationError, mat3, read_in, read_temp_degc
from .accel import EllipsoidFit, OffsetFit, fit_ellipsoid, fit_offsets
from .static import (
    StaticStats,
    detect_static,
    gyro_offset,
    static_intervals_from_trigger,
    static_means,
)
from .temperature import TemperatureModel

__all__ = [
    "Calibration",
    "calibrate",
    "applied_calibrations",
    "save_calibration_file",
    "load_calibration_file",
    "TumbleResult",
    "tumble_calibration",
]

_UNITS = {"acc": "g", "gyr": "deg/s", "mag": "uT"}


def _tup(v, shape, name: str):
    if v is None:
        return None
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(
            f"Calibration.{name} must be numbers of shape {shape}, got {v!r}"
        ) from None
    if a.shape != shape:
        raise ValueError(
            f"Calibration.{name} must have shape {shape}, got shape {a.shape}"
        )
    if not np.all(np.isfinite(a)):
        raise ValueError(
            f"Calibration.{name} has {int(np.sum(~np.isfinite(a)))} non-finite values"
        )
    return tuple(map(tuple, a)) if a.ndim == 2 else tuple(a.tolist())


@dataclass(frozen=True)
class Calibration:
    """Sensor corrections (offsets in g, °/s, µT; matrices dimensionless).

    Attributes
    ----------
    name : str
        Label (provenance; not part of the identity used to detect double application).
    acc_offset, gyr_offset, mag_offset : 3 floats, optional
    acc_matrix, gyr_matrix, mag_matrix : 3×3, optional
        Correction matrices C (applied after offset removal).
    acc_temp, gyr_temp : TemperatureModel, optional
        Temperature-dependent offsets (replace the constant offset of that sensor).
    rotation : 3×3, optional
        Frame rotation applied last to all vectors; ``target_frame`` names the new frame.
    info : dict
        JSON-compatible extra information (uncertainties, fit diagnostics).
    """

    name: str = "calibration"
    acc_offset: tuple | None = None
    acc_matrix: tuple | None = None
    gyr_offset: tuple | None = None
    gyr_matrix: tuple | None = None
    mag_offset: tuple | None = None
    mag_matrix: tuple | None = None
    acc_temp: TemperatureModel | None = None
    gyr_temp: TemperatureModel | None = None
    rotation: tuple | None = None
    target_frame: str | None = None
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        """Check and normalise the corrections (arrays to tuples)."""
        for s in ("acc", "gyr", "mag"):
            object.__setattr__(
                self,
                f"{s}_offset",
                _tup(getattr(self, f"{s}_offset"), (3,), f"{s}_offset"),
            )
            object.__setattr__(
                self,
                f"{s}_matrix",
                _tup(getattr(self, f"{s}_matrix"), (3, 3), f"{s}_matrix"),
            )
        for s in ("acc", "gyr"):
            tm = getattr(self, f"{s}_temp")
            if tm is not None:
                if not isinstance(tm, TemperatureModel):
                    raise TypeError(f"{s}_temp must be a TemperatureModel")
                if getattr(self, f"{s}_offset") is not None:
                    raise ValueError(
                        f"give either {s}_offset or {s}_temp (temperature-dependent offsets), not both"
                    )
                if _units.normalise_unit(tm.units) != _UNITS[s]:
                    raise ValueError(f"{s}_temp must be in {_UNITS[s]}, got {tm.units}")
        object.__setattr__(self, "rotation", _tup(self.rotation, (3, 3), "rotation"))
        if self.rotation is not None:
            R = np.asarray(self.rotation)
            if not np.allclose(R @ R.T, np.eye(3), atol=1e-6) or np.linalg.det(R) < 0:
                raise ValueError("rotation must be a proper rotation matrix")
            if not self.target_frame:
                raise ValueError("a rotation needs a target_frame name")
        json.dumps(self.info)  # must be JSON-compatible

    def corrects(self) -> list[str]:
        """List the corrections this calibration applies, e.g. ``["acc_offset", "acc_matrix"]``."""
        out = []
        for s in ("acc", "gyr", "mag"):
            if (
                getattr(self, f"{s}_offset") is not None
                or getattr(self, f"{s}_temp", None) is not None
            ):
                out.append(f"{s}_offset")
            if getattr(self, f"{s}_matrix") is not None:
                out.append(f"{s}_matrix")
        if self.rotation is not None:
            out.append("rotation")
        return out

    def to_dict(self) -> dict[str, Any]:
        """JSON-compatible dict (round trip with :meth:`from_dict`)."""
        d: dict[str, Any] = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, TemperatureModel):
                v = v.to_dict()
            elif isinstance(v, tuple):
                v = np.asarray(v).tolist()
            d[f.name] = v
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "Calibration":
        """Rebuild a calibration from :meth:`to_dict` output."""
        kw = dict(d)
        for s in ("acc_temp", "gyr_temp"):
            if kw.get(s) is not None:
                kw[s] = TemperatureModel.from_dict(kw[s])
        return cls(**kw)

    def to_json(self) -> str:
        """Serialise to a JSON string (sorted keys)."""
        return json.dumps(self.to_dict(), sort_keys=True)

    @classmethod
    def from_json(cls, s: str) -> "Calibration":
        """Rebuild a calibration from :meth:`to_json` output."""
        return cls.from_dict(json.loads(s))

    def fingerprint(self) -> str:
        """SHA-256 (16 hex digits) of the corrections, excluding ``name`` and ``info``."""
        d = self.to_dict()
        d.pop("name")
        d.pop("info")
        return hashlib.sha256(json.dumps(d, sort_keys=True).encode()).hexdigest()[:16]


def applied_calibrations(rec: xr.Dataset) -> list[dict]:
    """Return the calibrations recorded in ``rec.attrs["calibration"]`` (oldest first).

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording.

    Returns
    -------
    list of dict
        One entry per applied calibration (``name``, ``fingerprint``, ``applied``,
        ``calibration``); empty if none was applied.
    """
    raw = rec.attrs.get("calibration")
    if raw is None:
        return []
    return json.loads(raw) if isinstance(raw, str) else list(raw)


_FILE_FORMAT = "tiltlab-calibration"
_FILE_VERSION = 1


def _checksum(d: dict[str, Any]) -> str:
    return hashlib.sha256(json.dumps(d, sort_keys=True).encode()).hexdigest()


def save_calibration_file(calibration: Calibration, path: str | os.PathLike) -> Path:
    """Write a :class:`Calibration` to a JSON file that :func:`load_calibration_file` reads.

    The file holds the calibration (:meth:`Calibration.to_dict`), its
    :meth:`~Calibration.fingerprint` and a SHA-256 of the whole entry (name and info
    included), so that a file edited after saving is refused on loading.

    Parameters
    ----------
    calibration : Calibration
        The calibration to save (e.g. ``tumble_calibration(rec).calibration``).
    path : str or path-like
        The file to write (replaced if it exists); its folder must exist.

    Returns
    -------
    pathlib.Path
        The file written.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from tiltlab import calibration
    >>> cal = calibration.Calibration(name="bench", acc_offset=[0.01, -0.02, 0.0])
    >>> path = calibration.save_calibration_file(cal, Path(tempfile.mkdtemp()) / "imu.json")
    >>> calibration.load_calibration_file(path) == cal
    True
    """
    if not isinstance(calibration, Calibration):
        raise TypeError(
            "save_calibration_file writes a tiltlab.calibration.Calibration, got "
            f"{type(calibration).__name__}"
        )
    path = Path(path)
    entry = calibration.to_dict()
    record = {
        "format": _FILE_FORMAT,
        "version": _FILE_VERSION,
        "fingerprint": calibration.fingerprint(),
        "sha256": _checksum(entry),
        "calibration": entry,
    }
    path.write_text(json.dumps(record, indent=2, sort_keys=True) + "\n", "utf-8")
    return path


def load_calibration_file(path: str | os.PathLike) -> Calibration:
    """Read a :class:`Calibration` written by :func:`save_calibration_file`, checking it.

    Parameters
    ----------
    path : str or path-like
        A file written by :func:`save_calibration_file`.

    Returns
    -------
    Calibration
        The saved calibration, equal to the one that was saved (same fingerprint).

    Raises
    ------
    FileNotFoundError
        No file at ``path``.
    CalibrationError
        The file is not a tiltlab calibration file (not JSON, another format or a newer
        version, entries missing or invalid), or it was changed after saving: its
        corrections no longer match the stored fingerprint, or its name or info no
        longer match the stored checksum. The message names the problem.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from tiltlab import calibration
    >>> cal = calibration.Calibration(name="bench", gyr_offset=[1.5, -0.3, 0.2])
    >>> path = calibration.save_calibration_file(cal, Path(tempfile.mkdtemp()) / "imu.json")
    >>> loaded = calibration.load_calibration_file(path)
    >>> loaded.gyr_offset, loaded.fingerprint() == cal.fingerprint()
    ((1.5, -0.3, 0.2), True)
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no calibration file at {path}")
    try:
        record = json.loads(path.read_text("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise CalibrationError(
            f"{path} is not a calibration file: it is not valid JSON ({err})"
        ) from None
    if not isinstance(record, dict) or record.get("format") != _FILE_FORMAT:
        raise CalibrationError(
            f"{path} is not a calibration file: it has no 'format': {_FILE_FORMAT!r} "
            "entry (write one with tiltlab.calibration.save_calibration_file)"
        )
    version = record.get("version")
    if version != _FILE_VERSION:
        raise CalibrationError(
            f"{path} is a calibration file of version {version!r}; this tiltlab reads "
            f"version {_FILE_VERSION}"
        )
    missing = [k for k in ("fingerprint", "sha256", "calibration") if k not in record]
    if missing or not isinstance(record["calibration"], dict):
        raise CalibrationError(
            f"{path} is an incomplete calibration file: missing or invalid "
            f"{', '.join(missing) or 'calibration'}"
        )
    try:
        calibration = Calibration.from_dict(record["calibration"])
    except (TypeError, ValueError, KeyError) as err:
        raise CalibrationError(
            f"{path} holds an invalid calibration entry: {err}"
        ) from None
    stored, computed = record["fingerprint"], calibration.fingerprint()
    if stored != computed:
        raise CalibrationError(
            f"{path} was changed after saving: its corrections have fingerprint "
            f"{computed}, the file states {stored}; refit or re-save the calibration"
        )
    if record["sha256"] != _checksum(record["calibration"]):
        raise CalibrationError(
            f"{path} was changed after saving: its name or info no longer match the "
            "stored checksum (the corrections are unchanged); re-save the calibration"
        )
    return calibration


def _temp_celsius(rec):
    if "temp" not in rec:
        raise CalibrationError(
            "this calibration has temperature-dependent offsets but the Recording has no 'temp'"
        )
    return read_temp_degc(rec["temp"])


def calibrate(
    rec: xr.Dataset, calibration: Calibration, *, allow_stacking: bool = False
) -> xr.Dataset:
    """Apply a :class:`Calibration` to a Recording; returns a new Recording.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording (acc, gyr, optional mag, temp, q_ref). Units are respected (offsets
        are converted to the variable's units; the units are unchanged).
    calibration : Calibration
        The corrections to apply (e.g. ``tumble_calibration(rec).calibration``).
    allow_stacking : bool
        Allow a *different* calibration to correct a quantity that an earlier one already
        corrected (e.g. a residual offset). The same calibration twice always raises.

    Returns
    -------
    xarray.Dataset
        Corrected copy; ``attrs["calibration"]`` (JSON list) gains an entry with the
        calibration, its fingerprint and what was applied; ``attrs["frame"]`` changes if
        a rotation was applied, and ``q_ref`` is re-expressed for the new frame.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import calibration, simulate
    >>> rec = simulate.tumble_test(8, 50.0, seed=2)
    >>> cal = calibration.calibrate(rec, calibration.tumble_calibration(rec).calibration)
    >>> still = rec["orientation"].values >= 0
    >>> def norm_error(r):
    ...     return float(np.abs(np.linalg.norm(r.acc.values[still], axis=1) - 1).mean())
    >>> round(norm_error(rec), 3), round(norm_error(cal), 3)  # g, before and after
    (0.028, 0.003)
    >>> calibration.applied_calibrations(cal)[0]["name"]
    'tumble test'
    """
    if not isinstance(calibration, Calibration):
        raise TypeError("calibration must be a tiltlab.calibration.Calibration")
    history = applied_calibrations(rec)
    fp = calibration.fingerprint()
    if any(h.get("fingerprint") == fp for h in history):
        raise CalibrationError(
            f"calibration {calibration.name!r} (fingerprint {fp}) was already applied to this Recording"
        )
    done = {c for h in history for c in h.get("applied", [])}
    todo = [
        c for c in calibration.corrects() if c.split("_")[0] in rec or c == "rotation"
    ]
    twice = sorted(done.intersection(todo))
    if twice and not allow_stacking:
        raise CalibrationError(
            f"{', '.join(twice)} already corrected by an earlier calibration "
            "(pass allow_stacking=True to stack a residual correction)"
        )
    out = rec.copy(deep=True)
    R = None if calibration.rotation is None else np.asarray(calibration.rotation)
    applied = []
    for s in ("acc", "gyr", "mag"):
        if s not in rec:
            continue
        x = rec[s].values.astype(float)
        if "units" not in rec[s].attrs:
            raise RecordingError(
                f"Recording variable {s!r} has no 'units' attribute: the calibration "
                f"(in {_UNITS[s]}) cannot be converted to it"
            )
        units = rec[s].attrs["units"]
        f = _units.conversion_factor(
            _UNITS[s], units
        )  # calibration units -> data units
        tm = getattr(calibration, f"{s}_temp", None)
        o = getattr(calibration, f"{s}_offset")
        C = getattr(calibration, f"{s}_matrix")
        if tm is not None:
            x = x - tm(_temp_celsius(rec)) * f
            applied.append(f"{s}_offset")
        elif o is not None:
            x = x - np.asarray(o) * f
            applied.append(f"{s}_offset")
        if C is not None:
            x = x @ mat3(C, f"{s}_matrix").T
            applied.append(f"{s}_matrix")
        if R is not None:
            x = x @ R.T
        out[s].values[...] = x
    if R is not None:
        applied.append("rotation")
        out.attrs["frame"] = calibration.target_frame
        if "q_ref" in rec:
            qR = _quat.from_matrix(R)
            out["q_ref"].values[...] = _quat.mul(rec["q_ref"].values, _quat.conj(qR))
    if not applied:
        raise CalibrationError(
            "the calibration corrects nothing present in this Recording"
        )
    history.append(
        {
            "name": calibration.name,
            "fingerprint": fp,
            "applied": applied,
            "calibration": calibration.to_dict(),
        }
    )
    out.attrs["calibration"] = json.dumps(history)
    return out


class TumbleResult(NamedTuple):
    """Result of :func:`tumble_calibration`.

    Output of :func:`tumble_calibration`: the ``calibration``, the still ``intervals``,
    per-period accelerometer statistics ``acc_stats``, the accelerometer ``fit``
    (:class:`OffsetFit` or :class:`EllipsoidFit`) and ``gyr_stderr`` (°/s; None for a
    recording without a gyroscope).
    """

    calibration: Calibration
    intervals: np.ndarray
    acc_stats: StaticStats
    fit: OffsetFit | EllipsoidFit
    gyr_stderr: np.ndarray | None


def tumble_calibration(
    rec: xr.Dataset,
    *,
    model: str = "offsets",
    intervals=None,
    trigger=None,
    threshold_deg_s: float = 3.0,
    min_duration_s: float = 0.4,
    full_scale_g: float | None = None,
    name: str = "tumble test",
) -> TumbleResult:
    """Offsets (and optionally scale/misalignment) from a tumble-test Recording.

    Detects still periods (:func:`detect_static`, or ``intervals``/``trigger``), averages
    the accelerometer in each, fits ``model`` = ``"offsets"`` (:func:`fit_offsets`) or
    ``"ellipsoid"`` (:func:`fit_ellipsoid`, needs ≥ 9 well-spread poses), and takes
    gyroscope offsets as medians during stillness. A Recording without a gyroscope gets
    the accelerometer calibration alone (no gyroscope offset); its still periods must
    then be given (``intervals``, e.g. from the accelerometer rule of
    :func:`tiltlab.behavior.immobility` through :func:`mask_to_intervals`, or
    ``trigger``). Samples outside the still periods may be NaN (gaps).

    Parameters
    ----------
    rec : xarray.Dataset
        Tumble-test Recording (``acc``, optional ``gyr``, with units; ``fs``).
    model : {"offsets", "ellipsoid"}
        Accelerometer fit: offsets only, or the 9-parameter ellipsoid.
    intervals : array_like (P, 2), optional
        Still periods; default detected.
    trigger : DataArray or array_like (N,), optional
        Trigger channel for :func:`detect_static` (e.g. ``rec["trigger"]``).
    threshold_deg_s, min_duration_s : float
        Still-period detection settings (°/s, s), see :func:`detect_static`.
    full_scale_g : float, optional
        Accelerometer full scale (g): periods with saturated samples are refused.
    name : str
        Name of the resulting :class:`Calibration`.

    Returns
    -------
    TumbleResult
        The :class:`Calibration`, the still intervals, the per-period accelerometer
        statistics, the accelerometer fit and the gyroscope offset standard error (°/s).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import calibration, simulate
    >>> rec = simulate.tumble_test(8, 50.0, seed=2)
    >>> res = calibration.tumble_calibration(rec)
    >>> len(res.intervals)  # the start pose, 8 orientations and the return
    10
    >>> np.round(res.calibration.acc_offset, 3).tolist()  # true: -0.005, -0.042, -0.036
    [-0.006, -0.043, -0.037]
    """
    if model not in ("offsets", "ellipsoid"):
        raise ValueError(f"model must be 'offsets' or 'ellipsoid', got {model!r}")
    if not isinstance(rec, xr.Dataset):
        raise TypeError(
            f"rec must be a Recording (xarray.Dataset), got {type(rec).__name__}"
        )
    acc = read_in(rec, "acc", "g", need_fs=False, allow_nan=True)[0].values
    has_gyr = "gyr" in rec
    gyr = read_in(rec, "gyr", "deg/s", allow_nan=True)[0].values if has_gyr else None
    if full_scale_g is not None:
        full_scale_g = _v.positive(full_scale_g, "full_scale_g")
    if intervals is None and trigger is None and not has_gyr:
        raise CalibrationError(
            "the Recording has no gyroscope, so its still periods cannot be found from "
            "the angular speed: give intervals (e.g. calibration.mask_to_intervals of "
            "behavior.immobility(rec), the accelerometer rule) or a trigger"
        )
    if intervals is None and not has_gyr:
        fs = _v.check_fs(rec.attrs.get("fs"))
        tr = _v.signal(trigger, "trigger", fs=fs, width=None, ndim=1).values
        if tr.shape != (acc.shape[0],):
            raise ValueError(
                f"trigger must have shape ({acc.shape[0]},), got {tr.shape}"
            )
        intervals = static_intervals_from_trigger(tr, fs)
    if intervals is None:
        intervals = detect_static(
            rec,
            trigger=trigger,
            threshold_deg_s=threshold_deg_s,
            min_duration_s=min_duration_s,
        )
    stats = static_means(
        acc,
        intervals,
        full_scale=full_scale_g,
        min_periods=3 if model == "offsets" else 9,
    )
    go, gse = gyro_offset(gyr, intervals) if has_gyr else (None, None)
    gyr_info = {"gyr_offset_stderr": gse.tolist()} if has_gyr else {}
    if model == "offsets":
        fit = fit_offsets(stats.mean, sem=stats.sem)
        cal = Calibration(
            name=name,
            acc_offset=fit.offset,
            gyr_offset=go,
            info={
                "acc_offset_stderr": fit.stderr.tolist(),
                **gyr_info,
                "n_poses": int(fit.n),
                "model": model,
            },
        )
    else:
        fit = fit_ellipsoid(stats.mean, sem=stats.sem)
        cal = Calibration(
            name=name,
            acc_offset=fit.offset,
            acc_matrix=fit.matrix,
            gyr_offset=go,
            info={
                "acc_offset_stderr": fit.offset_stderr.tolist(),
                **gyr_info,
                "acc_matrix_stderr": fit.matrix_stderr.tolist(),
                "n_poses": int(fit.n),
                "model": model,
            },
        )
    return TumbleResult(cal, np.asarray(intervals), stats, fit, gse)
