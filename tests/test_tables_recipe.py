"""The table recipe: headers with units, rounding by quantity, p-values written once."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from tiltlab import plot
from tiltlab import stats as S
from tiltlab._labels import label_columns
from tiltlab.plot.tables import DECIMALS, MISSING


def _frame():
    df = pd.DataFrame(
        {
            "tilt": [1.23456, np.nan],
            "acc": [0.987654, 1.0],
            "acc_mg": [12.345, 3.0],
            "rate": [10.0, 2.555],
            "f": [12.34, 1.0],
            "ratio": [0.123456, 2.0],
            "n": [10, 200],
            "p_holm": [0.0002, 0.04321],
            "label": ["a", None],
        }
    )
    return label_columns(
        df,
        units={
            "tilt": "deg",
            "acc": "g",
            "acc_mg": "mg",
            "rate": "deg/s",
            "f": "Hz",
            "ratio": "1",
            "n": "1",
            "p_holm": "1",
            "label": "",
        },
        long_name={
            "tilt": "tilt error",
            "acc": "acceleration",
            "acc_mg": "offset",
            "rate": "angular speed",
            "f": "frequency",
            "ratio": "ratio",
            "n": "samples",
            "p_holm": "p, Holm",
            "label": "label",
        },
    )


def test_headers_carry_long_names_and_units():
    out = plot.table(_frame(), output="frame")
    assert list(out.columns) == [
        "tilt error [deg]",
        "acceleration [g]",
        "offset [mg]",
        "angular speed [deg/s]",
        "frequency [Hz]",
        "ratio",
        "samples",
        "p, Holm",
        "label",
    ]


def test_rounding_by_units_pvalues_once_and_missing_values():
    out = plot.table(_frame(), output="frame")
    assert out["tilt error [deg]"].tolist() == ["1.23", MISSING]
    assert out["acceleration [g]"].tolist() == ["0.988", "1.000"]
    assert out["offset [mg]"].tolist() == ["12.3", "3.0"]
    assert out["angular speed [deg/s]"].tolist() == ["10.00", "2.56"]
    assert out["frequency [Hz]"].tolist() == ["12.3", "1.0"]
    assert out["ratio"].tolist() == ["0.123", "2.000"]
    assert out["samples"].tolist() == ["10", "200"]
    assert out["p, Holm"].tolist() == ["<0.001", "0.043"]
    assert out["label"].tolist() == ["a", MISSING]
    assert DECIMALS["deg"] == 2 and DECIMALS["g"] == 3 and DECIMALS["mg"] == 1


def test_decimals_override_and_unknown_units():
    df = label_columns(
        pd.DataFrame({"a": [1.23456], "b": [0.000123456]}),
        units={"a": "deg", "b": "deg/√s"},
    )
    out = plot.table(df, decimals={"a": 4}, output="frame")
    assert out.iloc[0].tolist() == ["1.2346", "0.000123"]  # 3 significant digits
    assert plot.table(df, decimals=1, output="frame").iloc[0].tolist() == ["1.2", "0.0"]


def test_pvalue_columns_by_name_or_role():
    df = pd.DataFrame({"p": [0.5, 0.00001], "p (m·p)": [2.0, 0.0001], "ps": [0.25, 1]})
    out = plot.table(df, output="frame")
    assert out["p"].tolist() == ["0.500", "<0.001"]
    assert out["p (m·p)"].tolist() == ["2.000", "<0.001"]
    assert out["ps"].tolist() == ["0.25", "1"]  # not a p-value: no units, 3 digits
    marked = label_columns(pd.DataFrame({"alpha_m": [0.0001]}), role="p-value")
    assert plot.table(marked, output="frame")["alpha_m"].tolist() == ["<0.001"]


def test_missing_attrs_fall_back_to_column_names():
    df = pd.DataFrame({"x": [1.5, 2.25], "k": [1, 2]})
    out = plot.table(df, output="frame")
    assert list(out.columns) == ["x", "k"]
    assert out["x"].tolist() == ["1.5", "2.25"]
    assert out["k"].tolist() == ["1", "2"]


def test_dataset_input_reads_variable_attrs():
    ds = xr.Dataset(
        {
            "median": (
                ("speed",),
                [0.5, 1.234],
                {"units": "deg", "long_name": "median"},
            ),
            "n": (("speed",), [3, 4], {"units": "1", "long_name": "samples"}),
        },
        coords={"speed": ("speed", [25.0, 75.0], {"units": "deg/s"})},
    )
    out = plot.table(ds, output="frame")
    assert list(out.columns) == ["median [deg]", "samples"]
    assert out.index.name == "speed [deg/s]"
    assert list(out.index) == ["25.00", "75.00"]
    assert out["median [deg]"].tolist() == ["0.50", "1.23"]
    da = xr.DataArray([1.0, 2.0], dims="x", name="d", attrs={"units": "s"})
    assert list(plot.table(da, output="frame").columns) == ["d [s]"]


def test_absent_result_and_styler_output():
    empty = plot.table(None)
    assert "no result" in empty.to_html()
    styled = plot.table(_frame(), caption="Errors")
    html = styled.to_html()
    assert "Errors" in html and "tilt error [deg]" in html and "&lt;0.001" in html
    rows = pd.DataFrame({"v": [0.25]}, index=["fraction < 12 deg/s"])
    assert "fraction &lt; 12 deg/s" in plot.table(rows).to_html()
    with pytest.raises(ValueError, match="output"):
        plot.table(_frame(), output="latex")
    with pytest.raises(TypeError):
        plot.table([1, 2, 3])


def test_a_tidy_test_table_renders_without_chapter_formatting():
    rng = np.random.default_rng(1)
    df = pd.DataFrame(
        {
            "subject": [f"s{i}" for i in range(10)],
            "group": ["a"] * 5 + ["b"] * 5,
            "timepoint": ["7d"] * 10,
            "x": rng.normal(size=10),
        }
    )
    df.attrs["units"] = {"x": "deg"}
    tidy = S.between_groups(df, "x", [("a", "b", "greater")])
    out = plot.table(tidy, output="frame")
    assert out["n (group 1)"].tolist() == ["5"]
    assert out["family size m"].tolist() == ["1"]
    assert out["Hodges–Lehmann shift [deg]"].str.match(r"^-?\d+\.\d\d$").all()


def test_a_two_dimensional_dataarray_renders_as_a_matrix():
    da = xr.DataArray(
        [[0.5, 1.234], [2.0, np.nan]],
        dims=("estimator", "speed"),
        coords={
            "estimator": ["a", "b"],
            "speed": ("speed", [25.0, 75.0], {"units": "deg/s"}),
        },
        attrs={"units": "deg", "long_name": "median tilt error"},
    )
    out = plot.table(da, output="frame")
    assert out.loc["a"].tolist() == ["0.50", "1.23"]
    assert out.loc["b"].tolist() == ["2.00", MISSING]
    assert out.columns.name == "median tilt error [deg], by speed [deg/s]"
    assert list(out.columns) == ["25.00", "75.00"]
    assert out.index.name == "estimator"


def test_long_definitions_go_to_the_caption():
    import pandas as pd

    from tiltlab import plot
    from tiltlab._labels import label_columns

    definition = "fraction of time immobile (angular speed below 12 deg/s, merged)"
    df = label_columns(
        pd.DataFrame({"immobile_fraction": [0.25], "rmse": [1.0]}),
        units={"immobile_fraction": "1", "rmse": "deg"},
        long_name={"immobile_fraction": definition, "rmse": "tilt RMSE"},
    )
    assert list(plot.table(df, output="frame").columns) == [
        "immobile_fraction",
        "tilt RMSE [deg]",
    ]
    html = plot.table(df, caption="Sessions").to_html()
    assert f"Sessions. immobile_fraction: {definition}" in html
