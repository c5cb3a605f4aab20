"""Check function arguments: how every public function reads its inputs and reports problems.

What belongs here: the checks of arguments (arrays, labelled inputs, sampling rates,
scalars, time gaps) and :class:`RecordingError`. What does not: what a Recording is
and its validation (:mod:`tiltlab.schema`), data-quality findings such as saturation or
units the values contradict (:mod:`tiltlab.quality`), and the unit table
(:mod:`tiltlab.units`).

Layer 1 (beside :mod:`tiltlab.units`). Every science function that takes data calls
:func:`signal` (or :func:`vectors` / the scalar checks) instead of writing its own checks,
so that the same mistake gives the same message everywhere.

Policy
------
* **Error** (:class:`RecordingError` for data, :class:`ValueError` for parameters):
  anything that would give a wrong number — a missing or contradictory sampling rate or
  unit, a wrong shape, a non-finite or out-of-domain parameter. The message names the
  argument (or attribute) and the value.
* **Repair with a warning**, recorded in the output's attrs: reserved for cases where the
  right answer is unambiguous (none in this module).
* **NaN with a warning**: quantities that are undefined for some samples (e.g. heading at a
  magnetic pole) — decided by the function that computes them.

Reading labelled data
---------------------
:func:`signal` accepts, for one input named e.g. ``"gyr"``:

* a Recording (:class:`xarray.Dataset`): the variable ``gyr``, the dataset's ``fs`` and the
  variable's ``units``;
* a labelled :class:`xarray.DataArray`: its values, ``attrs["fs"]`` and ``attrs["units"]``;
* a plain array: the values, with ``fs`` and ``units`` given as arguments.

An ``fs`` or ``units`` given as an argument must agree with the one in the attrs; a
``time`` coordinate must agree with ``fs``. A missing one, where the function needs it,
is an error naming it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, TypedDict, Unpack

import numpy as np
import xarray as xr

from ._scalars import check_fs, finite, fraction, integer, nonnegative, positive
from .units import conversion_factor, normalise_unit

__all__ = [
    "RecordingError",
    "Signal",
    "signal",
    "labelled",
    "vectors",
    "check_fs",
    "positive",
    "finite",
    "nonnegative",
    "integer",
    "fraction",
    "output",
    "start_time",
    "windowed",
    "time_unit_hint",
]


class RecordingError(ValueError):
    """A Recording breaks the data contract; the message names what is wrong."""


# --------------------------------------------------------------------------- arrays
#
# Scalar checks (check_fs, finite, positive, nonnegative, integer, fraction) live in
# tiltlab._scalars and are re-exported here.


def vectors(
    a,
    name: str,
    *,
    width: int | None = 3,
    ndim: int | None = 2,
    allow_nan: bool = False,
    min_length: int = 0,
    copy: bool = True,
    check_values: bool = True,
) -> np.ndarray:
    """Return a float copy of ``a`` checked for shape and finiteness.

    Parameters
    ----------
    a : array_like
        The data.
    name : str
        Its name, used in error messages.
    width : int, optional
        Required size of the last dimension (``None``: any).
    ndim : int, optional
        Required number of dimensions (``None``: any).
    allow_nan : bool
        Accept NaN (never ±inf).
    min_length : int
        Minimum size of the first dimension.
    copy : bool
        ``False``: a C-contiguous float64 ``a`` is returned as it is (no copy), for
        callers that only read it; otherwise converted.
    check_values : bool
        ``False``: skip the finiteness check (the caller scans the values itself,
        e.g. in one compiled pass).

    Returns
    -------
    numpy.ndarray of float
        A new array (never a view of ``a``), unless ``copy=False``.

    Raises
    ------
    ValueError
        Non-numeric or complex data (complex values are refused even when their
        imaginary part is zero: converting them would silently drop it), a wrong shape,
        too few samples, or non-finite values.
    """
    try:
        raw = np.asarray(a)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numeric, got {type(a).__name__}") from None
    _not_complex(raw, name)
    try:
        x = (
            np.array(raw, dtype=float)
            if copy
            else np.ascontiguousarray(raw, dtype=np.float64)
        )
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numeric, got {type(a).__name__}") from None
    if ndim is not None and x.ndim != ndim:
        shape = "(N, {})".format(width) if (ndim == 2 and width) else f"{ndim}-D"
        raise ValueError(f"{name} must have shape {shape}, got {x.shape}")
    if width is not None and (x.ndim == 0 or x.shape[-1] != width):
        raise ValueError(
            f"{name} must have a last dimension of size {width}, got shape {x.shape}"
        )
    if x.ndim and x.shape[0] < min_length:
        raise ValueError(
            f"{name} needs at least {min_length} samples, got {x.shape[0]}"
        )
    if not check_values:
        return x
    bad = ~np.isfinite(x) if not allow_nan else np.isinf(x)
    if bad.any():
        what = "non-finite" if not allow_nan else "infinite"
        raise ValueError(f"{name} has {int(bad.sum())} {what} values")
    return x


def _not_complex(raw: np.ndarray, name: str) -> None:
    """Refuse complex data by name (a float conversion would drop the imaginary part)."""
    if raw.dtype.kind == "c":
        nonzero = int(np.count_nonzero(np.imag(raw)))
        part = (
            f"{nonzero} of them with a non-zero imaginary part"
            if nonzero
            else "all imaginary parts are zero"
        )
        raise ValueError(
            f"{name} holds complex numbers (dtype {raw.dtype}, {part}); tiltlab takes "
            f"real values and never drops an imaginary part silently: pass "
            f"{name}.real explicitly if that is what you mean"
        )


_TIME_UNIT_STEPS = (("milliseconds", 1e3), ("microseconds", 1e6), ("nanoseconds", 1e9))


def time_unit_hint(step: float, fs: float) -> str:
    """Name the time unit that makes a median step ``step`` agree with ``fs``.

    When ``step * fs`` is close (within 1 %) to 10³, 10⁶ or 10⁹, the time axis is most
    likely in milliseconds, microseconds or nanoseconds instead of seconds; the hint
    says so.

    Parameters
    ----------
    step : float
        The median time step, in the time axis' own unit.
    fs : float
        The sampling rate (Hz).

    Returns
    -------
    str
        The hint, to append to a message (``""`` when no unit explains the step).
    """
    if not (np.isfinite(step) and step > 0):
        return ""
    ratio = step * fs
    for unit, factor in _TIME_UNIT_STEPS:
        if abs(ratio / factor - 1.0) <= 0.01:
            return (
                f"; the time axis looks like {unit}, not seconds: divide it by "
                f"{factor:g} (a Recording's time is in seconds)"
            )
    return ""


def _numeric_time(coord, where: str) -> np.ndarray:
    """Return a time coordinate as float seconds; refuse date-times and durations by name."""
    values = np.asarray(coord.values)
    if values.dtype.kind in "mM":
        kind = "date-times" if values.dtype.kind == "M" else "durations"
        raise RecordingError(
            f"{where}: the time coordinate holds {kind} ({values.dtype}), not seconds; "
            "a Recording's time is a float number of seconds: convert it, e.g. "
            "ds.assign_coords(time=(ds.time - ds.time[0]) / np.timedelta64(1, 's'))"
            + (
                " and keep the absolute start in attrs['time_origin']"
                if values.dtype.kind == "M"
                else ""
            )
        )
    return np.asarray(values, dtype=float)


@dataclass(frozen=True)
class Signal:
    """Values of one input with the metadata read from it.

    ``values`` is a new array (never a view of the caller's data); ``fs`` (Hz), ``units``
    and ``time`` (s) are ``None`` where unknown; ``coords`` holds the ``time`` coordinate
    of a labelled input (to label the output); ``attrs`` its attributes.
    """

    values: np.ndarray
    fs: float | None
    units: str | None
    time: np.ndarray | None = None
    labelled: bool = False
    attrs: dict[str, Any] = field(default_factory=dict)


def _time_fs_check(time: np.ndarray, fs: float, where: str) -> None:
    if time.size < 3:
        return
    dt = np.diff(time)
    med = float(np.median(dt))
    if not np.isfinite(med) or med <= 0:
        raise RecordingError(f"{where}: the time coordinate is not increasing")
    if abs(med * fs - 1.0) > 0.01:
        raise RecordingError(
            f"{where}: attribute fs = {fs:g} Hz contradicts the time coordinate "
            f"(median step {med:.6g} s, i.e. {1.0 / med:.6g} Hz)"
            + time_unit_hint(med, fs)
        )


class Shape(TypedDict, total=False):
    """Shape requirements of :func:`signal`, passed on to :func:`vectors`."""

    width: int | None
    ndim: int | None


def _source(data, name: str, var: str | None):
    """Return ``(DataArray or None, attrs, own fs, own units, where)`` of an input."""
    if isinstance(data, xr.Dataset):
        key = var or name
        if key not in data:
            raise RecordingError(
                f"the Recording has no variable {key!r} (needed for {name})"
            )
        da = data[key]
        where = f"Recording variable {key!r}"
        return da, dict(data.attrs), data.attrs.get("fs"), da.attrs.get("units"), where
    if isinstance(data, xr.DataArray):
        da = data.transpose("time", ...) if "time" in data.dims else data
        attrs = dict(da.attrs)
        return da, attrs, attrs.get("fs"), attrs.get("units"), name
    return None, {}, None, None, name


def _agreed_fs(own_fs, fs, name: str, where: str, need_fs: bool, labelled: bool):
    """Return the sampling rate of an input: its attribute and ``fs`` must agree."""
    if own_fs is not None:
        f = check_fs(own_fs, name=f"{where} attribute fs")
        if fs is not None and not np.isclose(check_fs(fs), f, rtol=1e-9, atol=0.0):
            raise RecordingError(
                f"{name}: fs = {fs!r} contradicts the data's attribute fs = {f:g} Hz"
            )
        return f
    if fs is not None:
        return check_fs(fs)
    if need_fs:
        hint = "add attrs['fs'] to it" if labelled else "pass fs="
        raise RecordingError(
            f"{name}: the sampling rate fs is unknown ({hint}); tiltlab never assumes a default"
        )
    return None


def _agreed_units(own_units, units, name: str, need: bool, labelled: bool):
    """Return the canonical units of an input: its attribute and ``units`` must agree."""
    u = None
    if own_units is not None:
        u = normalise_unit(own_units)
        if units is not None and normalise_unit(units) != u:
            raise RecordingError(
                f"{name}: units = {units!r} contradicts the data's units {own_units!r}"
            )
    elif units is not None:
        u = normalise_unit(units)
    if u is None and need:
        hint = "add attrs['units'] to it" if labelled else "pass units="
        raise RecordingError(f"{name}: its units are unknown ({hint})")
    return u


def signal(
    data,
    name: str,
    *,
    var: str | None = None,
    fs=None,
    units: str | None = None,
    to_units: str | None = None,
    need_fs: bool = True,
    need_units: bool = False,
    allow_nan: bool = False,
    **shape: Unpack[Shape],
) -> Signal:
    """Read one input from a Recording, a labelled DataArray or a plain array.

    Parameters
    ----------
    data : xarray.Dataset, xarray.DataArray or array_like
        The input.
    name : str
        Its argument name, used in messages (and the variable read from a Recording unless
        ``var`` is given).
    var : str, optional
        Variable to read from a Recording (default ``name``).
    fs : float, optional
        Sampling rate (Hz) for a plain array; for labelled input it must agree with
        ``attrs["fs"]``.
    units : str, optional
        Units of a plain array; for labelled input it must agree with ``attrs["units"]``.
    to_units : str, optional
        Convert the values to these units (the input's units are then required).
    need_fs, need_units : bool
        Raise when the sampling rate / units cannot be determined.
    allow_nan : bool
        Accept NaN values.
    **shape
        ``width`` and ``ndim``: the shape requirements of :func:`vectors` (default
        ``width=3, ndim=2``, an (N, 3) array; ``None``: any).

    Returns
    -------
    Signal
        The values (a new float array) with the sampling rate, units, time coordinate
        and attributes read from the input.

    Raises
    ------
    RecordingError
        A missing or contradictory ``fs`` or unit, a missing variable, or a ``time``
        coordinate that is not float seconds (date-times or durations are refused with
        the conversion to write; a step that is 10³, 10⁶ or 10⁹ times ``1/fs`` names
        the likely time unit).
    ValueError
        Complex, non-numeric, mis-shaped or non-finite values (see :func:`vectors`).
    TypeError
        A keyword other than those above.
    """
    unknown = set(shape) - set(Shape.__annotations__)
    if unknown:
        raise TypeError(f"signal() got unexpected keyword arguments {sorted(unknown)}")
    shape = {"width": 3, "ndim": 2, **shape}
    da, attrs, own_fs, own_units, where = _source(data, name, var)
    labelled = da is not None
    time = None
    if labelled:
        raw = np.asarray(da.values)
        _not_complex(raw, name)
        values = np.array(raw, dtype=float)
        if "time" in da.coords and da.coords["time"].ndim == 1:
            time = _numeric_time(da.coords["time"], where)
        values = vectors(values, name, allow_nan=allow_nan, **shape)
    else:
        values = vectors(data, name, allow_nan=allow_nan, **shape)
    f = _agreed_fs(own_fs, fs, name, where, need_fs, labelled)
    if f is not None and time is not None:
        _time_fs_check(time, f, where)
    u = _agreed_units(
        own_units, units, name, need_units or to_units is not None, labelled
    )
    if to_units is not None:
        values = values * conversion_factor(u, to_units)
        u = normalise_unit(to_units)
    return Signal(values, f, u, time, labelled, attrs)


def labelled(
    values,
    like: Signal,
    name: str,
    *,
    units: str | None = None,
    dims: tuple[str, ...] | None = None,
    coords: dict | None = None,
    attrs: dict[str, Any] | None = None,
):
    """Wrap a per-sample result as a DataArray when its input was labelled.

    The output keeps the input's ``time`` coordinate and ``fs``; ``units`` and ``attrs``
    are added. Plain-array inputs give plain arrays back.

    Parameters
    ----------
    values : array_like
        The result, first dimension time.
    like : Signal
        What :func:`signal` read from the input.
    name : str
        The DataArray's name.
    units : str, optional
        Its ``units`` attribute.
    dims : tuple of str, optional
        Its dimensions (default ``("time", "axis")`` for (N, 3), else ``("time", ...)``).
    coords : dict, optional
        Extra coordinates.
    attrs : dict, optional
        Extra attributes.

    Returns
    -------
    xarray.DataArray or numpy.ndarray
        A DataArray when ``like`` was labelled, else ``values`` unchanged.
    """
    if not like.labelled:
        return values
    values = np.asarray(values)
    if dims is None:
        dims = ("time",) + tuple(f"dim_{k}" for k in range(1, values.ndim))
        if values.ndim == 2 and values.shape[1] == 3:
            dims = ("time", "axis")
    c = {}
    if (
        like.time is not None
        and "time" in dims
        and values.shape[dims.index("time")] == like.time.size
    ):
        c["time"] = like.time
    if "axis" in dims:
        c["axis"] = ["x", "y", "z"]
    if coords:
        c.update(coords)
    a: dict[str, Any] = {}
    if like.fs is not None:
        a["fs"] = like.fs
    if units is not None:
        a["units"] = units
    if attrs:
        a.update(attrs)
    return xr.DataArray(values, dims=dims, coords=c, name=name, attrs=a)


def output(values, like: Signal, name: str, units: str | None = None, attrs=None):
    """Return a per-sample (or scalar) result, labelled exactly when ``like`` was.

    Per-sample arrays become DataArrays with the input's ``time`` coordinate and ``fs``
    (:func:`labelled`); a scalar becomes a 0-d DataArray carrying ``units``.

    Parameters
    ----------
    values : array_like or float
        A per-sample array or a single number.
    like, name, units, attrs
        As for :func:`labelled`.

    Returns
    -------
    xarray.DataArray, numpy.ndarray or float
        Labelled exactly when ``like`` was, else ``values`` as given.
    """
    if not like.labelled:
        return values
    values = np.asarray(values)
    if values.ndim == 0:
        a = {} if units is None else {"units": units}
        return xr.DataArray(values, name=name, attrs={**a, **(attrs or {})})
    return labelled(values, like, name, units=units, attrs=attrs)


def start_time(like: Signal) -> float:
    """Return the time (s) of the first sample of a labelled input.

    Parameters
    ----------
    like : Signal
        The input.

    Returns
    -------
    float
        The first time, or 0 without a time coordinate.
    """
    if like.time is not None and like.time.size:
        return float(like.time[0])
    return 0.0


def windowed(values, like: Signal, name: str, *, centre_s, fs_out: float, units=None):
    """Return one value per window, labelled over window-centre times when ``like`` was.

    Parameters
    ----------
    values : array_like, shape (K,) or (K, 3)
        One value per window.
    like : Signal
        The input the windows were cut from.
    name, units
        As for :func:`labelled`.
    centre_s : array_like, shape (K,)
        Window centres (s), relative to the first sample.
    fs_out : float
        Windows per second (the output's ``fs``).

    Returns
    -------
    xarray.DataArray or numpy.ndarray
        Over the window centres (absolute times) when ``like`` was labelled.
    """
    if not like.labelled:
        return values
    centres = start_time(like) + np.asarray(centre_s, float)
    per_window = replace(like, time=None, fs=float(fs_out))
    return labelled(values, per_window, name, units=units, coords={"time": centres})


# --------------------------------------------------------------------------- time gaps
#
# A time axis with dropped samples (a step longer than ``(1 + tolerance) / fs``) or rows
# of non-finite samples breaks a recording into contiguous segments. :func:`signal` does
# not look for them (its ``time``/``fs`` check compares the *median* step with ``1/fs``,
# so a few long steps pass); functions that integrate over time (the orientation
# filters) call :func:`segments` and either refuse the recording (error, with
# :func:`describe_gaps` in the message) or process each segment on its own.

__all__ += ["segments", "describe_gaps", "unknown_keys"]


def unknown_keys(given, known, *, hints=None) -> tuple[list[str], str]:
    """List the keys of ``given`` that are not ``known``, with a hint for each known slip.

    Parameters
    ----------
    given : iterable of str
        Keys (of a mapping, of keyword arguments) as the caller gave them.
    known : container of str
        The accepted keys.
    hints : mapping of str to str, optional
        For a key that is a common slip, the advice appended when it is among the
        unknown ones (e.g. ``{"mag": " (pass use_mag=True ...)"}``).

    Returns
    -------
    unknown : list of str
        The unknown keys, in the order given.
    hint : str
        The advice for those of them in ``hints``, concatenated (``""`` if none).

    Examples
    --------
    >>> unknown_keys(["fs", "files"], {"fs"}, hints={"files": "; read_multi reads it"})
    (['files'], '; read_multi reads it')
    """
    unknown = [k for k in given if k not in known]
    hint = "".join(text for key, text in (hints or {}).items() if key in unknown)
    return unknown, hint


def _gap_time(time, name: str = "time") -> np.ndarray:
    t = vectors(time, name, width=None, ndim=1)
    if t.size >= 2 and np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0))
        raise RecordingError(
            f"{name} is not strictly increasing (at sample {i + 1}: "
            f"{t[i]:g} → {t[i + 1]:g} s)"
        )
    return t


def segments(time, fs, *, values=None, tolerance: float = 0.5) -> list[tuple[int, int]]:
    """Contiguous runs of valid samples, as ``[start, stop)`` index ranges.

    A new segment starts where the time step exceeds ``(1 + tolerance) / fs`` (dropped
    samples) and around every row of ``values`` that has a non-finite entry (such rows
    belong to no segment).

    Parameters
    ----------
    time : array_like, shape (N,)
        Sample times (s), strictly increasing.
    fs : float
        Nominal sampling rate (Hz).
    values : array_like, shape (N, ...), optional
        Samples whose rows must be finite (e.g. ``acc``, ``gyr`` and ``mag`` stacked
        side by side as an (N, 9) array).
    tolerance : float
        Accepted lengthening of a step, as a fraction of ``1/fs`` (default 0.5: a
        single dropped sample, a step of ``2/fs``, is a gap).

    Returns
    -------
    list of (int, int)
        ``(start, stop)`` pairs in increasing order; ``[(0, N)]`` for a gap-free,
        finite recording, ``[]`` when no sample is valid.

    Raises
    ------
    ValueError
        An invalid ``fs`` or ``tolerance``, a ``time`` that is not a finite 1-D array,
        or ``values`` whose first dimension is not N.
    RecordingError
        A ``time`` that is not strictly increasing.
    """
    fs = check_fs(fs)
    tolerance = nonnegative(tolerance, "tolerance")
    t = _gap_time(time)
    n = t.size
    if values is None:
        ok = np.ones(n, dtype=bool)
    else:
        v = np.asarray(values, dtype=float)
        if v.ndim == 0 or v.shape[0] != n:
            raise ValueError(
                f"values must have {n} rows (one per time sample), got shape {v.shape}"
            )
        ok = np.isfinite(v.reshape(n, -1)).all(axis=1) if n else np.ones(0, bool)
    if n == 0:
        return []
    jump = np.zeros(n, dtype=bool)
    jump[1:] = np.diff(t) > (1.0 + tolerance) / fs
    prev_ok = np.concatenate([[False], ok[:-1]])
    next_ok = np.concatenate([ok[1:], [False]])
    next_jump = np.concatenate([jump[1:], [True]])
    starts = np.flatnonzero(ok & (~prev_ok | jump))
    stops = np.flatnonzero(ok & (~next_ok | next_jump)) + 1
    return [(int(a), int(b)) for a, b in zip(starts, stops)]


def describe_gaps(time, fs, segs, *, tolerance: float = 0.5, max_items: int = 5) -> str:
    """Describe in a short sentence the gaps around ``segs`` (from :func:`segments`).

    Each gap is given by its duration (time without valid samples, beyond a normal
    step) and the time of its first missing sample, e.g. ``"2 gaps: 1.00 s at t =
    12.30 s (time jump), 0.05 s at t = 20.00 s (5 non-finite samples)"``; at most
    ``max_items`` are listed.

    Parameters
    ----------
    time, fs, tolerance
        As for :func:`segments`.
    segs : list of (int, int)
        The segments, as :func:`segments` returns them.
    max_items : int
        The most gaps listed.

    Returns
    -------
    str
        The sentence; ``"no gaps"`` when ``segs`` covers every sample.
    """
    fs = check_fs(fs)
    tolerance = nonnegative(tolerance, "tolerance")
    t = _gap_time(time)
    n = t.size
    dt = 1.0 / fs
    if n == 0:
        return "no samples"
    if not segs:
        return f"no valid samples (all {n} samples have non-finite values)"
    items = []  # (start time, duration, n non-finite, time jump)
    a0 = segs[0][0]
    if a0 > 0:
        items.append((t[0], t[a0] - t[0], a0, False))
    for (_, b), (a, _) in zip(segs[:-1], segs[1:]):
        jump = bool(np.any(np.diff(t[b - 1 : a + 1]) > (1.0 + tolerance) * dt))
        items.append((t[b - 1] + dt, t[a] - t[b - 1] - dt, a - b, jump))
    b1 = segs[-1][1]
    if b1 < n:
        items.append((t[b1 - 1] + dt, t[-1] - t[b1 - 1], n - b1, False))
    if not items:
        return "no gaps"

    def why(k: int, jump: bool) -> str:
        parts = (["time jump"] if jump else []) + (
            [f"{k} non-finite sample{'s' if k != 1 else ''}"] if k else []
        )
        return " and ".join(parts)

    shown = [
        f"{d:.2f} s at t = {s:.2f} s ({why(k, j)})" for s, d, k, j in items[:max_items]
    ]
    more = len(items) - len(shown)
    tail = f", and {more} more" if more else ""
    word = "gap" if len(items) == 1 else "gaps"
    return f"{len(items)} {word}: " + ", ".join(shown) + tail
