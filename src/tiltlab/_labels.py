"""Units and long names of a table's columns, and the one way a p-value is written.

Every table the package returns carries, per column, its units and a readable name in
``df.attrs["units"]`` and ``df.attrs["long_name"]`` (dicts column → string; ``""`` or
``"1"`` for a dimensionless column), and optionally its role in ``df.attrs["role"]``
(``"p-value"``, or ``"count"`` for whole numbers stored as floats) — the convention of :func:`tiltlab.cohort.to_table`.
:func:`label_columns` attaches them without touching the input;
:func:`tiltlab.plot.table` reads them to render the table.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

__all__ = ["LABEL_KEYS", "label_columns", "format_p"]

#: The ``attrs`` keys holding one entry per column.
LABEL_KEYS = ("units", "long_name", "role")


def _per_column(columns, given, key: str) -> dict:
    """Entries of ``given`` (one string for every column, or a mapping) per column."""
    if given is None:
        return {}
    if isinstance(given, str):
        return dict.fromkeys(columns, given)
    if not isinstance(given, Mapping):
        raise TypeError(
            f"{key} must be a string or a mapping column -> string, got "
            f"{type(given).__name__}"
        )
    unknown = [c for c in given if c not in columns]
    if unknown:
        raise ValueError(f"{key} names column(s) {unknown} that the table lacks")
    return {c: str(v) for c, v in given.items()}


def label_columns(
    df: pd.DataFrame,
    *,
    units: str | Mapping | None = None,
    long_name: Mapping | None = None,
    role: str | Mapping | None = None,
) -> pd.DataFrame:
    """Return a copy of a table with the units, long names and roles of its columns.

    Parameters
    ----------
    df : pandas.DataFrame
        The table; it is not modified.
    units : str or mapping, optional
        Column → units (``""`` or ``"1"``: dimensionless), or one string for every
        column.
    long_name : mapping, optional
        Column → readable name.
    role : str or mapping, optional
        Column → role (``"p-value"`` marks a p-value column, ``"count"`` whole
        numbers), or one string for all.

    Returns
    -------
    pandas.DataFrame
        A copy whose ``attrs["units"]``, ``attrs["long_name"]`` and ``attrs["role"]``
        are dicts column → string: the entries given, over any the input had.

    Raises
    ------
    ValueError
        A mapping names a column the table lacks.

    Examples
    --------
    >>> import pandas as pd
    >>> df = pd.DataFrame({"rmse": [1.234], "n": [10]})
    >>> out = label_columns(df, units={"rmse": "deg", "n": "1"},
    ...                     long_name={"rmse": "RMS tilt error", "n": "samples"})
    >>> out.attrs["units"], df.attrs
    ({'rmse': 'deg', 'n': '1'}, {})
    """
    out = df.copy()
    cols = list(df.columns)
    for key, given in zip(LABEL_KEYS, (units, long_name, role)):
        old = df.attrs.get(key)
        merged = dict(old) if isinstance(old, Mapping) else {}
        if isinstance(old, str):  # an older table: one unit for every column
            merged = dict.fromkeys(cols, old)
        merged.update(_per_column(cols, given, key))
        if merged or key != "role":
            out.attrs[key] = merged
    return out


def format_p(value, decimals: int = 3) -> str:
    """Write a p-value (or any small positive number) with ``decimals`` decimals.

    Parameters
    ----------
    value : float
        The value.
    decimals : int
        Decimals shown.

    Returns
    -------
    str
        ``"<0.001"`` (for 3 decimals) below :math:`10^{-3}`, else the value with
        ``decimals`` decimals; ``""`` for NaN or infinity.

    Examples
    --------
    >>> format_p(0.0004), format_p(0.01234), format_p(float("nan"))
    ('<0.001', '0.012', '')
    """
    v = float(value)
    if not np.isfinite(v):
        return ""
    small = 10.0**-decimals
    return f"<{small:.{decimals}f}" if v < small else f"{v:.{decimals}f}"
