"""Share the orientation filters' pieces: input checks, initial orientation, options.

The input checks, the initial orientation, the minimal tilt quaternion, ``q0`` and
``gyr_offset`` handling, and the tuning records of the Kalman filters (:func:`tuned`).

Every filter function reads its arrays through :func:`read_sensors` (or
:func:`unlabel` then :func:`samples`) and its numeric parameters through
:mod:`tiltlab._validate`, so that the same mistake gives the same message in every
method, and labelled inputs (DataArrays with ``units`` and ``fs`` attributes) are
honoured the same way in every method: :func:`unlabel` converts them once, at entry,
to the plain arrays in the units the kernels use.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np
import xarray as xr

from .. import _validate as _v
from .. import quaternion as quat
from .. import units as _units
from ._shared_kernel import _scan_samples

__all__ = [
    "check_tuning",
    "initial_orientation",
    "offset_vector",
    "tuned",
    "is_labelled",
    "read_sensors",
    "tilt_quaternion",
    "samples",
    "sensor_inputs",
    "start_orientation",
    "unlabel",
]

F = TypeVar("F", bound=Callable[..., Any])


def _checked(a, name: str, n: int | None, nonzero: bool | None):
    """Return ``(samples, largest absolute value)``; see :func:`samples`."""
    x = _v.vectors(a, name, width=3, ndim=2, copy=False, check_values=False)
    if x.shape[0] == 0:
        raise ValueError(
            f"{name} is empty (0 samples); the filters need at least one sample"
        )
    # two vectorised reductions, no temporary: NaN and ±inf show in the extremes;
    # the values are counted (one compiled pass) only when something is wrong
    hi, lo = float(x.max()), float(x.min())
    if np.isfinite(hi) and np.isfinite(lo):
        n_nan, n_inf, nonzero_seen, peak = 0, 0, hi != 0.0 or lo != 0.0, max(hi, -lo)
    else:
        n_nan, n_inf, nonzero_seen, peak = _scan_samples(x)
    if n_inf:
        raise ValueError(f"{name} has {n_inf} infinite values")
    if n_nan:
        raise ValueError(
            f"{name} has {n_nan} NaN values; the filters need finite samples "
            "(interpolate or split the recording)"
        )
    if n is not None and x.shape[0] != n:
        raise ValueError(f"{name} has {x.shape[0]} samples, expected {n}")
    if (name == "acc" if nonzero is None else nonzero) and not nonzero_seen:
        what = "; no gravity direction can be defined" if name == "acc" else ""
        raise ValueError(
            f"{name} is zero in all {x.shape[0]} samples (a disconnected or "
            f"zero-filled sensor?){what}"
        )
    return x, float(peak)


def samples(
    a, name: str, n: int | None = None, *, nonzero: bool | None = None
) -> np.ndarray:
    """Return ``a`` as contiguous float (N, 3) samples, refusing bad samples by name.

    Refused (a ValueError naming ``name``): a wrong shape, no samples at all, NaN or infinite values (the filters need
    finite samples: interpolate or split the recording, e.g. with
    ``estimate(..., gaps="segments")``), a length other than ``n`` and, with
    ``nonzero`` (default: for ``acc``), samples that are all zero (an accelerometer
    that reads exactly zero throughout has no gravity direction: a disconnected sensor
    or a zero-filled dropout).

    Parameters
    ----------
    a : array_like, shape (N, 3)
        The samples.
    name : str
        The input's name, for the messages.
    n : int, optional
        The number of samples required.
    nonzero : bool, optional
        Refuse samples that are all zero (default: for ``acc`` only).

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        Contiguous float64 samples: ``a`` itself when it already is such an array
        (the filters only read it), else a converted copy. Checked in one compiled
        pass (finiteness, an all-zero sensor).
    """
    return _checked(a, name, n, nonzero)[0]


#: Angular rates (rad/s) above this are refused: about 100 times the range of MEMS
#: gyroscopes (±2000–4000 °/s), far below where the kernels' arithmetic would overflow.
MAX_GYR_RAD_S = 1.0e4


def sensor_inputs(acc, gyr, mag=None):
    """Return ``(acc, gyr, mag_or_dummy, use_mag)`` as contiguous arrays for the kernels.

    Plain arrays (labelled ones are read first by :func:`unlabel`: see
    :func:`read_sensors`). Every filter and adapter reads its arrays here (or through
    :func:`samples`), so that they all refuse the same inputs: empty arrays, non-finite
    samples, mismatched lengths, an ``acc`` (or a given ``mag``) that is zero in every
    sample, and angular rates above :data:`MAX_GYR_RAD_S`.
    Without a magnetometer, a (1, 3) zero array stands in for ``mag`` (the kernels take
    an array in every case) and ``use_mag`` is False.

    Parameters
    ----------
    acc, gyr : array_like, shape (N, 3)
        Accelerometer and gyroscope samples (plain arrays; ``gyr`` in rad/s).
    mag : array_like, shape (N, 3), optional
        Magnetometer samples.

    Returns
    -------
    tuple
        ``(acc, gyr, mag_or_dummy, use_mag)``: three float64 arrays and a bool.
    """
    acc = samples(acc, "acc", nonzero=True)
    gyr, peak = _checked(gyr, "gyr", acc.shape[0], None)
    if peak > MAX_GYR_RAD_S:
        raise ValueError(
            f"gyr reaches {peak:.3g} rad/s ({np.degrees(peak):.3g} deg/s), beyond any "
            f"gyroscope (limit {MAX_GYR_RAD_S:g} rad/s): check its units or scale"
        )
    if mag is None:
        return acc, gyr, np.zeros((1, 3)), False
    return acc, gyr, samples(mag, "mag", acc.shape[0], nonzero=True), True


def read_sensors(fs, acc, gyr, mag=None, *, acc_si: bool = False):
    """Return ``(fs, acc, gyr, mag_or_dummy, use_mag)`` for the kernels, labels honoured.

    :func:`unlabel` (labelled inputs: units converted to m/s² and rad/s, ``fs`` read
    and cross-checked) followed by :func:`sensor_inputs` (shape, finiteness, length
    and range checks). Plain arrays give exactly what ``check_fs`` and
    :func:`sensor_inputs` gave before labels were read.

    Parameters
    ----------
    fs : float or None
        Sampling rate (Hz); may be None for labelled inputs with ``attrs["fs"]``.
    acc, gyr : array_like or xarray.DataArray, shape (N, 3)
        Accelerometer and gyroscope samples.
    mag : array_like or xarray.DataArray, shape (N, 3), optional
        Magnetometer samples.
    acc_si : bool
        The method uses ``acc`` in m/s² (a labelled ``acc`` needs ``units``).

    Returns
    -------
    tuple
        ``(fs, acc, gyr, mag_or_dummy, use_mag)``, as :func:`sensor_inputs` with the
        sampling rate first.
    """
    fs, acc, gyr, mag = unlabel(fs, acc=acc, gyr=gyr, mag=mag, acc_si=acc_si)
    return (fs, *sensor_inputs(acc, gyr, mag))


def init_samples(init_window_s: float, fs: float) -> int:
    """Count the samples (at least 1) in an initialisation window.

    Parameters
    ----------
    init_window_s : float
        The window (s), ``>= 0``.
    fs : float
        Sampling rate (Hz).

    Returns
    -------
    int
        ``max(1, round(init_window_s * fs))``.
    """
    init_window_s = _v.nonnegative(init_window_s, "init_window_s")
    return max(1, int(round(init_window_s * fs)))


def start_orientation(q0, acc, mag, fs: float, init_window_s: float) -> np.ndarray:
    """Return the initial orientation: ``q0`` normalised, or one from the first samples.

    Parameters
    ----------
    q0 : array_like, shape (4,) or None
        A given initial orientation (any non-zero norm).
    acc : numpy.ndarray, shape (N, 3)
        Accelerometer samples.
    mag : numpy.ndarray, shape (N, 3) or None
        Magnetometer samples (9D).
    fs : float
        Sampling rate (Hz).
    init_window_s : float
        Without ``q0``: :func:`initial_orientation` of the first ``init_window_s``
        seconds of ``acc`` (and ``mag``).

    Returns
    -------
    numpy.ndarray, shape (4,)
        Unit quaternion, sensor → world.
    """
    n = init_samples(init_window_s, fs)
    if q0 is None:
        return initial_orientation(acc[:n], None if mag is None else mag[:n])
    q = np.asarray(q0, dtype=np.float64).reshape(-1)
    if q.shape != (4,) or not np.all(np.isfinite(q)) or np.linalg.norm(q) == 0:
        raise ValueError(
            f"q0 must be a finite non-zero quaternion (w, x, y, z), got {q0!r}"
        )
    return q / np.linalg.norm(q)


def tilt_quaternion(g) -> np.ndarray:
    """Return the minimal rotations (zero heading part) taking unit ``g`` to e_z.

    Parameters
    ----------
    g : array_like, shape (..., 3)
        Unit vectors (sensor frame); ``g = -e_z`` gives the half turn about x.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions sensor → world with ``R(q) g = e_z``.
    """
    g = np.asarray(g, float)
    q = np.stack(
        [1.0 + g[..., 2], g[..., 1], -g[..., 0], np.zeros(g.shape[:-1])], axis=-1
    )
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    flip = n[..., 0] < 1e-9
    return np.where(
        flip[..., None],
        np.array([0.0, 1.0, 0.0, 0.0]),
        q / np.where(n == 0, 1.0, n),
    )


def initial_orientation(acc, mag=None) -> np.ndarray:
    r"""Orientation from a few (quasi-static) samples, TRIAD-style.

    The mean specific force :math:`\bar a` defines world up. Without magnetometer the
    quaternion is the minimal rotation taking :math:`\hat a` to :math:`e_z` (its heading
    part is zero: :math:`q_z = 0`). With magnetometer, TRIAD (Shuster & Oh 1981) with
    the gravity as the primary vector: east :math:`e = \bar m \times \hat a / \|\cdot\|`,
    north :math:`n = \hat a \times e`, and :math:`R = [e; n; \hat a]` (rows: the world
    axes in sensor coordinates, ENU).

    Parameters
    ----------
    acc : array_like, shape (N, 3) or (3,)
        Accelerometer samples (any unit).
    mag : array_like, shape (N, 3) or (3,), optional
        Magnetometer samples (any unit).

    Returns
    -------
    numpy.ndarray, shape (4,)
        Unit quaternion, sensor → world.
    """
    a = np.atleast_2d(np.asarray(acc, float)).mean(axis=0)
    an = np.linalg.norm(a)
    if not np.isfinite(an) or an == 0:
        raise ValueError(
            "cannot initialise: the mean accelerometer sample is zero or not finite"
        )
    up = a / an
    if mag is None:
        return tilt_quaternion(up)
    m = np.atleast_2d(np.asarray(mag, float)).mean(axis=0)
    east = np.cross(m, up)
    en = np.linalg.norm(east)
    if not np.isfinite(en) or en < 1e-12 * max(np.linalg.norm(m), 1e-300):
        raise ValueError(
            "cannot initialise: magnetometer is zero or parallel to gravity"
        )
    east /= en
    north = np.cross(up, east)
    return quat.from_matrix(np.stack([east, north, up]))


# --------------------------------------------------------------------------- labels

#: the unit each sensor is converted to when its input is labelled (``None``: kept as
#: it is, after checking that its unit measures the right quantity)
_LABEL_UNITS = {"acc": "m/s^2", "gyr": "rad/s", "mag": None}
_QUANTITY = {
    "acc": "acceleration",
    "gyr": "angular_velocity",
    "mag": "magnetic_field",
}
_UNIT_HINT = {"acc": "'g' or 'm/s^2'", "gyr": "'deg/s' or 'rad/s'", "mag": "'uT'"}
_PLAIN_UNIT = {"acc": "m/s²", "gyr": "rad/s", "mag": "any unit"}


def is_labelled(a) -> bool:
    """Tell whether ``a`` carries labels (an :class:`xarray.DataArray` or a Recording).

    Parameters
    ----------
    a : object
        An input.

    Returns
    -------
    bool
        True for a DataArray or a Dataset.
    """
    return isinstance(a, (xr.DataArray, xr.Dataset))


def _own_attr(a, name: str, key: str):
    if isinstance(a, xr.Dataset):
        if key == "fs":
            return a.attrs.get("fs")
        return a[name].attrs.get(key) if name in a else None
    return a.attrs.get(key)


def _read_labelled(a, name: str, fs: float | None, acc_si: bool) -> _v.Signal:
    if isinstance(a, xr.Dataset) and name not in a:
        raise _v.RecordingError(
            f"the Recording has no variable {name!r} (needed for {name})"
        )
    units = _own_attr(a, name, "units")
    if units is None and (name == "gyr" or (name == "acc" and acc_si)):
        why = (
            "the angular velocity must be converted to rad/s"
            if name == "gyr"
            else "this method uses the specific force in m/s² (not only its direction)"
        )
        raise _v.RecordingError(
            f"{name}: the labelled input has no 'units' attribute and {why}: add "
            f"attrs['units'] ({_UNIT_HINT[name]}), or pass plain values in "
            f"{_PLAIN_UNIT[name]}"
        )
    to = _LABEL_UNITS[name] if units is not None else None
    own_fs = _own_attr(a, name, "fs")
    if own_fs is None and fs is not None:
        _time_agrees(a, name, fs)
    try:
        sig = _v.signal(
            a,
            name,
            fs=fs if own_fs is not None else None,
            to_units=to,
            need_fs=False,
            width=3,
            ndim=None,
            allow_nan=True,
        )
        if sig.units is not None and _units.quantity_of(sig.units) != _QUANTITY[name]:
            raise _units.UnitsError(
                f"units {units!r} are not a unit of {_QUANTITY[name].replace('_', ' ')}"
                f" ({_UNIT_HINT[name]})"
            )
    except _units.UnitsError as e:
        msg = str(e)
        raise _units.UnitsError(
            msg if msg.startswith(f"{name}:") else f"{name}: {msg}"
        ) from None
    return sig


def _time_agrees(a, name: str, fs: float) -> None:
    """Refuse an ``fs`` contradicting the ``time`` of a labelled input without ``fs``.

    As :func:`tiltlab._validate.signal` does for the attribute.
    """
    da = a[name] if isinstance(a, xr.Dataset) and name in a else a
    if not isinstance(da, xr.DataArray) or "time" not in da.coords:
        return
    t = da.coords["time"]
    if t.ndim != 1 or t.size < 3:
        return
    med = float(np.median(np.diff(np.asarray(t.values, dtype=float))))
    if not np.isfinite(med) or med <= 0:
        raise _v.RecordingError(f"{name}: the time coordinate is not increasing")
    if abs(med * fs - 1.0) > 0.01:
        raise _v.RecordingError(
            f"{name}: fs = {fs:g} Hz contradicts its time coordinate (median step "
            f"{med:.6g} s, i.e. {1.0 / med:.6g} Hz)"
        )


def _same_rate(rates: dict[str, float]) -> float | None:
    """Return the one sampling rate of ``rates`` (by input name); refuse disagreements."""
    if not rates:
        return None
    (first, f0), *rest = rates.items()
    for name, f in rest:
        if not np.isclose(f, f0, rtol=1e-9, atol=0.0):
            raise _v.RecordingError(
                f"{first} and {name} disagree on the sampling rate: {first} has "
                f"attribute fs = {f0:g} Hz, {name} has fs = {f:g} Hz (resample one of "
                "them first)"
            )
    return f0


def _same_time(signals: dict[str, _v.Signal], fs: float | None) -> None:
    """Refuse labelled inputs whose ``time`` coordinates differ in length or values."""
    timed = [(n, s.time) for n, s in signals.items() if s.time is not None]
    if len(timed) < 2:
        return
    n0, t0 = timed[0]
    for name, t in timed[1:]:
        if t.shape != t0.shape:
            raise _v.RecordingError(
                f"{n0} and {name} have time coordinates of different lengths "
                f"({t0.size} and {t.size} samples): they are not the same recording"
            )
        if t.size == 0:
            continue
        if fs is not None:
            tol = 0.5 / fs
        elif t0.size > 1:
            tol = 0.5 * float(np.median(np.diff(t0)))
        else:
            tol = 0.0
        d = float(np.max(np.abs(t - t0)))
        if not d <= tol:
            raise _v.RecordingError(
                f"the time coordinates of {n0} and {name} disagree by up to {d:.6g} s "
                f"(more than half a sample): their samples are not aligned"
            )


def unlabel(
    fs,
    *,
    acc,
    gyr=None,
    mag=None,
    acc_si: bool = False,
    need_fs: bool = True,
):
    """Read the labels of the filters' inputs once: ``(fs, acc, gyr, mag)``.

    Plain arrays are returned as they are (the same objects; their checks follow in
    :func:`samples` / :func:`sensor_inputs`), and ``fs`` is then checked by
    :func:`tiltlab._validate.check_fs` exactly as before. A labelled input (an
    :class:`xarray.DataArray`, or a Recording read as its variable of that name) is
    read by :func:`tiltlab._validate.signal` into a new float array:

    * ``gyr`` is converted from its ``units`` attribute to rad/s (required: a labelled
      ``gyr`` without units is refused);
    * ``acc`` with a ``units`` attribute is converted to m/s²; without one it is
      accepted as is where only its direction matters, and refused where the method
      uses m/s² (``acc_si``);
    * ``mag`` keeps its values; a ``units`` attribute must be a magnetic-field unit;
    * ``fs``: an ``fs`` argument contradicting an input's ``attrs["fs"]`` is refused
      (both values in the message), as are inputs whose ``fs`` attributes disagree;
      without the argument the attributes give it; a ``time`` coordinate must agree
      with it (:func:`tiltlab._validate.signal`);
    * ``time`` coordinates of different lengths, or more than half a sample apart, are
      refused.

    Each input is read on its own: a plain array next to a labelled one keeps its
    documented unit. ``need_fs=False`` (functions without a sampling rate) returns the
    rate found, or ``None``. The conversion is one vectorised multiplication per input,
    before any kernel runs.

    Parameters
    ----------
    fs : float or None
        The sampling rate argument (Hz).
    acc : array_like, xarray.DataArray or xarray.Dataset
        Accelerometer samples (a Recording: its ``acc`` variable).
    gyr, mag : array_like, xarray.DataArray or xarray.Dataset, optional
        Gyroscope and magnetometer samples.
    acc_si : bool
        The method uses ``acc`` in m/s².
    need_fs : bool
        Refuse an unknown sampling rate.

    Returns
    -------
    tuple
        ``(fs, acc, gyr, mag)``: the rate and the inputs as plain arrays (plain inputs
        unchanged, ``None`` where not given).
    """
    given = {"acc": acc, "gyr": gyr, "mag": mag}
    labelled = {n: a for n, a in given.items() if a is not None and is_labelled(a)}
    if not labelled:
        return (_v.check_fs(fs) if need_fs else fs), acc, gyr, mag
    own = {
        n: _v.check_fs(f, name=f"{n} attribute fs")
        for n, a in labelled.items()
        if (f := _own_attr(a, n, "fs")) is not None
    }
    f_own = _same_rate(own)
    if fs is not None:
        f = _v.check_fs(fs)
        for name, fa in own.items():
            if not np.isclose(f, fa, rtol=1e-9, atol=0.0):
                raise _v.RecordingError(
                    f"{name}: fs = {fs!r} contradicts the data's attribute fs = "
                    f"{fa:g} Hz"
                )
    elif f_own is not None:
        f = f_own
    elif need_fs:
        raise _v.RecordingError(
            "fs (sampling rate, Hz) is unknown: pass fs= or give the inputs an "
            "attrs['fs']; tiltlab never assumes a default"
        )
    else:
        f = None
    signals = {n: _read_labelled(a, n, f, acc_si) for n, a in labelled.items()}
    _same_time(signals, f)
    out = {n: (signals[n].values if n in signals else a) for n, a in given.items()}
    return f, out["acc"], out["gyr"], out["mag"]


# --------------------------------------------------------------------------- options


def offset_vector(gyr_offset, default=None) -> np.ndarray:
    """Read a gyroscope offset (bias) argument as a contiguous float (3,) array.

    Parameters
    ----------
    gyr_offset : array_like, shape (3,), optional
        The offset (rad/s); any shape with 3 values is flattened.
    default : numpy.ndarray, shape (3,), optional
        Returned when ``gyr_offset`` is None (default: zeros).

    Returns
    -------
    numpy.ndarray, shape (3,)
        The offset; a finite value is required (ValueError naming ``gyr_offset``).
    """
    if gyr_offset is None:
        return np.zeros(3) if default is None else default
    flat = np.reshape(np.asarray(gyr_offset, float), -1)
    return np.ascontiguousarray(_v.vectors(flat, "gyr_offset", width=3, ndim=1))


def tuned(record: type) -> Callable[[F], F]:
    """Give a filter the fields of a tuning record as keyword options.

    The decorated function takes a keyword-only ``tuning`` argument (an instance of
    ``record``, a :class:`typing.NamedTuple` whose field defaults are the filter's
    defaults: the one place they are written). The returned function takes instead
    one keyword per field, builds the record from them (the others keep their
    defaults) and passes it on. Its signature (:func:`inspect.signature`, ``help``,
    :attr:`tiltlab.filters.Method.defaults`) lists the fields in place of ``tuning``,
    and its ``tuning`` attribute is ``record``.

    Parameters
    ----------
    record : type
        A :class:`typing.NamedTuple` with a default for every field.

    Returns
    -------
    callable
        The decorator.
    """
    fields = tuple(record._fields)

    def decorate(func: F) -> F:
        @functools.wraps(func)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            values = {k: kwargs.pop(k) for k in fields if k in kwargs}
            if "tuning" in kwargs:
                raise TypeError(
                    f"{func.__name__}() got an unexpected keyword argument 'tuning'"
                )
            return func(*args, tuning=record(**values), **kwargs)

        sig = inspect.signature(func)
        hints = {
            k: getattr(v, "__forward_arg__", v)  # "float", as the other annotations
            for k, v in record.__annotations__.items()
        }
        params = []
        for p in sig.parameters.values():
            if p.name != "tuning":
                params.append(p)
                continue
            params += [
                inspect.Parameter(
                    k,
                    inspect.Parameter.KEYWORD_ONLY,
                    default=record._field_defaults[k],
                    annotation=hints.get(k, inspect.Parameter.empty),
                )
                for k in fields
            ]
        wrapper.__signature__ = sig.replace(parameters=params)  # type: ignore[attr-defined]
        wrapper.tuning = record  # type: ignore[attr-defined]
        return wrapper  # type: ignore[return-value]

    return decorate


def check_tuning(tuning, *, positive: tuple[str, ...] = (), inf: tuple[str, ...] = ()):
    """Validate every field of a tuning record as a number ``>= 0``.

    Parameters
    ----------
    tuning : typing.NamedTuple
        A filter's tuning record (see :func:`tuned`).
    positive : tuple of str
        Fields that must be ``> 0`` (the others may be zero).
    inf : tuple of str
        Fields that may be infinite (the others must be finite).

    Returns
    -------
    typing.NamedTuple
        The record with every field as a float; a bad value is a ValueError naming
        its field.
    """
    return tuning._replace(
        **{
            k: _v.positive(v, k, allow_zero=k not in positive, allow_inf=k in inf)
            for k, v in tuning._asdict().items()
        }
    )
