r"""Cohort glue and tables of the tests of every comparison × time point.

Tidy, and laid out like Fayat et al.'s Tables A1–A8.

Input is the cohort table of :func:`tiltlab.cohort.run_cohort` — an
:class:`xarray.Dataset` with a ``session`` dimension, coordinates ``subject``,
``group``, ``timepoint`` and one variable per feature — or a :class:`pandas.DataFrame`
with those columns. Sessions whose ``status`` is not ``"ok"`` are left out of the tests
and counted in ``n_failed``; missing feature values of the other sessions are dropped
per cell and counted in ``n_missing``. Each animal is one experimental unit: a table
with two sessions of one subject at one time point is refused (pseudo-replication),
naming them.

Tidy columns (one row per comparison × time point)
-------------------------------------------------
``feature, comparison, group1, group2, timepoint, test, n1, n2, n_missing, n_failed,
statistic, alternative, method, p, family_size, p_paper, p_bonferroni, p_holm, p_bh,
rbc, rbc_low, rbc_high, ps, ps_low, ps_high, hl, hl_low, hl_high, hl_achieved,
conf_level, note``

* ``n_missing`` counts the sessions of the cell that ran but have no value of the
  feature (against baseline: the subjects of the group without both values, for
  another reason than a failed session); ``n_failed`` the sessions of the cell whose
  ``status`` is not ``"ok"`` (against baseline: those at the time point and at the
  baseline). ``n1 + n2 + n_missing + n_failed`` is every session of a between-group
  cell.

* ``alternative`` states the direction: ``"greater"`` means ``group1`` (or the time
  point, against baseline) tends to be larger.
* ``p_paper`` is Fayat et al.'s Bonferroni convention (:math:`m p`, uncapped,
  :math:`m` = ``family_size``); ``p_bonferroni``, ``p_holm``, ``p_bh`` are the capped
  statsmodels adjustments over the same family (:mod:`tiltlab.stats.multiple`).
* Effect sizes (:mod:`tiltlab.stats.effects`): between groups, ``rbc`` and ``ps`` are
  the rank-biserial correlation and :math:`P(X_1 > X_2) + \frac12 P(=)`, ``hl`` the
  Hodges–Lehmann shift ``group1 - group2``; against baseline, ``rbc`` is the
  matched-pairs rank-biserial correlation (no interval), ``ps`` is
  :math:`P(D > 0) + \frac12 P(D = 0)` and ``hl`` the pseudo-median of the differences
  (time point − baseline). Intervals are two-sided at ``conf_level``.
* A cell that cannot be tested (a group without enough values) keeps NaN values and
  says why in ``note``.
* ``method`` records the p-value method of each cell (``"exact"``,
  ``"exact-conditional"``, ``"asymptotic-cc"``…); ``method="paper"`` reproduces Fayat
  et al.'s mix (exact without ties, the normal approximation with ties).
* The Bonferroni family travels with the table: ``attrs["family_size"]`` (the
  multiplier), ``attrs["families"]`` (each family's ``family_size``, ``n_tested``,
  ``n_cells``) and ``attrs["family_caption"]``; ``family_size=`` states :math:`m`
  explicitly instead of counting the tested cells.

References
----------
.. [1] R. Fayat et al., Sensors 21(18):6318, 2021, Appendix A.7.
   doi:10.3390/s21186318
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from .. import _validate
from .._labels import format_p, label_columns
from .cells import (  # _timepoint_key, long_table: re-exported for design, summaries
    _feature_units,
    _frame,
    _ordered_timepoints,
    _timepoint_key,  # noqa: F401
    check_cells,
    long_table,  # noqa: F401
)
from .effects import (
    hodges_lehmann,
    paired_prob_superiority,
    paired_rank_biserial,
    prob_superiority,
)
from .multiple import ADDED_COLUMNS, add_adjustments, family_caption
from .nonparametric import _alternative, mann_whitney, wilcoxon_signed_rank

__all__ = [
    "between_groups",
    "against_baseline",
    "format_table",
    "THRESHOLDS",
    "COLOURS",
]

#: Highlight thresholds of Tables A1–A8 and their colours (yellow, green, blue).
THRESHOLDS = (0.05, 0.01, 0.001)
COLOURS = ("#fff176", "#a5d6a7", "#90caf9")


def _effects_row(x, y, conf_level, paired, zero_method="wilcox") -> dict:
    if paired:
        ps = paired_prob_superiority(x, y, conf_level=conf_level)
        rbc_est = paired_rank_biserial(x, y, zero_method=zero_method)
        rbc = (rbc_est, np.nan, np.nan)
    else:
        ps = prob_superiority(x, y, conf_level=conf_level)
        rbc = (2 * ps.estimate - 1, 2 * ps.low - 1, 2 * ps.high - 1)
    hl = hodges_lehmann(x, y, paired=paired, conf_level=conf_level)
    return {
        "rbc": rbc[0],
        "rbc_low": rbc[1],
        "rbc_high": rbc[2],
        "ps": ps.estimate,
        "ps_low": ps.low,
        "ps_high": ps.high,
        "hl": hl.estimate,
        "hl_low": hl.low,
        "hl_high": hl.high,
        "hl_achieved": hl.achieved,
    }


#: Long names of the tidy columns (:func:`between_groups`, :func:`against_baseline`).
TIDY_LONG_NAMES = {
    "family": "family of comparisons",
    "feature": "feature",
    "comparison": "comparison",
    "group1": "group 1",
    "group2": "group 2",
    "timepoint": "time point",
    "test": "test",
    "n1": "n (group 1)",
    "n2": "n (group 2)",
    "n_missing": "sessions without a value",
    "n_failed": "failed sessions",
    "statistic": "test statistic",
    "alternative": "alternative",
    "method": "p-value method",
    "p": "p",
    **ADDED_COLUMNS,
    "rbc": "rank-biserial correlation",
    "rbc_low": "rank-biserial correlation, lower bound",
    "rbc_high": "rank-biserial correlation, upper bound",
    "ps": "probability of superiority",
    "ps_low": "probability of superiority, lower bound",
    "ps_high": "probability of superiority, upper bound",
    "hl": "Hodges–Lehmann shift",
    "hl_low": "Hodges–Lehmann shift, lower bound",
    "hl_high": "Hodges–Lehmann shift, upper bound",
    "hl_achieved": "achieved level of the shift interval",
    "conf_level": "confidence level",
    "note": "note",
}
_HL = ("hl", "hl_low", "hl_high")


def _label_tidy(table: pd.DataFrame, units: str = "") -> pd.DataFrame:
    """Return a tidy test table with the units and long names of its columns.

    Parameters
    ----------
    table : pandas.DataFrame
        A tidy table (columns among :data:`TIDY_LONG_NAMES`; others keep their name).
    units : str
        Units of the feature: those of the Hodges–Lehmann shift and its bounds.

    Returns
    -------
    pandas.DataFrame
        A labelled copy: counts, p-values and rank effect sizes dimensionless
        (``"1"``), text columns ``""``, the p-value columns with role ``"p-value"``.
    """
    cols = list(table.columns)
    text = (
        "feature comparison group1 group2 timepoint test alternative method note family"
    ).split()
    return label_columns(
        table,
        units={c: units if c in _HL else ("" if c in text else "1") for c in cols},
        long_name={c: TIDY_LONG_NAMES.get(c, str(c)) for c in cols},
        role={
            c: "p-value" if c == "p" or c.startswith("p_") else "count"
            for c in cols
            if c == "p" or c.startswith(("p_", "n1", "n2", "n_", "family_size"))
        },
    )


_COLUMNS = (
    "feature comparison group1 group2 timepoint test n1 n2 n_missing n_failed statistic "
    "alternative method p rbc rbc_low rbc_high ps ps_low ps_high hl hl_low hl_high "
    "hl_achieved conf_level note"
).split()


def _finish(
    rows: list[dict], family, units: str = "", family_size=None
) -> pd.DataFrame:
    table = pd.DataFrame(rows)
    for c in _COLUMNS:
        if c not in table.columns:
            table[c] = np.nan
    table = add_adjustments(table[_COLUMNS], family, family_size=family_size)
    front = _COLUMNS[: _COLUMNS.index("p") + 1]
    adj = ["family_size", "p_paper", "p_bonferroni", "p_holm", "p_bh"]
    return _label_tidy(table[front + adj + _COLUMNS[len(front) :]], units)


def _checked_options(conf_level, test_options) -> float:
    """Check the effect-size level and the test options; return the level."""
    unknown = sorted(set(test_options) - {"method", "exact_max_n", "continuity"})
    if unknown:
        raise TypeError(
            f"unknown test option(s) {unknown}; the options are 'method', "
            "'exact_max_n' and 'continuity'"
        )
    return _validate.fraction(conf_level, "conf_level", open_low=True, open_high=True)


def between_groups(
    features,
    feature: str,
    comparisons: Sequence[tuple],
    *,
    alternative: str | None = None,
    timepoints: Sequence | None = None,
    baseline: str = "baseline",
    family: int | str | Sequence[str] | None = None,
    family_size: int | None = None,
    conf_level: float = 0.95,
    **test_options,
) -> pd.DataFrame:
    r"""One-sided Mann–Whitney tests between groups at each time point.

    Parameters
    ----------
    features : xarray.Dataset or pandas.DataFrame
        Cohort table (see the module docstring).
    feature : str
        Feature to compare.
    comparisons : sequence of tuples
        ``(group1, group2, alternative)``, e.g. ``("Arsanilate", "Healthy",
        "greater")`` — group1 tends to be larger — or ``(group1, group2)`` with the
        ``alternative`` keyword.
    alternative : {"greater", "less", "two-sided"}, optional
        Direction for 2-tuples; no default — every direction must be stated.
    timepoints : sequence, optional
        Time points (columns) in order; default every time point except ``baseline``,
        sorted by duration when the labels read as ``1h``, ``7d``… (else as found).
    baseline : str
        The baseline label excluded by default.
    family : int, str, sequence of str or None
        Bonferroni family (:func:`tiltlab.stats.multiple.add_adjustments`): default
        the whole table, i.e. Fayat et al.'s 3 comparisons × 6 time points per lesion
        type.
    family_size : int, optional
        The number of tests :math:`m` of the family, stated: e.g. 18 for Fayat et
        al.'s tables. Default: the tested cells (18 when all are testable, fewer —
        silently — when some are not). With ``family_size``, untested cells count as
        :math:`p = 1` and a :class:`RuntimeWarning` says how many were tested.
        Either way ``attrs["family_size"]``, ``attrs["families"]`` and
        ``attrs["family_caption"]`` state the family used and the cells tested.
    conf_level : float
        Level of the effect-size intervals.
    **test_options
        ``method`` (``"paper"`` for Fayat et al.'s mix of exact and asymptotic
        p-values), ``exact_max_n`` and ``continuity`` of
        :func:`tiltlab.stats.mann_whitney`; the ``method`` column records the method
        of each cell.

    Returns
    -------
    pandas.DataFrame
        The tidy table, one row per comparison × time point; ``n_failed`` counts the
        failed sessions of the two groups at that time point, left out.

    Raises
    ------
    ValueError
        Two sessions of one subject at one time point (:func:`check_cells`), a group
        absent from the data, a comparison without a direction, a ``family_size``
        below the tested cells.
    TypeError
        An unknown test option.

    Warns
    -----
    RuntimeWarning
        ``family_size`` larger than the number of tested cells.

    Examples
    --------
    >>> import pandas as pd
    >>> from tiltlab.stats import between_groups
    >>> table = pd.DataFrame({
    ...     "subject": [f"s{i}" for i in range(8)],
    ...     "group": ["lesion"] * 4 + ["sham"] * 4,
    ...     "timepoint": ["7d"] * 8,
    ...     "tilt": [9.0, 8.0, 7.5, 9.5, 5.0, 6.0, 5.5, 4.0],
    ... })
    >>> tidy = between_groups(table, "tilt", [("lesion", "sham", "greater")])
    >>> tidy[["comparison", "timepoint", "n1", "n2", "p", "hl"]].round(4)
            comparison timepoint  n1  n2       p   hl
    0  lesion vs. sham        7d   4   4  0.0143  3.5
    >>> tidy.attrs["long_name"]["hl"]
    'Hodges–Lehmann shift'
    """
    conf_level = _checked_options(conf_level, test_options)
    full = _frame(features, feature)
    check_cells(full)
    ok = full["status"] == "ok"
    df, failed = full[ok], full[~ok]
    groups = set(full["group"])
    specs = []
    for comp in comparisons:
        if not isinstance(comp, (tuple, list)) or len(comp) not in (2, 3):
            raise ValueError(
                "comparisons must be (group1, group2[, alternative]) tuples, got "
                f"{comp!r}"
            )
        g1, g2 = comp[0], comp[1]
        alt = comp[2] if len(comp) == 3 else alternative
        if alt is None:
            raise ValueError(
                f"comparisons: no alternative for {comp!r}; give (g1, g2, alternative) "
                "or the alternative keyword"
            )
        _alternative(alt, "alternative (in comparisons)")
        for g in (g1, g2):
            if g not in groups:
                raise ValueError(
                    f"comparisons names group {g!r}, absent from the data "
                    f"(groups: {sorted(map(str, groups))})"
                )
        specs.append((g1, g2, alt))
    if not specs:
        raise ValueError("comparisons is empty")
    tps = _ordered_timepoints(full, baseline, timepoints)
    rows = []
    for g1, g2, alt in specs:
        for t in tps:
            cell = df[df["timepoint"] == t]
            x = cell.loc[cell["group"] == g1, "value"].to_numpy()
            y = cell.loc[cell["group"] == g2, "value"].to_numpy()
            miss = int(np.isnan(x).sum() + np.isnan(y).sum())
            n_failed = int(
                ((failed["timepoint"] == t) & failed["group"].isin([g1, g2])).sum()
            )
            x, y = x[~np.isnan(x)], y[~np.isnan(y)]
            row = {
                "feature": feature,
                "comparison": f"{g1} vs. {g2}",
                "group1": g1,
                "group2": g2,
                "timepoint": t,
                "test": "mann-whitney",
                "n1": x.size,
                "n2": y.size,
                "n_missing": miss,
                "n_failed": n_failed,
                "alternative": alt,
                "conf_level": conf_level,
                "note": "",
            }
            try:
                res = mann_whitney(x, y, alternative=alt, **test_options)
            except ValueError as exc:
                row["note"] = f"not tested: {exc}"
                rows.append(row)
                continue
            row.update(statistic=res.statistic, method=res.method, p=res.p)
            row.update(_effects_row(x, y, conf_level, paired=False))
            rows.append(row)
    units = _feature_units(features, feature)
    return _finish(rows, family, units, family_size)


def against_baseline(
    features,
    feature: str,
    groups: Sequence[str] | None = None,
    *,
    baseline: str = "baseline",
    alternative: str | Mapping[str, str],
    timepoints: Sequence | None = None,
    family: int | str | Sequence[str] | None = "group1",
    family_size: int | None = None,
    zero_method: str = "wilcox",
    conf_level: float = 0.95,
    **test_options,
) -> pd.DataFrame:
    r"""One-sided Wilcoxon signed-rank tests of each time point against baseline.

    Subjects are paired by ``subject``; those missing either session are left out of
    that cell (``n_missing``).

    Parameters
    ----------
    features : xarray.Dataset or pandas.DataFrame
        Cohort table.
    feature : str
        Feature to test.
    groups : sequence of str, optional
        Groups (rows), default all in order of appearance.
    baseline : str
        Baseline time point label.
    alternative : str or mapping group -> str
        ``"greater"``: the time point's values exceed the baseline's. Required.
    timepoints : sequence, optional
        Time points (columns); default all but ``baseline``.
    family : int, str, sequence of str or None
        Bonferroni family: default ``"group1"`` — each group's time points, i.e.
        Fayat et al.'s 6 (Tables A2, A4, A6, A8).
    family_size : int, optional
        The number of tests :math:`m` of each family, stated (6 in Fayat et al.'s
        tables); default each family's tested cells (see :func:`between_groups`).
    zero_method : {"wilcox", "pratt"}
        Zero-difference rule (:func:`tiltlab.stats.wilcoxon_signed_rank`).
    conf_level : float
        Confidence level of the intervals around the effect sizes.
    **test_options
        The signed-rank test's ``method`` (``"paper"``: exact without ties or zeros,
        else the normal approximation), ``exact_max_n`` and ``continuity``
        (:func:`tiltlab.stats.wilcoxon_signed_rank`).

    Returns
    -------
    pandas.DataFrame
        The tidy table; ``comparison`` reads ``"<group> vs. <group> baseline"`` as in
        the paper; ``n1 = n2`` = number of pairs; ``n_failed`` counts the group's
        failed sessions at the time point and at the baseline, ``n_missing`` the
        subjects of the group without both values for another reason.

    Raises
    ------
    ValueError
        Two sessions of one subject at one time point (:func:`check_cells`), a group
        or the baseline absent from the data, a group without a direction, a
        ``family_size`` below a family's tested cells.

    Warns
    -----
    RuntimeWarning
        ``family_size`` larger than the number of tested cells of a family.
    """
    conf_level = _checked_options(conf_level, test_options)
    full = _frame(features, feature)
    check_cells(full)
    ok = full["status"] == "ok"
    df = full[ok]
    present = list(dict.fromkeys(full["group"]))
    groups = present if groups is None else list(groups)
    for g in groups:
        if g not in present:
            raise ValueError(f"groups names {g!r}, absent from the data ({present})")
    if not groups:
        raise ValueError("groups is empty")
    if isinstance(alternative, Mapping):
        alts = {g: alternative.get(g) for g in groups}
        lacking = [g for g, a in alts.items() if a is None]
        if lacking:
            raise ValueError(f"alternative gives no direction for groups {lacking}")
    else:
        alts = dict.fromkeys(groups, alternative)
    for a in alts.values():
        _alternative(a)
    if baseline not in set(full["timepoint"]):
        raise ValueError(f"baseline {baseline!r} is not a time point of the data")
    tps = _ordered_timepoints(full, baseline, timepoints)
    rows = []
    for g in groups:
        in_group = full[full["group"] == g]
        subjects = list(dict.fromkeys(in_group["subject"]))
        wide = (
            df[df["group"] == g]
            .pivot(index="subject", columns="timepoint", values="value")
            .reindex(index=subjects)
        )
        lost = in_group[in_group["status"] != "ok"]
        for t in tps:
            row = {
                "feature": feature,
                "comparison": f"{g} vs. {g} baseline",
                "group1": g,
                "group2": f"{g} baseline",
                "timepoint": t,
                "test": "wilcoxon",
                "alternative": alts[g],
                "conf_level": conf_level,
                "note": "",
            }
            at = lost[lost["timepoint"].isin([t, baseline])]
            row["n_failed"] = len(at)
            broken = set(at["subject"])  # pairs lost to a failed session
            if t not in wide.columns or baseline not in wide.columns:
                row.update(
                    n1=0,
                    n2=0,
                    n_missing=len([s for s in subjects if s not in broken]),
                    note="not tested: no data",
                )
                rows.append(row)
                continue
            pair = wide[[t, baseline]]
            complete = pair.notna().all(axis=1)
            x = pair.loc[complete, t].to_numpy()
            y = pair.loc[complete, baseline].to_numpy()
            incomplete = [s for s in pair.index[~complete] if s not in broken]
            row.update(n1=x.size, n2=x.size, n_missing=len(incomplete))
            try:
                res = wilcoxon_signed_rank(
                    x, y, alternative=alts[g], zero_method=zero_method, **test_options
                )
            except ValueError as exc:
                row["note"] = f"not tested: {exc}"
                rows.append(row)
                continue
            row.update(statistic=res.statistic, method=res.method, p=res.p)
            if res.n_zero:
                row["note"] = f"{res.n_zero} zero difference(s), rule {zero_method!r}"
            row.update(
                _effects_row(x, y, conf_level, paired=True, zero_method=zero_method)
            )
            rows.append(row)
    units = _feature_units(features, feature)
    return _finish(rows, family, units, family_size)


def _stars(v: float) -> str:
    return "*" * sum(v < t for t in THRESHOLDS) if np.isfinite(v) else ""


def format_table(
    tidy: pd.DataFrame,
    value: str = "p_paper",
    *,
    output: str = "text",
    decimals: int = 3,
    family_column: bool = False,
):
    r"""Lay a tidy table out like Fayat et al.'s Tables A1–A8.

    Rows are the comparisons, columns the time points (both in order of appearance);
    values below :math:`10^{-3}` print as ``"<0.001"``, others with 3 decimals. The
    Bonferroni family travels with the table: a Styler's caption, and
    ``attrs["caption"]`` of the other outputs, say which :math:`m` multiplied the
    p-values and how many cells were tested (:func:`tiltlab.stats.family_caption`).

    Parameters
    ----------
    tidy : pandas.DataFrame
        From :func:`between_groups` or :func:`against_baseline`.
    value : str
        Column to show (``"p_paper"``, ``"p"``, ``"p_holm"``, ``"p_bh"``, ``"hl"``…).
    output : {"text", "styler", "frame"}
        ``"text"``: strings with ``*``, ``**``, ``***`` for values below 0.05, 0.01,
        0.001 (for p-value columns); ``"styler"``: a pandas ``Styler`` with
        yellow / green / blue backgrounds at the same thresholds;
        ``"frame"``: the numeric pivot.
    decimals : int
        Decimals shown.
    family_column : bool
        Add a last column ``"m"``: each row's family size, with ``"(k of n tested)"``
        when some of its cells could not be tested.

    Returns
    -------
    pandas.DataFrame or pandas.io.formats.style.Styler

    Examples
    --------
    >>> import pandas as pd
    >>> tidy = pd.DataFrame({"comparison": ["a vs. b"] * 2, "timepoint": ["1d", "7d"],
    ...                      "p": [0.002, float("nan")]})
    >>> from tiltlab.stats import add_adjustments
    >>> out = format_table(add_adjustments(tidy), family_column=True)
    >>> out.loc["a vs. b"].tolist()
    ['0.002**', '', '1 (1 of 2 tested)']
    >>> out.attrs["caption"]
    'Bonferroni family: m = 1 (1 of 2 cells tested)'
    """
    if output not in ("text", "styler", "frame"):
        raise ValueError(f"output must be 'text', 'styler' or 'frame', got {output!r}")
    decimals = _validate.integer(decimals, "decimals", minimum=0)
    for c in ("comparison", "timepoint", value):
        if c not in tidy.columns:
            raise ValueError(f"tidy has no column {value if c == value else c!r}")
    rows = list(dict.fromkeys(tidy["comparison"]))
    cols = list(dict.fromkeys(tidy["timepoint"]))
    grid = tidy.pivot_table(
        index="comparison",
        columns="timepoint",
        values=value,
        aggfunc="first",
        dropna=False,
    ).reindex(index=rows, columns=cols)
    grid.index.name, grid.columns.name = None, None
    is_p = value == "p" or value.startswith("p_")
    caption = family_caption(tidy)
    m = _family_column(tidy, rows) if family_column else None
    if output == "frame":
        units = tidy.attrs.get("units", {})
        out = label_columns(
            grid,
            units="1" if is_p else str(units.get(value, "")),
            long_name={c: f"{TIDY_LONG_NAMES.get(value, value)}, {c}" for c in cols},
            role="p-value" if is_p else None,
        )
        if m is not None:
            out = label_columns(
                out.assign(m=m), units={"m": ""}, long_name={"m": "family size m"}
            )
        out.attrs["caption"] = caption
        return out
    text = grid.map(lambda v: format_p(v, decimals))
    if output == "text":
        out = text + grid.map(_stars) if is_p else text
        out = out.assign(m=m) if m is not None else out
        out.attrs["caption"] = caption
        return out

    def colour(_):
        out = pd.DataFrame("", index=grid.index, columns=grid.columns)
        if is_p:
            for t, c in zip(THRESHOLDS, COLOURS):
                out = out.mask(grid < t, f"background-color: {c}")
        return out

    shown = text.assign(m=m) if m is not None else text
    styler = shown.style.apply(
        lambda d: colour(d).reindex(columns=d.columns, fill_value=""), axis=None
    )
    return styler.set_caption(caption) if caption else styler


def _family_column(tidy: pd.DataFrame, rows: list) -> pd.Series:
    """Write each comparison's family size and, if some were not, its tested cells."""
    if "family_size" not in tidy.columns or "p" not in tidy.columns:
        raise ValueError("family_column needs the family_size and p columns of tidy")
    whole = tidy.attrs.get("family_size")
    out = {}
    for name, cell in tidy.groupby("comparison", sort=False):
        sizes = sorted({int(v) for v in cell["family_size"].dropna()})
        if not sizes and isinstance(whole, (int, np.integer)):
            sizes = [int(whole)]
        tested = int(np.isfinite(cell["p"].to_numpy(dtype=float)).sum())
        text = " or ".join(map(str, sizes))
        if tested < len(cell):
            text += f" ({tested} of {len(cell)} tested)"
        out[name] = text
    return pd.Series(out).reindex(rows)
