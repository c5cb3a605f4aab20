"""Fayat et al. (2021), Appendix A.7, Tables A1–A8 as transcribed in
:mod:`tiltlab.stats.published`: shapes, labels, spot cells quoted from the paper, and
the arithmetic the printed values must obey (Bonferroni factors, exact lattices)."""

from __future__ import annotations

import numpy as np
import pytest

import tiltlab.stats as S

BETWEEN_ROWS = [
    "Arsanilate vs. Healthy",
    "Arsanilate vs. ShamArsanilate",
    "ShamArsanilate vs. Healthy",
    "Kainate vs. Healthy",
    "Kainate vs. ShamKainate",
    "ShamKainate vs. Healthy",
]
BASELINE_ROWS = [
    f"{g} vs. {g} baseline"
    for g in ("Healthy", "Arsanilate", "ShamArsanilate", "Kainate", "ShamKainate")
]
NAMES = [f"A{i}" for i in range(1, 9)]


def _value(printed: str) -> float:
    """A printed cell as a number ("<0.001" as its bound)."""
    return 0.001 if printed == "<0.001" else float(printed)


@pytest.mark.parametrize("name", NAMES)
def test_every_table_has_the_printed_shape_and_labels(name):
    table = S.fayat_table(name)
    rows = BETWEEN_ROWS if int(name[1:]) % 2 else BASELINE_ROWS
    assert table.shape == (len(rows), 6)
    assert list(table.index) == rows
    assert list(table.columns) == list(S.FAYAT_TIME_POINTS)
    assert table.attrs["role"] == dict.fromkeys(S.FAYAT_TIME_POINTS, "p-value")


@pytest.mark.parametrize("name", NAMES)
def test_every_cell_is_a_printed_number(name):
    """Every cell is readable in the paper: no cell is missing."""
    for printed in S.fayat_table(name).to_numpy().ravel():
        assert printed == "<0.001" or (
            printed.count(".") == 1 and len(printed.split(".")[1]) == 3
        ), printed
        assert _value(printed) >= 0


@pytest.mark.parametrize(
    ("name", "row", "column", "printed"),
    [
        ("A3", "ShamArsanilate vs. Healthy", "1d", "16.592"),
        ("A3", "ShamArsanilate vs. Healthy", "7d", "13.204"),
        ("A3", "Kainate vs. ShamKainate", "1h", "<0.001"),
        ("A4", "ShamArsanilate vs. ShamArsanilate baseline", "14d", "4.688"),
        ("A4", "Kainate vs. Kainate baseline", "2d", "3.044"),
        ("A5", "Arsanilate vs. Healthy", "7d", "<0.001"),
        ("A5", "Kainate vs. ShamKainate", "1d", "15.443"),
        ("A6", "Healthy vs. Healthy baseline", "28d", "5.039"),
        ("A6", "Kainate vs. Kainate baseline", "28d", "0.109"),
        ("A7", "ShamArsanilate vs. Healthy", "2d", "17.753"),
        ("A7", "Arsanilate vs. Healthy", "28d", "<0.001"),
        ("A8", "Healthy vs. Healthy baseline", "28d", "5.903"),
        ("A8", "ShamArsanilate vs. ShamArsanilate baseline", "14d", "0.281"),
    ],
    ids=lambda v: str(v).replace(" ", "_"),
)
def test_spot_cells_read_as_printed(name, row, column, printed):
    """Cells quoted from Fayat et al. (2021), Appendix A.7, Table ``name``."""
    assert S.fayat_table(name).loc[row, column] == printed


def test_table_A3_row_1h_matches_the_paper():
    """Fayat et al. (2021) Table A3, column 1 h, top to bottom."""
    assert S.fayat_table("A3")["1h"].tolist() == [
        "3.350",
        "1.166",
        "16.376",
        "<0.001",
        "<0.001",
        "7.594",
    ]


def test_table_A8_kainate_row_matches_the_paper():
    """Fayat et al. (2021) Table A8, Kainate vs. Kainate baseline, 1 h … 28 d."""
    row = S.fayat_table("A8").loc["Kainate vs. Kainate baseline"].tolist()
    assert row == ["0.990", "0.537", "1.425", "2.324", "0.961", "2.782"]


@pytest.mark.parametrize("name", NAMES)
def test_fayat_table_states_feature_test_and_family(name):
    table = S.fayat_table(name)
    between = int(name[1:]) % 2 == 1
    assert table.attrs["table"] == name
    assert table.attrs["test"] == ("mann-whitney" if between else "wilcoxon")
    assert table.attrs["family_size"] == (18 if between else 6)
    assert name in S.FAYAT_FEATURE_TABLES[table.attrs["feature"]]
    assert f"Table {name}" in table.attrs["caption"]


@pytest.mark.parametrize("name", NAMES)
def test_printed_values_stay_below_their_bonferroni_factor(name):
    """m·p < m for every cell: 18 between groups, 6 against baseline (the families
    inferred in :mod:`tiltlab.stats.multiple` hold for all eight tables)."""
    table = S.fayat_table(name)
    values = np.vectorize(_value)(table.to_numpy())
    assert values.max() < table.attrs["family_size"]


@pytest.mark.parametrize("name", ["A2", "A4", "A6", "A8"])
def test_sham_arsanilate_baseline_rows_sit_on_the_signed_rank_lattice(name):
    """The ShamArsanilate group has 5 animals (Fayat et al., §2.4): its exact one-sided
    signed-rank p-values are k/2⁵, or k/2⁶ with one more pair, times the family of 6."""
    row = S.fayat_table(name).loc["ShamArsanilate vs. ShamArsanilate baseline"]
    lattice = {f"{6 * p:.3f}" for n in (5, 6) for p in S.signed_rank_p_lattice(n)["p"]}
    assert set(row) <= lattice


def test_unknown_table_name_is_refused_by_name():
    with pytest.raises(ValueError, match="name must be one of"):
        S.fayat_table("A9")


def test_group_sizes_are_those_of_the_paper():
    """Fayat et al. (2021) §2.4: n = 20, 11, 11, 5, 11 (58 rats in all)."""
    assert S.FAYAT_GROUP_SIZES == {
        "Kainate": 20,
        "ShamKainate": 11,
        "Arsanilate": 11,
        "ShamArsanilate": 5,
        "Healthy": 11,
    }
    assert sum(S.FAYAT_GROUP_SIZES.values()) == 58
