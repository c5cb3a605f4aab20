"""The design of a study, read from its cohort table and stated choices.

Groups and their order, the control group, time points and the baseline, one-sided test directions and
the families of comparisons (:func:`study_design`).

A chapter or a script states only what the data cannot say (which group is the control,
which direction each test takes); everything else — group names, animals per group, the
order of the time points — comes from the table, so that an analysis written for one
study runs unchanged on another.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
import xarray as xr

from .._labels import label_columns
from .nonparametric import ALTERNATIVES
from .tables import _label_tidy, _timepoint_key, check_cells

__all__ = ["StudyDesign", "design_tables", "session_table", "study_design"]


_SESSION_NAMES = {
    "subject": "subject",
    "group": "group",
    "timepoint": "time point",
    "status": "session status",
    "error": "why the session failed",
}


def session_table(features) -> pd.DataFrame:
    """Return one row per session of a cohort table.

    The row holds the session's ``subject``, ``group``, ``timepoint`` (strings),
    ``status`` (``"ok"`` when absent) and ``error``, indexed by ``session``.

    Parameters
    ----------
    features : xarray.Dataset or pandas.DataFrame
        A cohort feature table (:func:`tiltlab.cohort.run_cohort`), or the same as a
        DataFrame with those columns.

    Returns
    -------
    pandas.DataFrame
        Index ``session``; text columns, labelled (``attrs["long_name"]``).
    """
    need = ["subject", "group", "timepoint"]
    if isinstance(features, xr.Dataset):
        if "session" not in features.dims:
            raise ValueError("not a cohort table: no 'session' dimension")
        missing = [c for c in need if c not in features.variables]
        if missing:
            raise ValueError(f"the cohort table lacks {missing}")
        df = pd.DataFrame(
            {c: features[c].values.astype(str) for c in need},
            index=pd.Index(features["session"].values.astype(str), name="session"),
        )
        if "status" in features.variables:
            df["status"] = features["status"].values.astype(str)
        if "error" in features.variables:
            df["error"] = features["error"].values.astype(str)
    elif isinstance(features, pd.DataFrame):
        missing = [c for c in need if c not in features.columns]
        if missing:
            raise ValueError(f"the cohort table lacks column(s) {missing}")
        df = features[[c for c in need + ["status", "error"] if c in features]].copy()
        for c in need:
            df[c] = df[c].astype(str)
        if "session" in features.columns:
            df.index = pd.Index(features["session"].astype(str), name="session")
    else:
        raise TypeError(
            "features must be a cohort table (xarray.Dataset or pandas.DataFrame), got "
            f"{type(features).__name__}"
        )
    if "status" not in df:
        df["status"] = "ok"
    if "error" not in df:
        df["error"] = ""
    return label_columns(
        df,
        units=dict.fromkeys(df.columns, ""),
        long_name={c: _SESSION_NAMES[c] for c in df.columns},
    )


def _names(given, present: list[str], what: str) -> list[str]:
    """Return the labels ``given``, or every label present.

    ``given`` is a sequence of labels present in the data, in the order wanted; an unknown label is an error naming the known ones.
    """
    if given is None:
        return list(present)
    if isinstance(given, str):
        given = [given]
    given = [str(g) for g in given]
    unknown = [g for g in given if g not in present]
    if unknown:
        raise ValueError(
            f"{what} {unknown} not in the cohort table (its {what}: "
            f"{', '.join(present) or 'none'}); check the spelling"
        )
    if len(set(given)) != len(given):
        raise ValueError(f"{what} lists a label twice: {given}")
    return given


def _default_order(timepoints: list[str]) -> list[str]:
    """Order time points: 'baseline' first, then durations (1h, 2d …) in time order.

    Labels that do not read as durations keep their order of appearance.
    """
    rest = [t for t in timepoints if t != "baseline"]
    try:
        rest.sort(key=_timepoint_key)
    except KeyError:
        pass
    return (["baseline"] if "baseline" in timepoints else []) + rest


@dataclass(frozen=True)
class StudyDesign:
    """A study's design as the analysis uses it (made by :func:`study_design`).

    Attributes
    ----------
    groups : tuple of str
        Groups analysed, in display order.
    control : str
        The group every other group is compared with.
    timepoints : tuple of str
        Time points analysed, in order.
    baseline : str or None
        The time point each group's later sessions are compared with (paired tests, the
        mixed model); None when the study has one time point (between-group tests only).
    directions : dict
        Feature → alternative of its one-sided tests (``"greater"``: the first group, or
        the later time point, tends to be larger); features absent are two-sided.
    families : dict
        Family name → list of ``(group1, group2)`` comparisons; each family is one
        Bonferroni family per feature (its comparisons × the compared time points).
    animals : pandas.DataFrame
        Animals (distinct subjects with a usable session) per group × time point.
    failed : dict
        Sessions that failed in the cohort run → their error; they are left out.
    """

    groups: tuple[str, ...]
    control: str
    timepoints: tuple[str, ...]
    baseline: str | None
    directions: dict[str, str]
    families: dict[str, list[tuple[str, str]]]
    animals: pd.DataFrame = field(compare=False)
    failed: dict[str, str] = field(default_factory=dict, compare=False)

    @property
    def compared_timepoints(self) -> list[str]:
        """Time points of the between-group tests: after the baseline, or the only one."""
        return [t for t in self.timepoints if t != self.baseline]

    @property
    def longitudinal(self) -> bool:
        """True when there is a baseline and at least one later time point."""
        return self.baseline is not None and bool(self.compared_timepoints)

    def direction(self, feature: str) -> str:
        """Return the alternative of ``feature``'s tests (``"two-sided"`` when not stated)."""
        return self.directions.get(feature, "two-sided")

    def comparisons(self) -> list[tuple[str, str]]:
        """Every ``(group1, group2)`` of every family, in order."""
        return [c for comps in self.families.values() for c in comps]

    def family_size(self, name: str) -> int:
        """Count the tests in a family per feature: its comparisons × the compared time points."""
        return len(self.families[name]) * len(self.compared_timepoints)

    def others(self) -> list[str]:
        """Return the groups other than the control, in order."""
        return [g for g in self.groups if g != self.control]

    def describe(self) -> str:
        """Describe the design in words, from the data (group sizes, time points, tests)."""
        sizes = self.animals.max(axis=1)
        groups = ", ".join(
            f"{g} ({int(sizes.get(g, 0))} animal{'s' if sizes.get(g, 0) != 1 else ''})"
            for g in self.groups
        )
        lines = [f"{len(self.groups)} groups: {groups}; control: {self.control}"]
        if self.baseline is None:
            lines.append(
                f"{len(self.timepoints)} time point ({', '.join(self.timepoints)}): "
                "between-group tests only"
            )
        else:
            lines.append(
                f"{len(self.timepoints)} time points: {', '.join(self.timepoints)} "
                f"(baseline: {self.baseline})"
            )
        for name, comps in self.families.items():
            pairs = "; ".join(f"{a} vs. {b}" for a, b in comps)
            n_tp, m = len(self.compared_timepoints), self.family_size(name)
            lines.append(
                f"family {name!r}: {pairs} × {n_tp} time point{'s' if n_tp != 1 else ''}"
                f" = {m} test{'s' if m != 1 else ''} per feature"
            )
        if self.failed:
            lines.append(
                f"{len(self.failed)} session(s) failed in the cohort run and are left "
                f"out: {', '.join(self.failed)}"
            )
        return "\n".join(lines)


def study_design(
    features,
    *,
    groups: Sequence[str] | None = None,
    control: str | None = None,
    timepoints: Sequence[str] | None = None,
    baseline: str | None = "auto",
    directions: Mapping[str, str] | None = None,
    families: Mapping[str, Sequence[Sequence[str]]] | None = None,
) -> StudyDesign:
    """Read the design of a study from its cohort table and the choices the data cannot make.

    Parameters
    ----------
    features : xarray.Dataset or pandas.DataFrame
        The cohort feature table (:func:`tiltlab.cohort.run_cohort`); failed sessions
        (``status != "ok"``) are listed and left out.
    groups : sequence of str, optional
        Groups to analyse, in order; default every group, in the order of the table.
    control : str, optional
        Control group; default the first group.
    timepoints : sequence of str, optional
        Time points to analyse, in order; default every one: ``"baseline"`` first, then
        labels that read as durations (``1h``, ``7d`` …) in time order, others in the
        order of the table.
    baseline : str, None or "auto"
        The reference time point of the paired tests; ``"auto"``: ``"baseline"`` when
        present, else the first time point when there are several; None (or a single
        time point): between-group tests only.
    directions : mapping, optional
        Feature → ``"greater"``, ``"less"`` or ``"two-sided"``.
    families : mapping, optional
        Family name → ``[(group1, group2), ...]``; default one family, every other group
        against the control. Every group must be one of ``groups``.

    Returns
    -------
    StudyDesign

    Raises
    ------
    ValueError
        A group, control or time point not in the table (the message lists those that
        are: a typo never becomes a group of its own), an unknown direction, a family
        naming a group not analysed, fewer than two groups, or two sessions of one
        subject at one time point (pseudo-replication, :func:`check_cells`; failed
        sessions count), naming them.

    Examples
    --------
    >>> import pandas as pd
    >>> from tiltlab.stats import study_design
    >>> table = pd.DataFrame({"subject": ["a", "b", "c", "d"],
    ...                       "group": ["sham", "sham", "lesion", "lesion"],
    ...                       "timepoint": ["d7"] * 4, "x": [1.0, 2.0, 3.0, 4.0]})
    >>> d = study_design(table, control="sham", directions={"x": "greater"})
    >>> d.baseline is None, d.families
    (True, {'vs. sham': [('lesion', 'sham')]})
    """
    table = session_table(features)
    check_cells(table, "the cohort table")
    failed = dict(table.loc[table["status"] != "ok", "error"])
    ok = table[table["status"] == "ok"]
    if ok.empty:
        raise ValueError("the cohort table has no session with status 'ok'")
    present_groups = list(dict.fromkeys(ok["group"]))
    present_tps = _default_order(list(dict.fromkeys(ok["timepoint"])))
    groups_ = _names(groups, present_groups, "groups")
    if len(groups_) < 2:
        raise ValueError(
            f"a group comparison needs at least two groups, the design has {groups_}"
        )
    control_ = groups_[0] if control is None else _names(control, groups_, "groups")[0]
    tps = _names(timepoints, present_tps, "time points")
    if isinstance(baseline, str) and baseline == "auto":
        base = "baseline" if "baseline" in tps else (tps[0] if len(tps) > 1 else None)
    elif baseline is None or len(tps) == 1:
        base = None
    else:
        base = _names(baseline, tps, "time points")[0]
    if base is not None:  # the baseline first
        tps = [base] + [t for t in tps if t != base]
    dirs = {str(k): str(v) for k, v in dict(directions or {}).items()}
    bad = {k: v for k, v in dirs.items() if v not in ALTERNATIVES}
    if bad:
        raise ValueError(
            f"directions {bad}: each must be one of {', '.join(ALTERNATIVES)}"
        )
    if families is None:
        fams = {f"vs. {control_}": [(g, control_) for g in groups_ if g != control_]}
    else:
        fams = {}
        for name, comps in dict(families).items():
            pairs = [tuple(map(str, c)) for c in comps]
            if not pairs or any(len(p) != 2 for p in pairs):
                raise ValueError(
                    f"family {name!r} must list (group1, group2) pairs, got {comps!r}"
                )
            unknown = sorted({g for p in pairs for g in p} - set(groups_))
            if unknown:
                raise ValueError(
                    f"family {name!r} names group(s) {unknown} that are not analysed "
                    f"(groups: {', '.join(groups_)})"
                )
            fams[str(name)] = pairs
    used = ok[ok["group"].isin(groups_) & ok["timepoint"].isin(tps)]
    animals = (
        used.groupby(["group", "timepoint"])["subject"]
        .nunique()
        .unstack(fill_value=0)
        .reindex(index=groups_, columns=tps, fill_value=0)
        .astype(np.int64)
    )
    animals.index.name, animals.columns.name = "group", "time point"
    animals = label_columns(
        animals,
        units="1",
        long_name={t: f"animals at {t}" for t in animals.columns},
    )
    return StudyDesign(
        groups=tuple(groups_),
        control=control_,
        timepoints=tuple(tps),
        baseline=base,
        directions=dirs,
        families=fams,
        animals=animals,
        failed=failed,
    )


def design_tables(
    features,
    feature: str,
    design: StudyDesign,
    *,
    conf_level: float = 0.95,
    family_size: int | None = None,
    baseline_family_size: int | None = None,
    **test_options,
) -> tuple[pd.DataFrame, pd.DataFrame | None]:
    """Compute the rank-test tables of one feature under a design.

    Between groups: one-sided Mann–Whitney tests (the feature's direction) for every
    comparison of every family at each compared time point, adjusted within each family
    (:func:`~tiltlab.stats.between_groups`). Against baseline (a longitudinal design
    only): Wilcoxon signed-rank tests of each group's later time points against its
    baseline (:func:`~tiltlab.stats.against_baseline`).

    Parameters
    ----------
    features : xarray.Dataset or pandas.DataFrame
        The cohort table.
    feature : str
        The feature tested.
    design : StudyDesign
        From :func:`study_design`.
    conf_level : float
        Level of the effect-size intervals.
    family_size : int, optional
        Bonferroni family size of each between-group family (default: the number of
        cells tested in it); stated in the table (``family_size`` column,
        :func:`~tiltlab.stats.family_caption`).
    baseline_family_size : int, optional
        The same for each group's tests against baseline.
    **test_options
        Passed to both tests, e.g. ``method="paper"`` (exact without ties,
        tie-corrected normal approximation with ties, per cell; see
        :func:`~tiltlab.stats.between_groups`).

    Returns
    -------
    between : pandas.DataFrame
        Tidy table, one row per comparison × time point, with a ``family`` column.
    within : pandas.DataFrame or None
        Tidy table against baseline; None for a single time point.
    """
    from .tables import against_baseline, between_groups

    alt = design.direction(feature)
    parts = []
    for name, comps in design.families.items():
        part = between_groups(
            features,
            feature,
            [(a, b, alt) for a, b in comps],
            timepoints=design.compared_timepoints,
            baseline=design.baseline or "",
            conf_level=conf_level,
            family_size=family_size,
            **test_options,
        )
        part.insert(0, "family", name)
        parts.append(part)
    units = parts[0].attrs["units"].get("hl", "")
    between = _label_tidy(pd.concat(parts, ignore_index=True), units)
    within = None
    if design.longitudinal:
        within = against_baseline(
            features,
            feature,
            list(design.groups),
            baseline=design.baseline,
            alternative=alt,
            timepoints=design.compared_timepoints,
            conf_level=conf_level,
            family_size=baseline_family_size,
            **test_options,
        )
    return between, within
