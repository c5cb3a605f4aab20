"""Summaries of a calibration: acceleration norm error and Allan noise terms.

How far a recording's acceleration norm is from 1 g, and the Allan-deviation noise
terms read off a curve set against simulated truth.

Both are the numbers chapter 3 reports; they compute, the chapter narrates.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .._labels import label_columns
from ._util import read_in
from .drift import AllanNoise

__all__ = ["recording_norm_error", "allan_noise_table"]

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
