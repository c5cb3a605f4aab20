"""The Recording: tiltlab's data contract for inertial recordings.

A Recording is an :class:`xarray.Dataset` with

* dimensions ``time`` (samples), ``axis`` (``x, y, z``) and, where present, ``quat``
  (``w, x, y, z``);
* coordinate ``time`` in seconds (``units='s'``);
* variables ``acc`` (time, axis) and ``gyr`` (time, axis), optional ``mag``
  (time, axis), ``temp`` (time), ``q_ref`` (time, quat: ground-truth orientation,
  unit, scalar-first, sensor → world) and any extra per-sample variables
  (e.g. a boolean ``movement`` mask);
* mandatory dataset attribute ``fs`` (Hz), ``frame`` (the frame the vectors are
  expressed in, normally ``"sensor"``), and provenance attributes (``source``,
  ``sensor``, ``subject``, ``session``);
* a ``units`` attribute on every physical variable, and optionally a ``range``
  attribute on ``acc``, ``gyr``, ``mag``: the sensor's full scale in those units
  (``r`` for ±r, or ``[low, high]``), from which clipped samples are found.

:func:`make_recording` builds one from arrays and :func:`validate` checks one,
raising :class:`RecordingError` with a message naming the problem. :func:`validate`
also checks that the values are plausible for their units and looks for clipped
samples (:mod:`tiltlab.quality`): hard problems raise, soft ones warn
(:class:`tiltlab.quality.QualityWarning`).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import xarray as xr

from . import _validate as _v
from . import axes as _axes
from . import quality as _quality
from . import units as _units
from ._validate import RecordingError
from .quality import UnitCheckError
from ._validate import check_fs as _check_fs
from ._validate import finite as _finite
from ._validate import nonnegative as _nonnegative
from ._validate import positive as _positive

__all__ = [
    "AXES",
    "QUAT",
    "RecordingError",
    "UnitCheckError",
    "make_recording",
    "validate",
    "to_units",
    "VECTOR_VARS",
]

AXES: tuple[str, str, str] = ("x", "y", "z")
QUAT: tuple[str, str, str, str] = ("w", "x", "y", "z")

#: Per-sample 3-vector variables and the physical quantity each holds.
VECTOR_VARS: dict[str, str] = {
    "acc": "acceleration",
    "gyr": "angular_velocity",
    "mag": "magnetic_field",
}
_QUANTITY = {**VECTOR_VARS, "temp": "temperature", "q_ref": "dimensionless"}
_PROVENANCE = ("source", "sensor", "subject", "session")


def make_recording(
    acc,
    gyr=None,
    fs: float | None = None,
    *,
    acc_units: str | None = None,
    gyr_units: str | None = None,
    mag=None,
    mag_units: str | None = None,
    acc_range=None,
    gyr_range=None,
    mag_range=None,
    temp=None,
    temp_units: str | None = None,
    q_ref=None,
    time=None,
    t0: float = 0.0,
    frame: str = "sensor",
    axes=None,
    preset: str | None = None,
    axis_labels: Sequence[str] | None = None,
    extra: Mapping[str, Any] | None = None,
    attrs: Mapping[str, Any] | None = None,
    validate_result: bool = True,
    check_units: bool = True,
    **validate_kwargs,
) -> xr.Dataset:
    """Build a validated Recording from arrays.

    Parameters
    ----------
    acc : array_like or xarray.DataArray, shape (N, 3)
        Accelerometer samples (specific force) in ``acc_units``.
    gyr : array_like or xarray.DataArray, shape (N, 3), optional
        Gyroscope samples in ``gyr_units``. Optional: most bio-logging tags have none,
        and a Recording without ``gyr`` is valid (methods that need it refuse by name).
    fs : float
        Sampling rate in Hz. Mandatory: tiltlab never assumes a default.
    acc_units, gyr_units, mag_units, temp_units : str
        Units of each variable given (``"g"``, ``"m/s^2"``, ``"deg/s"``, ``"rad/s"``,
        ``"uT"``, ``"degC"`` …). Required for a plain array; a labelled DataArray's
        ``units`` attribute is used when the argument is omitted. tiltlab never assumes a
        unit.
    mag : array_like, shape (N, 3), optional
        Magnetometer samples in ``mag_units``.
    acc_range, gyr_range, mag_range : float or (float, float), optional
        The sensor's full scale (measurement range) in the variable's units, ``r`` for
        ±r or ``(low, high)``, stored as the variable's ``range`` attribute; used to find
        clipped samples (:func:`tiltlab.quality.saturation`). Unknown by default.
    temp : array_like, shape (N,), optional
        Sensor temperature in ``temp_units``.
    q_ref : array_like, shape (N, 4), optional
        Ground-truth orientation, unit quaternions (w, x, y, z), sensor → world.
    time : array_like, shape (N,), optional
        Sample times in seconds; default ``t0 + arange(N) / fs``.
    frame : str
        Frame in which the vectors are expressed (default ``"sensor"``).
    axes : sequence of str or mapping, optional
        How the device's axes map into the sensor frame, e.g. ``["x", "-y", "z"]``, or
        per variable ``{"acc": [...], "gyr": [...]}`` (:func:`tiltlab.axes.remap`).
    preset : str, optional
        A named device convention (:data:`tiltlab.axes.PRESETS`: ``"android"``,
        ``"ios"``, ``"tagtools"``, ``"animal"`` …) giving the axes, signs and axis labels.
        A left-handed device frame is refused unless ``axes`` makes it right-handed.
    axis_labels : sequence of 3 str, optional
        What the sensor axes point to (e.g. ``["forward", "left", "up"]``), stored in
        ``attrs['axis_labels']`` and used by the figure recipes.
    extra : mapping, optional
        Additional per-sample variables, ``name -> array`` (first dim = time) or
        ``name -> (dims, array, attrs)``. Copied: the Recording never shares memory with
        the caller's arrays.
    attrs : mapping, optional
        Dataset attributes (provenance: ``source``, ``sensor``, ``subject``, ``session`` …).
    validate_result : bool
        Run :func:`validate` on the result (default True).
    check_units : bool
        Check the values against their unit labels (:func:`validate`). Decisive
        contradictions raise :class:`UnitCheckError` naming every variable at once;
        ambiguous ones warn and are kept in ``attrs['quality_warnings']``. ``False``
        accepts the labels as they are (the one switch, honoured by every reader and
        command).
    **validate_kwargs
        Passed to :func:`validate`.

    Returns
    -------
    xarray.Dataset
        The Recording.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import schema
    >>> acc = np.tile([0.0, 0.0, 1.0], (200, 1))
    >>> rec = schema.make_recording(acc, fs=50.0, acc_units="g")  # no gyroscope
    >>> sorted(rec.data_vars), rec.attrs["fs"]
    (['acc'], 50.0)
    """
    if fs is None:
        raise RecordingError(
            "fs (sampling rate, Hz) is mandatory; tiltlab never assumes a default"
        )
    try:
        fs = _check_fs(fs)
    except ValueError as err:
        raise RecordingError(str(err)) from None
    acc_units = _given_units(acc, acc_units, "acc")
    acc = _as_array(acc, "acc")
    if acc.ndim != 2 or acc.shape[1] != 3:
        raise RecordingError(f"acc must have shape (N, 3), got {acc.shape}")
    n = acc.shape[0]
    if gyr is not None:
        gyr_units = _given_units(gyr, gyr_units, "gyr")
        gyr = _as_array(gyr, "gyr")
        if gyr.ndim != 2 or gyr.shape[1] != 3:
            raise RecordingError(f"gyr must have shape (N, 3), got {gyr.shape}")
        if gyr.shape[0] != n:
            raise RecordingError(
                f"acc and gyr lengths differ: {n} vs {gyr.shape[0]} samples"
            )
    if mag is not None:
        mag_units = _given_units(mag, mag_units, "mag")
        mag = _as_array(mag, "mag")
    if temp is not None:
        temp_units = _given_units(temp, temp_units, "temp")
        temp = _as_array(temp, "temp")
    if time is None:
        time = t0 + np.arange(n) / fs
    time = np.asarray(time)
    if time.dtype.kind in "mM":
        raise RecordingError(
            "time holds date-times or durations, not seconds: pass the seconds since "
            "the first sample, e.g. (t - t[0]) / np.timedelta64(1, 's'), and keep the "
            "absolute start in attrs['time_origin']"
        )
    time = np.array(time, dtype=float)  # a copy: never alias the caller's array
    if time.shape != (n,):
        raise RecordingError(f"time must have shape ({n},), got {time.shape}")
    frame_attrs: dict[str, Any] = {}
    if axes is not None or preset is not None:
        vectors = {
            k: v for k, v in (("acc", acc), ("gyr", gyr), ("mag", mag)) if v is not None
        }
        try:
            vectors, frame_attrs = _axes.remap(vectors, axes, preset=preset)
        except ValueError as err:
            raise RecordingError(str(err)) from None
        acc, gyr, mag = vectors["acc"], vectors.get("gyr"), vectors.get("mag")
    if axis_labels is not None:
        frame_attrs["axis_labels"] = _axes.check_labels(axis_labels)

    data_vars: dict[str, Any] = {
        "acc": (
            ("time", "axis"),
            acc.copy(),
            {
                "units": _units.normalise_unit(acc_units),
                "long_name": "acceleration (specific force)",
            },
        ),
    }
    if gyr is not None:
        data_vars["gyr"] = (
            ("time", "axis"),
            gyr.copy(),
            {
                "units": _units.normalise_unit(gyr_units),
                "long_name": "angular velocity",
            },
        )
    if mag is not None:
        data_vars["mag"] = (
            ("time", "axis"),
            mag,
            {"units": _units.normalise_unit(mag_units), "long_name": "magnetic field"},
        )
    if temp is not None:
        data_vars["temp"] = (
            ("time",),
            temp,
            {
                "units": _units.normalise_unit(temp_units),
                "long_name": "sensor temperature",
            },
        )
    if q_ref is not None:
        data_vars["q_ref"] = (
            ("time", "quat"),
            np.array(q_ref, dtype=float),
            {
                "units": "1",
                "long_name": "reference orientation, sensor to world",
                "frame": "sensor->world",
            },
        )
    for name, full in (("acc", acc_range), ("gyr", gyr_range), ("mag", mag_range)):
        if full is not None and name in data_vars:
            lo, hi = _quality.limits(full, f"{name}_range", RecordingError)
            data_vars[name][2]["range"] = hi if np.isclose(-lo, hi) else [lo, hi]
    for name, value in (extra or {}).items():
        if isinstance(value, tuple):
            if len(value) < 2:
                raise RecordingError(
                    f"extra variable {name!r}: give (dims, array) or (dims, array, attrs)"
                )
            data_vars[name] = (
                value[0],
                np.array(value[1]),  # a copy, as for every other variable
                *(dict(a) if isinstance(a, Mapping) else a for a in value[2:]),
            )
        else:
            arr = np.array(value)
            dims = (
                ("time",)
                if arr.ndim == 1
                else ("time", "axis")
                if arr.shape[1:] == (3,)
                else None
            )
            if dims is None:
                raise RecordingError(
                    f"extra variable {name!r}: give (dims, array, attrs) for shape {arr.shape}"
                )
            data_vars[name] = (dims, arr)
    ds = xr.Dataset(
        data_vars,
        coords={
            "time": ("time", time, {"units": "s"}),
            "axis": list(AXES),
            **({"quat": list(QUAT)} if q_ref is not None else {}),
        },
        attrs={"fs": fs, "frame": frame, **frame_attrs, **dict(attrs or {})},
    )
    if validate_result:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            validate(ds, check_units=check_units, **validate_kwargs)
        doubts = [
            str(w.message)
            for w in caught
            if issubclass(w.category, _quality.QualityWarning)
        ]
        if doubts:  # ambiguous evidence: kept with the data, and told
            ds.attrs["quality_warnings"] = [
                *list(ds.attrs.get("quality_warnings", [])),
                *doubts,
            ]
        for w in caught:
            warnings.warn_explicit(
                w.message, w.category, w.filename, w.lineno, source=w.source
            )
    return ds


def _given_units(x, units: str | None, name: str) -> str:
    """The unit of a variable: the argument, else a labelled DataArray's ``units``
    attribute (which the argument must not contradict); never a default.
    """
    label = x.attrs.get("units") if isinstance(x, xr.DataArray) else None
    if units is None:
        if label is None:
            raise RecordingError(
                f"{name}_units is required for a plain array: tiltlab never assumes a "
                f"unit (e.g. {name}_units={_EXAMPLE_UNITS[name]!r})"
            )
        units = label
    try:
        canon = _units.normalise_unit(units)
    except _units.UnitsError as exc:
        raise RecordingError(f"{name}_units: {exc}") from None
    if label is not None and _units.normalise_unit(label) != canon:
        raise RecordingError(
            f"{name}_units={units!r} contradicts the DataArray's units {label!r}"
        )
    return canon


def _as_array(x, name: str) -> np.ndarray:
    try:
        return np.array(x, dtype=float)  # a copy: never alias the caller's array
    except (TypeError, ValueError) as exc:
        raise RecordingError(f"{name} must be numeric: {exc}") from None


_EXAMPLE_UNITS = {"acc": "g", "gyr": "deg/s", "mag": "uT", "temp": "degC"}


def _check_vector_var(ds: xr.Dataset, name: str, allow_nan: bool) -> None:
    da = ds[name]
    if da.dims != ("time", "axis"):
        raise RecordingError(f"{name!r} must have dims ('time', 'axis'), got {da.dims}")
    if da.sizes["axis"] != 3:
        raise RecordingError(f"{name!r} must have 3 axes, got {da.sizes['axis']}")
    _check_finite(da, name, allow_nan)


def _check_finite(da: xr.DataArray, name: str, allow_nan: bool) -> None:
    values = np.asarray(da.values, dtype=float)
    bad = ~np.isfinite(values)
    if allow_nan:
        bad &= ~np.isnan(values)  # NaN marks a missing sample; inf is never allowed
    if bad.any():
        idx = np.argwhere(bad)[0]
        raise RecordingError(
            f"{name!r} has {int(bad.sum())} non-finite values (first at index {tuple(int(i) for i in idx)})"
            + (
                ""
                if allow_nan
                else "; NaN is not allowed here (pass allow_nan=True to accept gaps)"
            )
        )


def _check_units(da: xr.DataArray, name: str) -> None:
    u = da.attrs.get("units")
    if u is None:
        raise RecordingError(f"{name!r} has no 'units' attribute")
    try:
        canon = _units.normalise_unit(u)
    except _units.UnitsError as exc:
        raise RecordingError(f"{name!r}: {exc}") from None
    q = _QUANTITY.get(name)
    if q is not None and canon not in _units.UNITS[q]:
        raise RecordingError(
            f"{name!r} has units {u!r}, which do not measure {q.replace('_', ' ')} "
            f"(expected one of {_units.UNITS[q]})"
        )


def validate(
    ds: xr.Dataset,
    *,
    allow_nan: bool = False,
    max_jitter: float = 0.35,
    quat_atol: float = 1e-6,
    check_units: bool = True,
    check_saturation: bool = True,
) -> xr.Dataset:
    """Check that ``ds`` satisfies the Recording contract, and that its values are
    plausible for their units.

    Parameters
    ----------
    ds : xarray.Dataset
        Candidate Recording.
    allow_nan : bool
        Accept NaN (missing samples) in data variables; infinities are always rejected.
    max_jitter : float
        Largest accepted deviation of a sampling interval from ``1/fs``, as a fraction of
        ``1/fs``. The default (0.35) accepts the Fayat example, whose 300 → 100 Hz
        down-sampling left 27 intervals of 2/300 s, and rejects any dropped sample.
    quat_atol : float
        Tolerance on ``| ‖q‖ − 1 |`` for ``q_ref``.
    check_units : bool
        Run the plausibility checks of the values against their units
        (:func:`tiltlab.quality.plausibility`: raw ADC counts, accelerometer magnitude,
        gyroscope rate against the accelerometer's tilt, temperature). Decisive findings
        (e.g. ``acc`` labelled g with a median magnitude of 9.8) raise one
        :class:`UnitCheckError` listing every variable; ambiguous ones warn. ``False``
        accepts the labels as they are: the one switch, honoured by every reader, the
        mapping file (``"check_units": false``), the command line (``--no-check-units``)
        and a cohort manifest's ``reader_options``.
    check_saturation : bool
        Warn (:class:`tiltlab.quality.QualityWarning`) about clipped samples of ``acc``,
        ``gyr`` and ``mag``, with the fraction clipped per variable
        (:func:`tiltlab.quality.check_saturation`).

    Returns
    -------
    xarray.Dataset
        ``ds`` itself (unchanged), so that calls can be chained.

    Raises
    ------
    RecordingError
        With a message naming the first contract problem found.
    UnitCheckError
        (a RecordingError) When values decisively contradict their unit labels; the
        message names every such variable, the likely unit and the switch.

    Warns
    -----
    tiltlab.quality.QualityWarning
        One per soft problem: clipped samples, a doubtful magnitude or temperature.
    """
    if not isinstance(ds, xr.Dataset):
        raise RecordingError(
            f"a Recording is an xarray.Dataset, got {type(ds).__name__}"
        )
    max_jitter = _positive(max_jitter, "max_jitter", allow_zero=True, allow_inf=True)
    quat_atol = _nonnegative(_finite(quat_atol, "quat_atol"), "quat_atol")
    fs = ds.attrs.get("fs")
    if fs is None:
        raise RecordingError(
            "attribute 'fs' (sampling rate, Hz) is missing; it is mandatory"
        )
    try:
        fs = float(fs)
    except (TypeError, ValueError):
        raise RecordingError(
            f"attribute 'fs' must be a number of Hz, got {fs!r}"
        ) from None
    if not np.isfinite(fs) or fs <= 0:
        raise RecordingError(f"attribute 'fs' must be positive and finite, got {fs!r}")
    if "frame" not in ds.attrs:
        raise RecordingError("attribute 'frame' is missing (normally 'sensor')")
    if "acc" not in ds:
        raise RecordingError(
            "variable 'acc' is missing (a Recording needs at least an accelerometer)"
        )
    if "time" not in ds.coords:
        raise RecordingError("coordinate 'time' is missing")
    if "axis" not in ds.coords or tuple(str(a) for a in ds["axis"].values) != AXES:
        raise RecordingError(f"coordinate 'axis' must be {AXES}")
    if "gyr" in ds:
        n_acc, n_gyr = ds["acc"].sizes.get("time"), ds["gyr"].sizes.get("time")
        if n_acc != n_gyr:
            raise RecordingError(
                f"acc and gyr lengths differ: {n_acc} vs {n_gyr} samples"
            )

    t = _v._numeric_time(ds["time"], "validate")  # date-times refused by name
    if t.ndim != 1:
        raise RecordingError("coordinate 'time' must be one-dimensional")
    if not np.all(np.isfinite(t)):
        raise RecordingError("coordinate 'time' has non-finite values")
    if t.size >= 2:
        dt = np.diff(t)
        if np.any(dt <= 0):
            i = int(np.argmax(dt <= 0))
            raise RecordingError(
                f"time is not strictly increasing (at sample {i + 1}: {t[i]} → {t[i + 1]} s)"
            )
        jitter = np.abs(dt * fs - 1.0)
        if jitter.max() > max_jitter:
            i = int(np.argmax(jitter))
            raise RecordingError(
                f"time is irregular: interval {i}→{i + 1} is {dt[i]:.6g} s where 1/fs = {1 / fs:.6g} s "
                f"(deviation {jitter[i]:.2f} sample periods > max_jitter={max_jitter}); "
                "a dropped or duplicated sample, or a wrong fs"
                + _v.time_unit_hint(float(np.median(dt)), fs)
            )
    if ds["time"].attrs.get("units", "s") != "s":
        raise RecordingError(
            f"coordinate 'time' must be in seconds, got units {ds['time'].attrs['units']!r}"
        )

    for name in VECTOR_VARS:
        if name in ds:
            _check_vector_var(ds, name, allow_nan)
            _check_units(ds[name], name)
            _quality.full_scale(ds[name], repr(name))  # a malformed 'range' is an error
    if "temp" in ds:
        if ds["temp"].dims != ("time",):
            raise RecordingError(
                f"'temp' must have dims ('time',), got {ds['temp'].dims}"
            )
        _check_finite(ds["temp"], "temp", allow_nan)
        _check_units(ds["temp"], "temp")
    if "q_ref" in ds:
        q = ds["q_ref"]
        if q.dims != ("time", "quat"):
            raise RecordingError(
                f"'q_ref' must have dims ('time', 'quat'), got {q.dims}"
            )
        if tuple(str(c) for c in ds["quat"].values) != QUAT:
            raise RecordingError(f"coordinate 'quat' must be {QUAT} (scalar first)")
        _check_finite(q, "q_ref", allow_nan)
        qv = np.asarray(q.values, dtype=float)
        norms = np.linalg.norm(qv, axis=1)
        bad = np.abs(norms - 1.0) > quat_atol
        if allow_nan:
            bad &= np.isfinite(norms)
        if bad.any():
            i = int(np.argmax(bad))
            raise RecordingError(
                f"'q_ref' has {int(bad.sum())} non-unit quaternions (first at sample {i}, norm {norms[i]:.6g})"
            )
    for name, da in ds.data_vars.items():
        if "time" in da.dims and da.dims[0] != "time":
            raise RecordingError(
                f"variable {name!r}: 'time' must be the first dimension, got {da.dims}"
            )

    findings = _quality.plausibility(ds) if check_units else []
    errors = [f for f in findings if f.is_error]
    if errors:
        raise UnitCheckError(errors)
    if check_saturation:
        findings += _quality.check_saturation(ds)
    _quality.emit(findings)
    return ds


def to_units(ds: xr.Dataset, **targets: str) -> xr.Dataset:
    """Return a copy of ``ds`` with variables converted, e.g. ``to_units(rec, acc='m/s^2', gyr='rad/s')``.

    Attributes are kept and each converted variable's ``units`` attribute is updated, and
    its ``range`` (full scale) converted. The copy is deep: it shares no memory with
    ``ds``.

    Parameters
    ----------
    ds : xarray.Dataset
        A Recording whose variables carry a ``units`` attribute.
    **targets : str
        Variable name → target unit (any accepted spelling, see
        :func:`tiltlab.units.normalise_unit`).

    Returns
    -------
    xarray.Dataset
        The converted deep copy.

    Raises
    ------
    RecordingError
        If a named variable is missing or has no ``units`` attribute.
    tiltlab.units.UnitsError
        If a conversion is impossible.
    """
    out = ds.copy(deep=True)
    for name, dst in targets.items():
        if name not in ds:
            raise RecordingError(f"variable {name!r} is not in the Recording")
        src = ds[name].attrs.get("units")
        if src is None:
            raise RecordingError(f"{name!r} has no 'units' attribute")
        f = _units.conversion_factor(src, dst)
        out[name] = ds[name] * f
        attrs = {**ds[name].attrs, "units": _units.normalise_unit(dst)}
        full = _quality.full_scale(ds[name], repr(name))
        if full is not None:
            lo, hi = full[0] * f, full[1] * f
            attrs["range"] = hi if np.isclose(-lo, hi) else [lo, hi]
        out[name].attrs = attrs
    return out


def provenance(ds: xr.Dataset) -> dict[str, Any]:
    """The provenance attributes of a Recording (missing ones as None)."""
    return {k: ds.attrs.get(k) for k in _PROVENANCE}


def describe(ds: xr.Dataset) -> dict[str, Any]:
    """A one-line summary of a Recording: samples, duration, rate, variables with units, gaps.

    Returns
    -------
    dict
        Keys ``session, samples, duration_s, fs_hz, variables, missing_q_ref`` (fraction of
        samples whose reference orientation is NaN, or None without ``q_ref``).
    """
    t = ds["time"].values
    variables = ", ".join(
        f"{v} [{ds[v].attrs['units']}]" if "units" in ds[v].attrs else str(v)
        for v in ds.data_vars
    )
    missing = None
    if "q_ref" in ds:
        missing = float(np.mean(~np.isfinite(ds["q_ref"].values).all(axis=1)))
    return {
        "session": ds.attrs.get("session"),
        "samples": int(ds.sizes["time"]),
        "duration_s": float(t[-1] - t[0] + 1.0 / float(ds.attrs["fs"]))
        if t.size
        else 0.0,
        "fs_hz": float(ds.attrs["fs"]),
        "variables": variables,
        "missing_q_ref": missing,
    }
