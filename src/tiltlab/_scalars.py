"""Check scalar arguments: sampling rates, finite, positive, integral and fractional numbers.

The checks that every public function applies to its numeric parameters, re-exported by
:mod:`tiltlab._validate` (import them from there). Each returns the value as a plain
``float`` or ``int`` and raises a :class:`ValueError` naming the argument otherwise.
Arrays, labelled inputs and Recordings are :mod:`tiltlab._validate`'s business.
"""

from __future__ import annotations

import numpy as np

__all__ = ["check_fs", "finite", "positive", "nonnegative", "integer", "fraction"]


def check_fs(fs, name: str = "fs") -> float:
    """Return a sampling rate as a positive finite float (Hz).

    tiltlab never assumes a default sampling rate: ``None`` is an error.

    Parameters
    ----------
    fs : float
        The sampling rate (Hz).
    name : str
        Its name, used in messages.

    Returns
    -------
    float
        ``fs`` as a float.

    Raises
    ------
    ValueError
        ``None``, a bool, a non-number, or a rate that is not positive and finite.
    """
    if fs is None:
        raise ValueError(
            f"{name} (sampling rate, Hz) is mandatory; tiltlab never assumes a default"
        )
    if isinstance(fs, bool):
        raise ValueError(f"{name} must be a number of Hz, got {fs!r}")
    try:
        value = float(fs)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number of Hz, got {fs!r}") from None
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a positive finite number of Hz, got {fs!r}")
    return value


def _number(value, name: str, kind: str = "a number") -> float:
    """Return ``value`` as a float; bools, None and non-numbers are ``kind`` errors."""
    if isinstance(value, bool) or value is None:
        raise ValueError(f"{name} must be {kind}, got {value!r}")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be {kind}, got {value!r}") from None


def finite(value, name: str) -> float:
    """Return ``value`` as a finite float, else raise a :class:`ValueError` naming ``name``.

    Parameters
    ----------
    value : float-like
        Any real number except NaN and ±inf.
    name : str
        The argument's name for the error message.

    Returns
    -------
    float
        The finite value.
    """
    v = _number(value, name)
    if not np.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return v


def positive(
    value, name: str, *, allow_zero: bool = False, allow_inf: bool = False
) -> float:
    """Return ``value`` as a positive float (``> 0``, or ``>= 0`` with ``allow_zero``).

    Parameters
    ----------
    value : float-like
        The number to check; NaN is always refused.
    name : str
        Argument name shown in the error.
    allow_zero, allow_inf : bool
        Also accept 0, or +inf.

    Returns
    -------
    float
        The positive value.
    """
    v = _number(value, name)
    if (
        np.isnan(v)
        or (np.isinf(v) and not allow_inf)
        or v < 0
        or (v == 0 and not allow_zero)
    ):
        kind = "non-negative" if allow_zero else "positive"
        raise ValueError(f"{name} must be a {kind} number, got {value!r}")
    return v


def nonnegative(value, name: str) -> float:
    """Return ``value`` as a finite float ``>= 0``.

    Parameters
    ----------
    value, name
        As for :func:`positive`.

    Returns
    -------
    float
        The value, finite and at least 0.
    """
    return positive(value, name, allow_zero=True)


def integer(
    value, name: str, *, minimum: int | None = None, maximum: int | None = None
) -> int:
    """Return ``value`` as an int (integral floats accepted), within the given bounds.

    Parameters
    ----------
    value : int or integral float
        E.g. ``3`` or ``3.0``; ``3.5`` and ``True`` are refused.
    name : str
        Named in the error.
    minimum : int, optional
        Smallest accepted value.
    maximum : int, optional
        Largest accepted value.

    Returns
    -------
    int
        The value as a Python int.
    """
    v = _number(value, name, "an integer")
    if not np.isfinite(v) or v != int(v):
        raise ValueError(f"{name} must be an integer, got {value!r}")
    if minimum is not None and v < minimum:
        raise ValueError(f"{name} must be at least {minimum}, got {value!r}")
    if maximum is not None and v > maximum:
        raise ValueError(f"{name} must be at most {maximum}, got {value!r}")
    return int(v)


def fraction(
    value, name: str, *, open_low: bool = False, open_high: bool = False
) -> float:
    """Check that ``value`` lies in [0, 1] and return it as a float.

    Parameters
    ----------
    value : float
        A proportion; the ends are excluded with ``open_low`` / ``open_high``.
    name : str
        Named in the error.
    open_low, open_high : bool
        Exclude 0, or 1.

    Returns
    -------
    float
        The value, in the interval.
    """
    v = finite(value, name)
    if v < 0 or v > 1 or (open_low and v == 0) or (open_high and v == 1):
        lo = "(" if open_low else "["
        hi = ")" if open_high else "]"
        raise ValueError(f"{name} must be in {lo}0, 1{hi}, got {value!r}")
    return v
