"""Summaries of a calibration: norm error, its band over repeated tests, logs, Allan terms.

How far a recording's acceleration norm is from 1 g, its 5–95 % band per orientation
over repeated tumble tests, a sensor's offsets across calibration dates, and the
Allan-deviation noise terms read off a curve set against simulated truth.

Both are the numbers chapter 3 reports; they compute, the chapter narrates.
"""

from __future__ import annotations

import os
from collections.abc import Iterable

import numpy as np
import pandas as pd

from .._labels import label_columns
from ._util import read_in
from .apply import load_calibration_file
from .drift import AllanNoise

__all__ = [
    "recording_norm_error",
    "allan_noise_table",
    "norm_error_band",
    "calibration_log",
]

#: row labels of :func:`allan_noise_table` (a gyroscope in deg/s)
ALLAN_ROWS = {
    "arw": "angle random walk N (deg/√s)",
    "rrw": "rate random walk K (deg/s/√s)",
    "bias_instability": "bias instability B (deg/s)",
}


def recording_norm_error(data, *, units: str | None = None) -> np.ndarray:
    r"""Distance of the acceleration norm from 1 g, per sample.

    At rest an accelerometer measures gravity alone, so :math:`|1 - \|\mathbf a\||`
    (in g) is the calibration error left in each still sample.

    Parameters
    ----------
    data : xarray.Dataset, xarray.DataArray or array_like (n, 3)
        A Recording (its ``acc`` is used), a labelled acceleration, or a plain array.
    units : str, optional
        Units of a plain array (``"g"`` or ``"m/s^2"``); ``None`` means g. A labelled
        input carries its own ``units`` attribute.

    Returns
    -------
    numpy.ndarray (n,)
        :math:`|1 - \|\mathbf a\||` in g; NaN where a sample is NaN.

    Examples
    --------
    >>> recording_norm_error([[0.0, 0.0, 1.02], [0.0, 0.6, 0.8]]).round(3)
    array([0.02, 0.  ])
    >>> recording_norm_error([[0.0, 0.0, 9.80665]], units="m/s^2")
    array([0.])
    """
    s, _ = read_in(
        data, "acc", "g", var="acc", units=units, need_fs=False, allow_nan=True
    )
    return np.abs(1.0 - np.linalg.norm(s.values, axis=-1))


def _fmt(v) -> str:
    return ", ".join(
        "not found" if np.isnan(x) else f"{x:.2g}" for x in np.atleast_1d(v)
    )


def _recovered(v, truth, rtol: float) -> str:
    v = np.atleast_1d(np.asarray(v, dtype=float))
    if truth is None:  # the term is absent: any value read off the curve is spurious
        return "yes" if np.all(np.isnan(v)) else "no (spurious)"
    return "yes" if np.all(np.abs(v - truth) < rtol * truth) else "no"


def allan_noise_table(
    noise: AllanNoise,
    truth: dict[str, float | None] | None = None,
    *,
    rtol: float = 0.1,
) -> pd.DataFrame:
    """Tabulate the noise terms read off an Allan deviation curve, against their truth.

    Parameters
    ----------
    noise : AllanNoise
        As returned by :func:`allan_noise_parameters` (scalars or one value per axis).
    truth : dict, optional
        True ``"arw"``, ``"rrw"`` and ``"bias_instability"`` (e.g. of a simulation);
        ``None`` (or no key) for a term the data do not contain. Without ``truth`` the table has
        only the values read off the curve.
    rtol : float, default 0.1
        Relative tolerance under which a term counts as recovered (on every axis).

    Returns
    -------
    pandas.DataFrame
        One row per term (:data:`ALLAN_ROWS`), with the columns ``"simulated"`` (the
        true value, or ``"none"``), ``"read off the curve (x, y, z)"`` (two
        significant digits per axis, ``"not found"`` where the curve has no such
        slope) and ``"recovered"`` (``"yes"``, ``"no"``, or ``"no (spurious)"`` for
        an absent term found anyway); the first and last only with ``truth``. Text
        columns, labelled (``attrs["long_name"]``; each row's units are in its label).

    Examples
    --------
    >>> n = AllanNoise(arw=0.0141, bias_instability=0.0012, tau_min=90.0, rrw=2.1e-4)
    >>> t = allan_noise_table(n, {"arw": 0.0141, "rrw": 2e-4, "bias_instability": None})
    >>> t["recovered"].tolist()
    ['yes', 'yes', 'no (spurious)']
    >>> t["simulated"].tolist()
    ['0.014', '0.0002', 'none']
    """
    rtol = float(rtol)
    if not rtol > 0:
        raise ValueError(f"rtol must be positive, got {rtol}")
    terms = list(ALLAN_ROWS)
    read = {"read off the curve (x, y, z)": [_fmt(getattr(noise, k)) for k in terms]}
    if truth is None:
        return _label_allan(pd.DataFrame(read, index=list(ALLAN_ROWS.values())))
    unknown = set(truth) - set(terms)
    if unknown:
        raise ValueError(f"truth has unknown terms {sorted(unknown)}; use {terms}")
    true = [truth.get(k) for k in terms]
    table = pd.DataFrame(
        {
            "simulated": ["none" if t is None else f"{t:.2g}" for t in true],
            **read,
            "recovered": [
                _recovered(getattr(noise, k), t, rtol)
                for k, t in zip(terms, true, strict=True)
            ],
        },
        index=list(ALLAN_ROWS.values()),
    )
    return _label_allan(table)


def _label_allan(table: pd.DataFrame) -> pd.DataFrame:
    """Label the Allan table's columns (text: the units are in the row labels)."""
    names = {
        "simulated": "true value (simulation)",
        "read off the curve (x, y, z)": "read off the Allan deviation (x, y, z)",
        "recovered": "recovered within the tolerance",
    }
    return label_columns(
        table,
        units=dict.fromkeys(table.columns, ""),
        long_name={c: names[c] for c in table.columns},
    )


def norm_error_band(
    means,
    offsets=None,
    *,
    percentiles: tuple[float, float] = (5.0, 95.0),
) -> pd.DataFrame:
    r"""Summarise the norm error of each orientation over repetitions of a tumble test.

    For repetition :math:`r` and orientation :math:`p`, the error is
    :math:`e_{rp} = |1 - \|\bar{\mathbf a}_{rp} - \mathbf o_r\||` (g), with
    :math:`\bar{\mathbf a}_{rp}` the mean acceleration of the hold and
    :math:`\mathbf o_r` the offset removed (none without ``offsets``). Each orientation
    gets the median and the two percentiles of its errors over the repetitions: the
    band of Fayat et al.'s Fig. 1b.

    Parameters
    ----------
    means : array_like (n_repeats, n_orientations, 3)
        Mean acceleration (g) of every hold of every repetition, orientations in the
        same order in each repetition.
    offsets : array_like (3,) or (n_repeats, 3), optional
        Accelerometer offsets (g) removed before the norm: one for all repetitions or
        one per repetition (e.g. each repetition's own fit). ``None``: raw errors.
    percentiles : tuple of two floats, default (5, 95)
        Lower and upper percentiles of the band (0–100, lower first).

    Returns
    -------
    pandas.DataFrame
        One row per orientation (index ``orientation``, 0-based), columns ``"median"``,
        ``"low"`` and ``"high"`` in g (``attrs["units"]``, ``attrs["long_name"]``,
        ``attrs["percentiles"]``).

    References
    ----------
    Fayat R. et al. (2021) Inertial measurement of head tilt in rodents: principles and
    applications to vestibular research. Sensors 21, 6318. doi:10.3390/s21186318

    Examples
    --------
    >>> import numpy as np
    >>> means = np.array([[[0, 0, 1.02], [0, 0.99, 0]], [[0, 0, 1.04], [0, 0.97, 0]]])
    >>> norm_error_band(means, percentiles=(0, 100)).round(3).values.tolist()
    [[0.03, 0.02, 0.04], [0.02, 0.01, 0.03]]
    >>> norm_error_band(means, [0.0, 0.0, 0.03])["median"].round(3).tolist()
    [0.01, 0.02]
    """
    m = np.asarray(means, dtype=float)
    if m.ndim != 3 or m.shape[2] != 3 or m.shape[0] < 1 or m.shape[1] < 1:
        raise ValueError(
            f"means must have shape (n_repeats, n_orientations, 3), got shape {m.shape}"
        )
    if not np.all(np.isfinite(m)):
        raise ValueError(f"means has {int(np.sum(~np.isfinite(m)))} non-finite values")
    lo, hi = (float(p) for p in percentiles)
    if not 0 <= lo < hi <= 100:
        raise ValueError(
            f"percentiles must be two numbers with 0 <= low < high <= 100, got {percentiles!r}"
        )
    o = np.zeros(3) if offsets is None else np.asarray(offsets, dtype=float)
    if o.shape not in ((3,), (m.shape[0], 3)) or not np.all(np.isfinite(o)):
        raise ValueError(
            f"offsets must be 3 finite numbers or one row of 3 per repetition "
            f"({m.shape[0]}, 3), got shape {o.shape}"
        )
    o = np.broadcast_to(o, (m.shape[0], 3))[:, None, :]
    err = np.abs(1.0 - np.linalg.norm(m - o, axis=-1))  # (n_repeats, n_orientations)
    band = pd.DataFrame(
        {
            "median": np.median(err, axis=0),
            "low": np.percentile(err, lo, axis=0),
            "high": np.percentile(err, hi, axis=0),
        },
        index=pd.RangeIndex(m.shape[1], name="orientation"),
    )
    what = "|1 - ‖a‖| over repetitions"
    band = label_columns(
        band,
        units="g",
        long_name={
            "median": f"median {what}",
            "low": f"{lo:g}th percentile of {what}",
            "high": f"{hi:g}th percentile of {what}",
        },
    )
    band.attrs["percentiles"] = [lo, hi]
    return band


#: columns of :func:`calibration_log`: (Calibration field, info key of its stderr, units)
_LOG_SENSORS = {"acc": "g", "gyr": "deg/s"}


def calibration_log(paths: Iterable[str | os.PathLike]) -> pd.DataFrame:
    """Collect saved calibrations of one sensor into a table of offsets by date.

    Each file is read with :func:`load_calibration_file` (so an edited file is
    refused) and dated by its provenance, ``info["date"]`` (an ISO date such as
    ``"2021-03-14"``, stored when the calibration is saved). Offsets kept by the
    calibration, and their standard errors when its ``info`` has them
    (``"acc_offset_stderr"``, ``"gyr_offset_stderr"``, as written by
    :func:`tumble_calibration`), become columns.

    Parameters
    ----------
    paths : iterable of str or path-like
        Files written by :func:`save_calibration_file`, in any order.

    Returns
    -------
    pandas.DataFrame
        One row per file, sorted by date (index ``date``, datetime64), with columns
        ``acc_offset_x`` … ``gyr_offset_z`` (g, °/s), ``*_stderr`` for each offset with a
        standard error, ``name`` and ``file``; labelled (``attrs["units"]``,
        ``attrs["long_name"]``). A sensor none of the files calibrates has no columns.

    Raises
    ------
    ValueError
        No paths, or a file whose ``info`` has no valid ``"date"``.

    Examples
    --------
    >>> import dataclasses, tempfile
    >>> from pathlib import Path
    >>> from tiltlab import calibration
    >>> folder = Path(tempfile.mkdtemp())
    >>> paths = [
    ...     calibration.save_calibration_file(
    ...         calibration.Calibration(
    ...             acc_offset=[0.01 * k, 0, 0], info={"date": f"2021-0{k}-01"}
    ...         ),
    ...         folder / f"cal{k}.json",
    ...     )
    ...     for k in (3, 1, 2)
    ... ]
    >>> log = calibration_log(paths)
    >>> log.index.strftime("%m").tolist(), log["acc_offset_x"].tolist()
    (['01', '02', '03'], [0.01, 0.02, 0.03])
    """
    rows = []
    for p in paths:
        cal = load_calibration_file(p)
        date = cal.info.get("date")
        try:
            stamp = pd.Timestamp(date) if isinstance(date, str) else None
        except ValueError:
            stamp = None
        if stamp is None:
            raise ValueError(
                f"{p}: the calibration's info has no valid 'date' (got {date!r}); save "
                "it with info={'date': 'YYYY-MM-DD', ...}"
            )
        row = {"date": stamp, "name": cal.name, "file": str(p)}
        for s in _LOG_SENSORS:
            off = getattr(cal, f"{s}_offset")
            if off is None:
                continue
            se = cal.info.get(f"{s}_offset_stderr")
            for i, ax in enumerate("xyz"):
                row[f"{s}_offset_{ax}"] = off[i]
                if se is not None:
                    row[f"{s}_offset_{ax}_stderr"] = float(se[i])
        rows.append(row)
    if not rows:
        raise ValueError("paths must name at least one calibration file, got none")
    log = pd.DataFrame(rows).set_index("date").sort_index(kind="stable")
    cols = [c for c in log.columns if c.startswith(("acc_", "gyr_"))]
    log = log[cols + ["name", "file"]]
    units = {c: _LOG_SENSORS[c[:3]] for c in cols}
    names = {
        c: ("standard error of the " if c.endswith("_stderr") else "")
        + f"{'accelerometer' if c[:3] == 'acc' else 'gyroscope'} offset, {c.split('_')[2]} axis"
        for c in cols
    }
    return label_columns(
        log,
        units={**units, "name": "", "file": ""},
        long_name={**names, "name": "calibration name", "file": "calibration file"},
    )
