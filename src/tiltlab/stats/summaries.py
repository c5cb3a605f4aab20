"""Summaries of a cohort's tidy test tables, for reading and reporting them.

* :func:`group_quantiles` — quantiles (median and IQR by default) of a feature per
  group and time point;
* :func:`significant_cells` — the cells of a tidy table below a level, as one line;
* :func:`with_published` — our adjusted p-values next to a printed table (Fayat et
  al.'s Tables A1–A2, :func:`~tiltlab.stats.fayat_table`), comparison by comparison;
* :func:`recovery_table` — planted versus estimated group differences, for a simulated
  cohort whose planted values per session are known.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .._labels import label_columns
from .effects import hodges_lehmann
from .tables import format_table, long_table

__all__ = [
    "group_quantiles",
    "significant_cells",
    "with_published",
    "published_agreement",
    "recovery_table",
]

_TIDY = ("comparison", "timepoint")


def _need(table: pd.DataFrame, columns, what: str) -> None:
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise ValueError(f"{what} lacks column(s) {missing}")


def group_quantiles(features, feature: str, q=(0.25, 0.5, 0.75)) -> pd.DataFrame:
    """Quantiles of a feature per group and time point (usable sessions).

    Parameters
    ----------
    features : xarray.Dataset or pandas.DataFrame
        The cohort table (see :func:`~tiltlab.stats.long_table`).
    feature : str
        The feature variable.
    q : sequence of float
        Probabilities in [0, 1] (default: the quartiles and the median).

    Returns
    -------
    pandas.DataFrame
        Index (``group``, ``timepoint``), sorted; one column per probability in ``q``
        (in the feature's units). Missing values are left out; a cell without values
        is NaN.

    Examples
    --------
    >>> q = group_quantiles(features, "immobile_fraction")        # doctest: +SKIP
    >>> q.loc["Kainate", 0.5]  # medians by time point             # doctest: +SKIP
    """
    probs = [float(p) for p in np.atleast_1d(q)]
    if not probs or any(not 0.0 <= p <= 1.0 for p in probs):
        raise ValueError(f"q must hold probabilities in [0, 1], got {q!r}")
    long = long_table(features, feature)
    out = long.groupby(["group", "timepoint"])["value"].quantile(probs).unstack()
    return label_columns(
        out.reindex(columns=probs),
        units=long.attrs["units"]["value"],
        long_name={p: f"{feature}, quantile {p:g}" for p in probs},
    )


def significant_cells(tidy: pd.DataFrame, column: str = "p_paper", alpha=0.05) -> str:
    """List the cells of a tidy table with ``column < alpha``, as one line of text.

    Parameters
    ----------
    tidy : pandas.DataFrame
        From :func:`~tiltlab.stats.between_groups` or
        :func:`~tiltlab.stats.against_baseline` (``comparison``, ``timepoint``).
    column : str
        The p-value column (``"p_paper"``, ``"p_holm"``, ``"p"``…).
    alpha : float
        The level.

    Returns
    -------
    str
        ``"comparison: tp, tp; comparison: tp"`` in order of appearance; ``""`` when
        none is below ``alpha``.

    Examples
    --------
    >>> import pandas as pd
    >>> tidy = pd.DataFrame({"comparison": ["A vs. C", "A vs. C", "B vs. C"],
    ...                      "timepoint": ["1d", "7d", "1d"],
    ...                      "p_paper": [0.01, 0.2, 0.03]})
    >>> significant_cells(tidy, "p_paper", 0.05)
    'A vs. C: 1d; B vs. C: 1d'
    """
    _need(tidy, (*_TIDY, column), "tidy")
    sig = tidy[tidy[column] < alpha]
    by = sig.groupby("comparison", sort=False)["timepoint"]
    return "; ".join(f"{c}: {', '.join(map(str, t))}" for c, t in by)


def with_published(tidy: pd.DataFrame, printed: pd.DataFrame | None = None):
    """Our m·p and Holm p-values, with a printed table's next to them, for reading.

    Parameters
    ----------
    tidy : pandas.DataFrame
        From :func:`~tiltlab.stats.between_groups` or
        :func:`~tiltlab.stats.against_baseline` (with ``p_paper`` and ``p_holm``).
    printed : pandas.DataFrame, optional
        A printed table, comparisons × time points as strings (e.g.
        :func:`~tiltlab.stats.fayat_table`). Shown only when it has one of our
        comparisons; its cells we do not have are left out, ours it lacks are ``""``.

    Returns
    -------
    pandas.DataFrame
        Index (``comparison``, ``p-values``) with the sources ``"Fayat et al.
        (printed)"`` (when shown), ``"m·p (ours)"`` and ``"Holm (ours)"`` for each
        comparison; columns the time points; cells formatted by
        :func:`~tiltlab.stats.format_table` (strings; role ``"p-value"``).

    Examples
    --------
    >>> with_published(between, fayat_table("A1"))                   # doctest: +SKIP
    """
    _need(tidy, (*_TIDY, "p_paper", "p_holm"), "tidy")
    ours = {
        "m·p (ours)": format_table(tidy, "p_paper"),
        "Holm (ours)": format_table(tidy, "p_holm"),
    }
    rows, cols = list(ours["Holm (ours)"].index), list(ours["Holm (ours)"].columns)
    if printed is not None and printed.index.isin(rows).any():
        paper = printed.reindex(index=rows, columns=cols).astype(object).fillna("")
        ours = {"Fayat et al. (printed)": paper, **ours}
    table = pd.concat(ours, names=["source", "comparison"])
    table = table.swaplevel().reindex(pd.MultiIndex.from_product([rows, list(ours)]))
    table.index.names = ["comparison", "p-values"]
    return label_columns(
        table,
        units="1",
        long_name={c: f"p, {c}" for c in table.columns},
        role="p-value",
    )


def _printed_value(cell) -> float:
    """Read a printed m·p cell as a number (``"<0.001"`` becomes half its bound)."""
    text = str(cell).strip()
    if not text:
        return np.nan
    if text.startswith("<"):
        return float(text[1:]) / 2
    return float(text)


def published_agreement(
    tidy: pd.DataFrame, printed: pd.DataFrame, *, alpha: float = 0.05
) -> pd.DataFrame:
    r"""Set each cell's Bonferroni decision beside a printed table's, cell by cell.

    A cell is significant when its uncapped :math:`m\,p` is below ``alpha`` (Fayat et
    al.'s convention; a printed ``"<0.001"`` counts as below any ``alpha`` above
    0.001).

    Parameters
    ----------
    tidy : pandas.DataFrame
        From :func:`~tiltlab.stats.between_groups` or
        :func:`~tiltlab.stats.against_baseline` (``comparison``, ``timepoint``,
        ``p_paper``).
    printed : pandas.DataFrame
        A printed table, comparisons × time points as strings
        (:func:`~tiltlab.stats.fayat_table`).
    alpha : float
        Family-wise level.

    Returns
    -------
    pandas.DataFrame
        One row per cell both tables hold: ``comparison``, ``timepoint``,
        ``printed`` (as printed), ``ours`` (our :math:`m\,p`),
        ``printed_significant``, ``ours_significant`` and ``agree``.

    Raises
    ------
    ValueError
        If the two tables share no cell, or ``alpha`` is not in (0, 1).

    Examples
    --------
    >>> import pandas as pd
    >>> tidy = pd.DataFrame({"comparison": ["A vs. B"] * 2, "timepoint": ["1h", "1d"],
    ...                      "p_paper": [0.01, 0.4]})
    >>> printed = pd.DataFrame({"1h": ["<0.001"], "1d": ["0.020"]}, index=["A vs. B"])
    >>> published_agreement(tidy, printed)["agree"].tolist()
    [True, False]
    """
    if not 0 < alpha < 1:
        raise ValueError(f"alpha must be in (0, 1), got {alpha!r}")
    _need(tidy, ("comparison", "timepoint", "p_paper"), "tidy")
    rows = []
    for _, r in tidy.iterrows():
        c, t = r["comparison"], r["timepoint"]
        if c not in printed.index or t not in printed.columns:
            continue
        value = _printed_value(printed.loc[c, t])
        ours = float(r["p_paper"])
        if np.isnan(value) or np.isnan(ours):
            continue
        rows.append(
            {
                "comparison": c,
                "timepoint": t,
                "printed": str(printed.loc[c, t]),
                "ours": ours,
                "printed_significant": bool(value < alpha),
                "ours_significant": bool(ours < alpha),
            }
        )
    if not rows:
        raise ValueError(
            "the tidy table and the printed table share no cell (compare their "
            "comparison labels and time points)"
        )
    out = pd.DataFrame(rows)
    out["agree"] = out["printed_significant"] == out["ours_significant"]
    return out


_RECOVERY = {
    "comparison": "comparison",
    "time point": "time point",
    "planted Δ": "planted difference (Hodges–Lehmann)",
    "estimated Δ": "estimated difference (Hodges–Lehmann)",
    "p (m·p)": "p × m (Fayat et al.)",
    "found": "found (p × m below the level)",
}


def recovery_table(
    between: pd.DataFrame,
    planted: pd.Series,
    sessions: pd.DataFrame,
    *,
    control: str,
    alpha: float = 0.05,
) -> pd.DataFrame:
    """Planted versus estimated differences of each group against the control.

    For every row of ``between`` against ``control``, the planted difference is the
    Hodges–Lehmann shift between the planted values of the two groups' sessions at that
    time point, next to the estimated shift (``hl``) and the m·p p-value of the test.

    Parameters
    ----------
    between : pandas.DataFrame
        From :func:`~tiltlab.stats.between_groups` (``comparison``, ``group1``,
        ``group2``, ``timepoint``, ``hl``, ``p_paper``).
    planted : pandas.Series
        The planted value of each session (indexed by session id), e.g. a column of a
        simulated cohort's ``truth.csv``.
    sessions : pandas.DataFrame
        The sessions tested, indexed by session id with ``group`` and ``timepoint``
        columns (e.g. the usable rows of :func:`~tiltlab.stats.session_table`).
    control : str
        The reference group (``group2`` of the rows kept).
    alpha : float
        Level at which a difference counts as ``found`` (``p_paper < alpha``).

    Returns
    -------
    pandas.DataFrame
        Columns ``comparison``, ``time point``, ``planted Δ``, ``estimated Δ`` (in the
        units of ``between``'s ``hl``), ``p (m·p)`` and ``found``, one row per
        comparison and time point, labelled (``attrs["units"]``, ``attrs["long_name"]``).
    """
    _need(
        between,
        ("comparison", "group1", "group2", "timepoint", "hl", "p_paper"),
        "between",
    )
    _need(sessions, ("group", "timepoint"), "sessions")
    rows = between[between["group2"] == control]
    values = pd.Series(planted).reindex(sessions.index)
    out = []
    for _, r in rows.iterrows():
        at = sessions["timepoint"] == r["timepoint"]
        cells = [values[at & (sessions["group"] == g)] for g in (r["group1"], control)]
        out.append(
            {
                "comparison": r["comparison"],
                "time point": r["timepoint"],
                "planted Δ": hodges_lehmann(*cells).estimate,
                "estimated Δ": r["hl"],
                "p (m·p)": r["p_paper"],
                "found": bool(r["p_paper"] < alpha),
            }
        )
    units = between.attrs.get("units", {}).get("hl", "")
    table = pd.DataFrame(out, columns=list(_RECOVERY))
    return label_columns(
        table,
        units={"planted Δ": units, "estimated Δ": units, "p (m·p)": "1"}
        | dict.fromkeys(["comparison", "time point", "found"], ""),
        long_name=_RECOVERY,
        role={"p (m·p)": "p-value"},
    )
