"""Directions as printed text: short tuples of signed numbers for tables and reports."""

from __future__ import annotations

import numpy as np

from .. import _validate as _v

__all__ = ["format_direction"]


def format_direction(v, digits: int = 4) -> str:
    """Format a direction as a short tuple of signed numbers.

    Parameters
    ----------
    v : array_like, shape (3,)
        The direction (any vector; it is printed as given, not normalised).
    digits : int, default 4
        Decimals of every component.

    Returns
    -------
    str
        ``"(+x, +y, -z)"``: every component with its sign and ``digits`` decimals.

    Raises
    ------
    ValueError
        If ``v`` is not one-dimensional or ``digits`` is not a non-negative integer.

    Examples
    --------
    >>> format_direction([0.0, -0.5, 0.866025])
    '(+0.0000, -0.5000, +0.8660)'
    >>> format_direction([1, 0, 0], digits=1)
    '(+1.0, +0.0, +0.0)'
    """
    x = np.asarray(v, float)
    if x.ndim != 1:
        raise ValueError(f"v must be one vector (1-D), got shape {x.shape}")
    digits = _v.integer(digits, "digits", minimum=0)
    return "(" + ", ".join(f"{c:+.{digits}f}" for c in x) + ")"
