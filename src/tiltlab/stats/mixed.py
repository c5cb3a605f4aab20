r"""Longitudinal linear mixed model of one feature.

Group × time with a random intercept per subject, fitted by statsmodels ``MixedLM`` with its convergence checked.

Model
-----
For subject :math:`s` in group :math:`g(s)` at time point :math:`t`,

.. math::
    y_{st} = \beta_0 + \alpha_{g(s)} + \tau_t + (\alpha\tau)_{g(s)t} + b_s
             + \varepsilon_{st},
    \qquad b_s \sim N(0, \sigma_b^2),\ \varepsilon_{st} \sim N(0, \sigma^2),

i.e. ``feature ~ C(group) * C(timepoint) + (1 | subject)``, with treatment coding
against a reference group and the baseline time point: :math:`(\alpha\tau)_{gt}` is the
change from baseline to :math:`t` in group :math:`g` minus the same change in the
reference group (a difference in differences). Fitted by REML (default).

Convergence
-----------
The optimisers are tried in turn (default L-BFGS, then BFGS, Powell, Nelder–Mead) until
one converges; a fit counts as converged when statsmodels reports it and every
fixed-effect standard error is finite (a singular Hessian leaves them NaN). Every
warning raised during the fits is captured and returned; when no optimiser converges
the result says so (``converged=False``) and a :class:`RuntimeWarning` is issued rather
than returning silently.

References
----------
.. [1] N. M. Laird and J. H. Ware, "Random-effects models for longitudinal data",
   Biometrics 38:963–974, 1982. doi:10.2307/2529876
.. [2] M. J. Lindstrom and D. M. Bates, "Newton–Raphson and EM algorithms for linear
   mixed-effects models for repeated-measures data", J. Am. Stat. Assoc.
   83:1014–1022, 1988. doi:10.1080/01621459.1988.10478693
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
import statsmodels.formula.api as smf
from scipy.stats import norm

from .._stack import user_stacklevel
from .._labels import label_columns

__all__ = ["MixedModelResult", "mixed_model"]

_OPTIMIZERS = ("lbfgs", "bfgs", "powell", "nm")


@dataclass
class MixedModelResult:
    r"""A fitted (or failed) mixed model.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per fixed effect: ``term``, ``estimate``, ``se``, ``z``, ``p``,
        ``ci_low``, ``ci_high``, and ``converged`` (the same flag on every row).
    converged : bool
        Whether an optimiser converged with finite standard errors.
    optimizer : str
        The optimiser of the returned fit (the last one tried if none converged).
    warnings : list of str
        Distinct warning messages captured over all attempts, prefixed by optimiser.
    group_var, residual_var : float
        :math:`\\sigma_b^2` and :math:`\\sigma^2` (NaN if the fit failed).
    formula : str
        The fixed-effects formula.
    result : object
        The statsmodels results object (None if every attempt raised).
    """

    table: pd.DataFrame
    converged: bool
    optimizer: str
    warnings: list[str] = field(default_factory=list)
    group_var: float = float("nan")
    residual_var: float = float("nan")
    formula: str = ""
    result: Any = None


_MIXED_NAMES = {
    "term": "fixed effect",
    "estimate": "estimate",
    "se": "standard error",
    "z": "Wald z",
    "p": "p (Wald, two-sided)",
    "ci_low": "95% interval, lower bound",
    "ci_high": "95% interval, upper bound",
    "converged": "converged",
}


def _label_fixed(table: pd.DataFrame, units: str) -> pd.DataFrame:
    """Label the fixed-effects table with units (those of the response) and long names."""
    same = ("estimate", "se", "ci_low", "ci_high")
    return label_columns(
        table,
        units={
            c: units if c in same else ("1" if c in ("z", "p") else "") for c in table
        },
        long_name=_MIXED_NAMES,
        role={"p": "p-value"},
    )


def _q(name: str) -> str:
    return f"Q({name!r})"


def mixed_model(
    data: pd.DataFrame,
    feature: str,
    *,
    group: str = "group",
    timepoint: str = "timepoint",
    subject: str = "subject",
    reference_group: str | None = None,
    baseline: str | None = "baseline",
    reml: bool = True,
    optimizers: Sequence[str] = _OPTIMIZERS,
) -> MixedModelResult:
    r"""Fit ``feature ~ C(group) * C(timepoint) + (1 | subject)``.

    Parameters
    ----------
    data : pandas.DataFrame
        Long table, one row per session (e.g. from :func:`tiltlab.stats.long_table`);
        rows with a missing ``feature`` are dropped.
    feature : str
        Column of the response.
    group, timepoint, subject : str
        Column names.
    reference_group : str, optional
        Reference level of the group factor (default: the first in sorted order).
    baseline : str, optional
        Reference time point (default ``"baseline"`` when present).
    reml : bool
        REML (default) or maximum likelihood.
    optimizers : sequence of str
        ``MixedLM.fit`` methods tried in order until one converges.

    Returns
    -------
    MixedModelResult
        The tidy fixed-effects table and the ``converged`` flag.

    Raises
    ------
    ValueError
        Missing columns, fewer than 2 subjects, or an empty optimiser list.
    """
    for c in (feature, group, timepoint, subject):
        if c not in data.columns:
            raise ValueError(
                f"data has no column {c!r} (columns: {list(data.columns)})"
            )
    if not optimizers:
        raise ValueError("optimizers must name at least one MixedLM.fit method")
    d = data[[feature, group, timepoint, subject]].copy()
    d = d[np.isfinite(pd.to_numeric(d[feature], errors="coerce"))]
    d[feature] = d[feature].astype(float)
    if d[subject].nunique() < 2:
        raise ValueError(f"data needs at least 2 subjects, got {d[subject].nunique()}")
    for c in (group, timepoint):
        d[c] = d[c].astype(str)
    g_ref = (
        reference_group if reference_group is not None else sorted(d[group].unique())[0]
    )
    levels = list(dict.fromkeys(d[timepoint]))
    t_ref = (
        baseline if baseline is not None and baseline in levels else sorted(levels)[0]
    )
    formula = (
        f"{_q(feature)} ~ C({_q(group)}, Treatment(reference={str(g_ref)!r}))"
        f" * C({_q(timepoint)}, Treatment(reference={str(t_ref)!r}))"
    )
    captured: list[str] = []
    best = None
    used = optimizers[-1]
    converged = False
    for opt in optimizers:
        with warnings.catch_warnings(record=True) as w, np.errstate(all="ignore"):
            warnings.simplefilter("always")
            try:
                res = smf.mixedlm(formula, d, groups=d[subject]).fit(
                    reml=reml, method=[opt]
                )
            except (np.linalg.LinAlgError, ValueError) as exc:
                res = None
                captured.append(f"{opt}: {type(exc).__name__}: {exc}")
        for msg in dict.fromkeys(str(x.message) for x in w):
            captured.append(f"{opt}: {msg}")
        if res is None:
            continue
        best, used = res, opt
        ok = bool(res.converged) and bool(np.all(np.isfinite(np.asarray(res.bse_fe))))
        if ok:
            converged = True
            break
    if not converged:
        warnings.warn(
            f"MixedLM for {feature!r} did not converge with any of "
            f"{list(optimizers)}; see MixedModelResult.warnings",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    given = data.attrs.get("units", {})
    units = str(given.get(feature, "")) if isinstance(given, dict) else ""
    if best is None:
        empty = _label_fixed(pd.DataFrame(columns=list(_MIXED_NAMES)), units)
        return MixedModelResult(empty, False, used, captured, formula=formula)
    fe = best.fe_params
    with np.errstate(all="ignore"):
        se = np.asarray(best.bse_fe, dtype=float)
        z = fe.to_numpy() / se
        p = 2 * norm.sf(np.abs(z))
        zc = norm.isf(0.025)
    table = pd.DataFrame(
        {
            "term": [_tidy_term(t, group, timepoint) for t in fe.index],
            "estimate": fe.to_numpy(),
            "se": se,
            "z": z,
            "p": p,
            "ci_low": fe.to_numpy() - zc * se,
            "ci_high": fe.to_numpy() + zc * se,
            "converged": converged,
        }
    )
    table = _label_fixed(table, units)
    table.attrs.update(
        converged=converged, optimizer=used, reference_group=g_ref, baseline=t_ref
    )
    cov_re = np.asarray(best.cov_re, dtype=float)
    return MixedModelResult(
        table,
        converged,
        used,
        captured,
        float(cov_re.ravel()[0]) if cov_re.size else float("nan"),
        float(best.scale),
        formula,
        best,
    )


def _tidy_term(term: str, group: str, timepoint: str) -> str:
    """``C(Q('group'), Treatment(...))[T.B]:C(...)[T.7d]`` → ``group[B]:timepoint[7d]``."""
    parts = []
    for piece in term.split(":"):
        if "[T." in piece:
            level = piece.split("[T.", 1)[1].rstrip("]")
            name = group if _q(group) in piece else timepoint
            parts.append(f"{name}[{level}]")
        else:
            parts.append(piece)
    return ":".join(parts)
