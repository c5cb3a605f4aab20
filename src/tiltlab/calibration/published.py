r"""Published gyroscope-drift numbers of LaCanna (2018), transcribed for recomputation.

LaCanna's thesis [1]_ (Results, "Baseline Correction", Tables 2–4; the Results section
starts on p. 10 of the thesis) measured the static drift rate of two MetaWear C-Pro
gyroscopes (devices 1 and 2, serial numbers 00C08D and 00C500): 30-s recordings, 9–10
back-to-back runs per row, the device flat on a table (position 0°) or strapped to a
vertical surface (90°), on two dates two weeks apart (Table 2: 22 February 2018,
Table 3: 8 March 2018). The text below the tables then summarises them by six rates
and their one-hour drifts (:data:`LACANNA_REPORTED`). :func:`lacanna_drift_summary`
recomputes those six rates from the tables, so that a reader can see which summaries
the tables support.

The tables are transcribed as printed (Table 3's device 2, y, 0° standard deviation
is printed with one more digit than the others, 0.003021 °/s). Table 4 gives the
integrated angle after one hour of one static device (which one is not stated) without
correction, with a prior average slope removed and with a whole-record linear fit
removed.

Beyond the drift tables, :data:`LACANNA_TABLE5` holds the angle changes measured after
repeated 1-rad rotations of one axis at a time on a robotic arm (Barrett WAM), and
:data:`LACANNA_TABLE6` the time differences between matching acceleration peaks of a
MetaWear and an Arduino-driven sensor; :func:`lacanna_table5_summary` and
:func:`lacanna_lag_summary` recompute the summaries printed in the text from them.
:data:`LACANNA_BACK_TO_BACK` holds the range of back-to-back standard deviations and the
one-hour drifts the Discussion derives from it.

References
----------
.. [1] C. Q. LaCanna, "Inertial measurement units for tracking human pose and motions:
   testing and calibration", MSc thesis, Rutgers, The State University of New Jersey,
   2018, Tables 2–6, the paragraph after Table 3 and the Discussion.
"""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd

__all__ = [
    "LACANNA_TABLES",
    "LACANNA_TABLE4",
    "LACANNA_REPORTED",
    "lacanna_drift_summary",
    "LACANNA_TABLE5",
    "LACANNA_TABLE6",
    "LACANNA_TABLE5_REPORTED",
    "LACANNA_TABLE6_REPORTED",
    "LACANNA_BACK_TO_BACK",
    "lacanna_table5_summary",
    "lacanna_lag_summary",
]


def _tables(tables: dict[tuple[int, str], list[tuple]]) -> pd.DataFrame:
    # one row per table, date, device, axis and position; each table (number, date)
    # lists runs (device, position, iterations, x/y/z means, x/y/z SDs)
    rows = [
        (table, date, device, axis, position, 30.0, iterations, mean, sd)
        for (table, date), runs in tables.items()
        for device, position, iterations, means, sds in runs
        for axis, mean, sd in zip("xyz", means, sds)
    ]
    columns = ["table", "date", "device", "axis", "position_deg", "duration_s"]
    return pd.DataFrame(
        rows, columns=[*columns, "iterations", "mean_deg_s", "sd_deg_s"]
    )


#: Tables 2 and 3: mean ± SD drift rate (°/s) of 30-s static runs, one row per date,
#: device, axis and position (24 rows).
LACANNA_TABLES = _tables(
    {
        (2, "2018-02-22"): [
            (1, 0, 9, (0.29266, -0.94509, 0.82520), (0.00258, 0.00577, 0.00225)),
            (1, 90, 10, (0.32767, -0.92189, 0.82041), (0.00658, 0.00831, 0.00335)),
            (2, 0, 10, (-0.17152, -0.24403, 0.56894), (0.00761, 0.00798, 0.00460)),
            (2, 90, 10, (-0.17172, -0.26093, 0.57133), (0.00708, 0.00356, 0.00262)),
        ],
        (3, "2018-03-08"): [
            (1, 0, 10, (0.29473, -0.93504, 0.77847), (0.00268, 0.00562, 0.00451)),
            (1, 90, 10, (0.29408, -0.95385, 0.77228), (0.00220, 0.00846, 0.00145)),
            (2, 0, 10, (-0.14406, -0.26186, 0.56432), (0.00819, 0.003021, 0.00592)),
            (2, 90, 10, (-0.14223, -0.28351, 0.56147), (0.00270, 0.00357, 0.00382)),
        ],
    }
)

#: Table 4: integrated angle (°) after ``final_time_s`` of one static device, per axis:
#: raw, with a prior average slope removed, with a whole-record linear fit removed.
LACANNA_TABLE4 = pd.DataFrame(
    {
        "final_time_s": {"x": 3604.0, "y": 3604.0, "z": 3604.0},
        "raw_deg": {"x": 1424.0, "y": -3672.0, "z": 2997.0},
        "prior_average_deg": {"x": 438.5, "y": -574.0, "z": -35.23},
        "linear_fit_deg": {"x": -0.2048, "y": 2.463, "z": -1.768},
    }
).rename_axis("axis")

#: The six summary rates of the text after Table 3 (°/s) and the one-hour drifts it
#: prints for them (°/h).
LACANNA_REPORTED = pd.DataFrame(
    {
        "rate_deg_s": {
            "largest drift": 0.95385,
            "axis to axis": 1.2316,
            "device to device": 0.4562,
            "back-to-back SD": 0.004718,
            "0 vs 90 deg": 0.0112,
            "two weeks": 0.0237,
        },
        "per_hour_deg": {
            "largest drift": 3433.86,
            "axis to axis": 4433.76,
            "device to device": 1642.32,
            "back-to-back SD": 16.986,
            "0 vs 90 deg": 40.32,
            "two weeks": 85.32,
        },
    }
)


def lacanna_drift_summary(tables: pd.DataFrame | None = None) -> pd.Series:
    """Recompute LaCanna's six summary drift rates (°/s) from his Tables 2 and 3.

    Each "average difference" is read as the mean absolute difference of table means
    over every pair that differs in one factor only:

    * ``"largest drift"``: the largest absolute mean rate;
    * ``"axis to axis"``: the three axis pairs (x–y, x–z, y–z) of the same device,
      position and date (24 differences);
    * ``"device to device"``: the same axis, position and date on devices 1 and 2 (12);
    * ``"back-to-back SD"``: the mean of the 24 run-to-run standard deviations;
    * ``"0 vs 90 deg"``: the same device, axis and date at 0° and 90° (12);
    * ``"two weeks"``: the same device, axis and position in Tables 2 and 3 (12).

    Parameters
    ----------
    tables : DataFrame, optional
        Rows with columns ``table``, ``device``, ``axis``, ``position_deg``,
        ``mean_deg_s`` and ``sd_deg_s``; default :data:`LACANNA_TABLES`.

    Returns
    -------
    pandas.Series
        The six rates (°/s), indexed like :data:`LACANNA_REPORTED`.
    """
    t = LACANNA_TABLES if tables is None else tables
    m = t.set_index(["table", "device", "position_deg", "axis"])["mean_deg_s"]
    if not m.index.is_unique:
        raise ValueError(
            "tables must have one row per table, device, position and axis"
        )

    def mean_abs_diff(level: str) -> float:
        others = [n for n in m.index.names if n != level]
        diffs = []
        for _, grp in m.groupby(level=others):
            v = grp.to_numpy()
            diffs += [abs(a - b) for a, b in itertools.combinations(v, 2)]
        return float(np.mean(diffs))

    return pd.Series(
        {
            "largest drift": float(m.abs().max()),
            "axis to axis": mean_abs_diff("axis"),
            "device to device": mean_abs_diff("device"),
            "back-to-back SD": float(t["sd_deg_s"].mean()),
            "0 vs 90 deg": mean_abs_diff("position_deg"),
            "two weeks": mean_abs_diff("table"),
        },
        name="rate_deg_s",
    )


def _labelled(
    df: pd.DataFrame, units: dict, long_name: dict, title: str
) -> pd.DataFrame:
    # column attrs as the package's result tables carry them
    df.attrs = {"title": title, "units": units, "long_name": long_name}
    return df


#: Table 5: angle change (°) measured after each of five repeated 1-rad rotations about
#: one axis at a time (robotic arm; drift removed in post-processing), as printed.
LACANNA_TABLE5 = _labelled(
    pd.DataFrame(
        {
            "x_deg": [56.26, 56.52, 56.57, 56.49, 56.5],
            "y_deg": [-55.69, -55.44, -55.43, -55.36, -55.4],
            "z_deg": [56.17, 56.25, 56.35, 56.35, 56.27],
        },
        index=pd.RangeIndex(1, 6, name="rotation"),
    ),
    {"x_deg": "deg", "y_deg": "deg", "z_deg": "deg"},
    {
        "x_deg": "angle change after a 1-rad rotation about x",
        "y_deg": "angle change after a 1-rad rotation about y",
        "z_deg": "angle change after a 1-rad rotation about z",
    },
    "LaCanna (2018) Table 5",
)

#: The Discussion's summary of Table 5: the range of the measured changes (°), the
#: nominal radian (°) and the largest difference between readings of one axis (°).
LACANNA_TABLE5_REPORTED = pd.Series(
    {
        "smallest change": 55.36,
        "largest change": 56.57,
        "one radian": 57.3,
        "largest spread": 0.33,
    },
    name="deg",
)


def _table6() -> pd.DataFrame:
    rows = [  # run, axis, MetaWear peak (s), toothbrush peak (s), printed difference (s)
        (1, "x", 10.4, 10.75, 0.35),
        (1, "y", 7.68, 8.0, 0.32),
        (1, "z", 6.76, 7.062, 0.302),
        (2, "x", 5.82, 6.098, 0.278),
        (2, "y", 4.8, 5.060, 0.26),
        (2, "z", 2.94, 3.187, 0.247),
        (3, "x", 5.12, 5.4, 0.28),
        (3, "y", 3.1, 3.355, 0.255),
        (3, "z", 1.68, 1.917, 0.237),
        (4, "x", 5.7, 6.033, 0.333),
        (4, "y", 4.28, 4.627, 0.347),
        (4, "z", 1.66, 1.984, 0.324),
        (5, "x", 3.18, 3.489, 0.309),
        (5, "y", 5.2, 5.531, 0.331),
        (5, "z", 2.5, 2.821, 0.321),
    ]
    cols = ["run", "axis", "metawear_s", "toothbrush_s", "difference_s"]
    return _labelled(
        pd.DataFrame(rows, columns=cols),
        {
            "run": "1",
            "axis": "1",
            "metawear_s": "s",
            "toothbrush_s": "s",
            "difference_s": "s",
        },
        {
            "run": "recording run",
            "axis": "accelerometer axis of the matched peak",
            "metawear_s": "peak time on the MetaWear clock",
            "toothbrush_s": "peak time on the Arduino (toothbrush) clock",
            "difference_s": "printed time difference",
        },
        "LaCanna (2018) Table 6",
    )


#: Table 6: times (s) of matching acceleration peaks in a MetaWear C-Pro and the
#: Arduino-driven sensor of an instrumented toothbrush, 5 runs × 3 axes, as printed.
LACANNA_TABLE6 = _table6()

#: The printed summary of Table 6: mean ± SD (s) of the 15 time differences.
LACANNA_TABLE6_REPORTED = pd.Series({"mean": 0.2996, "sd": 0.0374, "n": 15.0}, name="s")

#: The Discussion's range of back-to-back standard deviations (°/s) and the one-hour
#: shifts (°/h) it prints for them.
LACANNA_BACK_TO_BACK = pd.DataFrame(
    {
        "rate_deg_s": {"smallest": 0.00145, "largest": 0.00846},
        "per_hour_deg": {"smallest": 5.22, "largest": 30.456},
    }
)


def lacanna_table5_summary(table: pd.DataFrame | None = None) -> pd.Series:
    """Recompute the Discussion's summary of LaCanna's Table 5 (1-rad rotations).

    Parameters
    ----------
    table : DataFrame, optional
        One column of angle changes (°) per axis, one row per rotation; default
        :data:`LACANNA_TABLE5`.

    Returns
    -------
    pandas.Series
        In degrees: ``"smallest change"`` and ``"largest change"`` (of the absolute
        changes), ``"one radian"`` (180/π), ``"largest shortfall"`` (one radian minus
        the smallest change) and ``"largest spread"`` (the largest max − min of one
        axis), with ``"spread x"``, ``"spread y"``, ``"spread z"`` per column.

    Examples
    --------
    >>> from tiltlab.calibration.published import lacanna_table5_summary
    >>> round(float(lacanna_table5_summary()["largest spread"]), 2)
    0.33
    """
    t = LACANNA_TABLE5 if table is None else table
    v = np.abs(t.to_numpy(dtype=float))
    if v.ndim != 2 or v.shape[0] < 2 or not np.all(np.isfinite(v)):
        raise ValueError(
            "table must hold finite angle changes, at least two rotations per column"
        )
    spread = v.max(axis=0) - v.min(axis=0)
    rad = float(np.degrees(1.0))
    out = {
        "smallest change": float(v.min()),
        "largest change": float(v.max()),
        "one radian": rad,
        "largest shortfall": rad - float(v.min()),
        "largest spread": float(spread.max()),
    }
    out.update({f"spread {str(c)[0]}": float(s) for c, s in zip(t.columns, spread)})
    return pd.Series(out, name="deg")


def lacanna_lag_summary(table: pd.DataFrame | None = None) -> pd.Series:
    """Recompute the mean ± SD lag of LaCanna's Table 6 from its peak times.

    The lag of each matched peak is ``toothbrush_s − metawear_s``; the SD is the sample
    standard deviation (``ddof=1``), which reproduces the printed 0.0374 s.

    Parameters
    ----------
    table : DataFrame, optional
        Columns ``metawear_s`` and ``toothbrush_s`` (s), plus ``difference_s`` (the
        printed differences); default :data:`LACANNA_TABLE6`.

    Returns
    -------
    pandas.Series
        ``"mean"``, ``"sd"`` (s) and ``"n"`` of the recomputed differences, and
        ``"max |recomputed - printed|"`` (s).

    Examples
    --------
    >>> from tiltlab.calibration.published import lacanna_lag_summary
    >>> round(float(lacanna_lag_summary()["mean"]), 4)
    0.2996
    """
    t = LACANNA_TABLE6 if table is None else table
    missing = {"metawear_s", "toothbrush_s", "difference_s"} - set(t.columns)
    if missing:
        raise ValueError(f"table lacks the columns {sorted(missing)}")
    d = t["toothbrush_s"].to_numpy(float) - t["metawear_s"].to_numpy(float)
    if d.size < 2:
        raise ValueError("table must hold at least two matched peaks")
    return pd.Series(
        {
            "mean": float(d.mean()),
            "sd": float(d.std(ddof=1)),
            "n": float(d.size),
            "max |recomputed - printed|": float(
                np.abs(d - t["difference_s"].to_numpy(float)).max()
            ),
        },
        name="s",
    )
