r"""Cells of a cohort table: the sessions of each group × time point, checked.

The glue between a cohort table and the tests of :mod:`tiltlab.stats.tables`: read a
cohort :class:`xarray.Dataset` (``session`` dimension, coordinates ``subject``,
``group``, ``timepoint``, one variable per feature, optional ``status``) or
:class:`pandas.DataFrame` into one row per session, refuse two sessions of one subject
at one time point (pseudo-replication), order the time points by duration and read a
feature's units.

References
----------
.. [1] R. Fayat et al., Sensors 21(18):6318, 2021, §2.4 and Appendix A.7.
   doi:10.3390/s21186318
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import numpy as np
import pandas as pd
import xarray as xr

from .._labels import label_columns

__all__ = ["long_table", "check_cells"]

_DURATION = re.compile(r"^\s*([-+]?\d+(?:\.\d+)?)\s*(min|h|d|w)\s*$", re.IGNORECASE)
_UNIT_HOURS = {"min": 1 / 60, "h": 1.0, "d": 24.0, "w": 168.0}


def _frame(features, feature: str) -> pd.DataFrame:
    """Return every session of a cohort table as a frame.

    Columns ``session`` (None when the table has no ids), ``subject``,
    ``group``, ``timepoint``, ``value`` and ``status`` (``"ok"`` when absent).
    """
    need = ("subject", "group", "timepoint")
    if isinstance(features, xr.Dataset):
        if "session" not in features.dims:
            raise ValueError("features must have a 'session' dimension")
        if feature not in features.data_vars:
            raise ValueError(
                f"feature {feature!r} is not a variable of features "
                f"(variables: {sorted(map(str, features.data_vars))})"
            )
        if features[feature].dims != ("session",):
            raise ValueError(f"feature {feature!r} must have dims ('session',)")
        missing = [c for c in need if c not in features.variables]
        if missing:
            raise ValueError(f"features lacks coordinate(s) {missing}")
        cols = {c: features[c].values for c in need}
        cols["value"] = features[feature].values
        cols["status"] = (
            features["status"].values.astype(str)
            if "status" in features.variables
            else "ok"
        )
        cols["session"] = (
            features["session"].values.astype(str)
            if "session" in features.variables
            else None
        )
        df = pd.DataFrame(cols)
    elif isinstance(features, pd.DataFrame):
        missing = [c for c in (*need, feature) if c not in features.columns]
        if missing:
            raise ValueError(f"features lacks column(s) {missing}")
        df = features[list(need)].copy()
        df["value"] = features[feature].to_numpy()
        df["status"] = (
            features["status"].astype(str).to_numpy()
            if "status" in features.columns
            else "ok"
        )
        df["session"] = (
            features["session"].astype(str).to_numpy()
            if "session" in features.columns
            else None
        )
    else:
        raise ValueError(
            f"features must be an xarray.Dataset or a pandas.DataFrame, got "
            f"{type(features).__name__}"
        )
    df["value"] = pd.to_numeric(df["value"], errors="coerce").astype(float)
    return df.reset_index(drop=True)


def check_cells(table: pd.DataFrame, what: str = "features") -> None:
    """Refuse a cohort table with two sessions of one subject at one time point.

    Each animal is one experimental unit: two sessions of it in one cell would count
    it twice (pseudo-replication) in a between-group test, and cannot be paired with
    its baseline. Every session counts, failed ones included.

    Parameters
    ----------
    table : pandas.DataFrame
        With ``subject`` and ``timepoint`` columns, and ``session`` ids as a column or
        as the index (named ``session``) when available.
    what : str
        The table's name in the message.

    Raises
    ------
    ValueError
        Naming each duplicated (subject, time point) and its sessions (or rows).
    """
    df = table.reset_index() if table.index.name == "session" else table
    dup = df.duplicated(["subject", "timepoint"], keep=False)
    if not dup.any():
        return
    cells = []
    for (subject, tp), rows in df[dup].groupby(
        ["subject", "timepoint"], sort=False, dropna=False
    ):
        if "session" in rows.columns and rows["session"].notna().all():
            which = "sessions " + ", ".join(map(repr, rows["session"].astype(str)))
        else:
            which = "rows " + ", ".join(str(i) for i in rows.index)
        cells.append(f"subject {subject!r} at {tp!r} ({which})")
    shown = "; ".join(cells[:5]) + (
        f"; and {len(cells) - 5} more" if len(cells) > 5 else ""
    )
    raise ValueError(
        f"{what} has more than one session of a subject at a time point: {shown}. "
        "Each animal is one unit: counting it twice is pseudo-replication. Keep one "
        "session per subject and time point (drop one, or average them into one row) "
        "before testing"
    )


def long_table(features, feature: str, *, include_failed: bool = False) -> pd.DataFrame:
    """One row per usable session: ``subject``, ``group``, ``timepoint``, ``value``.

    Parameters
    ----------
    features : xarray.Dataset or pandas.DataFrame
        The cohort table (see the module docstring).
    feature : str
        The feature variable / column.
    include_failed : bool
        Also return the sessions whose ``status`` is not ``"ok"`` (``value`` NaN
        there), with a ``status`` column, e.g. to count them.

    Returns
    -------
    pandas.DataFrame
        Sessions with ``status == "ok"`` (when a status exists), or every session with
        ``include_failed``; ``value`` may be NaN.
    """
    df = _frame(features, feature)
    keep = ["subject", "group", "timepoint", "value"]
    if include_failed:
        df.loc[df["status"] != "ok", "value"] = np.nan
        out = df[keep + ["status"]].reset_index(drop=True)
    else:
        out = df.loc[df["status"] == "ok", keep].reset_index(drop=True)
    names = {"subject": "subject", "group": "group", "timepoint": "time point"}
    names.update(value=feature, status="session status")
    units = dict.fromkeys(out.columns, "")
    units["value"] = _feature_units(features, feature)
    return label_columns(out, units=units, long_name={c: names[c] for c in out.columns})


def _timepoint_key(label) -> float:
    if isinstance(label, (int, float, np.integer, np.floating)):
        return float(label) * 24.0  # numbers are days
    m = _DURATION.match(str(label))
    if m:
        return float(m.group(1)) * _UNIT_HOURS[m.group(2).lower()]
    raise KeyError(label)


def _ordered_timepoints(df: pd.DataFrame, baseline, timepoints) -> list:
    present = list(dict.fromkeys(df["timepoint"]))
    if timepoints is not None:
        unknown = [t for t in timepoints if t not in present]
        if unknown:
            raise ValueError(f"timepoints {unknown} are not in the data ({present})")
        return list(timepoints)
    rest = [t for t in present if t != baseline]
    try:
        rest.sort(key=_timepoint_key)
    except KeyError:
        pass  # keep the order of appearance
    return rest


def _feature_units(features, feature: str) -> str:
    """Return the units of a feature of a cohort table (``""`` when not stated).

    Parameters
    ----------
    features : xarray.Dataset or pandas.DataFrame
        The cohort table: a Dataset variable's ``attrs["units"]``, or a DataFrame's
        ``attrs["units"][feature]``.
    feature : str
        The feature.

    Returns
    -------
    str
        Its units, ``""`` when the table does not say.

    Examples
    --------
    >>> import pandas as pd
    >>> df = pd.DataFrame({"x": [1.0]})
    >>> df.attrs["units"] = {"x": "deg"}
    >>> _feature_units(df, "x"), _feature_units(df, "y")
    ('deg', '')
    """
    if isinstance(features, xr.Dataset) and feature in features.variables:
        return str(features[feature].attrs.get("units", ""))
    units = getattr(features, "attrs", {}).get("units", {})
    return str(units.get(feature, "")) if isinstance(units, Mapping) else ""
