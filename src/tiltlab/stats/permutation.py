r"""Subject-level permutation test of a group × time interaction.

The small-sample companion of :func:`tiltlab.stats.mixed_model`'s Wald tests: the same
difference in differences, with a null distribution built by relabelling whole subjects.

Statistic
---------
For subject :math:`s` and time point :math:`t` after the baseline :math:`t_0`, the
change from baseline is :math:`d_{st} = y_{st} - y_{st_0}`. For a group :math:`g`
against the reference group :math:`r`,

.. math::
    T_{gt} = \bar d_{\cdot t}^{(g)} - \bar d_{\cdot t}^{(r)},

the mean change in :math:`g` minus the mean change in :math:`r` over the subjects with
both sessions — the mixed model's interaction :math:`(\alpha\tau)_{gt}` estimated by cell
means (equal to it for complete, balanced data).

Null distribution
-----------------
Under the null hypothesis that the group does not change how a subject's feature moves
from baseline to :math:`t`, the group labels of the :math:`n_g + n_r` subjects are
exchangeable. Relabelling moves whole subjects (each keeps its own change), so the
correlation between an animal's sessions is kept without being modelled. With
:math:`B` relabellings drawn at random the p-value is

.. math::
    p = \frac{1 + \#\{b : |T^*_b| \ge |T|\}}{1 + B}

(two-sided; :math:`T^*_b \ge T` or :math:`\le T` one-sided), which is never zero and is a
valid p-value [1]_. When the number of distinct relabellings
:math:`\binom{n_g + n_r}{n_g}` is at most :math:`B` they are all enumerated and
:math:`p` is the exact fraction of them at least as extreme as the observed one (the
observed labelling among them).

References
----------
.. [1] B. Phipson and G. K. Smyth, "Permutation p-values should never be zero:
   calculating exact p-values when permutations are randomly drawn", Stat. Appl.
   Genet. Mol. Biol. 9(1):39, 2010. doi:10.2202/1544-6115.1585
.. [2] P. Good, *Permutation, Parametric, and Bootstrap Tests of Hypotheses*, 3rd ed.,
   Springer, 2005.
"""

from __future__ import annotations

from itertools import combinations
from math import comb

import numpy as np
import pandas as pd

from .._labels import label_columns

__all__ = ["permutation_interaction"]

_ALTERNATIVES = ("two-sided", "greater", "less")

_NAMES = {
    "term": "interaction term",
    "group": "group",
    "timepoint": "time point",
    "estimate": "difference in mean change from baseline",
    "n1": "subjects in the group",
    "n2": "subjects in the reference group",
    "p": "p (subject permutation)",
    "n_relabellings": "relabellings evaluated",
    "method": "null distribution",
}


def _validated(
    data: pd.DataFrame,
    feature: str,
    group: str,
    timepoint: str,
    subject: str,
    baseline: str,
) -> pd.DataFrame:
    """Return the needed columns as a new table (feature as float), or raise."""
    if not isinstance(data, pd.DataFrame):
        raise TypeError(f"data must be a pandas DataFrame, got {type(data).__name__}")
    missing = [c for c in (feature, group, timepoint, subject) if c not in data.columns]
    if missing:
        raise ValueError(
            f"data has no column(s) {missing} (columns: {list(data.columns)})"
        )
    d = data[[feature, group, timepoint, subject]].copy()
    d[feature] = pd.to_numeric(d[feature], errors="coerce").astype(float)
    for c in (group, timepoint, subject):
        d[c] = d[c].astype(str)
    groups_per_subject = d.groupby(subject)[group].nunique()
    mixed = sorted(groups_per_subject.index[groups_per_subject > 1])
    if mixed:
        raise ValueError(
            f"subject(s) {mixed} appear in more than one group: the test relabels "
            "whole subjects, so each must belong to exactly one group"
        )
    dup = d.duplicated([subject, timepoint])
    if dup.any():
        pairs = d.loc[dup, [subject, timepoint]].drop_duplicates().values.tolist()
        raise ValueError(
            f"several rows for (subject, time point) {pairs[:5]}: one value per "
            "subject and time point is needed"
        )
    if str(baseline) not in set(d[timepoint]):
        raise ValueError(
            f"baseline time point {baseline!r} is not in column {timepoint!r} "
            f"(levels: {sorted(set(d[timepoint]))})"
        )
    return d


def _extreme(stat: np.ndarray, observed: float, alternative: str) -> np.ndarray:
    """Flag the relabelled statistics at least as extreme as the observed one.

    A tolerance for rounding makes ties count.
    """
    tol = 1e-9 * max(1.0, abs(observed))
    if alternative == "greater":
        return stat >= observed - tol
    if alternative == "less":
        return stat <= observed + tol
    return np.abs(stat) >= abs(observed) - tol


def _one_contrast(
    changes: np.ndarray,
    n1: int,
    alternative: str,
    n_permutations: int,
    rng: np.random.Generator,
) -> tuple[float, float, int, str]:
    """Test one group pair at one time point.

    ``changes`` holds the group's subjects first, then the reference group's; returns
    the statistic, the p-value, the relabellings used and the method.
    """
    n = len(changes)
    n2 = n - n1
    total = changes.sum()
    observed = changes[:n1].mean() - changes[n1:].mean()
    n_labels = comb(n, n1)
    if n_labels <= n_permutations:
        picks = np.array(list(combinations(range(n), n1)), dtype=np.intp)
        s1 = changes[picks].sum(axis=1)
        stat = s1 / n1 - (total - s1) / n2
        hits = int(_extreme(stat, observed, alternative).sum())
        return float(observed), hits / n_labels, n_labels, "exact"
    order = rng.permuted(np.tile(np.arange(n), (n_permutations, 1)), axis=1)
    s1 = changes[order[:, :n1]].sum(axis=1)
    stat = s1 / n1 - (total - s1) / n2
    hits = int(_extreme(stat, observed, alternative).sum())
    return float(observed), (1 + hits) / (1 + n_permutations), n_permutations, "random"


def permutation_interaction(
    data: pd.DataFrame,
    feature: str,
    *,
    group: str = "group",
    timepoint: str = "timepoint",
    subject: str = "subject",
    reference_group: str | None = None,
    baseline: str = "baseline",
    alternative: str = "two-sided",
    n_permutations: int = 9999,
    seed: int | np.random.Generator | None = None,
) -> pd.DataFrame:
    r"""Test each group × time interaction by permuting group labels across subjects.

    For every group other than the reference and every time point after the baseline,
    the statistic is the difference between the two groups' mean change from baseline
    (the mixed model's interaction term, by cell means); its null distribution relabels
    whole subjects between the two groups.

    Parameters
    ----------
    data : pandas.DataFrame
        Long table, one row per session (e.g. from :func:`tiltlab.stats.long_table`);
        not modified. Sessions with a missing ``feature`` are left out, and a subject
        enters the test at a time point only if it has a value there and at baseline.
    feature : str
        Column of the response.
    group, timepoint, subject : str
        Column names (as in :func:`tiltlab.stats.mixed_model`).
    reference_group : str, optional
        The group every other group is compared with (default: the first in sorted
        order, as in :func:`~tiltlab.stats.mixed_model`).
    baseline : str
        The time point changes are measured from.
    alternative : {"two-sided", "greater", "less"}
        ``"greater"``: the group's mean change exceeds the reference group's.
    n_permutations : int
        Random relabellings :math:`B`, drawn when there are more distinct relabellings
        than this; otherwise every relabelling is enumerated (an exact test).
    seed : int or numpy.random.Generator, optional
        Seed of the random relabellings (exact enumeration uses none).

    Returns
    -------
    pandas.DataFrame
        One row per group (sorted) and time point (in the order of a categorical
        ``timepoint`` column, else of first appearance): ``term`` (named as in the mixed model's
        table, ``group[g]:timepoint[t]``), ``group``, ``timepoint``, ``estimate`` (the
        difference in mean change, in the feature's units), ``n1`` and ``n2`` (subjects
        of the group and of the reference group with both sessions), ``p``,
        ``n_relabellings`` and ``method`` (``"exact"`` or ``"random"``); units and long
        names in ``attrs`` (units of the feature from ``data.attrs["units"]``), and the
        reference group, baseline and alternative in ``attrs`` too. ``p`` is NaN where
        either group has fewer than 2 subjects with both sessions.

    Raises
    ------
    ValueError
        A missing column, a subject in two groups, two rows for one subject and time
        point, a baseline absent from the data, an unknown reference group or
        alternative, fewer than 2 subjects with a baseline in a compared group, or
        ``n_permutations`` below 1.
    TypeError
        ``data`` is not a DataFrame.

    Notes
    -----
    The test assumes only that, under the null hypothesis, subjects are exchangeable
    between the two groups: no normality, no common variance, no random-effect model.
    Its p-value is exact (enumeration) or valid at every :math:`B` (random
    relabellings, [1]_), at the price of a lattice: with :math:`n_g` and :math:`n_r`
    subjects, the smallest two-sided p-value is :math:`2/\binom{n_g+n_r}{n_g}`. Each time
    point is tested on its own; no adjustment for multiple time points is applied.

    References
    ----------
    .. [1] B. Phipson and G. K. Smyth, "Permutation p-values should never be zero",
       Stat. Appl. Genet. Mol. Biol. 9(1):39, 2010. doi:10.2202/1544-6115.1585

    Examples
    --------
    >>> import pandas as pd
    >>> d = pd.DataFrame({
    ...     "subject": ["a", "a", "b", "b", "c", "c", "d", "d"],
    ...     "group": ["L", "L", "L", "L", "C", "C", "C", "C"],
    ...     "timepoint": ["baseline", "1d"] * 4,
    ...     "value": [0.1, 0.5, 0.2, 0.7, 0.1, 0.1, 0.3, 0.2],
    ... })
    >>> out = permutation_interaction(d, "value", reference_group="C")
    >>> out[["term", "estimate", "p", "method"]].round(3).to_dict("records")
    [{'term': 'group[L]:timepoint[1d]', 'estimate': 0.5, 'p': 0.333, 'method': 'exact'}]
    """
    if alternative not in _ALTERNATIVES:
        raise ValueError(
            f"alternative must be one of {_ALTERNATIVES}, got {alternative!r}"
        )
    if int(n_permutations) < 1:
        raise ValueError(f"n_permutations must be at least 1, got {n_permutations}")
    baseline = str(baseline)
    d = _validated(data, feature, group, timepoint, subject, baseline)
    d = d[np.isfinite(d[feature])]
    wide = d.pivot(index=subject, columns=timepoint, values=feature)
    group_of = d.groupby(subject)[group].first()
    levels = sorted(group_of.unique())
    ref = str(reference_group) if reference_group is not None else levels[0]
    if ref not in levels:
        raise ValueError(
            f"reference_group {ref!r} is not a group of the data: {levels}"
        )
    if baseline not in wide:
        raise ValueError(f"no finite {feature!r} value at baseline {baseline!r}")
    has_base = wide[baseline].notna()
    for g in levels:
        n_g = int((has_base & (group_of.reindex(wide.index) == g)).sum())
        if n_g < 2:
            raise ValueError(
                f"group {g!r} has {n_g} subject(s) with a baseline value; the "
                "permutation test needs at least 2 per group"
            )
    change = wide.drop(columns=baseline).sub(wide[baseline], axis=0)
    tp = data[timepoint]
    order = (
        [str(c) for c in tp.cat.categories]
        if isinstance(tp.dtype, pd.CategoricalDtype)
        else list(dict.fromkeys(d[timepoint]))
    )
    post = [t for t in order if t != baseline and t in change]
    gen = np.random.default_rng(seed)
    member = group_of.reindex(change.index)
    rows = []
    for g in (x for x in levels if x != ref):
        for t in post:
            x = change.loc[member == g, t].dropna().to_numpy()
            y = change.loc[member == ref, t].dropna().to_numpy()
            row = {
                "term": f"{group}[{g}]:{timepoint}[{t}]",
                "group": g,
                "timepoint": t,
                "n1": len(x),
                "n2": len(y),
            }
            if min(len(x), len(y)) < 2:
                row.update(estimate=np.nan, p=np.nan, n_relabellings=0, method="")
            else:
                est, p, used, how = _one_contrast(
                    np.concatenate([x, y]),
                    len(x),
                    alternative,
                    int(n_permutations),
                    gen,
                )
                row.update(estimate=est, p=p, n_relabellings=used, method=how)
            rows.append(row)
    out = pd.DataFrame(rows, columns=list(_NAMES))
    given = data.attrs.get("units", {})
    units = str(given.get(feature, "")) if isinstance(given, dict) else ""
    out = label_columns(
        out,
        units={
            c: units if c == "estimate" else ("1" if c in ("p", "n1", "n2") else "")
            for c in out
        },
        long_name=_NAMES,
        role={"p": "p-value"},
    )
    out.attrs.update(reference_group=ref, baseline=baseline, alternative=alternative)
    return out
