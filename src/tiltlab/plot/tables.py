"""Tables that render themselves: headers with units, rounding by quantity, p-values once.

:func:`table` is the table recipe beside the figure recipes. It reads the units and
long names that every table of the package carries (``df.attrs["units"]`` and
``df.attrs["long_name"]``, dicts column → string, see :func:`tiltlab._labels
.label_columns`; a Dataset's variable attributes) and writes

* headers as ``"long name [units]"`` (no brackets for a dimensionless column);
* numbers rounded by their units, by one table of rules (:data:`DECIMALS`): degrees
  with 2 decimals, g with 3, mg with 1… (3 significant digits for units not listed
  or not stated; integers, and columns of role ``"count"``, without decimals);
* p-values (role ``"p-value"``, or a column named ``p``, ``p_…`` or ``p (…)``) once,
  the way :func:`tiltlab.stats.format_table` writes them: ``"<0.001"``, else 3
  decimals;
* missing values (NaN, None) as ``"–"``.

It takes absent results too (``None``: nothing was computed, e.g. no reference), so
that a chapter shows a table without branching on what its data hold.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import numpy as np
import pandas as pd
import xarray as xr

from .._labels import format_p

__all__ = ["DECIMALS", "MAX_HEADER", "MISSING", "P_DECIMALS", "table"]

#: Decimals shown per units (the one table of rounding rules); units not listed show
#: three significant digits.
DECIMALS = {
    "deg": 2,
    "rad": 3,
    "deg/s": 2,
    "rad/s": 3,
    "g": 3,
    "mg": 1,
    "m/s^2": 3,
    "m/s²": 3,
    "uT": 1,
    "µT": 1,
    "s": 2,
    "ms": 1,
    "min": 1,
    "h": 2,
    "Hz": 1,
    "%": 1,
    "1": 3,
    "": 3,
}
#: Decimals of a p-value (``"<0.001"`` below :math:`10^{-3}`).
P_DECIMALS = 3
#: How a missing value is shown.
MISSING = "–"
#: A long name longer than this (characters) is a definition, not a header: the
#: column is headed by its name and the definition goes to the caption.
MAX_HEADER = 48

_P_NAME = re.compile(r"^p($|_| \()")


def _frame_of_dataset(ds: xr.Dataset) -> tuple[pd.DataFrame, dict, dict]:
    """Return a Dataset as a frame, with the units and long names of its variables."""
    if ds.sizes:
        df = ds.to_dataframe()
    else:
        df = pd.DataFrame({k: [v.item()] for k, v in ds.data_vars.items()})
    names = [*df.columns, *(n for n in df.index.names if n is not None)]
    units = {n: ds[n].attrs["units"] for n in names if "units" in ds[n].attrs}
    long = {n: ds[n].attrs["long_name"] for n in names if "long_name" in ds[n].attrs}
    return df, units, long


def _frame_of_matrix(da: xr.DataArray) -> tuple[pd.DataFrame, dict, dict, dict]:
    """Return a 2-D DataArray as a matrix: rows its first dim, columns its second."""
    df = da.to_pandas()
    cell = str(da.attrs.get("units", ""))
    units = dict.fromkeys(df.columns, cell)
    long = {}
    for d in da.dims:
        coord = da.coords.get(d)
        attrs = coord.attrs if coord is not None else {}
        if "units" in attrs:
            units[d] = attrs["units"]
        long[d] = attrs.get("long_name", d)
    quantity = str(da.attrs.get("long_name", da.name or "value"))
    if cell not in ("", "1"):
        quantity += f" [{cell}]"
    long[da.dims[1]] = f"{quantity}, by {long[da.dims[1]]}"  # the columns' level
    return df, units, long, dict.fromkeys(df.columns, "matrix")


def _as_frame(result) -> tuple[pd.DataFrame, dict, dict, dict]:
    """Return ``result`` as a frame with its units, long names and roles."""
    if result is None:
        return pd.DataFrame(), {}, {}, {}
    if isinstance(result, xr.DataArray) and result.ndim == 2:
        return _frame_of_matrix(result)
    if isinstance(result, xr.DataArray):
        result = result.to_dataset(name=result.name or "value")
    if isinstance(result, xr.Dataset):
        return (*_frame_of_dataset(result), {})
    if isinstance(result, pd.Series):
        result = result.to_frame(result.name if result.name is not None else "value")
    elif isinstance(result, Mapping):
        result = pd.DataFrame([dict(result)])
    if not isinstance(result, pd.DataFrame):
        raise TypeError(
            "table shows a pandas DataFrame or Series, an xarray Dataset or DataArray, "
            f"a mapping or None, got {type(result).__name__}"
        )
    got = [result.attrs.get(k, {}) for k in ("units", "long_name", "role")]
    if isinstance(got[0], str):  # one unit for every column (an older table)
        got[0] = dict.fromkeys(result.columns, got[0])
    return (result, *(dict(g) if isinstance(g, Mapping) else {} for g in got))


def _is_p(name, role: str) -> bool:
    return role == "p-value" or (isinstance(name, str) and bool(_P_NAME.match(name)))


def _number(v, decimals: int | None, counts: bool) -> str:
    """Write one number: integers whole, floats with ``decimals`` (or 3 significant)."""
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    v = float(v)
    if not np.isfinite(v):
        return MISSING if np.isnan(v) else str(v)
    if counts:
        return str(int(v))
    if decimals is None:
        return f"{v:.3g}"
    return f"{v:.{decimals}f}"


def _formatter(units: str | None, role: str, is_p: bool, decimals: int | None):
    """Return the function writing each cell of one column (units None: unknown)."""
    if is_p:
        return lambda v: (
            (format_p(v, P_DECIMALS) or MISSING) if _numeric(v) else _text(v)
        )
    counts = role == "count" and decimals is None
    d = decimals if decimals is not None or units is None else DECIMALS.get(units)
    return lambda v: _number(v, d, counts) if _numeric(v) else _text(v)


def _numeric(v) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating, np.bool_))


def _text(v) -> str:
    if v is None or v is pd.NA or v is pd.NaT:
        return MISSING
    return str(v)


def _header(name, units: dict, long: dict, bare: bool = False) -> object:
    """Return ``"long name [units]"`` for one column (the name when no long name)."""
    if bare:  # a matrix column: a coordinate value, the units are in the level name
        return _formatter(units.get(name), "", False, None)(name)
    u = str(units.get(name, "") or "")
    suffix = f" [{u}]" if u not in ("", "1") else ""
    if isinstance(name, tuple):  # MultiIndex columns: units on the last level
        return (*name[:-1], f"{name[-1]}{suffix}")
    return f"{long.get(name) or name}{suffix}"


def _level_name(columns: pd.Index, units: dict, long: dict):
    """Return the header of the columns' level (a matrix's second dim), if named."""
    name = columns.name
    return None if name is None else _header(name, units, long)


def _decimals_of(decimals, name) -> int | None:
    if decimals is None or isinstance(decimals, (int, np.integer)):
        return decimals
    if not isinstance(decimals, Mapping):
        raise TypeError(
            f"decimals must be an int or a mapping column -> int, got {decimals!r}"
        )
    return decimals.get(name)


def _formatted_index(index: pd.Index, units: dict, long: dict) -> pd.Index:
    """Write the index labels by their units, and name the levels with headers."""
    levels = []
    for i, name in enumerate(index.names):
        values = index.get_level_values(i)
        if values.dtype.kind == "f":
            fmt = _formatter(units.get(name), "", False, None)
            values = pd.Index([fmt(v) for v in values])
        levels.append(values)
    names = [None if n is None else _header(n, units, long) for n in index.names]
    if len(levels) == 1:
        return pd.Index(levels[0], name=names[0])
    return pd.MultiIndex.from_arrays(levels, names=names)


def table(
    result,
    *,
    caption: str | None = None,
    decimals: int | Mapping | None = None,
    output: str = "styler",
):
    """Render a result table: readable headers with units, rounding by quantity.

    Parameters
    ----------
    result : pandas.DataFrame, pandas.Series, xarray.Dataset, xarray.DataArray, mapping or None
        A table of the package (units and long names in ``attrs``, see
        :func:`tiltlab._labels.label_columns`), a Dataset (units and long names in its
        variables' attributes), a 2-D DataArray (a matrix: rows its first dim,
        columns its second, every cell in its units), a mapping (one row), or
        ``None`` (nothing to show: an empty table). A column without units or long
        name is headed by its name.
    caption : str, optional
        The table's caption (``None``: none; ``"no result"`` for an absent result).
        Long names longer than :data:`MAX_HEADER` characters are definitions: those
        columns are headed by their names and the definitions are added to the
        caption.
    decimals : int or mapping, optional
        Decimals of every numeric column, or per column (column → int); default by
        units (:data:`DECIMALS`). p-values always show :data:`P_DECIMALS`.
    output : {"styler", "frame"}
        ``"styler"``: a pandas ``Styler`` to display; ``"frame"``: the same cells as a
        DataFrame of strings.

    Returns
    -------
    pandas.io.formats.style.Styler or pandas.DataFrame
        Headers ``"long name [units]"``, numbers rounded, p-values as ``"<0.001"`` or
        with 3 decimals, missing values ``"–"``. A default integer index is hidden in
        the Styler.

    Examples
    --------
    >>> import pandas as pd
    >>> from tiltlab import plot
    >>> from tiltlab._labels import label_columns
    >>> df = label_columns(
    ...     pd.DataFrame({"rmse": [1.23456, float("nan")], "p": [0.0002, 0.04321]}),
    ...     units={"rmse": "deg", "p": "1"},
    ...     long_name={"rmse": "tilt RMSE", "p": "p"},
    ... )
    >>> plot.table(df, output="frame").to_dict("list")
    {'tilt RMSE [deg]': ['1.23', '–'], 'p': ['<0.001', '0.043']}
    """
    if output not in ("styler", "frame"):
        raise ValueError(f"output must be 'styler' or 'frame', got {output!r}")
    df, units, long, role = _as_frame(result)
    cells = {}
    for name in df.columns:
        r = str(role.get(name, ""))
        fmt = _formatter(
            None if units.get(name) is None else str(units[name]),
            r,
            _is_p(name, r),
            _decimals_of(decimals, name),
        )
        cells[name] = [fmt(v) for v in df[name].tolist()]
    text = pd.DataFrame(cells, index=_formatted_index(df.index, units, long))
    defined = {
        c: long[c]
        for c in df.columns
        if not isinstance(c, tuple) and len(str(long.get(c) or "")) > MAX_HEADER
    }
    short = {c: n for c, n in long.items() if c not in defined}
    headers = [_header(c, units, short, role.get(c) == "matrix") for c in df.columns]
    if defined:
        notes = "; ".join(f"{c}: {text}" for c, text in defined.items())
        caption = f"{caption}. {notes}" if caption else notes
    seen: set = set()
    for i, h in enumerate(headers):
        if h in seen:  # two columns, one long name: tell them apart
            headers[i] = f"{h} ({df.columns[i]})"
        seen.add(headers[i])
    text.columns = (
        pd.MultiIndex.from_tuples(headers, names=df.columns.names)
        if isinstance(df.columns, pd.MultiIndex)
        else pd.Index(headers, dtype=object, name=_level_name(df.columns, units, long))
    )
    if output == "frame":
        return text
    styler = (
        text.style.format(escape="html")
        .format_index(escape="html", axis=0)
        .format_index(escape="html", axis=1)
    )
    if caption is not None or result is None:
        styler = styler.set_caption(caption if caption is not None else "no result")
    if isinstance(df.index, pd.RangeIndex) and df.index.name is None:
        styler = styler.hide(axis="index")
    return styler
