r"""Recording-level entry points: :func:`estimate` (a labelled ``q``); :func:`gravity` is :func:`tiltlab.quaternion.gravity`.

:func:`prepare` reads a Recording once (through :func:`tiltlab._validate.signal`: ``fs``
from the attrs and checked against the ``time`` axis, units from the attrs, converted to
SI for the kernels) and :func:`run_method` runs a registered method on it;
:func:`estimate` is the two together plus the labelling. Parameter searches
(:func:`tiltlab.evaluate.grid_search`) call :func:`prepare` once per Recording and
:func:`run_method` once per parameter set. (``run`` is the former name of
:func:`run_method`, kept for one release with a FutureWarning.)
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from .._stack import user_stacklevel
from .. import _validate as _v
from ..quaternion import gravity  # one function, labelled or plain (re-exported)
from .._deprecate import alias, renamed
import tiltlab.filters.registry as registry
from .registry import get_method

__all__ = [
    "ESTIMATE_GAP_POLICIES",
    "Inputs",
    "prepare",
    "run_method",
    "run",
    "estimate",
    "gravity",
]


@dataclass(frozen=True)
class Inputs:
    """A Recording's sensor data in SI, ready for the kernels.

    ``acc`` (m/s²) as an (N, 3) array, ``gyr`` (rad/s) as an (N, 3) array or ``None``
    (a Recording without a gyroscope), ``mag`` (its own unit) or ``None``, ``fs`` (Hz)
    and ``like``: the accelerometer's :class:`tiltlab._validate.Signal`, used to label
    outputs with the Recording's ``time`` coordinate.
    """

    acc: np.ndarray
    gyr: np.ndarray | None
    mag: np.ndarray | None
    fs: float
    like: _v.Signal

    @property
    def use_mag(self) -> bool:
        """Whether a magnetometer was read (9D)."""
        return self.mag is not None

    @property
    def sensors(self) -> tuple[str, ...]:
        """The sensor variables read (``acc``, and ``gyr``, ``mag`` when present)."""
        return (
            ("acc",)
            + (("gyr",) if self.gyr is not None else ())
            + (("mag",) if self.mag is not None else ())
        )


@renamed(recording="rec")
def prepare(
    rec: xr.Dataset, *, use_mag: bool = False, allow_nan: bool = False
) -> Inputs:
    """Read a Recording's ``acc``, ``gyr`` when it has one (and ``mag``) in SI units.

    Parameters
    ----------
    rec : xarray.Dataset
        A tiltlab Recording (formerly ``recording``): ``acc`` (time, axis) with a ``units`` attr, optional
        ``gyr`` (read when present; ``Inputs.gyr`` is ``None`` otherwise, and the
        methods that need it refuse by name in :func:`run_method`) and ``mag``; attrs ``fs``.
    use_mag : bool
        Also read ``mag`` (9D).
    allow_nan : bool
        Accept NaN samples (dropouts), e.g. to split the recording into segments with
        :func:`tiltlab._validate.segments` (as ``estimate(..., gaps="segments")``
        does); the kernels themselves refuse NaN. Infinite values are always refused.

    Returns
    -------
    Inputs
        The sensor data in SI units, with ``fs`` and the accelerometer's labels.

    Raises
    ------
    tiltlab._validate.RecordingError
        A missing variable, ``fs`` or unit, an ``fs`` contradicting the time axis, or
        non-finite samples.

    Notes
    -----
    The ``fs``/time-axis check compares the *median* time step with ``1/fs``: a time
    axis with a few long steps (dropped samples) passes here. :func:`estimate` looks
    for such gaps (``gaps=``); code that calls :func:`run_method` directly should too
    (:func:`tiltlab._validate.segments`).
    """
    if not isinstance(rec, xr.Dataset):
        raise _v.RecordingError(
            "rec (the recording) must be an xarray Dataset (a tiltlab Recording), "
            f"got {type(rec).__name__}"
        )
    names = ["acc"] + (["gyr"] if "gyr" in rec else [])
    names += ["mag"] if use_mag else []
    for name in names:
        if name not in rec:
            hint = " (needed for use_mag=True)" if name == "mag" else ""
            raise _v.RecordingError(f"the Recording has no {name!r} variable{hint}")
    sensors = rec[names]
    if "time" in sensors.dims:
        sensors = sensors.transpose("time", ...)
    acc = _v.signal(sensors, "acc", to_units="m/s^2", allow_nan=allow_nan)
    gyr = (
        _v.signal(sensors, "gyr", to_units="rad/s", allow_nan=allow_nan).values
        if "gyr" in names
        else None
    )
    mag = _v.signal(sensors, "mag", allow_nan=allow_nan).values if use_mag else None

    def c(a):
        return None if a is None else np.ascontiguousarray(a, dtype=np.float64)

    return Inputs(c(acc.values), c(gyr), c(mag), acc.fs, acc)


def _check_sensors(m, inputs: Inputs) -> None:
    """Refuse a method whose sensor the prepared data lack, naming the methods that run."""
    for name in m.needs:
        if name not in inputs.sensors:
            raise _v.RecordingError(
                registry.missing_sensor_message(m, name, inputs.sensors)
            )


def run_method(method: str, inputs: Inputs, **params) -> np.ndarray:
    """Run a registered method on prepared :class:`Inputs`; return (N, 4) quaternions.

    Unspecified parameters take the registry's defaults; an unknown method or
    parameter is a ValueError naming it; a method that needs a sensor the inputs lack
    (a gyroscope, a magnetometer) is a :class:`~tiltlab._validate.RecordingError` naming
    it and the methods that would run.

    Parameters
    ----------
    method : str
        A registered method name (see :mod:`tiltlab.filters.registry`).
    inputs : Inputs
        Prepared sensor inputs (acc in m/s², gyr in rad/s, fs in Hz, optional mag).
    **params
        Method parameters, overriding the registry's defaults.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Unit quaternions (w, x, y, z) sensor → world.
    """
    m = get_method(method)
    full = m.resolve(params)
    _check_sensors(m, inputs)
    return m(inputs.acc, inputs.gyr, inputs.fs, inputs.mag, **full)


#: former name of :func:`run_method` (FutureWarning)
run = alias(run_method, "run")


def attr_value(v):
    """Convert a parameter value to a netCDF-friendly attribute.

    Parameters
    ----------
    v : object
        A parameter value.

    Returns
    -------
    object
        ``"none"`` for None, an int for a bool, a string of its scalar fields for a
        parameter record (a named tuple), a float array for an array, list or
        tuple, else ``v`` itself.
    """
    if v is None:
        return "none"
    if isinstance(v, (bool, np.bool_)):
        return int(v)
    if hasattr(v, "_fields"):  # a parameter record (e.g. learned weights): its scalars
        scalars = [(f, getattr(v, f)) for f in v._fields]
        return (
            f"{type(v).__name__}("
            + ", ".join(f"{f}={x:g}" for f, x in scalars if isinstance(x, (int, float)))
            + ")"
        )
    if isinstance(v, (np.ndarray, list, tuple)):
        return np.asarray(v, float)
    return v


#: values of ``estimate(..., gaps=)``
ESTIMATE_GAP_POLICIES = ("raise", "segments")


def _time_axis(inputs: Inputs) -> np.ndarray:
    t = inputs.like.time
    if t is None or t.shape != (inputs.acc.shape[0],):
        return np.arange(inputs.acc.shape[0]) / inputs.fs
    return t


@renamed(recording="rec")
def estimate(
    rec: xr.Dataset,
    method: str,
    *,
    use_mag: bool = False,
    gaps: str = "raise",
    min_segment_s: float = 1.0,
    **params,
) -> xr.DataArray:
    """Estimate the orientation of a Recording with a registered method.

    The Recording is read by :func:`prepare` (``fs`` from its attrs and checked
    against its ``time`` axis; ``acc`` in g or m/s² and ``gyr`` in °/s or rad/s, per
    their ``units`` attrs, converted to SI for the kernels).

    Parameters
    ----------
    rec : xarray.Dataset
        A tiltlab Recording (``acc``; ``gyr`` and ``mag`` optional; attrs ``fs``);
        formerly ``recording``.
        Without ``gyr`` only the methods that need no gyroscope run
        (``filters.methods(needs=rec)``: ``lowpass``, and ``davenport`` with a
        magnetometer); any other is refused by name.
    method : str
        A name of :data:`tiltlab.filters.METHODS` (:func:`tiltlab.filters.methods`).
    use_mag : bool
        Use the magnetometer (9D, ENU world frame). Implied for a method that requires
        one (``davenport``).
    gaps : {"raise", "segments"}
        What to do with gaps: time steps longer than 1.5/``fs`` (dropped samples) and
        samples where ``acc``, ``gyr`` (when the method uses it) or ``mag`` (with
        ``use_mag``) are not finite
        (:func:`tiltlab._validate.segments`). ``"raise"`` (default): a
        :class:`~tiltlab._validate.RecordingError` saying where they are — a filter
        integrating the gyroscope across a gap would be silently wrong. ``"segments"``:
        estimate each contiguous segment separately, each from its own initial
        orientation exactly as if it were a Recording of its own (a ``q0`` given in
        ``params`` starts every segment); samples in gaps and in segments shorter
        than ``min_segment_s`` are NaN, with a :class:`RuntimeWarning` saying how many.
    min_segment_s : float
        Shortest segment estimated with ``gaps="segments"`` (s; its number of samples
        over ``fs``). It applies to a gap-free recording too.
    **params
        Method parameters; unspecified ones take the registry's defaults (the
        function's signature), and all are recorded in the output's attrs.

    Returns
    -------
    xarray.DataArray, dims (time, quat)
        ``q``: unit quaternions sensor → world, with the Recording's ``time``
        coordinate and attrs ``fs``, ``method``, ``use_mag``, ``world_frame``, every
        parameter as ``param_<name>`` and the Recording's ``axis_labels`` (when it
        has them). With ``gaps="segments"`` also ``gaps``,
        ``min_segment_s``, ``n_segments`` (segments estimated) and ``segments``: the
        times (s) of the first and last sample of each estimated segment, flattened
        ``[start_0, last_0, start_1, last_1, ...]``.

    Raises
    ------
    tiltlab._validate.RecordingError
        A method that needs a variable the Recording lacks (a gyroscope, a
        magnetometer): the message names the method and lists those that run. With
        ``gaps="raise"``, a recording with gaps (and, whatever ``gaps``, the problems
        :func:`prepare` reports).
    ValueError
        An unknown method, parameter or ``gaps`` value, or a negative
        ``min_segment_s``.

    Examples
    --------
    >>> import numpy as np
    >>> from tiltlab import filters, schema
    >>> acc = np.tile([0.0, 0.0, 1.0], (200, 1))
    >>> rec = schema.make_recording(acc, fs=50.0, acc_units="g")  # no gyroscope
    >>> filters.methods(needs=rec)
    ('lowpass',)
    >>> q = filters.estimate(rec, "lowpass")
    >>> q.dims, q.attrs["method"]
    (('time', 'quat'), 'lowpass')
    """
    m = get_method(method)
    if use_mag and not m.supports_mag:
        raise ValueError(
            f"method {method!r} does not use a magnetometer; "
            "use_mag=True is not supported"
        )
    use_mag = bool(use_mag or m.requires_mag)
    if not isinstance(gaps, str) or gaps not in ESTIMATE_GAP_POLICIES:
        raise ValueError(f"gaps must be one of {ESTIMATE_GAP_POLICIES}, got {gaps!r}")
    min_segment_s = _v.nonnegative(min_segment_s, "min_segment_s")
    full = m.resolve(params)
    if isinstance(rec, xr.Dataset):
        have = [v for v in registry.SENSORS if v in rec]
        for name in m.needs:
            if name not in have:
                raise _v.RecordingError(registry.missing_sensor_message(m, name, have))
    inputs = prepare(rec, use_mag=use_mag, allow_nan=True)
    n = inputs.acc.shape[0]
    time = _time_axis(inputs)
    used = ["acc"] + (["gyr"] if m.uses_gyr else []) + (["mag"] if use_mag else [])
    stacked = [getattr(inputs, v) for v in used]
    segs = _v.segments(time, inputs.fs, values=np.concatenate(stacked, axis=1))
    labels = rec.attrs.get("axis_labels")
    attrs: dict[str, Any] = {
        "method": method,
        "use_mag": int(bool(use_mag)),
        "units": "1",
        "frame": "sensor->world",
        "world_frame": "ENU" if use_mag else "z up, heading arbitrary",
        **{f"param_{k}": attr_value(v) for k, v in full.items()},
        **({"axis_labels": list(labels)} if labels is not None else {}),
    }
    if gaps == "raise" and n and segs != [(0, n)]:
        names = ", ".join(used)
        raise _v.RecordingError(
            f"the Recording has gaps (time steps longer than 1.5/fs = "
            f"{1.5 / inputs.fs:.3g} s, or non-finite {names} samples): "
            f"{_v.describe_gaps(time, inputs.fs, segs)}; the filters would "
            'integrate across them. Pass gaps="segments" to estimate each '
            "contiguous segment separately (NaN in the gaps), or repair the "
            "recording"
        )
    if gaps == "raise" or n == 0:  # (an empty recording: the method says so)
        q = m(inputs.acc, inputs.gyr, inputs.fs, inputs.mag, **full)
    else:
        q = np.full((n, 4), np.nan)
        kept = []
        for a, b in segs:
            if (b - a) / inputs.fs < min_segment_s:
                continue
            mag = None if inputs.mag is None else inputs.mag[a:b]
            gyr = None if inputs.gyr is None else inputs.gyr[a:b]
            q[a:b] = m(inputs.acc[a:b], gyr, inputs.fs, mag, **full)
            kept.append((a, b))
        left = int(np.isnan(q[:, 0]).sum())
        if left:
            short = len(segs) - len(kept)
            warnings.warn(
                f"estimate({method!r}, gaps='segments'): {left} of {n} samples left "
                f"NaN ({_v.describe_gaps(time, inputs.fs, segs)}; {short} "
                f"segment{'s' if short != 1 else ''} shorter than min_segment_s = "
                f"{min_segment_s:g} s)",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
        attrs.update(
            gaps=gaps,
            min_segment_s=min_segment_s,
            n_segments=len(kept),
            segments=np.array(
                [time[i] for a, b in kept for i in (a, b - 1)], dtype=float
            ),
        )
    return _v.labelled(
        q,
        inputs.like,
        "q",
        dims=("time", "quat"),
        coords={"quat": list("wxyz")},
        attrs=attrs,
    )
