"""Published values to read our tables against: Fayat et al. (2021), Tables A1–A8.

The p-values are copied digit for digit as printed (strings: ``"<0.001"`` is how the
paper prints the smallest ones), Bonferroni-corrected with the paper's uncapped
convention (:func:`tiltlab.stats.paper_bonferroni`). Rows are comparisons, columns the
time points after the lesion. Odd tables (A1, A3, A5, A7) are one-sided Mann–Whitney
tests between groups, even tables (A2, A4, A6, A8) one-sided Wilcoxon signed-rank tests
against each group's baseline; :data:`FAYAT_FEATURE_TABLES` maps each feature to its
pair. Every cell of the eight tables is readable in the paper: none is missing.

References
----------
.. [1] R. Fayat et al., "Inertial Measurement of Head Tilt in Rodents: Principles and
   Applications to Vestibular Research", Sensors 21(18):6318, 2021, Appendix A.7.
   doi:10.3390/s21186318
"""

from __future__ import annotations

import pandas as pd

from .._labels import label_columns
from .multiple import FAYAT_FAMILIES

__all__ = [
    "FAYAT_DESIGN",
    "FAYAT_FEATURE_TABLES",
    "FAYAT_GROUP_SIZES",
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

#: Animals per group as allocated (Fayat et al., §2.4): the most a cell can hold (a
#: session may be missing at some time points).
FAYAT_GROUP_SIZES: dict[str, int] = {
    "Kainate": 20,
    "ShamKainate": 11,
    "Arsanilate": 11,
    "ShamArsanilate": 5,
    "Healthy": 11,
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
    # fraction of the sphere visited during movement,
    # one-sided Mann–Whitney U
    "A3": {
        "Arsanilate vs. Healthy": (
            "3.350",
            "0.002",
            "0.001",
            "4.603",
            "5.394",
            "6.684",
        ),
        "Arsanilate vs. ShamArsanilate": (
            "1.166",
            "0.003",
            "0.016",
            "2.407",
            "5.317",
            "14.032",
        ),
        "ShamArsanilate vs. Healthy": (
            "16.376",
            "16.592",
            "2.407",
            "13.204",
            "5.944",
            "5.951",
        ),
        "Kainate vs. Healthy": ("<0.001", "9.000", "1.617", "3.512", "0.426", "0.449"),
        "Kainate vs. ShamKainate": (
            "<0.001",
            "9.000",
            "7.819",
            "4.985",
            "0.125",
            "1.617",
        ),
        "ShamKainate vs. Healthy": (
            "7.594",
            "8.060",
            "2.641",
            "6.684",
            "8.060",
            "6.684",
        ),
    },
    # fraction of the sphere visited during movement, one-sided Wilcoxon
    # signed rank against baseline
    "A4": {
        "Healthy vs. Healthy baseline": (
            "0.006",
            "0.009",
            "0.442",
            "0.442",
            "0.835",
            "1.239",
        ),
        "Arsanilate vs. Arsanilate baseline": (
            "0.001",
            "0.001",
            "0.003",
            "0.021",
            "0.442",
            "0.721",
        ),
        "ShamArsanilate vs. ShamArsanilate baseline": (
            "0.188",
            "2.438",
            "2.438",
            "5.438",
            "4.688",
            "2.438",
        ),
        "Kainate vs. Kainate baseline": (
            "<0.001",
            "0.126",
            "3.044",
            "2.471",
            "0.863",
            "1.712",
        ),
        "ShamKainate vs. ShamKainate baseline": (
            "0.003",
            "0.009",
            "0.021",
            "0.056",
            "0.442",
            "0.202",
        ),
    },
    # average tilt point angle to xz plane during
    # immobility, one-sided Mann–Whitney U
    "A5": {
        "Arsanilate vs. Healthy": (
            "0.715",
            "<0.001",
            "<0.001",
            "<0.001",
            "<0.001",
            "0.002",
        ),
        "Arsanilate vs. ShamArsanilate": (
            "1.440",
            "0.003",
            "0.029",
            "0.004",
            "0.001",
            "0.016",
        ),
        "ShamArsanilate vs. Healthy": (
            "7.442",
            "5.250",
            "1.990",
            "7.442",
            "4.724",
            "5.250",
        ),
        "Kainate vs. Healthy": ("0.022", "0.192", "0.100", "0.870", "0.112", "0.369"),
        "Kainate vs. ShamKainate": (
            "0.220",
            "15.443",
            "4.005",
            "14.296",
            "5.207",
            "0.596",
        ),
        "ShamKainate vs. Healthy": (
            "3.876",
            "0.015",
            "7.135",
            "0.512",
            "1.909",
            "5.394",
        ),
    },
    # average tilt point angle to xz plane during immobility, one-sided Wilcoxon
    # signed rank against baseline
    "A6": {
        "Healthy vs. Healthy baseline": (
            "3.507",
            "2.695",
            "1.913",
            "3.305",
            "3.899",
            "5.039",
        ),
        "Arsanilate vs. Arsanilate baseline": (
            "0.081",
            "0.001",
            "0.003",
            "0.003",
            "0.003",
            "0.003",
        ),
        "ShamArsanilate vs. ShamArsanilate baseline": (
            "1.312",
            "1.875",
            "0.375",
            "1.875",
            "0.656",
            "2.438",
        ),
        "Kainate vs. Kainate baseline": (
            "<0.001",
            "0.024",
            "0.005",
            "0.018",
            "0.042",
            "0.109",
        ),
        "ShamKainate vs. ShamKainate baseline": (
            "1.239",
            "0.056",
            "0.961",
            "0.618",
            "2.294",
            "4.441",
        ),
    },
    # number of circles per minute, one-sided Mann–Whitney U
    "A7": {
        "Arsanilate vs. Healthy": (
            "14.650",
            "15.706",
            "1.511",
            "0.012",
            "0.003",
            "<0.001",
        ),
        "Arsanilate vs. ShamArsanilate": (
            "17.066",
            "12.185",
            "0.247",
            "0.029",
            "1.341",
            "0.008",
        ),
        "ShamArsanilate vs. Healthy": (
            "3.396",
            "13.413",
            "17.753",
            "17.382",
            "1.945",
            "4.587",
        ),
        "Kainate vs. Healthy": (
            "10.904",
            "11.776",
            "14.627",
            "16.069",
            "10.135",
            "3.373",
        ),
        "Kainate vs. ShamKainate": (
            "8.852",
            "3.643",
            "5.714",
            "8.863",
            "10.135",
            "11.469",
        ),
        "ShamKainate vs. Healthy": (
            "5.394",
            "16.298",
            "16.663",
            "15.865",
            "12.188",
            "3.221",
        ),
    },
    # number of circles per minute, one-sided Wilcoxon
    # signed rank against baseline
    "A8": {
        "Healthy vs. Healthy baseline": (
            "1.731",
            "2.101",
            "3.305",
            "2.493",
            "3.507",
            "5.903",
        ),
        "Arsanilate vs. Arsanilate baseline": (
            "5.096",
            "3.627",
            "0.161",
            "0.015",
            "0.006",
            "0.003",
        ),
        "ShamArsanilate vs. ShamArsanilate baseline": (
            "0.562",
            "2.438",
            "5.438",
            "5.062",
            "0.281",
            "0.938",
        ),
        "Kainate vs. Kainate baseline": (
            "0.990",
            "0.537",
            "1.425",
            "2.324",
            "0.961",
            "2.782",
        ),
        "ShamKainate vs. ShamKainate baseline": (
            "0.961",
            "4.441",
            "4.087",
            "3.305",
            "3.507",
            "3.899",
        ),
    },
}


def fayat_table(name: str, *, columns=FAYAT_TIME_POINTS) -> pd.DataFrame:
    """Return one of Fayat et al.'s printed tables (comparisons × time points).

    Parameters
    ----------
    name : str
        ``"A1"`` … ``"A8"`` (see :data:`FAYAT_FEATURE_TABLES`).
    columns : sequence of str
        Labels for the six time points (default ``1h … 28d``).

    Returns
    -------
    pandas.DataFrame
        The printed m·p values as strings (``"<0.001"`` as printed), one row per
        comparison, one column per time point; labelled (role ``"p-value"``), with
        ``attrs`` ``table``, ``feature``, ``test`` (``"mann-whitney"`` or
        ``"wilcoxon"``), ``family_size`` (the multiplier, :data:`FAYAT_FAMILIES`) and
        ``caption``.

    Examples
    --------
    >>> fayat_table("A2").loc["Kainate vs. Kainate baseline", "1h"]
    '<0.001'
    >>> fayat_table("A7").loc["Arsanilate vs. Healthy", "28d"]
    '<0.001'
    """
    if name not in FAYAT_TABLES:
        raise ValueError(f"name must be one of {sorted(FAYAT_TABLES)}, got {name!r}")
    if len(columns) != len(FAYAT_TIME_POINTS):
        raise ValueError(f"columns must name {len(FAYAT_TIME_POINTS)} time points")
    table = pd.DataFrame.from_dict(
        FAYAT_TABLES[name], orient="index", columns=list(columns)
    )
    out = label_columns(
        table,
        units="1",
        long_name={c: f"p × m (printed), {c}" for c in table.columns},
        role="p-value",
    )
    feature = next(f for f, pair in FAYAT_FEATURE_TABLES.items() if name in pair)
    test = "mann-whitney" if int(name[1:]) % 2 else "wilcoxon"
    out.attrs.update(
        table=name,
        feature=feature,
        test=test,
        family_size=FAYAT_FAMILIES[test],
        caption=(
            f"Fayat et al. (2021), Table {name}: Bonferroni-corrected one-sided "
            f"{'Mann–Whitney' if test == 'mann-whitney' else 'Wilcoxon signed-rank'} "
            f"p-values (× {FAYAT_FAMILIES[test]}, uncapped) of {feature}"
        ),
    )
    return out
