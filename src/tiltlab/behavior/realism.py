"""Side-by-side activity statistics of recordings.

How a simulated session compares with a real one (:func:`realism_table`), by the
gyroscope or, without one, the accelerometer.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import _validate as _v
from .._labels import label_columns
from ._common import need_gyr, read_behavior_input
from .immobility import acc_immobility
from .speed import NO_GYRO_HINT, gyro_spectrum, recording_speed, speed_modes

__all__ = ["realism_table"]


def realism_table(recs, *, threshold_deg_s: float = 12.0, rule: str = "auto"):
    """Side-by-side activity statistics of several recordings (one column each).

    Rows, with the gyroscope rule: duration; still mode, valley, moving mode and valley
    depth of the angular-speed distribution (:func:`speed_modes` on
    :func:`recording_speed`); fraction of samples below ``threshold_deg_s``;
    percentiles of ‖acc‖ (g), overall and while moving; the largest peak of the
    gyroscope spectrum above 0.5 Hz, its median frequency (half the power above 0.5 Hz
    lies below it) and the share of power above 10 Hz. With the accelerometer rule
    (recordings without a gyroscope): duration, the immobile fraction by
    :func:`~tiltlab.behavior.acc_immobility` (VeDBA) and the ‖acc‖ percentiles, moving
    meaning not immobile by that rule. Percentiles skip samples in gaps (NaN).

    Parameters
    ----------
    recs : mapping of str to xarray.Dataset
        Recordings by column name (units and ``fs`` read from each).
    threshold_deg_s : float
        Gyroscope rule: angular-speed threshold (°/s) separating still and moving
        samples.
    rule : {"auto", "gyroscope", "accelerometer"}
        ``"auto"``: the gyroscope rule when every recording has a gyroscope, else the
        accelerometer rule for all (so that the columns compare like with like).

    Returns
    -------
    pandas.DataFrame
        One row per statistic (its units in its label), one column per recording;
        ``attrs['rule']`` is ``"gyroscope"`` or ``"accelerometer"``, ``attrs["units"]``
        and ``attrs["long_name"]`` label the columns.

    Raises
    ------
    tiltlab._validate.RecordingError
        ``rule="gyroscope"`` with a recording that has no gyroscope.
    """
    threshold_deg_s = _v.positive(threshold_deg_s, "threshold_deg_s")
    if rule not in ("auto", "gyroscope", "accelerometer"):
        raise ValueError(
            f"rule must be 'auto', 'gyroscope' or 'accelerometer', got {rule!r}"
        )
    if rule == "auto":
        rule = (
            "gyroscope" if all("gyr" in r for r in recs.values()) else "accelerometer"
        )
    cols = {}
    for name, rec in recs.items():
        acc = read_behavior_input(rec, "acc", to_units="g", allow_nan=True).values
        an = np.linalg.norm(acc, axis=1)
        fs = float(rec.attrs["fs"])
        if rule == "accelerometer":
            mov = ~np.asarray(acc_immobility(rec), dtype=bool)
            head = {"immobile fraction (VeDBA rule)": float(np.mean(~mov))}
        else:
            need_gyr(rec, "realism_table with rule='gyroscope'", NO_GYRO_HINT)
            sp = np.asarray(recording_speed(rec))
            m = speed_modes(sp)
            mov = sp >= threshold_deg_s
            head = {
                "still mode (deg/s)": m["still_mode"],
                "valley (deg/s)": m["valley"],
                "moving mode (deg/s)": m["moving_mode"],
                "valley depth (rel. to lower mode)": m["depth"],
                f"fraction < {threshold_deg_s:g} deg/s": float(np.mean(~mov)),
            }
        moving = an[mov & np.isfinite(an)]
        col = {
            "duration (s)": an.size / fs,
            **head,
            **{f"|acc| p{p} (g)": np.nanpercentile(an, p) for p in (5, 50, 95)},
            **{
                f"|acc| p{p} moving (g)": np.percentile(moving, p)
                if moving.size
                else np.nan
                for p in (5, 95)
            },
        }
        if rule == "gyroscope":
            f, p = gyro_spectrum(rec)
            band = f > 0.5
            cum = np.cumsum(p[band])
            col["gyro spectral peak (Hz)"] = f[band][np.argmax(p[band])]
            col["gyro median frequency (Hz)"] = f[band][
                np.searchsorted(cum, cum[-1] / 2)
            ]
            col["gyro power share > 10 Hz"] = float(p[f > 10].sum() / p.sum())
        cols[name] = col
    table = label_columns(
        pd.DataFrame(cols),
        units=dict.fromkeys(cols, ""),  # mixed units: each row's are in its label
        long_name={name: str(name) for name in cols},
    )
    table.attrs["rule"] = rule
    return table
