"""The Recording: the one place that says what a Recording is, builds one and checks one.

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

What belongs here: the variables, dimensions and attributes of a Recording, building
and validating one, converting its units and summarising it. What does not: checks of
function arguments (arrays, sampling rates, scalars: :mod:`tiltlab._validate`), the
data-quality findings themselves (saturation, unit plausibility: :mod:`tiltlab.quality`)
and the unit table (:mod:`tiltlab.units`).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from . import _validate as _v
from . import axes as _axes
from . import quality as _quality
from . import units as _units
from ._deprecate import renamed
from ._recording_options import Options, read_options
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
    "provenance",
    "describe",
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
#: The sensor variables with a unit: their dims and long name.
_SENSORS: dict[str, tuple[tuple[str, ...], str]] = {
    "acc": (("time", "axis"), "acceleration (specific force)"),
    "gyr": (("time", "axis"), "angular velocity"),
    "mag": (("time", "axis"), "magnetic field"),
    "temp": (("time",), "sensor temperature"),
}
_EXAMPLE_UNITS = {"acc": "g", "gyr": "deg/s", "mag": "uT", "temp": "degC"}
#: Keywords of :func:`validate` that :func:`make_recording` passes on.
_VALIDATE_OPTIONS = ("allow_nan", "max_jitter", "quat_atol", "check_saturation")


# --------------------------------------------------------------------------- building


def make_recording(
    acc,
    gyr=None,
    fs: float | None = None,
    *,
    mag=None,
    temp=None,
    q_ref=None,
    time=None,
    units: Mapping[str, str] | None = None,
    extra: Mapping[str, Any] | None = None,
    attrs: Mapping[str, Any] | None = None,
    **options,
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
    mag : array_like, shape (N, 3), optional
        Magnetometer samples in ``mag_units``.
    temp : array_like, shape (N,), optional
        Sensor temperature in ``temp_units``.
    q_ref : array_like, shape (N, 4), optional
        Ground-truth orientation, unit quaternions (w, x, y, z), sensor → world.
    time : array_like, shape (N,), optional
        Sample times in seconds; default ``t0 + arange(N) / fs``.
    units : mapping, optional
        Units of each variable given, e.g. ``{"acc": "g", "gyr": "deg/s"}`` (``"g"``,
        ``"m/s^2"``, ``"deg/s"``, ``"rad/s"``, ``"uT"``, ``"degC"`` …); the same as
        the keywords ``acc_units=``, ``gyr_units=``, ``mag_units=``, ``temp_units=``.
        Required for a plain array; a labelled DataArray's ``units`` attribute is used
        when none is given. tiltlab never assumes a unit.
    extra : mapping, optional
        Additional per-sample variables, ``name -> array`` (first dim = time) or
        ``name -> (dims, array, attrs)``. Copied: the Recording never shares memory with
        the caller's arrays.
    attrs : mapping, optional
        Dataset attributes (provenance: ``source``, ``sensor``, ``subject``, ``session`` …).
    **options
        The keywords listed under Other Parameters.

    Returns
    -------
    xarray.Dataset
        The Recording.

    Other Parameters
    ----------------
    acc_units, gyr_units, mag_units, temp_units : str
        The unit of one variable (shorthand for an entry of ``units``).
    ranges : mapping, optional
        The sensors' full scales, e.g. ``{"acc": 16, "gyr": 2000}``, in each variable's
        units: ``r`` for ±r or ``(low, high)``; stored as the variable's ``range``
        attribute and used to find clipped samples
        (:func:`tiltlab.quality.saturation`). Unknown by default.
    acc_range, gyr_range, mag_range : float or (float, float)
        The full scale of one sensor (shorthand for an entry of ``ranges``).
    t0 : float
        Time of the first sample (s) when ``time`` is not given (default 0).
    frame : str
        Frame in which the vectors are expressed (default ``"sensor"``).
    axes : sequence of str or mapping
        How the device's axes map into the sensor frame, e.g. ``["x", "-y", "z"]``, or
        per variable ``{"acc": [...], "gyr": [...]}`` (:func:`tiltlab.axes.remap`).
    preset : str
        A named device convention (:data:`tiltlab.axes.PRESETS`: ``"android"``,
        ``"ios"``, ``"tagtools"``, ``"animal"`` …) giving the axes, signs and axis labels.
        A left-handed device frame is refused unless ``axes`` makes it right-handed.
    axis_labels : sequence of 3 str
        What the sensor axes point to (e.g. ``["forward", "left", "up"]``), stored in
        ``attrs['axis_labels']`` and used by the figure recipes.
    validate_result : bool
        Run :func:`validate` on the result (default True).
    check_units : bool
        Check the values against their unit labels (:func:`validate`). Decisive
        contradictions raise :class:`UnitCheckError` naming every variable at once;
        ambiguous ones warn and are kept in ``attrs['quality_warnings']``. ``False``
        accepts the labels as they are (the one switch, honoured by every reader and
        command).
    allow_nan, max_jitter, quat_atol, check_saturation
        Passed to :func:`validate`.

    Raises
    ------
    RecordingError
        A missing sampling rate or unit, a wrong shape, or a result that breaks the
        contract (:func:`validate`).
    TypeError
        An unknown keyword, or a unit or full scale given twice.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import schema
    >>> acc = np.tile([0.0, 0.0, 1.0], (200, 1))
    >>> rec = schema.make_recording(acc, fs=50.0, acc_units="g")  # no gyroscope
    >>> sorted(rec.data_vars), rec.attrs["fs"]
    (['acc'], 50.0)
    >>> gyr = np.zeros((200, 3))
    >>> rec = schema.make_recording(acc, gyr, 50.0, units={"acc": "g", "gyr": "deg/s"})
    >>> rec["gyr"].attrs["units"], float(rec["time"][-1])
    ('deg/s', 3.98)
    """
    opts = read_options(
        units,
        options,
        unit_vars=tuple(_SENSORS),
        range_vars=tuple(VECTOR_VARS),
        validate_keys=_VALIDATE_OPTIONS,
    )
    fs = _recording_fs(fs)
    sensors = _sensor_arrays({"acc": acc, "gyr": gyr, "mag": mag, "temp": temp}, opts)
    n = sensors["acc"][0].shape[0]
    t = _time_axis(time, opts.t0, n, fs)
    frame_attrs = _remap_axes(sensors, opts)
    data_vars: dict[str, Any] = {}
    for name, (values, unit) in sensors.items():
        dims, long_name = _SENSORS[name]
        data_vars[name] = (dims, values.copy(), {"units": unit, "long_name": long_name})
    if q_ref is not None:
        data_vars["q_ref"] = (
            ("time", "quat"),
            np.array(q_ref, dtype=float),
            {
                "units": "1",
                "long_name": "reference orientation, sensor to world",
                "frame": "sensor->world",
                # what the sensor axes point to travels with the orientation, as it
                # does on the filters' estimates (tilt from it is labelled alike)
                **(
                    {"axis_labels": list(frame_attrs["axis_labels"])}
                    if "axis_labels" in frame_attrs
                    else {}
                ),
            },
        )
    _set_ranges(data_vars, opts.ranges)
    for name, value in (extra or {}).items():
        data_vars[name] = _extra_variable(name, value)
    rec = xr.Dataset(
        data_vars,
        coords={
            "time": ("time", t, {"units": "s"}),
            "axis": list(AXES),
            **({"quat": list(QUAT)} if q_ref is not None else {}),
        },
        attrs={"fs": fs, "frame": opts.frame, **frame_attrs, **dict(attrs or {})},
    )
    if opts.validate_result:
        _validate_and_keep_doubts(rec, opts)
    return rec


def _recording_fs(fs) -> float:
    """Check the mandatory sampling rate, a contract problem (:class:`RecordingError`)."""
    if fs is None:
        raise RecordingError(
            "fs (sampling rate, Hz) is mandatory; tiltlab never assumes a default"
        )
    try:
        return _check_fs(fs)
    except ValueError as err:
        raise RecordingError(str(err)) from None


def _sensor_arrays(
    given: Mapping[str, Any], opts: Options
) -> dict[str, tuple[np.ndarray, str]]:
    """Each sensor given as ``(float copy, canonical unit)``, shapes checked."""
    out: dict[str, tuple[np.ndarray, str]] = {}
    for name, x in given.items():
        if x is None:
            continue
        unit = _given_units(x, opts.units.get(name), name)
        out[name] = (_as_array(x, name), unit)
    n = None
    for name in ("acc", "gyr"):
        if name not in out:
            continue
        values = out[name][0]
        if values.ndim != 2 or values.shape[1] != 3:
            raise RecordingError(f"{name} must have shape (N, 3), got {values.shape}")
        if n is not None and values.shape[0] != n:
            raise RecordingError(
                f"acc and gyr lengths differ: {n} vs {values.shape[0]} samples"
            )
        n = values.shape[0]
    return out


def _time_axis(time, t0: float, n: int, fs: float) -> np.ndarray:
    """Return the time coordinate (s), a copy: ``time`` or ``t0 + arange(n) / fs``."""
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
    return time


def _remap_axes(sensors: dict[str, tuple[np.ndarray, str]], opts: Options) -> dict:
    """Express the vectors in the sensor frame (in place in ``sensors``); frame attrs."""
    frame_attrs: dict[str, Any] = {}
    if opts.axes is not None or opts.preset is not None:
        vectors = {k: sensors[k][0] for k in VECTOR_VARS if k in sensors}
        try:
            vectors, frame_attrs = _axes.remap(vectors, opts.axes, preset=opts.preset)
        except ValueError as err:
            raise RecordingError(str(err)) from None
        for name, values in vectors.items():
            sensors[name] = (values, sensors[name][1])
    if opts.axis_labels is not None:
        frame_attrs["axis_labels"] = _axes.check_labels(opts.axis_labels)
    return frame_attrs


def _set_ranges(data_vars: dict[str, Any], ranges: Mapping[str, Any]) -> None:
    """Store each given full scale as its variable's ``range`` attribute."""
    for name, full in ranges.items():
        if full is not None and name in data_vars:
            lo, hi = _quality.limits(full, f"{name}_range", RecordingError)
            data_vars[name][2]["range"] = hi if np.isclose(-lo, hi) else [lo, hi]


def _extra_variable(name: str, value) -> tuple:
    """Return an extra per-sample variable as ``(dims, array copy[, attrs])``."""
    if isinstance(value, tuple):
        if len(value) < 2:
            raise RecordingError(
                f"extra variable {name!r}: give (dims, array) or (dims, array, attrs)"
            )
        return (
            value[0],
            np.array(value[1]),  # a copy, as for every other variable
            *(dict(a) if isinstance(a, Mapping) else a for a in value[2:]),
        )
    arr = np.array(value)
    if arr.ndim == 1:
        return (("time",), arr)
    if arr.shape[1:] == (3,):
        return (("time", "axis"), arr)
    raise RecordingError(
        f"extra variable {name!r}: give (dims, array, attrs) for shape {arr.shape}"
    )


def _validate_and_keep_doubts(rec: xr.Dataset, opts: Options) -> None:
    """Validate ``rec``; keep its quality warnings in attrs and warn them again."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        validate(rec, check_units=opts.check_units, **opts.validate_kwargs)
    doubts = [
        str(w.message)
        for w in caught
        if issubclass(w.category, _quality.QualityWarning)
    ]
    if doubts:  # ambiguous evidence: kept with the data, and told
        rec.attrs["quality_warnings"] = [
            *list(rec.attrs.get("quality_warnings", [])),
            *doubts,
        ]
    for w in caught:
        warnings.warn_explicit(
            w.message, w.category, w.filename, w.lineno, source=w.source
        )


def _given_units(x, units: str | None, name: str) -> str:
    """Return the unit of a variable: the argument, else a DataArray's ``units``.

    The argument must not contradict a labelled DataArray's attribute; there is never a
    default.
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


# --------------------------------------------------------------------------- checking


def _check_vector_var(rec: xr.Dataset, name: str, allow_nan: bool) -> None:
    da = rec[name]
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


def _check_structure(rec: xr.Dataset) -> float:
    """Check the attributes and the coordinates of a Recording; return its ``fs``."""
    fs = rec.attrs.get("fs")
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
    if "frame" not in rec.attrs:
        raise RecordingError("attribute 'frame' is missing (normally 'sensor')")
    if "acc" not in rec:
        raise RecordingError(
            "variable 'acc' is missing (a Recording needs at least an accelerometer)"
        )
    if "time" not in rec.coords:
        raise RecordingError("coordinate 'time' is missing")
    if "axis" not in rec.coords or tuple(str(a) for a in rec["axis"].values) != AXES:
        raise RecordingError(f"coordinate 'axis' must be {AXES}")
    if "gyr" in rec:
        n_acc, n_gyr = rec["acc"].sizes.get("time"), rec["gyr"].sizes.get("time")
        if n_acc != n_gyr:
            raise RecordingError(
                f"acc and gyr lengths differ: {n_acc} vs {n_gyr} samples"
            )
    return fs


def _check_time(rec: xr.Dataset, fs: float, max_jitter: float) -> None:
    """Check that ``time`` is 1-D, finite, strictly increasing, regular and in seconds."""
    t = _v._numeric_time(rec["time"], "validate")  # date-times refused by name
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
    if rec["time"].attrs.get("units", "s") != "s":
        raise RecordingError(
            f"coordinate 'time' must be in seconds, got units {rec['time'].attrs['units']!r}"
        )


def _check_q_ref(rec: xr.Dataset, allow_nan: bool, quat_atol: float) -> None:
    """Check the dims, the ``quat`` coordinate and the unit norm of ``q_ref``."""
    q = rec["q_ref"]
    if q.dims != ("time", "quat"):
        raise RecordingError(f"'q_ref' must have dims ('time', 'quat'), got {q.dims}")
    if tuple(str(c) for c in rec["quat"].values) != QUAT:
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


def _check_variables(rec: xr.Dataset, allow_nan: bool, quat_atol: float) -> None:
    """Check the dims, values and units of every variable of a Recording."""
    for name in VECTOR_VARS:
        if name in rec:
            _check_vector_var(rec, name, allow_nan)
            _check_units(rec[name], name)
            _quality.full_scale(
                rec[name], repr(name)
            )  # a malformed 'range' is an error
    if "temp" in rec:
        if rec["temp"].dims != ("time",):
            raise RecordingError(
                f"'temp' must have dims ('time',), got {rec['temp'].dims}"
            )
        _check_finite(rec["temp"], "temp", allow_nan)
        _check_units(rec["temp"], "temp")
    if "q_ref" in rec:
        _check_q_ref(rec, allow_nan, quat_atol)
    for name, da in rec.data_vars.items():
        if "time" in da.dims and da.dims[0] != "time":
            raise RecordingError(
                f"variable {name!r}: 'time' must be the first dimension, got {da.dims}"
            )


@renamed(ds="rec")
def validate(
    rec: xr.Dataset,
    *,
    allow_nan: bool = False,
    max_jitter: float = 0.35,
    quat_atol: float = 1e-6,
    check_units: bool = True,
    check_saturation: bool = True,
) -> xr.Dataset:
    """Check that ``rec`` satisfies the Recording contract and has plausible values.

    Parameters
    ----------
    rec : xarray.Dataset
        Candidate Recording (``ds`` is its old name).
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
        ``rec`` itself (unchanged), so that calls can be chained.

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
    if not isinstance(rec, xr.Dataset):
        raise RecordingError(
            f"a Recording is an xarray.Dataset, got {type(rec).__name__}"
        )
    max_jitter = _positive(max_jitter, "max_jitter", allow_zero=True, allow_inf=True)
    quat_atol = _nonnegative(_finite(quat_atol, "quat_atol"), "quat_atol")
    fs = _check_structure(rec)
    _check_time(rec, fs, max_jitter)
    _check_variables(rec, allow_nan, quat_atol)
    findings = _quality.plausibility(rec) if check_units else []
    errors = [f for f in findings if f.is_error]
    if errors:
        raise UnitCheckError(errors)
    if check_saturation:
        findings += _quality.check_saturation(rec)
    _quality.emit(findings)
    return rec


# --------------------------------------------------------------------------- using


@renamed(ds="rec")
def to_units(rec: xr.Dataset, **targets: str) -> xr.Dataset:
    """Return a copy of ``rec`` with variables converted to other units.

    Attributes are kept and each converted variable's ``units`` attribute is updated, and
    its ``range`` (full scale) converted. The copy is deep: it shares no memory with
    ``rec``.

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording whose variables carry a ``units`` attribute (``ds`` is its old
        name).
    **targets : str
        Variable name → target unit (any accepted spelling, see
        :func:`tiltlab.units.normalise_unit`), e.g. ``acc="m/s^2", gyr="rad/s"``.

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

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import schema
    >>> acc = np.tile([0.0, 0.0, 1.0], (100, 1))
    >>> rec = schema.make_recording(acc, fs=50.0, acc_units="g", acc_range=2)
    >>> si = schema.to_units(rec, acc="m/s^2")
    >>> si["acc"].attrs["units"], float(si["acc"][0, 2]), si["acc"].attrs["range"]
    ('m/s^2', 9.80665, 19.6133)
    """
    out = rec.copy(deep=True)
    for name, dst in targets.items():
        if name not in rec:
            raise RecordingError(f"variable {name!r} is not in the Recording")
        src = rec[name].attrs.get("units")
        if src is None:
            raise RecordingError(f"{name!r} has no 'units' attribute")
        f = _units.conversion_factor(src, dst)
        out[name] = rec[name] * f
        attrs = {**rec[name].attrs, "units": _units.normalise_unit(dst)}
        full = _quality.full_scale(rec[name], repr(name))
        if full is not None:
            lo, hi = full[0] * f, full[1] * f
            attrs["range"] = hi if np.isclose(-lo, hi) else [lo, hi]
        out[name].attrs = attrs
    return out


@renamed(ds="rec")
def provenance(rec: xr.Dataset) -> dict[str, Any]:
    """Return the provenance attributes of a Recording.

    Parameters
    ----------
    rec : xarray.Dataset
        The Recording whose attrs are read (``ds``: the old keyword).

    Returns
    -------
    dict
        ``source``, ``sensor``, ``subject`` and ``session`` (None where missing).
    """
    return {k: rec.attrs.get(k) for k in _PROVENANCE}


@renamed(ds="rec")
def describe(rec: xr.Dataset) -> dict[str, Any]:
    """Summarise a Recording in one line: samples, duration, rate, variables, gaps.

    Parameters
    ----------
    rec : xarray.Dataset
        The Recording to summarise; its old keyword was ``ds``.

    Returns
    -------
    dict
        Keys ``session, samples, duration_s, fs_hz, variables, missing_q_ref`` (fraction of
        samples whose reference orientation is NaN, or None without ``q_ref``).

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import schema
    >>> acc = np.tile([0.0, 0.0, 1.0], (100, 1))
    >>> rec = schema.make_recording(acc, fs=50.0, acc_units="g", attrs={"session": "s1"})
    >>> schema.describe(rec)
    {'session': 's1', 'samples': 100, 'duration_s': 2.0, 'fs_hz': 50.0, 'variables': 'acc [g]', 'missing_q_ref': None}
    """
    t = rec["time"].values
    variables = ", ".join(
        f"{v} [{rec[v].attrs['units']}]" if "units" in rec[v].attrs else str(v)
        for v in rec.data_vars
    )
    missing = None
    if "q_ref" in rec:
        missing = float(np.mean(~np.isfinite(rec["q_ref"].values).all(axis=1)))
    return {
        "session": rec.attrs.get("session"),
        "samples": int(rec.sizes["time"]),
        "duration_s": float(t[-1] - t[0] + 1.0 / float(rec.attrs["fs"]))
        if t.size
        else 0.0,
        "fs_hz": float(rec.attrs["fs"]),
        "variables": variables,
        "missing_q_ref": missing,
    }
