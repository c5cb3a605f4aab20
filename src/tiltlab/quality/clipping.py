"""Find sensor saturation (clipped samples at the full scale) and raw ADC counts."""

from __future__ import annotations


import numpy as np
import xarray as xr

from .. import _validate
from .. import units as _units
from .._deprecate import renamed
from .._validate import RecordingError
from ._common import (
    Finding,
    _PHYSICAL,
    _VECTORS,
    _finite_rows,
    _integral,
    _name,
    _read,
    _u,
)


def full_scale(attrs_or_da, name: str = "the variable") -> tuple[float, float] | None:
    """Return the full scale recorded in a variable's ``range`` attribute.

    ``range`` is the sensor's measurement range in the variable's units: a positive number
    ``r`` (meaning ±r) or a pair ``[low, high]`` with ``low < 0 < high``.

    Parameters
    ----------
    attrs_or_da : mapping, xarray.DataArray or xarray.Dataset
        The attributes, or the variable carrying them.
    name : str
        The variable's name, used in messages.

    Returns
    -------
    (float, float) or None
        ``(low, high)``, or None when there is no ``range`` attribute.

    Raises
    ------
    RecordingError
        A malformed ``range`` attribute.
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
    """Return a full scale as ``(low, high)``.

    Parameters
    ----------
    value : float or (float, float)
        ``r`` (a positive number) meaning ±r, or a pair with ``low < 0 < high``.
    what : str
        Its name, used in messages.
    error : type of Exception
        The exception raised for anything else (naming ``what``).

    Returns
    -------
    (float, float)
        ``(low, high)``.
    """
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
    """Return the largest |value| if it behaves like a rail the signal is clipped at."""
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
    """Return how often the signal repeats its previous value.

    Counted on consecutive samples just below the maximum (``near`` and not ``top``)
    when there are at least 10 such pairs, else on the whole axis outside the maximum (a
    sample-and-hold signal repeats everywhere).
    """
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
    """Return the full scale of the ``range`` attribute and the peak when it is stale.

    The full scale is None when absent or stale (the data exceed it by more than 5 %);
    the peak |value| is given when stale, else None.
    """
    lim = full_scale(attrs, repr(name))
    if lim is None:
        return None, None
    peak = float(np.nanmax(np.abs(v))) if np.isfinite(v).any() else 0.0
    if peak > 1.05 * max(-lim[0], lim[1]):
        return None, peak
    return lim, None


@renamed(ds="rec")
def check_saturation(
    rec: xr.Dataset, *, fraction: float = 0.999, min_run: int = 3
) -> list[Finding]:
    """Return warnings about clipped samples and stale full scales of a Recording.

    Clipped samples of ``acc``, ``gyr`` and ``mag`` (see :func:`saturation`), and a
    ``range`` attribute the data exceed by more than 5 % (a stale or wrong full scale,
    e.g. after a change of units). Saturation is a warning, never an error: the
    Recording is still valid and the clipped samples are known (mask them with
    :func:`saturation`).

    Parameters
    ----------
    rec : xarray.Dataset
        A Recording (``ds`` is its old name).
    fraction, min_run
        As for :func:`saturation`.

    Returns
    -------
    list of Finding
        One warning per variable with clipped samples or a stale ``range``.
    """
    frac = _validate.fraction(fraction, "fraction", open_low=True)
    min_run = _validate.integer(min_run, "min_run", minimum=1)
    out: list[Finding] = []
    for name in _VECTORS:
        if name not in rec:
            continue
        v, u, attrs, _, _ = _read(rec, name, need_units=False)
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

    Returns
    -------
    Finding or None
        An error finding, or None when the values are within a physical range.
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
