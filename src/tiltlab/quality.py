"""Data quality: sensor saturation, and whether the values are plausible for their units.

Layer 1, beside :mod:`tiltlab.units` and :mod:`tiltlab.schema` (which runs these checks
in :func:`tiltlab.schema.validate`). Everything here is cheap — medians, percentiles and
run lengths, O(N) — so that every Recording can be checked when it is built.

Findings and the validation policy
----------------------------------
Each check returns a :class:`Finding` (or ``None``) naming the variable and the problem,
with a severity that follows :mod:`tiltlab._validate`'s policy:

* **error** — the numbers would be wrong by a known, large factor and the evidence is
  unambiguous: an accelerometer labelled g whose median magnitude is ~9.8 (m/s²) or
  labelled m/s² with a median of ~1 (g); raw ADC counts (or values far beyond any
  physical range); a gyroscope labelled rad/s whose 99th percentile is beyond any MEMS
  gyroscope's full scale (°/s), or labelled °/s although it integrates to a fraction of
  the tilt the accelerometer sees (rad/s); a temperature labelled °C that is plainly in
  kelvin (or the reverse). :func:`tiltlab.schema.validate` raises
  :class:`~tiltlab._validate.RecordingError` with the message.
* **warning** (:class:`QualityWarning`) — the data are usable but doubtful, or the
  evidence is not decisive: clipped (saturated) samples, a median acceleration far from
  1 g that no unit mistake explains, a gyroscope 99th percentile between 40 and 100
  rad/s, a temperature outside the −40…85 °C operating range of MEMS sensors, a full
  scale attribute the data exceed.

:func:`assess` returns every finding of a Recording without raising or warning;
:func:`emit` raises the errors and warns the rest.
"""

from __future__ import annotations

import os
import sys
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import xarray as xr

from . import _validate
from . import units as _units
from ._validate import RecordingError

__all__ = [
    "QualityWarning",
    "UnitCheckError",
    "UNIT_CHECK_SWITCH",
    "Finding",
    "saturation",
    "full_scale",
    "limits",
    "check_saturation",
    "check_raw_counts",
    "check_acc_units",
    "check_gyr_units",
    "check_temperature",
    "plausibility",
    "assess",
    "emit",
    "ACC_MEDIAN_G",
    "ACC_COUNTS_G",
    "GYR_COUNTS_DEG_S",
    "MAG_COUNTS_UT",
    "GYR_RAD_S_P99",
    "GYR_WINDOW_S",
    "GYR_MIN_TILT_DEG",
    "GYR_DECISIVE_SHARE",
    "TEMP_RANGE_DEGC",
]

#: Plausible median magnitude of an accelerometer (g): gravity dominates any recording.
ACC_MEDIAN_G: tuple[float, float] = (0.5, 2.0)
#: Median |acc| (g) beyond which the values cannot be physical (raw counts or wrong scale).
ACC_COUNTS_G: float = 50.0
#: 99th percentile of |gyr| (°/s) beyond which the values cannot be physical.
GYR_COUNTS_DEG_S: float = 10_000.0
#: Median |mag| (µT) beyond which the values cannot be physical (Earth: 25–65 µT).
MAG_COUNTS_UT: float = 10_000.0
#: 99th percentile of |gyr| (rad/s): above the first, a "rad/s" gyroscope looks like °/s
#: (warning); above the second, beyond any MEMS gyroscope's full scale, it must be (error).
GYR_RAD_S_P99: tuple[float, float] = (40.0, 100.0)
#: Operating range of MEMS inertial sensors (°C).
TEMP_RANGE_DEGC: tuple[float, float] = (-40.0, 85.0)

_VECTORS = ("acc", "gyr", "mag")
_PHYSICAL = {
    "acc": ("acceleration", "g", ACC_COUNTS_G, "median"),
    "gyr": ("angular velocity", "deg/s", GYR_COUNTS_DEG_S, "99th percentile"),
    "mag": ("magnetic field", "uT", MAG_COUNTS_UT, "median"),
}
_PRETTY = {"m/s^2": "m/s²", "deg/s": "°/s", "uT": "µT", "degC": "°C"}


class QualityWarning(UserWarning):
    """Data that satisfy the Recording contract but look doubtful (e.g. clipped samples)."""


#: The one switch that accepts unit labels as they are, in the form each entry point
#: takes it (the error message names the one the user is using).
UNIT_CHECK_SWITCH: dict[str, str] = {
    "python": "check_units=False",
    "mapping": '"check_units": false in the mapping',
    "cli": "--no-check-units",
    "manifest": 'reader_options {"check_units": false} in its manifest row',
}


class UnitCheckError(RecordingError):
    """Values that decisively contradict their unit labels.

    The message names every such variable and the unit its values look like, then the
    switch that accepts the labels as they are, in the form of the entry point in use
    (:data:`UNIT_CHECK_SWITCH`; :meth:`for_switch` re-words it).

    Attributes
    ----------
    findings : tuple of Finding
        The error findings, one per variable.
    switch : str
        A key of :data:`UNIT_CHECK_SWITCH`.
    """

    def __init__(self, findings: Sequence[Finding], switch: str = "python"):
        self.findings = tuple(findings)
        self.switch = switch if switch in UNIT_CHECK_SWITCH else "python"
        body = "; ".join(f.message for f in self.findings)
        super().__init__(
            f"{body}. If the labels are right after all, "
            f"{UNIT_CHECK_SWITCH[self.switch]} accepts them as they are"
        )

    def for_switch(self, switch: str) -> UnitCheckError:
        """The same error, naming the switch as ``switch`` takes it."""
        return UnitCheckError(self.findings, switch)

    def __reduce__(self):  # picklable across process pools
        return (UnitCheckError, (self.findings, self.switch))


@dataclass(frozen=True)
class Finding:
    """One result of a quality check.

    Attributes
    ----------
    var : str
        The variable concerned (``"acc"``, ``"gyr"``, ``"mag"``, ``"temp"``).
    check : str
        Which check: ``"saturation"``, ``"range"``, ``"raw_counts"``, ``"acc_units"``,
        ``"gyr_units"`` or ``"temperature"``.
    severity : str
        ``"error"`` or ``"warning"`` (see the module's policy).
    message : str
        One line naming the variable, the problem and the fix.
    value : float, optional
        The number behind it (fraction clipped, median magnitude, percentile…).
    """

    var: str
    check: str
    severity: str
    message: str
    value: float | None = None

    @property
    def is_error(self) -> bool:
        return self.severity == "error"


def _u(unit: str) -> str:
    return _PRETTY.get(unit, unit)


# --------------------------------------------------------------------------- reading


def _raw_dtype(x, var: str):
    if isinstance(x, xr.Dataset):
        return x[var].dtype if var in x else np.dtype(float)
    if isinstance(x, xr.DataArray):
        return x.dtype
    try:
        return np.asarray(x).dtype
    except (TypeError, ValueError):  # pragma: no cover - reported by _validate
        return np.dtype(object)


def _read(x, name: str, *, units: str | None = None, need_units: bool = True):
    """Values (2-D, float, NaN kept), canonical units (or None), variable attrs, fs, and
    whether the input had an integer dtype."""
    kind = _raw_dtype(x, name).kind
    if isinstance(x, xr.Dataset):
        # a Recording's variables: read directly (its time/fs consistency and shapes are
        # validate's business, with its tolerances); values are only read, never written
        if name not in x:
            raise RecordingError(f"the Recording has no variable {name!r}")
        da = x[name]
        fs = x.attrs.get("fs")
        fs = (
            None
            if fs is None
            else _validate.check_fs(fs, "the Recording's attribute fs")
        )
        u = da.attrs.get("units")
        if units is not None:
            u = u if u is not None else units
            if _units.normalise_unit(units) != _units.normalise_unit(u):
                raise RecordingError(
                    f"{name}: units = {units!r} contradicts the data's units {u!r}"
                )
        if u is None and need_units:
            raise RecordingError(f"{name}: its units are unknown (add attrs['units'])")
        v = np.asarray(da.values, dtype=float)
        if v.ndim == 1:
            v = v[:, None]
        elif v.ndim != 2:
            raise RecordingError(f"{name} must have dims (time,) or (time, axis)")
        u = None if u is None else _units.normalise_unit(u)
        return v, u, dict(da.attrs), fs, kind in "iu"
    sig = _validate.signal(
        x,
        name,
        units=units,
        need_fs=False,
        need_units=need_units,
        width=None,
        ndim=None,
        allow_nan=True,
    )
    v = sig.values
    if v.ndim == 1:
        v = v[:, None]
    elif v.ndim != 2:
        raise ValueError(f"{name} must have shape (N,) or (N, k), got {v.shape}")
    attrs = dict(x.attrs) if isinstance(x, xr.DataArray) else {}
    return v, sig.units, attrs, sig.fs, kind in "iu"


def _finite_rows(v: np.ndarray) -> np.ndarray:
    return v[np.isfinite(v).all(axis=1)]


def _integral(v: np.ndarray, is_int: bool) -> bool:
    if is_int:
        return True
    f = v[np.isfinite(v)]
    return bool(f.size) and bool(np.all(f == np.round(f)))


# --------------------------------------------------------------------------- saturation


def full_scale(attrs_or_da, name: str = "the variable") -> tuple[float, float] | None:
    """The full scale recorded in a variable's ``range`` attribute, as ``(low, high)``.

    ``range`` is the sensor's measurement range in the variable's units: a positive number
    ``r`` (meaning ±r) or a pair ``[low, high]`` with ``low < 0 < high``. Returns None
    when there is no such attribute; a malformed one is a :class:`RecordingError`.
    """
    attrs = (
        attrs_or_da.attrs
        if isinstance(attrs_or_da, (xr.DataArray, xr.Dataset))
        else attrs_or_da
    )
    if not attrs or attrs.get("range") is None:
        return None
    return limits(attrs["range"], f"{name} attribute 'range'", RecordingError)


def limits(value, what: str = "limit", error=ValueError) -> tuple[float, float]:
    """A full scale as ``(low, high)``: ``r`` (a positive number) means ±r, a pair must
    have ``low < 0 < high``; anything else raises ``error`` naming ``what``."""
    bad = error(
        f"{what} must be a positive full scale r (for ±r) or [low, high] with "
        f"low < 0 < high, in the variable's units; got {value!r}"
    )
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise bad from None
    if arr.ndim == 0:
        r = float(arr)
        if not np.isfinite(r) or r <= 0:
            raise bad
        return (-r, r)
    if arr.shape != (2,) or not np.all(np.isfinite(arr)) or not arr[0] < 0 < arr[1]:
        raise bad
    return (float(arr[0]), float(arr[1]))


def _run_lengths(flags: np.ndarray) -> np.ndarray:
    d = np.diff(np.concatenate(([0], flags.astype(np.int8), [0])))
    return np.flatnonzero(d == -1) - np.flatnonzero(d == 1)


def _observed_rail(v: np.ndarray, min_run: int) -> float | None:
    """The largest |value| if it behaves like a rail the signal is clipped at, else None."""
    a = np.abs(v)
    finite = np.isfinite(a)
    if not finite.any():
        return None
    m = float(np.max(a[finite]))
    if m <= 0:
        return None
    with np.errstate(invalid="ignore"):
        for k in range(v.shape[1]):
            ak = a[:, k]
            col = v[finite[:, k], k]
            if not col.size or col.max() - col.min() < 0.5 * m:
                # the axis does not swing: a constant or a static offset also repeats
                # its maximum
                continue
            # the global maximum itself (to rounding) on a flat run of this axis, where a
            # smooth peak reaches its maximum on one sample
            top = ak >= m * (1.0 - 1e-9)
            longest = _run_lengths(top).max(initial=0)
            if longest < min_run:
                continue
            levels = np.unique(col)
            if levels.size < 3 or m < 20.0 * float(np.diff(levels).min()):
                continue  # coarsely quantised: its top level repeats anyway
            # a slowly varying quantised (or sample-and-hold) signal repeats values near
            # its maximum too: the run must be unlikely at the repeat rate p seen just
            # below the maximum, p ** (run - 1) < 1 %
            if _repeat_rate(v[:, k], top, ak >= 0.9 * m) ** (longest - 1) >= 0.01:
                continue
            return m
    return None


def _repeat_rate(col: np.ndarray, top: np.ndarray, near: np.ndarray) -> float:
    """How often the signal repeats its previous value: on consecutive samples just below
    the maximum (``near`` and not ``top``) when there are at least 10 such pairs, else on
    the whole axis outside the maximum (a sample-and-hold signal repeats everywhere)."""
    for sel in (near & ~top, ~top):
        pair = sel[1:] & sel[:-1] & np.isfinite(col[1:]) & np.isfinite(col[:-1])
        if pair.sum() >= 10:
            return float(np.mean(col[1:][pair] == col[:-1][pair]))
    return 0.0


def _saturation_mask(
    v: np.ndarray, lim: tuple[float, float] | None, frac: float, min_run: int
) -> tuple[np.ndarray, tuple[float, float] | None]:
    if lim is None:
        m = _observed_rail(v, min_run)
        if m is None:
            return np.zeros(v.shape[0], dtype=bool), None
        lim = (-m, m)
    with np.errstate(invalid="ignore"):
        clipped = (v >= frac * lim[1]) | (v <= frac * lim[0])
    return clipped.any(axis=1), lim


def saturation(
    x,
    *,
    fraction: float = 0.999,
    min_run: int = 3,
    limit=None,
    var: str | None = None,
    units: str | None = None,
) -> np.ndarray:
    """Which samples are clipped at the sensor's full scale (on any axis).

    A MEMS sensor whose input exceeds its measurement range outputs the end of the range
    (the ADC's rail) instead of the true value, so a sample is *clipped* when a component
    reaches the rail: ``|x| >= fraction × limit``. The true value there is unknown (at
    least the rail), so orientation filters and calibrations are biased on these samples.

    The rail is the sensor's full scale when it is known: the ``limit`` argument, or the
    variable's ``range`` attribute (see :func:`full_scale`). Otherwise the largest
    ``|value|`` observed (over all axes) is taken as the rail, but only when it behaves
    like one. On some axis the maximum itself must be reached on a run of at least
    ``min_run`` consecutive samples — a clipped signal stays flat at the rail, while a
    signal that merely peaks reaches its maximum on one sample — and, so that signals
    that repeat values for other reasons are not called clipped, that axis must swing
    (span at least half the level: not a constant or static offset), the level must be
    many resolution steps (≥ 20) above zero (not a coarsely quantised still signal), and
    the run must be improbable at the rate ``p`` at which the axis repeats its previous
    value just below the maximum (within 10 %; anywhere when too few samples come that
    close): ``p ** (run − 1) < 0.01`` (not a slow quantised or sample-and-hold signal,
    such as a magnetometer read more slowly than the IMU). Once the rail is established,
    every sample with a component at or beyond ``fraction`` × the rail is clipped, runs
    or not. A ``range`` attribute that the data exceed by more than 5 % is stale (units
    changed without it) and ignored.

    Parameters
    ----------
    x : xarray.Dataset, xarray.DataArray or array_like, shape (N,) or (N, k)
        A Recording (variable ``var``; by default every one of ``acc``, ``gyr`` and
        ``mag`` present, each against its own full scale), a labelled DataArray or a
        plain array (NaN allowed: never clipped).
    fraction : float
        Fraction of the rail at and above which a sample counts as clipped, in (0, 1].
        Below 1 so that a rail slightly moved by a calibration (offset, scale) is found.
    min_run : int
        Shortest run of consecutive samples at the observed maximum that reveals a rail
        (not used when the full scale is known).
    limit : float or (float, float), optional
        Full scale in the data's units: ``r`` for ±r, or ``(low, high)``. Overrides the
        ``range`` attribute. With a Recording, give ``var`` too.
    var : str, optional
        Variable of a Recording.
    units : str, optional
        Units of a plain array (only checked against the attrs of labelled input).

    Returns
    -------
    numpy.ndarray of bool, shape (N,)
        True where a sample is clipped on any axis.

    Notes
    -----
    Without a known full scale the rail is a guess: a quantised signal whose largest
    peak is so slow that it stays on its top quantisation level for ``min_run`` samples
    looks clipped, and a rail moved by a cross-axis calibration (no longer flat) is
    missed. Give ``limit`` — the sensor's configured range — to decide without guessing.
    """
    frac = _validate.fraction(fraction, "fraction", open_low=True)
    min_run = _validate.integer(min_run, "min_run", minimum=1)
    lim_arg = None if limit is None else limits(limit, "limit")
    if isinstance(x, xr.Dataset):
        if var is None:
            if limit is not None:
                raise ValueError(
                    "limit is the full scale of one variable: give var= too "
                    "(e.g. var='acc')"
                )
            names = [v for v in _VECTORS if v in x]
            if not names:
                raise RecordingError(
                    "the Recording has none of 'acc', 'gyr', 'mag' to check"
                )
        else:
            names = [var]
        mask = np.zeros(x.sizes.get("time", 0), dtype=bool)
        for name in names:
            v, _, attrs, _, _ = _read(x, name, units=units, need_units=False)
            lim = lim_arg if lim_arg is not None else _attr_limit(v, attrs, name)[0]
            mask |= _saturation_mask(v, lim, frac, min_run)[0]
        return mask
    name = var or (x.name if isinstance(x, xr.DataArray) and x.name else "x")
    v, _, attrs, _, _ = _read(x, str(name), units=units, need_units=False)
    lim = lim_arg if lim_arg is not None else _attr_limit(v, attrs, str(name))[0]
    return _saturation_mask(v, lim, frac, min_run)[0]


def _attr_limit(v: np.ndarray, attrs, name: str):
    """The full scale of the ``range`` attribute, or None when absent or stale (the data
    exceed it by more than 5 %); and the peak |value| when stale, else None."""
    lim = full_scale(attrs, repr(name))
    if lim is None:
        return None, None
    peak = float(np.nanmax(np.abs(v))) if np.isfinite(v).any() else 0.0
    if peak > 1.05 * max(-lim[0], lim[1]):
        return None, peak
    return lim, None


def check_saturation(
    ds: xr.Dataset, *, fraction: float = 0.999, min_run: int = 3
) -> list[Finding]:
    """Warnings about clipped samples of ``acc``, ``gyr`` and ``mag`` (see
    :func:`saturation`), and about a ``range`` attribute the data exceed by more than 5 %
    (a stale or wrong full scale, e.g. after a change of units).

    Saturation is a warning, never an error: the Recording is still valid and the clipped
    samples are known (mask them with :func:`saturation`).
    """
    frac = _validate.fraction(fraction, "fraction", open_low=True)
    min_run = _validate.integer(min_run, "min_run", minimum=1)
    out: list[Finding] = []
    for name in _VECTORS:
        if name not in ds:
            continue
        v, u, attrs, _, _ = _read(ds, name, need_units=False)
        unit = f" {_u(u)}" if u else ""
        lim, stale = _attr_limit(v, attrs, name)
        if stale is not None:
            out.append(
                Finding(
                    name,
                    "range",
                    "warning",
                    f"{name} reaches {stale:.4g}{unit}, beyond its full scale "
                    f"(attribute range = {attrs['range']!r}): the attribute is wrong "
                    "or stale (were the units changed?); saturation is judged from "
                    "the data instead",
                    stale,
                )
            )
        mask, rail = _saturation_mask(v, lim, frac, min_run)
        n_clip = int(mask.sum())
        if not n_clip:
            continue
        n = mask.size
        if lim is not None:
            where = f"its full scale {_span(rail)}{unit} (attribute 'range')"
        else:
            where = (
                f"{_span(rail)}{unit}, its largest value, reached on runs of "
                f"≥ {min_run} samples: the sensor's rail"
            )
        out.append(
            Finding(
                name,
                "saturation",
                "warning",
                f"{name}: {n_clip} of {n} samples ({100.0 * n_clip / n:.3g} %) are "
                f"clipped at {where}; their true values are unknown "
                f"(tiltlab.quality.saturation(rec, var={name!r}) masks them)",
                n_clip / n,
            )
        )
    return out


def _span(lim: tuple[float, float]) -> str:
    lo, hi = lim
    return f"±{hi:.6g}" if np.isclose(-lo, hi) else f"[{lo:.6g}, {hi:.6g}]"


# --------------------------------------------------------------------------- plausibility


def check_raw_counts(
    x, units: str | None = None, *, var: str | None = None
) -> Finding | None:
    """Error when ``acc``, ``gyr`` or ``mag`` values are far beyond any physical range.

    Thresholds, in the labelled units converted: median |acc| > 50 g, 99th percentile
    |gyr| > 10 000 (read as °/s, so that °/s values labelled rad/s are left to
    :func:`check_gyr_units`), median |mag| > 10 000 µT. Integral values (or an integer
    dtype) are raw ADC counts ("scale them to physical units first"); other values a wrong unit
    or scale. Either way every number computed from them would be wrong: an error.

    Parameters
    ----------
    x : xarray.Dataset, xarray.DataArray or array_like, shape (N, 3)
        A Recording (variable ``var``), a labelled DataArray or a plain array.
    units : str, optional
        Units of a plain array.
    var : {"acc", "gyr", "mag"}
        Which quantity (default the DataArray's name).
    """
    name = _name(x, var)
    if name not in _PHYSICAL:
        raise ValueError(f"var must be one of {list(_PHYSICAL)}, got {name!r}")
    quantity, ref, bound, stat = _PHYSICAL[name]
    v, u, _, _, is_int = _read(x, name, units=units)
    if u == "a.u.":
        return None
    rows = _finite_rows(v)
    if not rows.size:
        return None
    # a gyroscope is judged in °/s whatever its label: °/s values labelled rad/s are
    # physical, and check_gyr_units names that mistake
    factor = 1.0 if name == "gyr" else _units.conversion_factor(u, ref)
    norm = np.linalg.norm(rows, axis=1) * factor
    level = float(np.median(norm) if stat == "median" else np.percentile(norm, 99))
    if level <= bound:
        return None
    if name == "gyr":
        shown = f"{level:.4g} (> {bound:g}: beyond any gyroscope, in °/s or rad/s)"
    else:
        shown = f"{level:.4g} {_u(ref)} (> {bound:g} {_u(ref)})"
    if _integral(v, is_int):
        what = "looks like raw ADC counts: scale them to physical units first"
    else:
        what = f"far beyond any physical {quantity}: a wrong unit or scale factor"
    return Finding(
        name,
        "raw_counts",
        "error",
        f"{name} is labelled {_u(u)} but its {stat} magnitude is {shown}: {what}",
        level,
    )


def check_acc_units(acc, units: str | None = None, *, var: str = "acc"):
    """Accelerometer magnitude against its unit label.

    Gravity dominates any recording, so the median ``|acc|`` is about 1 g
    (``ACC_MEDIAN_G`` = 0.5–2 g). Labelled g with a median of 4.9–19.6 (= 0.5–2 × 9.81)
    the values are m/s²; labelled m/s² with a median of 0.5–2 they are g: an **error**
    (every number would be off by 9.81). Any other median outside 0.5–2 g is a
    **warning** (no single unit mistake explains it: a scale error, a gravity-compensated
    signal, free fall). Medians beyond 50 g are left to :func:`check_raw_counts`.

    The m/s²-looks-like-g error needs gravity to be there: when the sampling rate is
    known and the acceleration averaged over 1 s keeps less than half of its median
    magnitude (a gravity-free "linear acceleration" signal, whose median in m/s² can be
    about 1), the finding is only a warning.

    Returns
    -------
    Finding or None
    """
    name = _name(acc, var)
    v, u, _, fs, _ = _read(acc, name, units=units)
    rows = _finite_rows(v)
    if not rows.size:
        return None
    med = float(np.median(np.linalg.norm(rows, axis=1)))
    g = med * _units.conversion_factor(u, "g")
    lo, hi = ACC_MEDIAN_G
    if lo <= g <= hi or g > ACC_COUNTS_G:
        return None
    other = "m/s^2" if u == "g" else "g"
    gravity_free = False
    if other == "g" and fs is not None and rows.shape[0] > 2 * fs:
        w = max(1, int(round(fs)))
        c = np.cumsum(np.vstack([np.zeros((1, 3)), rows]), axis=0)
        mean_1s = np.linalg.norm((c[w:] - c[:-w]) / w, axis=1)
        gravity_free = float(np.median(mean_1s)) < 0.5 * med
    if gravity_free and lo <= med * _units.conversion_factor(other, "g") <= hi:
        return Finding(
            name,
            "acc_units",
            "warning",
            f"{name}: median magnitude {med:.3g} {_u(u)} is far from gravity's 9.81 and "
            "its 1-s average is small: a gravity-free (linear acceleration) signal, or g "
            "labelled m/s²; tilt needs the gravity-including accelerometer",
            med,
        )
    if lo <= med * _units.conversion_factor(other, "g") <= hi:
        return Finding(
            name,
            "acc_units",
            "error",
            f"{name} is labelled {_u(u)} but its median magnitude is {med:.3g}: "
            f"looks like {_u(other)} (set units={other!r})",
            med,
        )
    return Finding(
        name,
        "acc_units",
        "warning",
        f"{name}: median magnitude {med:.3g} {_u(u)} ({g:.3g} g) is far from the 1 g of "
        f"gravity (expected {lo:g}–{hi:g} g): check its units and scale",
        med,
    )


def _smoothed_directions(
    acc: np.ndarray, w: int, tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions of the acceleration averaged over ``w`` samples (centred), and
    whether each is gravity-dominated (its magnitude within ``tol`` of the median)."""
    a = np.where(np.isfinite(acc), acc, 0.0)
    c = np.cumsum(np.vstack([np.zeros((1, 3)), a]), axis=0)
    n = a.shape[0]
    lo = np.clip(np.arange(n) - w // 2, 0, n)
    hi = np.clip(lo + w, 0, n)
    sm = (c[hi] - c[lo]) / np.maximum(hi - lo, 1)[:, None]
    norm = np.linalg.norm(sm, axis=1)
    med = float(np.median(norm)) if n else 0.0
    ok = np.isfinite(acc).all(axis=1) & (norm > 0)
    if med > 0:
        ok &= np.abs(norm / med - 1.0) < tol
    d = sm / np.where(norm > 0, norm, 1.0)[:, None]
    return d, ok


#: Window (s) over which the gyroscope's rotation is compared with the accelerometer's
#: tilt, the smallest tilt (degrees) that counts as turning, and the share of turning
#: windows that must contradict the label before it is refused (below: a warning).
GYR_WINDOW_S: float = 1.0
GYR_MIN_TILT_DEG: float = 20.0
GYR_DECISIVE_SHARE: float = 0.6


def _rotation_bound(
    gyr_rad_s: np.ndarray, acc: np.ndarray, fs: float
) -> tuple[int, int, float]:
    """Windows in which the accelerometer turns by more than ``GYR_MIN_TILT_DEG``, and
    how many of them the gyroscope cannot explain (it integrates to less than a fifth
    of that tilt), and the median |cosine| between the axis the accelerometer turns
    about and the gyroscope's (perpendicular to gravity) in those windows: the |median
    signed cosine|. The angle between two gravity directions is at most the rotation
    integrated between them, so a correctly labelled gyroscope explains every window,
    whatever its bias or noise."""
    n = gyr_rad_s.shape[0]
    w = max(1, int(round(0.25 * fs)))  # direction smoothing (vibration, noise)
    step = max(1, int(round(GYR_WINDOW_S * fs)))
    if n < step + 2 * w:
        return 0, 0, float("nan")
    d, ok = _smoothed_directions(acc, w, 0.05)
    speed = np.linalg.norm(np.where(np.isfinite(gyr_rad_s), gyr_rad_s, 0.0), axis=1)
    integral = np.concatenate([[0.0], np.cumsum(speed) / fs])
    i0 = np.arange(w, n - step - w, step)
    i1 = i0 + step
    good = ok[i0] & ok[i1]
    tilt = np.arccos(np.clip(np.sum(d[i0] * d[i1], axis=1), -1.0, 1.0))
    # the smoothed directions see half a smoothing window beyond each end
    turned = (
        integral[np.minimum(i1 + w // 2 + 1, n)] - integral[np.maximum(i0 - w // 2, 0)]
    )
    turning = good & (tilt > np.radians(GYR_MIN_TILT_DEG))
    unexplained = turning & (turned < tilt / 5.0)
    # does the gyroscope turn about the axis the accelerometer turns about? (its
    # direction does not depend on the unit label; noise and bias point anywhere).
    # Judged over short steps (0.1 s) inside the unexplained windows, where the
    # rotation axis is nearly constant.
    agree = 0.0
    if unexplained.any():
        h = max(1, int(round(0.1 * fs)))
        inside = np.zeros(n, dtype=bool)
        for k0, k1 in zip(i0[unexplained], i1[unexplained], strict=True):
            inside[k0 : k1 - h] = True
        j0 = np.flatnonzero(inside & ok & np.roll(ok, -h))
        j1 = j0 + h
        gsum = np.vstack(
            [np.zeros((1, 3)), np.cumsum(np.nan_to_num(gyr_rad_s), axis=0)]
        )
        rot = gsum[j1] - gsum[j0]
        axis_acc = np.cross(d[j0], d[j1])
        mean_g = d[j0] + d[j1]
        mean_g /= np.maximum(np.linalg.norm(mean_g, axis=1, keepdims=True), 1e-12)
        rot_perp = rot - np.sum(rot * mean_g, axis=1, keepdims=True) * mean_g
        size = np.linalg.norm(axis_acc, axis=1)
        denom = size * np.linalg.norm(rot_perp, axis=1)
        # signed: for a right-handed frame d0 × d1 = −θ ω̂⊥, so the cosine is near −1
        # (near +1 for a left-handed one); noise gives cosines of either sign
        cos = np.sum(axis_acc * rot_perp, axis=1) / np.maximum(denom, 1e-300)
        if size.sum() > 0:
            agree = abs(float(np.sum(cos * size) / size.sum()))
    return int(turning.sum()), int(unexplained.sum()), agree


def check_gyr_units(
    gyr,
    units: str | None = None,
    *,
    acc=None,
    fs: float | None = None,
    var: str = "gyr",
) -> Finding | None:
    """Gyroscope magnitude against its unit label, where decidable.

    * Labelled rad/s: a 99th percentile of ``|gyr|`` above 40 rad/s (2300 °/s, beyond the
      full scale of most MEMS gyroscopes) looks like °/s: a **warning**; above 100 rad/s
      (5700 °/s, beyond any MEMS gyroscope) it cannot be rad/s: an **error**.
    * Labelled °/s: decided from the accelerometer, window by window. Over
      ``GYR_WINDOW_S`` = 1 s, the angle between two gravity directions is at most the
      rotation integrated between them, ``∫|ω| dt``; a gyroscope that, read in °/s,
      integrates to less than a fifth of the tilt in most (``GYR_DECISIVE_SHARE``) of at
      least three windows that turn by more than 20° is in rad/s (or does not work): an
      **error**. Fewer such windows (linear acceleration can turn the accelerometer
      without rotation) are a **warning**. Bias and noise only add to the integral, so
      they cannot cause either; a still or barely turning recording is not judged.

    Parameters
    ----------
    gyr : xarray.Dataset, xarray.DataArray or array_like, shape (N, 3)
        A Recording (its ``acc`` and ``fs`` are then used), a labelled DataArray or a
        plain array.
    units : str, optional
        Units of a plain array.
    acc : array_like, shape (N, 3), optional
        Acceleration (any units) for the °/s case.
    fs : float, optional
        Sampling rate (Hz) for the °/s case.

    Returns
    -------
    Finding or None
    """
    name = _name(gyr, var)
    v, u, _, f, _ = _read(gyr, name, units=units)
    if fs is not None:
        f = _validate.check_fs(fs) if f is None else f
    rows = _finite_rows(v)
    if not rows.size:
        return None
    norm = np.linalg.norm(rows, axis=1)
    if u == "rad/s":
        p99 = float(np.percentile(norm, 99))
        warn_at, err_at = GYR_RAD_S_P99
        if p99 <= warn_at or p99 > GYR_COUNTS_DEG_S:  # beyond: check_raw_counts
            return None
        sev = "error" if p99 > err_at else "warning"
        return Finding(
            name,
            "gyr_units",
            sev,
            f"{name} is labelled rad/s but its 99th percentile magnitude is {p99:.4g} "
            f"(> {warn_at:g} rad/s = {np.degrees(warn_at):.0f} °/s"
            + (", beyond any MEMS gyroscope" if sev == "error" else "")
            + "): looks like °/s (set units='deg/s')",
            p99,
        )
    # labelled deg/s: compare the integrated rotation with the accelerometer's tilt
    if acc is None and isinstance(gyr, xr.Dataset) and "acc" in gyr:
        acc = gyr["acc"].values
    if acc is None or f is None:
        return None
    a = np.asarray(acc, dtype=float)
    if a.shape != v.shape or v.shape[1] != 3:
        return None
    rad = v * _units.conversion_factor(u, "rad/s")
    # over the whole recording: the gyroscope must explain the largest tilt (decisive:
    # no linear acceleration holds the accelerometer 45° off for half a second)
    ok = np.isfinite(v).all(axis=1)
    if ok.mean() >= 0.99:
        tilt = _tilt_span(a, f)
        turned_all = float(np.linalg.norm(rad[ok], axis=1).sum() / f)
        if tilt is not None and tilt >= np.radians(45.0) and turned_all < tilt / 5.0:
            return Finding(
                name,
                "gyr_units",
                "error",
                f"{name} is labelled °/s but integrates to {np.degrees(turned_all):.3g}° "
                f"of rotation while the accelerometer tilts by {np.degrees(tilt):.0f}°: "
                "looks like rad/s (set units='rad/s'), or the gyroscope is not working",
                np.degrees(turned_all),
            )
    turning, unexplained, agree = _rotation_bound(rad, a, f)
    if turning < 3 or unexplained == 0:
        return None
    share = unexplained / turning
    # decisive: most turning windows unexplained, and the gyroscope does turn about
    # the accelerometer's axis (it measures the rotation, too small by a unit factor)
    decisive = share >= GYR_DECISIVE_SHARE and agree >= 0.8
    if not decisive and share < 0.2:
        return None
    what = (
        f"in {unexplained} of {turning} one-second windows where the accelerometer "
        f"tilts by more than {GYR_MIN_TILT_DEG:g}°, {name} (read as °/s) integrates to "
        "less than a fifth of that tilt"
    )
    if decisive:
        return Finding(
            name,
            "gyr_units",
            "error",
            f"{name} is labelled °/s but {what}, about the same axis: looks like rad/s "
            "(set units='rad/s')",
            share,
        )
    return Finding(
        name,
        "gyr_units",
        "warning",
        f"{what}: if {name} is really °/s, the accelerometer also sees linear "
        "acceleration; if not, it may be rad/s",
        share,
    )


def _tilt_span(acc: np.ndarray, fs: float) -> float | None:
    """A lower bound (rad) of how far the gravity direction seen by the accelerometer
    turns: the angle between two of its directions, smoothed over 0.5 s and taken on
    samples whose magnitude is within 10 % of the median (gravity-dominated)."""
    a = _finite_rows(acc)
    w = max(1, int(round(0.5 * fs)))
    if a.shape[0] < 2 * w:
        return None
    c = np.cumsum(np.vstack([np.zeros((1, 3)), a]), axis=0)
    sm = (c[w:] - c[:-w]) / w
    norm = np.linalg.norm(sm, axis=1)
    med = float(np.median(norm))
    if not med > 0:
        return None
    keep = np.abs(norm / med - 1.0) < 0.1
    if keep.sum() < 2:
        return None
    d = sm[keep] / norm[keep, None]
    i = int(np.argmin(d @ d[0]))
    j = int(np.argmin(d @ d[i]))
    return float(np.arccos(np.clip(d[i] @ d[j], -1.0, 1.0)))


def check_temperature(temp, units: str | None = None, *, var: str = "temp"):
    """Sensor temperature against the −40…85 °C operating range of MEMS sensors.

    Labelled °C with every value in 233–358 (i.e. −40…85 °C in kelvin), or labelled K
    with every value in −40…85, the unit is swapped: an **error** (it shifts every
    temperature correction by 273.15). Other values outside the range are a **warning**
    (a sensor outside its rated range, or a bad channel).
    """
    name = _name(temp, var)
    v, u, _, _, _ = _read(temp, name, units=units, need_units=True)
    t = v[np.isfinite(v)]
    if not t.size:
        return None
    lo, hi = TEMP_RANGE_DEGC
    k0 = 273.15
    c = t - k0 if u == "K" else t
    if lo <= c.min() and c.max() <= hi:
        return None
    swapped = c + k0 if u == "K" else c - k0
    if lo <= swapped.min() and swapped.max() <= hi:
        other = "degC" if u == "K" else "K"
        return Finding(
            name,
            "temperature",
            "error",
            f"{name} is labelled {_u(u)} but its values ({np.min(t):.4g}…{np.max(t):.4g}) "
            f"look like {_u(other)} (set units={other!r})",
            float(np.median(t)),
        )
    out = int(np.sum((c < lo) | (c > hi)))
    return Finding(
        name,
        "temperature",
        "warning",
        f"{name}: {out} of {t.size} values are outside the {lo:g}…{hi:g} °C operating "
        f"range of MEMS sensors ({c.min():.4g}…{c.max():.4g} °C): check the channel "
        "and its units",
        float(out / t.size),
    )


def _name(x, var: str | None) -> str:
    if var is not None:
        return var
    if isinstance(x, xr.DataArray) and x.name is not None:
        return str(x.name)
    raise ValueError("give var= (e.g. var='acc') to name the data")


def plausibility(ds: xr.Dataset) -> list[Finding]:
    """Every plausibility finding of a Recording: raw counts, accelerometer and gyroscope
    units, temperature (see the ``check_*`` functions). NaN samples are ignored."""
    out: list[Finding] = []
    counts = set()
    for name in _VECTORS:
        if name in ds:
            f = check_raw_counts(ds, var=name)
            if f is not None:
                out.append(f)
                counts.add(name)
    if "acc" in ds and "acc" not in counts:
        f = check_acc_units(ds, var="acc")
        if f is not None:
            out.append(f)
    if "gyr" in ds and "gyr" not in counts:
        f = check_gyr_units(ds, var="gyr")
        if f is not None:
            out.append(f)
    if "temp" in ds:
        f = check_temperature(ds, var="temp")
        if f is not None:
            out.append(f)
    return out


def assess(
    ds: xr.Dataset, *, units: bool = True, saturation: bool = True
) -> list[Finding]:
    """All quality findings of a Recording (plausibility, then saturation), without
    raising or warning. ``units`` / ``saturation`` select the checks."""
    out: list[Finding] = []
    if units:
        out += plausibility(ds)
    if saturation:
        out += check_saturation(ds)
    return out


def _stacklevel() -> int:
    """The stack level of the first caller outside tiltlab, for :func:`warnings.warn`
    called from :func:`emit`."""
    pkg = os.path.dirname(os.path.abspath(__file__))
    frame = sys._getframe(1)  # emit
    level = 1
    while frame.f_back is not None and os.path.abspath(
        frame.f_code.co_filename
    ).startswith(pkg + os.sep):
        frame = frame.f_back
        level += 1
    return level


def emit(findings: Sequence[Finding]) -> None:
    """Raise :class:`RecordingError` with every error's message (joined by ``"; "``),
    else warn each warning as a :class:`QualityWarning`."""
    errors = [f for f in findings if f.is_error]
    if errors:
        raise UnitCheckError(errors)
    level = _stacklevel()
    for f in findings:
        warnings.warn(f.message, QualityWarning, stacklevel=level)
