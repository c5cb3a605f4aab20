r"""Multiple-comparison adjustments, including the convention of Fayat et al.'s tables.

Four adjustments of the p-values :math:`p_1..p_m` of one family of :math:`m` tests:

``"paper"``
    :math:`\tilde p_i = m\,p_i`, **left uncapped above 1** — the Bonferroni values as
    printed in Fayat et al. (2021), Tables A1–A8 (e.g. 17.753). Read
    :math:`\tilde p_i < \alpha` exactly as a Bonferroni decision at family-wise level
    :math:`\alpha`; values above 1 are not probabilities.
``"bonferroni"``
    :math:`\min(1, m p_i)` (``statsmodels.stats.multitest.multipletests``).
``"holm"``
    Holm's step-down: :math:`\tilde p_{(i)} = \max_{j \le i} \min(1, (m - j + 1)
    p_{(j)})`.
``"bh"``
    Benjamini–Hochberg step-up (false discovery rate): :math:`\tilde p_{(i)} =
    \min_{j \ge i} \min(1, m p_{(j)} / j)`.

The family size :math:`m` defaults to the number of p-values given; a larger ``family``
treats the missing tests as having :math:`p = 1` (for Bonferroni/Holm/BH this is the
usual correction for :math:`m` tests of which only some are shown). In a table
(:func:`add_adjustments`), the default family is the *tested* cells, so it shrinks
when some cells cannot be tested (18 → 16 with two empty cells); ``family_size``
states :math:`m` instead, and every table records the family it used and how many of
its cells were tested (``attrs["families"]``, :func:`family_caption`).

Fayat et al.'s families (inferred from Tables A1–A8)
----------------------------------------------------
The paper does not state its family sizes; the printed values fix them:

* **Between groups (Mann–Whitney, Tables A1, A3, A5, A7): m = 18** — the 3 comparisons
  of one lesion type (lesion vs Healthy, lesion vs its sham, sham vs Healthy) × 6
  post-lesion time points. Evidence: the largest of the 144 printed values is 17.753
  (< 18) although one-sided p-values near 1 occur; 9.000 = 18 × 1/2 (the exact
  one-sided p of :math:`U = 28` for 5 vs 11 animals, :math:`n_1 n_2 = 55` odd, is
  exactly 1/2); and the ShamArsanilate (n = 5) vs 11-animal comparisons fall on the
  exact lattice :math:`18k/\binom{16}{5} = 18k/4368`: 16.376 (k = 3974), 14.032
  (3405), 13.413 (3255), 5.951 (1444), 5.250 (1274), 1.990 (483), 17.753 (4308).
* **Against baseline (Wilcoxon, Tables A2, A4, A6, A8): m = 6** per group — the 6
  post-lesion time points each compared with the group's own baseline. Evidence: the
  largest printed value is 5.903 (< 6); ShamArsanilate (n = 5) values are multiples of
  6/32 (0.188 = 6/32, the smallest attainable; 0.562 = 6 × 3/32; 2.438 = 6 × 13/32;
  5.438 = 6 × 29/32); Healthy and ShamKainate (n = 11) values are :math:`6k/2^{11}`
  (0.003 = 6/2048, 0.009 = 6 × 3/2048, 0.961 = 6 × 328/2048, 1.239 = 6 × 423/2048).

These are :data:`FAYAT_FAMILIES`. (A few cells fit the lattices only with one more
animal — e.g. Arsanilate 0.001 in Table A2 needs :math:`n \ge 12` — so group sizes
varied slightly between sessions; that does not change the multipliers.)

References
----------
.. [1] R. Fayat et al., "Inertial measurement of head tilt in rodents", Sensors
   21(18):6318, 2021, Appendix A.7. doi:10.3390/s21186318
.. [2] S. Holm, "A simple sequentially rejective multiple test procedure", Scand. J.
   Statist. 6:65–70, 1979. doi:10.2307/4615733
.. [3] Y. Benjamini and Y. Hochberg, "Controlling the false discovery rate", J. R.
   Stat. Soc. B 57:289–300, 1995. doi:10.1111/j.2517-6161.1995.tb02031.x
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np
import pandas as pd
from statsmodels.stats.multitest import multipletests

from .. import _validate
from .._labels import label_columns
from .._stack import user_stacklevel

__all__ = [
    "ADJUSTMENTS",
    "FAYAT_FAMILIES",
    "adjust",
    "paper_bonferroni",
    "add_adjustments",
    "family_caption",
]

#: Adjustment names and their statsmodels methods ("paper" is ours).
ADJUSTMENTS = {
    "paper": None,
    "bonferroni": "bonferroni",
    "holm": "holm",
    "bh": "fdr_bh",
}

#: Family sizes of Fayat et al. (2021) Tables A1–A8 (see the module docstring):
#: Mann–Whitney tables, per lesion type; Wilcoxon tables, per group.
FAYAT_FAMILIES = {"mann-whitney": 18, "wilcoxon": 6}


def _pvalues(p) -> np.ndarray:
    a = np.asarray(p, dtype=float).reshape(-1)
    bad = ~np.isfinite(a) | (a < 0) | (a > 1)
    if bad.any():
        raise ValueError(
            f"p must hold probabilities in [0, 1], got {a[bad][:3].tolist()} at "
            f"positions {np.flatnonzero(bad)[:3].tolist()}"
        )
    return a


def _family(family, m: int) -> int:
    if family is None:
        return m
    f = _validate.integer(family, "family", minimum=1)
    if f < m:
        raise ValueError(
            f"family ({f}) is smaller than the number of p-values in it ({m})"
        )
    return f


def paper_bonferroni(p, family: int | None = None) -> np.ndarray:
    r"""Bonferroni as printed by Fayat et al.: :math:`m\,p`, uncapped.

    Parameters
    ----------
    p : array_like
        Unadjusted p-values of one family.
    family : int, optional
        The multiplier :math:`m` (number of tests in the family); default ``len(p)``.
        Fayat et al. use 18 for their Mann–Whitney tables and 6 for their Wilcoxon
        tables (:data:`FAYAT_FAMILIES`).

    Returns
    -------
    numpy.ndarray
        :math:`m p_i`, possibly above 1.
    """
    a = _pvalues(p)
    return a * _family(family, a.size)


def adjust(p, method: str = "holm", *, family: int | None = None) -> np.ndarray:
    r"""Adjust the p-values of one family of tests.

    Parameters
    ----------
    p : array_like
        Unadjusted p-values.
    method : {"paper", "bonferroni", "holm", "bh"}
        See the module docstring; all but ``"paper"`` are computed by
        ``statsmodels.stats.multitest.multipletests`` and capped at 1.
    family : int, optional
        Number of tests in the family (default ``len(p)``); the extra
        ``family - len(p)`` tests enter with :math:`p = 1`.

    Returns
    -------
    numpy.ndarray
        Adjusted values, in the order of ``p``.
    """
    if method not in ADJUSTMENTS:
        raise ValueError(f"method must be one of {tuple(ADJUSTMENTS)}, got {method!r}")
    a = _pvalues(p)
    m = _family(family, a.size)
    if a.size == 0:
        return a.copy()
    if method == "paper":
        return a * m
    padded = np.concatenate([a, np.ones(m - a.size)])
    return multipletests(padded, method=ADJUSTMENTS[method])[1][: a.size]


#: The columns :func:`add_adjustments` adds, with their long names.
ADDED_COLUMNS = {
    "family_size": "family size m",
    "p_paper": "p × m (Fayat et al.)",
    "p_bonferroni": "p, Bonferroni",
    "p_holm": "p, Holm",
    "p_bh": "p, Benjamini–Hochberg",
}


def _family_keys(
    table: pd.DataFrame, family
) -> tuple[dict[str, np.ndarray], int | None]:
    """Row-index groups forming the families (by label), and a fixed multiplier."""
    if family is None or isinstance(family, (int, np.integer)):
        return {"all": np.arange(len(table))}, (None if family is None else int(family))
    cols = [family] if isinstance(family, str) else list(family)
    missing = [c for c in cols if c not in table.columns]
    if missing:
        raise ValueError(f"family names unknown column(s) {missing}")
    groups = table.reset_index(drop=True).groupby(cols, sort=False).indices

    def label(key) -> str:
        return " / ".join(map(str, key)) if isinstance(key, tuple) else str(key)

    return {label(k): np.asarray(v) for k, v in groups.items()}, None


def _family_size(family_size, fixed: int | None) -> int | None:
    """Check ``family_size`` against an integer ``family``; return the multiplier."""
    if family_size is None:
        return fixed
    m = _validate.integer(family_size, "family_size", minimum=1)
    if fixed is not None and fixed != m:
        raise ValueError(
            f"family_size ({m}) and the integer family ({fixed}) disagree; give one"
        )
    return m


def family_caption(table: pd.DataFrame) -> str:
    r"""Say which Bonferroni family a tidy table used, and how many cells were tested.

    Parameters
    ----------
    table : pandas.DataFrame
        From :func:`add_adjustments` (or :func:`~tiltlab.stats.between_groups`,
        :func:`~tiltlab.stats.against_baseline`): read from ``attrs["families"]``
        when they describe its rows, else from the ``family_size`` and ``p`` columns
        (one family per value of a ``family`` column, as in
        :func:`~tiltlab.stats.design_tables`).

    Returns
    -------
    str
        E.g. ``"Bonferroni family: m = 18 (16 of 18 cells tested)"``; one clause per
        family when they differ; ``""`` when the table says nothing about it.

    Examples
    --------
    >>> import pandas as pd
    >>> family_caption(add_adjustments(pd.DataFrame({"p": [0.01, 0.2]})))
    'Bonferroni family: m = 2 (2 of 2 cells tested)'
    """
    fams = table.attrs.get("families")
    by = table.attrs.get("family_by", "family")
    usable = isinstance(fams, dict) and fams
    if not usable or sum(f["n_cells"] for f in fams.values()) != len(table):
        fams, by = _families_from_columns(table), "family"  # e.g. attrs lost in concat
        if not fams:
            return ""

    def clause(f: dict) -> str:
        return (
            f"m = {f['family_size']} ({f['n_tested']} of {f['n_cells']} cells tested)"
        )

    items = list(fams.values())
    if len(items) == 1:
        return f"Bonferroni family: {clause(items[0])}"
    if len({(f["family_size"], f["n_tested"], f["n_cells"]) for f in items}) == 1:
        each = (
            "Bonferroni families, each"
            if by == "family"
            else f"Bonferroni family per {by}"
        )
        return f"{each}: {clause(items[0])}"
    return "Bonferroni families: " + "; ".join(
        f"{name}: {clause(f)}" for name, f in fams.items()
    )


def _families_from_columns(table: pd.DataFrame) -> dict[str, dict]:
    """Rebuild ``attrs["families"]`` from the ``family_size`` and ``p`` columns."""
    if "family_size" not in table.columns or "p" not in table.columns:
        return {}
    parts = (
        table.groupby("family", sort=False)
        if "family" in table.columns
        else [("all", table)]
    )
    out = {}
    for name, part in parts:
        sizes = sorted({int(v) for v in part["family_size"].dropna()})
        if sizes:
            out[str(name)] = {
                "family_size": " or ".join(map(str, sizes)),
                "n_tested": int(np.isfinite(part["p"].to_numpy(dtype=float)).sum()),
                "n_cells": len(part),
            }
    return out


def add_adjustments(
    table: pd.DataFrame,
    family: int | str | Sequence[str] | None = None,
    *,
    family_size: int | None = None,
) -> pd.DataFrame:
    r"""Add ``family_size``, ``p_paper``, ``p_bonferroni``, ``p_holm``, ``p_bh``.

    Parameters
    ----------
    table : pandas.DataFrame
        A tidy test table with a ``p`` column (NaN for cells that were not tested).
    family : int, str, sequence of str or None
        ``None``: all rows form one family; a column name or names: one family per
        distinct value (e.g. ``"group1"`` for the baseline tables); an int: the
        fixed multiplier :math:`m` for every row (Holm and BH then treat the table
        as one family of :math:`m` tests).
    family_size : int, optional
        The number of tests :math:`m` of every family, stated explicitly (e.g. 18
        for Fayat et al.'s between-group tables, 6 against baseline,
        :data:`FAYAT_FAMILIES`). Default: the family's *tested* rows — so a family
        silently shrinks when some cells cannot be tested; with ``family_size`` the
        untested cells count as :math:`p = 1` and a family whose tested count
        differs from ``family_size`` is reported by a warning.

    Returns
    -------
    pandas.DataFrame
        A copy with the five columns added (dimensionless, with their long names in
        ``attrs["long_name"]``; the p-value columns have role ``"p-value"``).
        ``attrs["families"]`` maps each family (``"all"`` when the whole table is
        one) to its ``family_size``, ``n_tested`` and ``n_cells``;
        ``attrs["family_size"]`` is the multiplier (an int when every family has the
        same one, else a dict family → m); ``attrs["family_by"]`` the grouping;
        ``attrs["family_caption"]`` says it in words (:func:`family_caption`).

    Raises
    ------
    ValueError
        ``family_size`` below 1, smaller than the tested rows of a family, or
        disagreeing with an integer ``family``.

    Warns
    -----
    RuntimeWarning
        ``family_size`` larger than the tested rows of a family (untested cells).
    """
    out = table.copy().reset_index(drop=True)
    p = out["p"].to_numpy(dtype=float)
    cols = {k: np.full(len(out), np.nan) for k in ("paper", "bonferroni", "holm", "bh")}
    size = np.full(len(out), np.nan)
    groups, fixed = _family_keys(out, family)
    fixed = _family_size(family_size, fixed)
    families, short = {}, []
    for name, rows in groups.items():
        idx = rows[np.isfinite(p[rows])]
        m = fixed if fixed is not None else idx.size
        families[name] = {
            "family_size": int(m),
            "n_tested": int(idx.size),
            "n_cells": int(rows.size),
        }
        if family_size is not None and idx.size > m:
            raise ValueError(
                f"family_size ({m}) is smaller than the {idx.size} tested cells of "
                f"family {name!r}"
            )
        if family_size is not None and idx.size < m:
            short.append(f"{name!r}: {idx.size} of {rows.size} cells")
        if idx.size == 0:
            continue
        size[idx] = m
        for k in cols:
            cols[k][idx] = adjust(p[idx], k, family=m)
    if short:
        warnings.warn(
            f"family_size = {fixed} but fewer cells were tested in family "
            f"{'; '.join(short)}; the untested ones count as p = 1 (Bonferroni over "
            f"{fixed} tests)",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    out["family_size"] = size
    for k, v in cols.items():
        out[f"p_{k}"] = v
    ms = {f["family_size"] for f in families.values()}
    by = "table" if family is None or isinstance(family, (int, np.integer)) else family
    out.attrs.update(
        families=families,
        family_by=by if isinstance(by, str) else " / ".join(map(str, by)),
        family_size=(
            ms.pop()
            if len(ms) == 1
            else {k: f["family_size"] for k, f in families.items()}
        ),
    )
    out.attrs["family_caption"] = family_caption(out)
    return label_columns(
        out,
        units=dict.fromkeys(ADDED_COLUMNS, "1"),
        long_name=ADDED_COLUMNS,
        role={c: "count" if c == "family_size" else "p-value" for c in ADDED_COLUMNS},
    )
