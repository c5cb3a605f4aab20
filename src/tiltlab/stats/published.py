"""Published values to read our tables against: Fayat et al. (2021), Tables A1–A2.

The p-values are copied as printed (strings: ``"<0.001"`` is how the paper prints the
smallest ones), Bonferroni-corrected with the paper's uncapped convention
(:func:`tiltlab.stats.paper_bonferroni`). Rows are comparisons, columns the time points
after the lesion.

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021, Appendix A.7.
   doi:10.3390/s21186318
"""

from __future__ import annotations

import pandas as pd

from .._labels import label_columns

__all__ = [
    "FAYAT_DESIGN",
    "FAYAT_FEATURE_TABLES",
    "FAYAT_TIME_POINTS",
    "FAYAT_TABLES",
    "fayat_table",
]

FAYAT_TIME_POINTS: tuple[str, ...] = ("1h", "1d", "2d", "7d", "14d", "28d")

#: The appendix tables of each feature: (between groups, Mann–Whitney; against
#: baseline, Wilcoxon signed rank).
FAYAT_FEATURE_TABLES: dict[str, tuple[str, str]] = {
    "immobile_fraction": ("A1", "A2"),
    "visited_fraction_moving": ("A3", "A4"),
    "tilt_immobile_sagittal_deg": ("A5", "A6"),
    "circling_index": ("A7", "A8"),
}

#: Fayat et al.'s analysis design (§2.4, §3.4, Tables A1–A8) as keywords of
#: :func:`tiltlab.stats.study_design`: the anaesthesia-only control group, one family
#: per lesion type (lesion vs control, lesion vs its sham, sham vs control) and the
#: one-sided alternatives of their features (lesioned animals more immobile, less
#: mobile, tilted toward the lesion, circling), plus ``focus``, the group of their
#: tilt maps and Fig. A5.
FAYAT_DESIGN: dict = {
    "control": "Healthy",
    "families": {
        "Arsanilate": [
            ("Arsanilate", "Healthy"),
            ("Arsanilate", "ShamArsanilate"),
            ("ShamArsanilate", "Healthy"),
        ],
        "Kainate": [
            ("Kainate", "Healthy"),
            ("Kainate", "ShamKainate"),
            ("ShamKainate", "Healthy"),
        ],
    },
    "directions": {
        "immobile_fraction": "greater",
        "immobile_fraction_auto": "greater",
        "visited_fraction": "less",
        "visited_fraction_moving": "less",
        "tilt_immobile_sagittal_deg": "greater",
        "circling_index": "greater",
    },
    "focus": "Arsanilate",
}

#: Table name → comparison → the six printed p-values (1 h … 28 d).
FAYAT_TABLES: dict[str, dict[str, tuple[str, ...]]] = {
    # fraction of the time spent immobile, one-sided Mann–Whitney U
    "A1": {
        "Arsanilate vs. Healthy": (
            "6.202",
            "<0.001",
            "<0.001",
            "0.790",
            "1.702",
            "2.379",
        ),
        "Arsanilate vs. ShamArsanilate": (
            "1.751",
            "0.003",
            "0.004",
            "5.951",
            "1.945",
            "13.413",
        ),
        "ShamArsanilate vs. Healthy": (
            "16.376",
            "14.032",
            "9.000",
            "5.250",
            "9.349",
            "1.990",
        ),
        "Kainate vs. Healthy": ("0.001", "0.861", "0.089", "1.017", "0.512", "0.714"),
        "Kainate vs. ShamKainate": (
            "0.070",
            "4.500",
            "4.945",
            "14.855",
            "9.853",
            "4.945",
        ),
        "ShamKainate vs. Healthy": (
            "4.991",
            "3.876",
            "0.686",
            "0.321",
            "0.136",
            "1.511",
        ),
    },
    # fraction of the time spent immobile, one-sided Wilcoxon signed-rank vs baseline
    "A2": {
        "Healthy vs. Healthy baseline": (
            "0.003",
            "0.009",
            "0.961",
            "0.126",
            "1.239",
            "0.618",
        ),
        "Arsanilate vs. Arsanilate baseline": (
            "0.001",
            "0.001",
            "0.003",
            "0.006",
            "0.041",
            "0.029",
        ),
        "ShamArsanilate vs. ShamArsanilate baseline": (
            "0.188",
            "0.188",
            "0.562",
            "0.188",
            "3.469",
            "0.188",
        ),
        "Kainate vs. Kainate baseline": ("<0.001",) * 6,
        "ShamKainate vs. ShamKainate baseline": (
            "0.003",
            "0.009",
            "0.202",
            "0.073",
            "0.009",
            "0.249",
        ),
    },
}


def fayat_table(name: str, *, columns=FAYAT_TIME_POINTS) -> pd.DataFrame:
    """Return one of Fayat et al.'s printed tables (comparisons × time points).

    Parameters
    ----------
    name : str
        ``"A1"`` or ``"A2"``.
    columns : sequence of str
        Labels for the six time points (default ``1h … 28d``).

    Returns
    -------
    pandas.DataFrame
        The printed m·p values as strings (``"<0.001"`` as printed), one row per
        comparison, one column per time point; labelled (role ``"p-value"``).

    Examples
    --------
    >>> fayat_table("A2").loc["Kainate vs. Kainate baseline", "1h"]
    '<0.001'
    """
    if name not in FAYAT_TABLES:
        raise ValueError(f"name must be one of {sorted(FAYAT_TABLES)}, got {name!r}")
    if len(columns) != len(FAYAT_TIME_POINTS):
        raise ValueError(f"columns must name {len(FAYAT_TIME_POINTS)} time points")
    table = pd.DataFrame.from_dict(
        FAYAT_TABLES[name], orient="index", columns=list(columns)
    )
    return label_columns(
        table,
        units="1",
        long_name={c: f"p × m (printed), {c}" for c in table.columns},
        role="p-value",
    )
