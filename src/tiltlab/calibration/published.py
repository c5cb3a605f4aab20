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

References
----------
.. [1] C. Q. LaCanna, "Inertial measurement units for tracking human pose and motions:
   testing and calibration", MSc thesis, Rutgers, The State University of New Jersey,
   2018, Tables 2, 3 and 4 and the paragraph after Table 3.
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
