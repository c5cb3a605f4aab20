r"""Tilt error against angular speed: a robust slope and where two curves cross.

Fayat et al. [1]_ (their Fig. 2f) plot each filter's tilt error against the head's
angular speed and read from it which filter to prefer at which speed. Two numbers
summarise such a figure:

* **the slope** of the error against the speed while moving, fitted by the Theil–Sen
  estimator [2]_ [3]_: the median of the pairwise slopes

  .. math::
      \hat b = \operatorname{median}_{i<j,\ s_i \ne s_j}
      \frac{\epsilon_j - \epsilon_i}{s_j - s_i},

  which ignores up to about 29 % of outlying points, unlike least squares. Adding a
  constant to every error leaves every pairwise slope, hence :math:`\hat b`,
  unchanged; scaling the errors scales it.
* **the crossover speed** of two binned median curves :math:`a(s)`, :math:`b(s)`
  (bin centres :math:`s_i`): the first sign change of :math:`d_i = a_i - b_i`
  between consecutive finite bins, found by linear interpolation,

  .. math::
      s^\ast = s_i + (s_{i+1} - s_i)\,\frac{d_i}{d_i - d_{i+1}} .

References
----------
.. [1] R. Fayat, V. Delgado Betancourt, T. Goyallon, M. Petremann, P. Liaudet,
   V. Descossy, L. Reveret, G. P. Dugué, "Inertial measurement of head tilt in
   rodents: principles and applications to vestibular research", Sensors 21(18):6318,
   2021. doi:10.3390/s21186318
.. [2] H. Theil, "A rank-invariant method of linear and polynomial regression
   analysis", Proc. KNAW 53, 1950.
.. [3] P. K. Sen, "Estimates of the regression coefficient based on Kendall's tau",
   J. Am. Stat. Assoc. 63(324):1379–1389, 1968. doi:10.1080/01621459.1968.10480934
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr
from scipy import stats

__all__ = ["speed_slope", "crossover_speed"]


def _positive(value: float, name: str) -> float:
    value = float(value)
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    return value


def speed_slope(
    errors: Mapping[str, Any],
    speed,
    *,
    mask=None,
    per: float = 100.0,
    confidence: float = 0.95,
    max_samples: int = 2000,
) -> xr.Dataset:
    """Fit the Theil–Sen slope of each estimator's tilt error against angular speed.

    Parameters
    ----------
    errors : mapping
        Estimator → per-sample tilt errors (degrees), each as long as ``speed``.
    speed : array_like
        Angular speed (°/s) of each sample.
    mask : array_like of bool, optional
        Samples to fit (e.g. those while moving); default all. Non-finite errors or
        speeds are dropped too.
    per : float
        The slope is given in degrees of error per ``per`` °/s (default 100).
    confidence : float
        Confidence level of the slope's interval, in (0, 1).
    max_samples : int
        At most this many samples, evenly spaced in the kept ones, enter the fit (the
        estimator forms every pair of samples: its cost grows as their square).

    Returns
    -------
    xarray.Dataset
        Over dim ``estimator``: ``slope``, ``slope_lo``, ``slope_hi`` (the interval of
        :func:`scipy.stats.theilslopes`, which assumes independent samples),
        ``intercept`` (deg, at zero speed) and ``n`` (samples fitted); each variable has
        ``units`` and ``long_name``. ``attrs["per"]`` is ``per``.

    Examples
    --------
    >>> import numpy as np
    >>> s = np.linspace(0.0, 400.0, 50)
    >>> out = speed_slope({"a": 0.5 + 0.01 * s}, s)
    >>> round(float(out["slope"].sel(estimator="a")), 6)
    1.0
    """
    per = _positive(per, "per")
    confidence = float(confidence)
    if not 0 < confidence < 1:
        raise ValueError(f"confidence must lie in (0, 1), got {confidence!r}")
    if int(max_samples) != max_samples or max_samples < 3:
        raise ValueError(f"max_samples must be an integer >= 3, got {max_samples!r}")
    if not isinstance(errors, Mapping) or not errors:
        raise ValueError("errors must be a non-empty mapping estimator → errors")
    sp = np.asarray(speed, dtype=float).ravel()
    keep = np.isfinite(sp)
    if mask is not None:
        m = np.asarray(mask).ravel()
        if m.shape != sp.shape or m.dtype != bool:
            raise ValueError(
                f"mask must be a boolean array of {sp.size} samples like speed, got "
                f"dtype {m.dtype} and {m.size} samples"
            )
        keep &= m
    names = list(errors)
    out = {k: np.full(len(names), np.nan) for k in ("slope", "lo", "hi", "intercept")}
    n = np.zeros(len(names), dtype=np.int64)
    for i, name in enumerate(names):
        e = np.asarray(errors[name], dtype=float).ravel()
        if e.shape != sp.shape:
            raise ValueError(
                f"errors[{name!r}] has {e.size} samples, speed has {sp.size}"
            )
        idx = np.flatnonzero(keep & np.isfinite(e))
        if idx.size > max_samples:
            idx = idx[
                np.linspace(0, idx.size - 1, int(max_samples)).round().astype(int)
            ]
        n[i] = idx.size
        if idx.size < 2 or np.ptp(sp[idx]) == 0:
            continue  # no slope: fewer than two distinct speeds
        res = stats.theilslopes(e[idx], sp[idx], alpha=confidence)
        out["slope"][i], out["lo"][i], out["hi"][i] = (
            per * res.slope,
            per * res.low_slope,
            per * res.high_slope,
        )
        out["intercept"][i] = res.intercept
    unit = f"deg per {per:g} deg/s"
    pct = f"{100 * confidence:g} %"
    var = {
        "slope": (out["slope"], unit, "Theil–Sen slope of tilt error against speed"),
        "slope_lo": (out["lo"], unit, f"slope, lower end of the {pct} interval"),
        "slope_hi": (out["hi"], unit, f"slope, upper end of the {pct} interval"),
        "intercept": (out["intercept"], "deg", "tilt error at zero speed (fit)"),
        "n": (n, "1", "samples fitted"),
    }
    return xr.Dataset(
        {
            k: ("estimator", v, {"units": u, "long_name": ln})
            for k, (v, u, ln) in var.items()
        },
        coords={"estimator": names},
        attrs={"per": per, "confidence": confidence},
    )


def crossover_speed(speeds, a, b) -> xr.DataArray:
    """Find the speed where two binned error curves cross, by linear interpolation.

    Parameters
    ----------
    speeds : array_like
        Bin centres (°/s), strictly increasing.
    a, b : array_like
        The two curves (e.g. median errors) at the bin centres; NaN bins are skipped.

    Returns
    -------
    xarray.DataArray
        A scalar: the first speed where ``a - b`` changes sign (or is zero), NaN when
        the curves do not cross. ``attrs``: ``units`` (``deg/s``), ``long_name``,
        ``reason`` (a sentence: which curve goes below the other, or why NaN) and
        ``n_crossings`` (sign changes between consecutive finite bins).

    Examples
    --------
    The difference ``a - b`` is -1, -0.5, +0.5: it vanishes halfway from 100 to 200.

    >>> c = crossover_speed([0.0, 100.0, 200.0], [1.0, 2.0, 3.0], [2.0, 2.5, 2.5])
    >>> float(c), c.attrs["reason"]
    (150.0, 'a goes above b')
    """
    x = np.asarray(speeds, dtype=float).ravel()
    if x.size < 2 or not np.all(np.isfinite(x)) or np.any(np.diff(x) <= 0):
        raise ValueError(
            "speeds must hold at least two finite, strictly increasing bin centres"
        )
    curves = []
    for name, c in (("a", a), ("b", b)):
        c = np.asarray(c, dtype=float).ravel()
        if c.shape != x.shape:
            raise ValueError(f"{name} has {c.size} values, speeds has {x.size}")
        curves.append(c)
    d = curves[0] - curves[1]
    ok = np.isfinite(d)
    xs, ds = x[ok], d[ok]
    value, reason, n_cross = np.nan, "", 0
    if xs.size < 2:
        reason = "fewer than two bins where both curves are finite"
    else:
        sign = np.sign(ds)
        change = np.flatnonzero(sign[:-1] * sign[1:] < 0)
        zeros = np.flatnonzero(sign == 0)
        n_cross = int(change.size + zeros.size)
        first = min([*change, *zeros], default=None)
        if first is None:
            side = "above" if ds[0] > 0 else "below"
            reason = f"the curves do not cross: a stays {side} b in every bin"
        elif sign[first] == 0:
            value, reason = float(xs[first]), "a equals b at a bin centre"
        else:
            i = int(first)
            value = float(xs[i] + (xs[i + 1] - xs[i]) * ds[i] / (ds[i] - ds[i + 1]))
            reason = f"a goes {'below' if ds[i] > 0 else 'above'} b"
    return xr.DataArray(
        value,
        attrs={
            "units": "deg/s",
            "long_name": "angular speed where the two curves cross",
            "reason": reason,
            "n_crossings": n_cross,
        },
    )
