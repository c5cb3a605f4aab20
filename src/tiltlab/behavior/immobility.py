r"""Detect immobility from the gyroscope or, without one, from the accelerometer.

The gyroscope rule is Fayat et al. 2021, §2.9.

**Gyroscope rule** (Fayat et al. 2021 §2.9). A sample is still when the angular speed
(norm of the offset-corrected gyroscope, °/s) is below 12 °/s; still periods separated
by gaps shorter than 0.1 s are merged; still periods shorter than 0.5 s are discarded.
The 12 °/s threshold was chosen by eye at the valley of the bimodal angular-speed
distribution (their Fig. A3); :func:`~tiltlab.behavior.valley_threshold` finds that
valley automatically (``threshold_deg_s="auto"``).

**Accelerometer rule** (most bio-logging tags have no gyroscope). A sample is still when
the vectorial dynamic body acceleration,

.. math::
    d_i = \lVert \mathbf a_i - \bar{\mathbf a}_i \rVert ,

(VeDBA [2]_; :math:`\bar{\mathbf a}_i` the centred mean over ``window_s``, the static
acceleration of Benhamou 2023 §2 [3]_), averaged over ``smooth_s``, is below
``threshold_g`` (g); the same merging and minimum duration follow. Any movement that
changes the head's tilt, or accelerates it, raises :math:`d`; a still head leaves only
the accelerometer's noise. Thresholding DBA to separate rest from activity is the usual
practice with acceleration-only tags [4]_. The default (0.03 g with a 0.5 s window and
a 0.2 s average) sits above the noise floor of MEMS accelerometers of the MPU-9250 class
(VeDBA ≈ 0.015 g at rest at 100 Hz) and below head movements; check it against
:func:`~tiltlab.behavior.dba` of a known still period of your own sensor. A rotation
about the gravity axis (a pure turn in place, head level) changes no acceleration and
is missed: the gyroscope rule is preferred whenever a gyroscope exists.

Both rules run through :func:`tiltlab.dsp.still_mask`, tiltlab's one still-period
detector. :func:`immobility` picks the gyroscope rule when the data have a gyroscope
and the accelerometer rule otherwise, and records which (``rule``, ``threshold``,
``threshold_units``) in the attrs of its result.

Units and ``fs`` are read from the data (a Recording or a labelled DataArray), so a
recording in rad/s gives the same mask as the same recording in °/s, and one in m/s²
the same as in g.

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021.
   doi:10.3390/s21186318
.. [2] L. Qasem et al., "Tri-axial dynamic acceleration as a proxy for animal energy
   expenditure; should we be summing values or calculating the vector?", PLoS ONE
   7:e31187, 2012. doi:10.1371/journal.pone.0031187
.. [3] S. Benhamou, arXiv:2310.05820, 2023. doi:10.48550/arXiv.2310.05820
.. [4] E. L. C. Shepard et al., "Identification of animal movement patterns using
   tri-axial accelerometry", Endang. Species Res. 10:47–60, 2008.
   doi:10.3354/esr00084
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import xarray as xr

from .. import _validate as _v
from .. import units as _units
from ..dsp import still_mask, window_samples
from ._common import label, need_gyr, read_behavior_input, read_speed
from .activity import _sliding_mean
from .speed import _offset, _read_gyr, _speed, valley_threshold

__all__ = ["detect_immobility", "immobility", "acc_immobility", "IMMOBILITY_RULES"]

#: values of ``immobility(..., rule=)``
IMMOBILITY_RULES = ("auto", "gyroscope", "accelerometer")


class _Periods(NamedTuple):
    """How still samples become still periods: gaps merged, short periods dropped."""

    merge_gap_s: float = 0.1
    min_duration_s: float = 0.5

    def mask(self, values, fs: float, threshold: float, smooth_s: float = 0.0):
        """Return the still mask of ``values`` (:func:`tiltlab.dsp.still_mask`)."""
        return still_mask(
            values,
            fs,
            threshold=threshold,
            smooth_s=smooth_s,
            merge_gap_s=self.merge_gap_s,
            min_duration_s=self.min_duration_s,
        )

    def attrs(self) -> dict:
        """Return the settings as attributes of a mask."""
        return {
            "merge_gap_s": float(self.merge_gap_s),
            "min_duration_s": float(self.min_duration_s),
        }


def _rule_attrs(rule: str, thr: float, own: dict, periods: _Periods, text: str):
    """Return the attributes of an :func:`immobility` mask made by ``rule``."""
    return {
        "rule": rule,
        "threshold": thr,
        "threshold_units": "deg/s" if rule == "gyroscope" else "g",
        **own,
        **periods.attrs(),
        "rule_description": text,
    }


def _threshold(threshold_deg_s) -> float:
    if isinstance(threshold_deg_s, str):
        raise ValueError(
            f"threshold_deg_s must be a number of °/s or 'auto', got {threshold_deg_s!r}"
        )
    return _v.positive(threshold_deg_s, "threshold_deg_s")


def detect_immobility(
    speed,
    fs=None,
    *,
    threshold_deg_s: float = 12.0,
    merge_gap_s: float = 0.1,
    min_duration_s: float = 0.5,
    units: str | None = None,
):
    """Fayat et al.'s immobility mask from an angular-speed series.

    Parameters
    ----------
    speed : xarray.DataArray or array_like (N,)
        Angular speed (see :func:`~tiltlab.behavior.angular_speed`): a labelled
        DataArray (``fs`` and ``units`` read from its attributes) or a plain array in
        °/s (or ``units``) with ``fs``. NaN is refused: fill or drop gaps first.
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    threshold_deg_s : float
        Speed (°/s) below which a sample is still (Fayat: 12 °/s; strict).
    merge_gap_s : float
        Still periods separated by a gap strictly shorter than this (s) are merged
        (Fayat: 0.1 s).
    min_duration_s : float
        Still periods shorter than this (s), after merging, are discarded (Fayat: 0.5 s).
    units : str, optional
        Units of a plain ``speed`` (default °/s).

    Returns
    -------
    numpy.ndarray of bool (N,) or xarray.DataArray (time)
        True where the animal is immobile; a DataArray ``immobile`` with ``time``,
        ``fs`` and the settings as attributes for labelled input.
    """
    thr = _threshold(threshold_deg_s)
    periods = _Periods(merge_gap_s, min_duration_s)
    s = read_speed(speed, fs, units=units, need_fs=True)
    mask = periods.mask(s.values, s.fs, thr)
    attrs = {"threshold_deg_s": thr, "threshold_method": "fixed", **periods.attrs()}
    return label(mask, s, "immobile", attrs=attrs)


def acc_immobility(
    acc,
    fs=None,
    *,
    threshold_g: float = 0.03,
    window_s: float = 0.5,
    smooth_s: float = 0.2,
    merge_gap_s: float = 0.1,
    min_duration_s: float = 0.5,
    units: str | None = None,
):
    r"""Immobility mask from the accelerometer alone (VeDBA below a threshold).

    :math:`d_i = \lVert \mathbf a_i - \bar{\mathbf a}_i \rVert` in g, with
    :math:`\bar{\mathbf a}` the centred mean over ``window_s``
    (:func:`~tiltlab.behavior.dba`), averaged over ``smooth_s``; still where it is below
    ``threshold_g``, then periods merged across gaps shorter than ``merge_gap_s`` and
    periods shorter than ``min_duration_s`` dropped (:func:`tiltlab.dsp.still_mask`).
    See the module notes for the choice of the defaults and the rule's blind spot
    (turns about the gravity axis).

    Parameters
    ----------
    acc : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        A Recording (its ``acc`` and ``fs``), a labelled DataArray, or a plain array with
        ``fs`` and ``units`` ('g' or 'm/s^2').
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    threshold_g : float
        VeDBA (g) below which a sample is still.
    window_s : float
        Window (s) of the static acceleration.
    smooth_s : float
        Running mean (s) of the VeDBA before thresholding (0: none).
    merge_gap_s, min_duration_s : float
        As in :func:`detect_immobility` (s).
    units : str, optional
        Units of a plain ``acc``.

    Returns
    -------
    xarray.DataArray of bool (time), or numpy.ndarray for a plain array
        ``immobile``, with attributes ``rule = "accelerometer"``, ``threshold``,
        ``threshold_units = "g"``, ``threshold_g``, ``window_s``, ``smooth_s``,
        ``merge_gap_s``, ``min_duration_s`` and ``rule_description``.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> acc = np.tile([0.0, 0.0, 1.0], (1000, 1)) + rng.normal(0, 0.005, (1000, 3))
    >>> acc[500:] += 0.3 * np.sin(np.arange(500) / 5.0)[:, None]  # moving
    >>> m = acc_immobility(acc, 100.0, units="g")
    >>> bool(m[:400].all()), bool(m[600:].any())
    (True, False)
    """
    thr = _v.positive(threshold_g, "threshold_g")
    smooth_s = _v.nonnegative(smooth_s, "smooth_s")
    s = read_behavior_input(
        acc, "acc", fs=fs, units=units, to_units="g", need_fs=True, allow_nan=True
    )
    a = s.values
    ok = np.isfinite(a).all(axis=1)
    if not ok.any():
        raise _v.RecordingError("acc has no finite sample: immobility is undefined")
    if not ok.all():  # missing samples (gaps kept as NaN): bridged for the running
        # mean, and never counted as immobile themselves
        idx = np.arange(a.shape[0])
        a = np.column_stack([np.interp(idx, idx[ok], a[ok, k]) for k in range(3)])
    d = np.linalg.norm(a - _sliding_mean(a, window_samples(window_s, s.fs)), axis=1)
    d[~ok] = 1e3 * thr  # far above the threshold: a missing sample is never still
    periods = _Periods(merge_gap_s, min_duration_s)
    mask = periods.mask(d, s.fs, thr, smooth_s)
    own = {"threshold_g": thr, "window_s": float(window_s), "smooth_s": float(smooth_s)}
    text = (
        f"VeDBA ({float(window_s):g} s static window, {smooth_s:g} s running mean) "
        f"< {thr:g} g"
    )
    attrs = _rule_attrs("accelerometer", thr, own, periods, text)
    return label(mask, s, "immobile", attrs=attrs)


def _choose_rule(data, rule: str, units: str | None) -> str:
    """Return the rule :func:`immobility` applies to ``data``."""
    if not isinstance(rule, str) or rule not in IMMOBILITY_RULES:
        raise ValueError(f"rule must be one of {IMMOBILITY_RULES}, got {rule!r}")
    if rule != "auto":
        return rule
    if isinstance(data, xr.Dataset):
        return "gyroscope" if "gyr" in data else "accelerometer"
    u = data.attrs.get("units") if isinstance(data, xr.DataArray) else units
    if u is None and isinstance(data, xr.DataArray) and data.name in ("acc", "gyr"):
        return "gyroscope" if data.name == "gyr" else "accelerometer"
    if u is None:
        raise _v.RecordingError(
            "immobility: the units of the data are unknown, so neither the sensor nor "
            "the rule can be chosen; pass units='deg/s' (gyroscope) or units='g' "
            "(accelerometer), or rule="
        )
    try:
        quantity = _units.quantity_of(u)
    except _units.UnitsError as exc:
        raise _v.RecordingError(f"immobility: units: {exc}") from None
    if quantity == "angular_velocity":
        return "gyroscope"
    if quantity == "acceleration":
        return "accelerometer"
    raise _v.RecordingError(
        f"immobility: units {u!r} are neither an angular velocity (gyroscope rule) nor "
        "an acceleration (accelerometer rule)"
    )


def immobility(
    data,
    fs=None,
    *,
    rule: str = "auto",
    threshold_deg_s: float | str = 12.0,
    gyr_offset=None,
    merge_gap_s: float = 0.1,
    min_duration_s: float = 0.5,
    units: str | None = None,
    **acc_rule,
):
    """Detect immobility with the gyroscope rule, or the accelerometer rule without one.

    Parameters
    ----------
    data : xarray.Dataset, xarray.DataArray or array_like (N, 3)
        A Recording (its ``gyr`` if it has one, else its ``acc``; and ``fs``), a
        labelled DataArray (gyroscope or accelerometer, told by its ``units``), or a
        plain array with ``fs`` and ``units`` (which say which sensor it is).
    fs : float, optional
        Sampling rate (Hz) of a plain array.
    rule : {"auto", "gyroscope", "accelerometer"}
        ``"auto"``: the gyroscope rule when the data have a gyroscope (a Recording with
        ``gyr``, angular-velocity units), the accelerometer rule otherwise.
        ``"accelerometer"`` forces the acceleration-only rule on a Recording that has a
        gyroscope too (e.g. to compare them); ``"gyroscope"`` on data without one is a
        :class:`~tiltlab._validate.RecordingError`.
    threshold_deg_s : float or "auto"
        Gyroscope rule: angular-speed threshold in °/s, or ``"auto"`` for
        :func:`~tiltlab.behavior.valley_threshold`.
    gyr_offset : "auto", None or array_like (3,)
        Gyroscope rule: offset subtracted first, in the units of ``gyr``; ``"auto"``:
        :func:`tiltlab.calibration.robust_gyro_offset`.
    merge_gap_s, min_duration_s : float
        Both rules; see :func:`detect_immobility`.
    units : str, optional
        Units of a plain array ('deg/s' or 'rad/s' for a gyroscope, 'g' or 'm/s^2' for
        an accelerometer).
    **acc_rule
        Accelerometer rule (:func:`acc_immobility`): ``threshold_g`` (VeDBA threshold,
        g; default 0.03), ``window_s`` (static window, s; 0.5) and ``smooth_s``
        (running mean, s; 0.2).

    Returns
    -------
    xarray.DataArray of bool (time), or numpy.ndarray for a plain array
        With attributes ``rule`` (``"gyroscope"`` or ``"accelerometer"``),
        ``threshold`` and ``threshold_units`` (°/s or g), ``rule_description``,
        ``merge_gap_s``, ``min_duration_s`` (and ``fs``); the gyroscope rule adds
        ``threshold_deg_s`` and ``threshold_method``, the accelerometer rule
        ``threshold_g``, ``window_s`` and ``smooth_s``.

    Raises
    ------
    tiltlab._validate.RecordingError
        Missing ``fs`` or units, or ``rule="gyroscope"`` on data without a gyroscope.

    Examples
    --------
    A head still for 2 s, then turning in place (about gravity) at 90 °/s:

    >>> import numpy as np
    >>> from tiltlab import behavior, schema
    >>> gyr = np.zeros((400, 3))
    >>> gyr[200:, 2] = 90.0
    >>> acc = np.tile([0.0, 0.0, 1.0], (400, 1))
    >>> rec = schema.make_recording(
    ...     acc, gyr, fs=100.0, acc_units="g", gyr_units="deg/s"
    ... )
    >>> still = behavior.immobility(rec)
    >>> still.attrs["rule_description"]
    'angular speed < 12 deg/s (fixed)'
    >>> bool(still[:150].all()), bool(still[250:].any())
    (True, False)

    The accelerometer rule (the only one without a gyroscope) misses the turn:

    >>> by_acc = behavior.immobility(rec, rule="accelerometer")
    >>> by_acc.attrs["threshold_units"], bool(by_acc.all())
    ('g', True)
    """
    if isinstance(threshold_deg_s, str) and threshold_deg_s != "auto":
        raise ValueError(
            f"threshold_deg_s must be a number of °/s or 'auto', got {threshold_deg_s!r}"
        )
    unknown = sorted(set(acc_rule) - {"threshold_g", "window_s", "smooth_s"})
    if unknown:
        raise TypeError(
            f"immobility() got an unexpected keyword argument {unknown[0]!r}"
        )
    chosen = _choose_rule(data, rule, units)
    periods = _Periods(merge_gap_s, min_duration_s)
    if chosen == "accelerometer":
        return acc_immobility(data, fs, **periods._asdict(), units=units, **acc_rule)
    return _gyro_immobility(data, fs, units, threshold_deg_s, gyr_offset, periods)


def _gyro_immobility(data, fs, units, threshold_deg_s, gyr_offset, periods: _Periods):
    """Apply the gyroscope rule of :func:`immobility`."""
    need_gyr(data, "immobility(rule='gyroscope')", "use rule='accelerometer'")
    s = _read_gyr(data, fs, units, need_fs=True)
    speed = _speed(s, _offset(s, gyr_offset, "gyr_offset"))
    if isinstance(threshold_deg_s, str):
        thr, method = (
            valley_threshold(speed),
            "valley of the log angular-speed histogram",
        )
    else:
        thr, method = _threshold(threshold_deg_s), "fixed"
    mask = detect_immobility(speed, s.fs, threshold_deg_s=thr, **periods._asdict())
    own = {"threshold_deg_s": thr, "threshold_method": method}
    text = f"angular speed < {thr:g} deg/s ({method})"
    attrs = _rule_attrs("gyroscope", thr, own, periods, text)
    return label(np.asarray(mask), s, "immobile", attrs=attrs)
